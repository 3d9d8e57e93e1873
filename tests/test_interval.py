"""The `interval` method: F's enclosure over a ray segment, and the march that skips by it.

- The enclosure (implc/interval.py), evaluated in float64 by implc/numeric.py: on random
  segments of random rays it holds every sampled value of F, for every function rule
  (sin/cos across their extrema, tan across a pole, even and odd powers, division by an
  interval holding 0, real roots, min/max/abs, exp/log/sqrt domains).
- The shader (GL, through the library's intersect): rays through a shell 0.001 thick
  and grazing it, rays at a CSG cube's edges and corners and
  through the crease of a union, against their first roots in closed form.
- Every non-polynomial bundled example against the CPU reference, and refusals.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy
from cases import EXAMPLES
from conftest import require_gl
from gl_rays import intersect

from implc.cli import main
from implc.derive import polynomial_degree
from implc.errors import InputError
from implc.interval import DIRECTION, ORIGIN, TINY, ULP, WIDENING, A, B, range_program
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.metrics import compare
from implc.numeric import evaluate, evaluate_program
from implc.render.run import render
from implc.symbols import POINT

NON_POLYNOMIAL = [e for e in EXAMPLES if polynomial_degree(load_surface(e).expr) is None]

# Each rule's cases: the shell and CSG surfaces of the shader tests, and expressions that
# cross each function's extrema, poles and domain ends on rays of length up to 8.
ENCLOSED = [
    "sin(3x) cos(3y) + sin(3y) cos(3z) + sin(3z) cos(3x)",
    "cos(4x) - sin(5y) + sin(x y z)",
    "tan(x + y) - z",
    "x^4 - y^3 z + (x - y)^2 - 1",
    "1/(x^2 + y^2 - 0.5) - z",
    "x/(y - 0.3) + z",
    "x^(1/3) + y^(2/3) - z",
    "sqrt(x^2 + y) - log(z + 1) - 1",
    "exp(-x^2 - y^2) - asin(z/3) + acos(y/2) - atan(x)",
    "sinh(x) - cosh(y) + tanh(z) + sign(x - y)",
    "max(max(abs(x), abs(y)), abs(z)) - 0.5",
    "min(x^2 + y^2 + z^2 - 1, (x - 1)^2 + y^2 + z^2 - 1)",
    "abs(x^2 + y^2 + z^2 - 1) - 0.001",
]


@pytest.mark.parametrize("equation", ENCLOSED)
def test_enclosure_holds_every_value_of_f(equation):
    expr = load_surface(equation=equation).expr
    program = range_program(expr)
    rng = np.random.default_rng(7)
    rays = 400
    origin = rng.uniform(-2, 2, (rays, 3))
    direction = rng.normal(size=(rays, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    a = rng.uniform(-4, 4, rays)
    b = a + rng.choice([1e-4, 1e-2, 0.3, 4.0], rays)
    env = {A: a, B: b, ULP: WIDENING["double"][0], TINY: WIDENING["double"][1]}
    env.update({s: origin[:, i] for i, s in enumerate(ORIGIN)})
    env.update({s: direction[:, i] for i, s in enumerate(DIRECTION)})
    lo, hi = evaluate_program(program.assignments, [program.lo, program.hi], env)
    s = a[:, None] + (b - a)[:, None] * np.linspace(0, 1, 257)[None, :]
    points = origin[:, None, :] + s[..., None] * direction[:, None, :]
    values = evaluate(expr, {v: points[..., i] for i, v in enumerate(POINT)})
    defined = np.isfinite(values)
    below = defined & (values < lo[:, None])
    above = defined & (values > hi[:, None])
    assert not below.any() and not above.any(), (
        f"{below.sum() + above.sum()} sampled values outside the enclosure; first on ray "
        f"{np.argwhere(below | above)[0][0]}")
    # and it is not vacuous: most enclosures of short segments are finite and narrow
    short = (b - a) <= 1e-2
    width = (hi - lo)[short]
    assert np.median(width[np.isfinite(width)]) < 1.0


def _shell_rays():
    """Rays along x at height y through |r^2 - 1| - 0.001 = 0 (a shell from radius
    sqrt(0.999) to sqrt(1.001), 0.001 thick), with the first root in closed form."""
    outer = math.sqrt(1.001)
    rays, expected = [], []
    for y in (0.0, 0.3, 0.9, 0.999, 1.0, 1.0003, 1.00045):  # the last ones graze it
        rays.append(((-2.0, y, 0.0), (1, 0, 0), 0.0, 4.0))
        expected.append(2.0 - math.sqrt(outer**2 - y * y))
    for y in (1.0006, 1.01):  # above the shell: no root
        rays.append(((-2.0, y, 0.0), (1, 0, 0), 0.0, 4.0))
        expected.append(None)
    return rays, expected


def _check(got, expected, tol=2e-4):
    for i, ((hit, t), want) in enumerate(zip(got, expected, strict=True)):
        if want is None:
            assert hit == 0.0, f"ray {i}: a hit at t = {t}, expected none"
        else:
            assert hit == 1.0, f"ray {i}: no hit, expected t = {want}"
            assert abs(t - want) <= tol, f"ray {i}: t = {t}, expected {want}"


def test_thin_shell_and_grazing_rays_are_found():
    require_gl()
    rays, expected = _shell_rays()
    surface = load_surface(equation="abs(x^2 + y^2 + z^2 - 1) - 0.001")
    _check(intersect(surface, "interval", rays), expected)


def test_csg_edges_corners_and_creases():
    require_gl()
    cube = load_surface(equation="max(max(abs(x), abs(y)), abs(z)) - 0.5")
    rays = [((-2.0, 0.5, 0.0), (1, 0, 0), 0.0, 4.0),      # along an edge of a face
            ((-2.0, 0.4999, 0.4999), (1, 0, 0), 0.0, 4.0),  # just inside a corner edge
            ((-2.0, -2.0, -2.0), (1, 1, 1), 0.0, 6.0),      # into the corner
            ((-2.0, 0.5001, 0.0), (1, 0, 0), 0.0, 4.0)]     # just outside: no root
    expected = [1.5, 1.5, math.sqrt(3) * 1.5, None]
    _check(intersect(cube, "interval", rays), expected)
    union = load_surface(equation="min(x^2 + y^2 + z^2 - 1, (x - 1.5)^2 + y^2 + z^2 - 1)")
    # down through the crease where the two spheres meet (x = 0.75, y^2 + z^2 = 0.4375)
    crease = math.sqrt(0.4375)
    rays = [((0.75, 2.0, 0.0), (0, -1, 0), 0.0, 4.0),
            ((0.75, 2.0, crease - 1e-4), (0, -1, 0), 0.0, 4.0)]
    got = intersect(union, "interval", rays)
    want0 = 2.0 - crease
    want1 = 2.0 - math.sqrt(1 - 0.75**2 - (crease - 1e-4) ** 2)
    _check(got, [want0, want1])


@pytest.mark.parametrize("example", NON_POLYNOMIAL)
def test_interval_matches_the_reference(example):
    require_gl()
    surface = load_surface(example)
    size = 96
    reference = render(surface, "reference", "", METHODS["taylor"].defaults, size, size)
    result = render(surface, "gl", "interval", METHODS["interval"].defaults, size, size)
    m = compare(result, reference)
    assert m["false_hits"] == 0 and m["missed_hits"] == 0, m
    assert m["wrong_root"] <= 0.001 * size * size, m


def test_a_function_without_a_rule_is_refused(tmp_path, capsys):
    out = tmp_path / "a.frag"
    code = main(["compile", "-e", "atan2(y, x) - z", "-m", "interval", "-o", str(out)])
    assert code == 1 and not out.exists()
    assert "no interval rule for 'atan2'" in capsys.readouterr().err
    with pytest.raises(InputError, match="variable exponent"):
        range_program(sympy.Pow(POINT[0], POINT[1]))


def test_show_says_what_a_node_encloses(capsys):
    assert main(["show", "gyroid", "-m", "interval"]) == 0
    assert "interval: per node, the enclosure of F and F' over the segment" in \
        capsys.readouterr().out
    # sign's derivative is a delta: no F' enclosure, no monotonic test
    assert main(["show", "-e", "sign(x) + y^2 + z^2 - 1", "-m", "interval"]) == 0
    assert "no monotonic test" in capsys.readouterr().out
