"""Method variants: every --taylor2 reading compiles on every target, and implc's
extremum test finds exactly the reference's roots on the paper surfaces.

Measured at 512^2 (hessian, b = 0.002): extremum has 0 false, 0 missed, 0 wrong-root
pixels on the Cross-Cap, Miter and Steiner, where Eq. 4 as printed misses 26 / 6 / 2.
At the test's 128^2 the same holds; the thresholds allow one pixel of float32 slack.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from cases import PAPER
from conftest import require_gl

from implc.emit import emit
from implc.loaders import load_surface
from implc.methods import CONSTANT_SYMBOLS, D0, F0, METHODS, TAYLOR2_CHOICES, X0, interval_test
from implc.metrics import compare
from implc.numeric import evaluate
from implc.render.run import render
from implc.targets import get_target
from implc.validate import validate_text

SIZE = 128


@pytest.mark.parametrize("target", ["glsl", "wgsl", "opencl"])
@pytest.mark.parametrize("method", ["hessian", "hessian-approx"])
@pytest.mark.parametrize("taylor2", TAYLOR2_CHOICES)
def test_every_taylor2_reading_validates(target, method, taylor2):
    constants = METHODS[method].constants(taylor2=taylor2)
    text = emit(load_surface("cross-cap"), target, method, constants)
    assert ("extremum of each end" in text) == (taylor2 == "extremum")
    verdict = validate_text(text, target, f"cross-cap.{taylor2}.{target}")
    assert verdict.ok, verdict.render(f"cross-cap.{taylor2}")


@pytest.mark.parametrize("example", PAPER)
def test_extremum_matches_the_exact_reference(example):
    require_gl()
    surface = load_surface(example)
    ref = render(surface, "reference", "hessian", METHODS["hessian"].defaults, SIZE, SIZE)
    paper = compare(render(surface, "gl", "hessian", METHODS["hessian"].defaults, SIZE, SIZE),
                    ref)
    constants = METHODS["hessian"].constants(taylor2="extremum")
    ours = compare(render(surface, "gl", "hessian", constants, SIZE, SIZE), ref)
    assert ours["false_hits"] <= 1 and ours["missed_hits"] <= 1 and ours["wrong_root"] <= 1, ours
    assert ours["missed_hits"] <= paper["missed_hits"]
    assert ours["ssim"] >= paper["ssim"] - 1e-4
    assert ours["mean_steps"] == pytest.approx(paper["mean_steps"], rel=1e-3)  # no extra cost


@pytest.mark.parametrize("target", ["glsl", "wgsl", "opencl"])
def test_min_and_max_print_as_balanced_trees(target):
    """A root test's min/max over four values is two levels deep, not three: the march
    loop is bound by its dependency chain (docs/journal/2026-12-01-marcher-and-forms.md)."""
    a, b, c, d, e = sympy.symbols("a b c d e", real=True)
    printer = get_target(target).printer()
    name = printer.known_functions["Max"]
    four = printer.doprint(sympy.Max(a, b, c, d))
    assert four == f"{name}({name}(a, b), {name}(c, d))"
    five = printer.doprint(sympy.Max(a, b, c, d, e))
    assert five == f"{name}({name}({name}(a, b), c), {name}(d, e))"


@pytest.mark.parametrize("target", ["glsl", "wgsl", "opencl"])
def test_root_test_takes_the_end_sample_last(target):
    """The end sample (F1, F1') is what a march step computes last: F1 is one comparison
    from the root test's answer, F1' one product (optimize.arrange_by_depth), and the
    values free of F1 are one min (docs/journal/2026-12-01-marcher-and-forms.md)."""
    printer = get_target(target).printer()
    sign, high = printer.known_functions["sign"], printer.known_functions["Max"]
    for method in ("taylor", "hessian"):
        text = emit(load_surface("cross-cap"), target, method, METHODS[method].defaults)
        line = next(t for t in text.splitlines() if f"f1.x*{sign}(f0.x) <= " in t)
        assert f"f1.x*{sign}(f0.x) <= {high}({printer.float_literal(0.0)}, " in line, line
        # f1.y is its product's last factor (left to right: multiplied last), once
        assert "*f1.y" in line and "f1.y*" not in line and line.count("f1.") == 2, line


def test_interval_test_is_zero_in_min_max():
    """The root tests' form, min(sign(F0) v) <= 0 over the values free of F1 or
    sign(F0) F1 <= max(0, -sign(F0) w) over those that are F1 + w, is the paper's
    0 in [min, max] of F0, q, r = F1 + w rounded to float32, and F1: on values with
    zeros, ties, cancellations and signs mixed."""
    rng = np.random.default_rng(3)
    n = 40000
    picks = rng.choice([-2.0, -1e-30, 0.0, 1e-30, 0.5, 3.0], size=(4, n))
    spread = rng.normal(size=(4, n)) * 10.0 ** rng.integers(-8, 3, size=(4, n))
    f0, q, f1, w = np.where(rng.random((4, n)) < 0.5, picks, spread).astype(np.float32)
    w[: n // 8] = -f1[: n // 8]  # r rounds to exactly 0
    w[n // 8: n // 4] = np.nextafter(-f1, np.float32(0))[n // 8: n // 4]  # r a hair off 0
    r = f1 + w  # float32, rounded
    a, b, c, d = sympy.symbols("a b c d", real=True)
    test = interval_test(a, b, c + d, c, late=c)
    assert isinstance(test, sympy.Or) and len(test.args) == 2
    env = dict(zip((a, b, c, d), (x.astype(np.float64) for x in (f0, q, f1, w)), strict=True))
    got = np.zeros(n, dtype=bool)
    for part in test.args:  # each a <=, its sides exact in float64 on float32 inputs
        got |= evaluate(part.lhs, env) <= evaluate(part.rhs, env)
    values = np.stack([f0, q, r, f1])
    want = (values.min(axis=0) <= 0) & (values.max(axis=0) >= 0)
    assert (got == want).all(), int((got != want).sum())
    assert want.any() and not want.all()


def test_step_rules_read_only_the_start_sample():
    """A step rule reads the carried start sample (F0, F0', X0) and constants, never a ray
    quantity of its own: one evaluated inside the rule sits on the march loop's chain
    (the `sign` method's lazy F' measured 10-40 % a frame)."""
    for method in METHODS.values():
        if method.solves:
            continue
        calls = [a for a in sympy.preorder_traversal(method.step)
                 if isinstance(a, sympy.core.function.AppliedUndef)]
        assert not calls, (method.name, calls)
        assert method.step.free_symbols <= {F0, D0, X0, *CONSTANT_SYMBOLS}, method.name
