"""exact in float32 where S's monomials do not fit float32 (issue 48): S at the point in
Chebyshev's basis of the surface's box (implc/chebyshev.py) and Newton's last steps on it
(solver.POLISH_STEPS).

The picture is counted against the certified float64 reference: Chmutov's T_12 written in
monomials, 192^2, at most 0.01 % of the pixels bad (false + missed + wrong root). Before
this change the float32 program had 24 bad pixels there on gl and on wgpu (0.065 %); now
1-2. Chmutov's T_16 at the same size: 18 on gl with F expanded once about the chord's
middle, 1 where a node in doubt is decided on F re-expanded about its own middle
(solver.RECENTER_TOL). Chmutov's T_18 framed: 8 wrong roots on gl with Newton's slope from the
ray's coefficients, 0 from the gradient at the point. Chmutov's T_19: 19 wrong roots on gl where a
root node in doubt was taken as it came, 1 where it is re-expanded too."""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from cases import chmutov
from conftest import require_backend

from implc.chebyshev import chebyshev_program, chebyshev_ray_program, surface_box
from implc.emit import emit
from implc.framing import frame
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.metrics import compare
from implc.numeric import evaluate, evaluate_program
from implc.raypoly import coefficient_program
from implc.render.run import render
from implc.symbols import DIRECTION, POINT

SIZE = 192
BAD_SHARE = 1e-4  # the bound: 0.01 % of the pixels


@pytest.fixture(scope="module", params=[(12, False), (16, False), (18, True), (19, False)],
                ids=lambda p: f"T{p[0]}" + ("-framed" if p[1] else ""))
def chmutov_reference(request):
    """T_12: S's monomials do not fit float32, its Chebyshev form does. T_16: besides, the
    chord's power series rounds to more than F near roots at the box's edge (a root pair
    skipped, a later root taken); re-expanded about a node in doubt it holds. T_18 framed
    as every command frames it: besides, Newton's slope from the ray's coefficients rounds
    so far off that its NEWTON_STEPS end short of the root (8 wrong roots on gl); from the
    gradient it converges. T_19: besides, a root node whose rounded coefficients change
    sign once may hold three roots (Newton took the last: 19 wrong roots on gl); decided
    on F re-expanded about its own middle, 1."""
    degree, framed = request.param
    surface = load_surface(equation=chmutov(degree))
    if framed:
        surface = frame(surface)[0]
    return surface, render(surface, "reference", "", METHODS["taylor"].defaults, SIZE, SIZE)


@pytest.mark.parametrize("backend", ["gl", "wgpu"])
def test_exact_in_float32_is_right_on_chmutov(chmutov_reference, backend):
    require_backend(backend)
    surface, reference = chmutov_reference
    result = render(surface, backend, "exact", METHODS["exact"].defaults, SIZE, SIZE)
    m = compare(result, reference)
    bad = m["false_hits"] + m["missed_hits"] + m["wrong_root"]
    assert bad <= BAD_SHARE * SIZE * SIZE, m


@pytest.mark.parametrize("degree", [12, 13])  # even series; odd ones (third kind)
def test_clenshaw_programs_are_s_and_its_ray_coefficients(degree):
    """The Chebyshev programs are S and the ray's coefficients: float64 values agree with
    S's and with Horner's route's at random points and directions to float64's rounding
    of their terms."""
    expr = load_surface(equation=chmutov(degree)).expr
    program, ray = chebyshev_program(expr), chebyshev_ray_program(expr)
    assert program is not None and ray is not None
    rng = np.random.default_rng(7)
    points = rng.uniform(-1.4, 1.4, (3, 500))
    directions = rng.normal(size=(3, 500))
    directions /= np.linalg.norm(directions, axis=0)
    env = {**dict(zip(POINT, points, strict=True)),
           **dict(zip(DIRECTION, directions, strict=True))}
    (value,) = evaluate_program(program.assignments, program.outputs, env)
    exact = evaluate(expr, env)
    assert np.max(np.abs(value - exact) / (1 + np.abs(exact))) < 1e-9
    horner = coefficient_program(expr, "double")
    for mine, theirs in zip(evaluate_program(ray.assignments, ray.outputs, env),
                            evaluate_program(horner.assignments, horner.outputs, env),
                            strict=True):
        assert np.max(np.abs(mine - theirs) / (1 + np.abs(theirs))) < 1e-8


def test_clenshaw_in_float32_holds_t20_where_monomials_do_not():
    """On points of T_20's surface, float32 Clenshaw moves it by less than 1e-5 (90th
    percentile), S's monomials in float32 by more than 1e-3 at some of them."""
    expr = load_surface(equation=chmutov(20)).expr
    program = chebyshev_program(expr)
    assert program is not None
    rng = np.random.default_rng(3)
    y, z = rng.uniform(-1.0, 1.0, (2, 4000))
    t20 = np.polynomial.chebyshev.Chebyshev.basis(20)
    rhs = -(t20(y) + t20(z))
    keep = np.abs(rhs) <= 1
    y, z, rhs = y[keep], z[keep], rhs[keep]
    x = np.cos(np.arccos(rhs) / 20)  # T_20(x) = rhs: a point of the surface
    points = [v.astype(np.float32) for v in (x, y, z)]
    slope = np.sqrt(sum(t20.deriv()(v.astype(np.float64)) ** 2 for v in points))
    (clenshaw,) = evaluate_program(program.assignments, program.outputs,
                                   dict(zip(POINT, points, strict=True)), real=np.float32)
    terms = sympy.Poly(expr, *POINT).terms()
    monomials = np.zeros_like(points[0])
    for exponents, c in terms:  # S as written, term by term, in float32
        term = np.float32(float(c)) * np.prod(
            [p ** np.float32(e) for p, e in zip(points, exponents, strict=True)], axis=0)
        monomials = (monomials + term.astype(np.float32)).astype(np.float32)
    exact = sum(t20(v.astype(np.float64)) for v in points)
    assert np.quantile(np.abs(clenshaw - exact) / slope, 0.9) < 1e-5
    assert np.max(np.abs(monomials - exact) / slope) > 1e-3


def test_well_conditioned_monomials_are_kept():
    """The sums of powers keep S as written (no gain), so does a float32 program of
    degree below ROBUST_NEWTON_BELOW, and the double programs."""
    powers = load_surface(equation="x^12 + y^12 + z^12 - 1").expr
    assert surface_box(powers) is None
    t12 = load_surface(equation=chmutov(12))
    double = emit(t12, "glsl", "exact", METHODS["exact"].defaults, precision="double")
    single = emit(t12, "glsl", "exact", METHODS["exact"].defaults)
    assert "k0" in single and "k0" not in double
