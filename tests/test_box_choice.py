"""The plain-Python choice of Chebyshev's box (implc/box_choice.py on implc/plain_extent.py's
sampling), which a compile without numpy makes, against numpy's (implc/box_numpy.py on
implc/extent.py's): the same quantiles to the bit, the same search, the same box, so the
float32 exact program's bytes do not depend on numpy (issue 48; tests/test_numpy_free.py
compares the programs; scripts/box_choice_check.py the corpus's rows of degree 7 and
more: 40 surfaces, 14 with a box, all the same)."""

from __future__ import annotations

import random

import numpy as np
import pytest
from cases import chmutov

from implc import box_numpy, plain_extent
from implc.box_choice import QUANTILES, quantile
from implc.chebyshev import _plain_box
from implc.extent import locate_surface, sign_changes
from implc.loaders import load_surface


def test_quantile_is_numpys_to_the_bit():
    rng = random.Random(48)
    for n in (1, 2, 3, 7, 100, 1501):
        values = [rng.lognormvariate(0, 3) for _ in range(n)] + [1.0] * (n % 3)
        for q in (*QUANTILES, 0.1, 1 / 3, 0.999):
            assert quantile(values, q) == float(np.quantile(values, q)), (n, q)


# a sum of monomials (contracted as written) and a polynomial written otherwise (its
# expanded form, checked against the walker where its rounding could decide a sign)
SEARCHED = {"chmutov7": chmutov(7), "factored": "(x^2 + y^2 + z^2 - 1)*(x^2 + y^2/4 - z)"
            " + x^7/10 = 0"}


@pytest.mark.parametrize("name", SEARCHED)
def test_the_plain_search_finds_numpys_sign_changes(name):
    expr = load_surface(equation=SEARCHED[name]).expr
    extent = locate_surface(expr)
    assert plain_extent.locate(expr) == (extent.center, extent.radius)
    points, spacing, touching = sign_changes(expr, np.asarray(extent.center), extent.radius)
    plain, plain_spacing, plain_touching = plain_extent.sign_changes(
        expr, extent.center, extent.radius)
    assert (plain_spacing, plain_touching) == (spacing, touching)
    assert len(plain) == len(points) > 100  # in numpy's order, an ulp or so apart
    assert np.abs(np.array(plain) - points).max() <= 1e-12 * extent.radius


@pytest.mark.parametrize("n", [8, 9])  # Chmutov's T_8 has a box, T_9's monomials are kept
def test_the_plain_box_is_numpys(n):
    expr = load_surface(equation=chmutov(n) if n == 8 else "x^9 + y^9 + z^9 - 1 = 0").expr
    box = box_numpy.surface_box(expr)
    assert (box is not None) == (n == 8)
    assert _plain_box(expr) == box


# the search's rarer branches: a surface smaller than a cell of the first cube (shrinking
# cubes), one thinner than a cell (grown until clear of the clip sphere), one whose arms
# still pierce the grown sphere (unbounded), none at all
BRANCHES = ("(x-0.37)^2 + (y+0.21)^2 + z^2 - 0.0003 = 0", "x^2/100 + y^2 + z^2/0.01 = 1",
            "6x^2 - 2x^4 = y^2 z^2", "x^2 + y^2 + z^2 + 1 = 0")


@pytest.mark.parametrize("equation", BRANCHES)
def test_the_plain_search_takes_numpys_branches(equation):
    expr = load_surface(equation=equation).expr
    extent = locate_surface(expr)
    assert plain_extent.locate(expr) == (None if extent is None
                                         else (extent.center, extent.radius))
