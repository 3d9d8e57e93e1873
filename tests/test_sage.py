"""A real SageMath expression as input: passagemath-symbolics (the `sage` extra, a 1 GB
install that also brings gmpy2, which changes sympy's ground types, so it is not in the
test extra). Skipped with the reason where it is absent; the `_sympy_()` protocol itself is
tested without it in tests/test_api.py.

Run it with `pip install -e '.[sage]'` (or `pip install --target DIR passagemath-symbolics`
and DIR on PYTHONPATH)."""

from __future__ import annotations

import pytest

import implc
from implc.errors import InputError

sage = pytest.importorskip(
    "sage.all__sagemath_symbolics",
    reason="passagemath-symbolics is not installed (the optional `sage` extra)")

CROSS_CAP = "4x^2(x^2+y^2+z^2+z) + y^2(y^2+z^2-1) = 0"


def test_a_sage_expression_is_the_same_surface_as_its_text():
    x, y, z = sage.var("x y z")
    expr = 4 * x**2 * (x**2 + y**2 + z**2 + z) + y**2 * (y**2 + z**2 - 1)
    assert type(expr).__module__.startswith("sage.")
    text = implc.Surface(CROSS_CAP).compile().text
    assert implc.Surface(expr).compile().text == text
    assert implc.Surface(expr == 0).compile().text == text  # a Sage relation: an equation


def test_sage_parameters_values_and_messages():
    x, y, z, a = sage.var("x y z a")
    ball = implc.Surface(x**2 + y**2 + z**2 - a, params={"a": sage.QQ(1) / 4})
    assert ball.params == {"a": 0.25} and ball.degree == 2
    assert implc.Surface(sage.sin(x) + y**2 + z**2 - 1).default_method == "interval"
    with pytest.raises(InputError, match="unknown function 'besselj'") as err:
        implc.Surface(sage.bessel_J(0, x) + y + z)
    assert "^" in str(err.value)  # the caret, in the message a notebook shows
