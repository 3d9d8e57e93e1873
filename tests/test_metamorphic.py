"""Metamorphic render tests (in the spirit of GraphicsFuzz): two inputs whose pictures
must agree by construction, rendered on every target (GL, wgpu, OpenCL float) at 48².

Which relations are exact, and why:

- S and -S (sign, taylor, hessian, hessian-approx): each step rule and root test depends
  only on |F|, |F'| and whether 0 lies in an interval whose ends all change sign, and the
  refinement's Newton step F/F' is unchanged. Where the -S program is the term-by-term
  negation of the S program (the Cross-Cap: CSE picks the same temporaries, and float
  negation is exact) every value changes sign exactly, so hit mask and t agree bit for
  bit. Where CSE picks other temporaries for -S (the Steiner surface's gradient: 2x, 2y,
  2z instead of 2y and yz) F' rounds differently: t within T_TOL, masks within
  EDGE_PIXELS boundary pixels (measured: identical masks, t within 1 ulp).
  The *colour* is not compared: the front/back side is chosen by the sign of grad(S).D.
  Not `curvature`: its step is b/2 where -ΔS < 0 and 2b elsewhere, and -ΔS changes sign
  with S, so -S marches with other steps (measured: 8 of 2304 pixels differ at 48²).
- S and c·S, c > 0: the root tests (sign of a product, 0 in an interval) and the
  curvature rule (sign of -ΔS) are scale-free, but Eq. 2 compares |F| with tau1, tau2 and
  |F'| with tau3, so c·S takes other steps unless the thresholds are scaled by c too:
  compared with tau_i -> c·tau_i (curvature has no tau). Exact in real arithmetic; in
  float32, sympy distributes c over the sum (c·S is not printed as c*(S)), which rounds
  differently, so a ray that grazes the surface may decide otherwise: the masks may
  differ on boundary pixels only (a pixel with a differently-hit 4-neighbour), at most
  EDGE_PIXELS of them, and t within T_TOL where both hit. Measured: 0 pixels differ.
- A surface and its rotated or translated copy, with the camera (eye, target, up, clip
  centre) moved alike: the same rays relative to the surface, so the same picture, up to
  float rounding of the moved coordinates (the lights are fixed to the camera, so the
  shading moves with it): hit masks within EDGE_PIXELS boundary pixels, colour within
  COLOR_TOL where both hit. The rotation is a cyclic permutation of the axes and the
  translation dyadic, so the moved camera is exact. Measured: 0 pixels, |dcolour| < 2e-5.
- One polynomial spelled two ways that the parser keeps apart (factored and expanded,
  `x^2(...)` and `x(x ...)`, a sum grouped otherwise): different shader text, so other
  float32 rounding; hit masks within EDGE_PIXELS boundary pixels and t within T_TOL.
  (Rewrites the parser folds into the same tree, `+ 0*x^3` or `(x*y)^2` for `x^2y^2`,
  are pinned as equal trees in tests/test_parse.py: no render can tell them apart.)
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from conftest import require_backend

from implc.loaders import load_surface
from implc.methods import METHODS
from implc.render.run import render
from implc.scene import View
from implc.surface import Surface
from implc.symbols import X, Y, Z

SIZE = 48
EDGE_PIXELS = 4  # of 2304: a few grazing rays, only on the mask's boundary
T_TOL = 1e-4
COLOR_TOL = 2e-3
BACKENDS = ("gl", "wgpu", "cl")
SURFACES = ("cross-cap", "steiner")
EXACT_NEGATION = {"cross-cap"}  # its -S program is the S program with every sign flipped


def frame(surface: Surface, backend: str, method: str, **constants):
    return render(surface, backend, method, METHODS[method].constants(**constants), SIZE, SIZE)


def boundary(hit: np.ndarray) -> np.ndarray:
    """Pixels with a 4-neighbour of the other hit value."""
    edge = np.zeros_like(hit)
    edge[1:, :] |= hit[1:, :] != hit[:-1, :]
    edge[:-1, :] |= hit[:-1, :] != hit[1:, :]
    edge[:, 1:] |= hit[:, 1:] != hit[:, :-1]
    edge[:, :-1] |= hit[:, :-1] != hit[:, 1:]
    return edge


def assert_masks_close(a, b, what: str) -> None:
    differ = a.hit != b.hit
    assert a.hit.sum() > 0.1 * a.hit.size, f"{what}: the surface is hardly in the picture"
    off_edge = differ & ~(boundary(a.hit) | boundary(b.hit))
    assert not off_edge.any(), f"{what}: {off_edge.sum()} pixels differ inside the mask"
    assert differ.sum() <= EDGE_PIXELS, f"{what}: {differ.sum()} boundary pixels differ"
    both = a.hit & b.hit
    assert np.abs(a.t - b.t)[both].max(initial=0.0) <= T_TOL, f"{what}: t differs"


def moved(surface: Surface, move, expr: sympy.Expr, turn=lambda v: v) -> Surface:
    v = surface.view
    view = View(eye=move(v.eye), target=move(v.target), up=turn(v.up), fov_y_deg=v.fov_y_deg,
                clip_center=move(v.clip_center), clip_radius=v.clip_radius)
    return Surface(surface.name + " moved", expr, surface.params, view)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("example", SURFACES)
@pytest.mark.parametrize("method", ["sign", "taylor", "hessian", "hessian-approx"])
def test_negated_surface_has_the_same_hits(backend, example, method):
    require_backend(backend)
    s = load_surface(example)
    a = frame(s, backend, method)
    b = frame(Surface(s.name, -s.expr, s.params, s.view), backend, method)
    assert_masks_close(a, b, f"-S, {example}, {method}, {backend}")
    if example in EXACT_NEGATION:
        assert np.array_equal(a.hit, b.hit), f"{(a.hit != b.hit).sum()} pixels differ"
        assert np.array_equal(a.t[a.hit], b.t[b.hit])


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("c", [4, sympy.Rational(3, 10)], ids=["4", "0.3"])
@pytest.mark.parametrize("method", ["sign", "hessian", "curvature"])
def test_scaled_surface_has_the_same_hits(backend, c, method):
    require_backend(backend)
    s = load_surface("cross-cap")
    d = METHODS[method].defaults
    scaled = {} if method == "curvature" else {
        "tau1": d.tau1 * float(c), "tau2": d.tau2 * float(c), "tau3": d.tau3 * float(c)}
    a = frame(s, backend, method)
    b = frame(Surface(s.name, c * s.expr, s.params, s.view), backend, method, **scaled)
    assert_masks_close(a, b, f"{c}·S, {method}, {backend}")



# S times a constant far outside float32's comfort (issue 44, point 1): the compile brings
# S's constants near 1 by a power of two (implc/scaling.py), so every method draws c*S as it
# draws S; before that, 1e-25*S gave false hits and wrong roots with exact, taylor and
# interval, and 1e20*S a flat disc (|grad S|^2 overflowed in the shading).
EXTREME = {"1e25": sympy.Integer(10) ** 25, "1e-25": sympy.Integer(10) ** -25,
           "1e20": sympy.Integer(10) ** 20}


def assert_same_picture(a, b, what: str, strays: int = 0, t_tol: float = T_TOL,
                        color_tol: float = COLOR_TOL) -> None:
    """Masks close, t within `t_tol` but on at most `strays` pixels (taylor's thresholds
    on |F| are absolute: c*S, brought near 1 by a power of two, is not S to the last bit),
    and the colour close where t agrees."""
    differ = a.hit != b.hit
    off_edge = differ & ~(boundary(a.hit) | boundary(b.hit))
    assert a.hit.sum() > 0.1 * a.hit.size, f"{what}: the surface is hardly in the picture"
    assert not off_edge.any() and differ.sum() <= EDGE_PIXELS, f"{what}: masks differ"
    both = a.hit & b.hit
    agree = both & (np.abs(a.t - b.t) <= t_tol)
    assert (both & ~agree).sum() <= strays, f"{what}: t differs on {(both & ~agree).sum()}"
    assert np.abs(a.color - b.color)[agree].max() <= color_tol, f"{what}: colour differs"


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("c", list(EXTREME.values()), ids=list(EXTREME))
@pytest.mark.parametrize("method", ["exact", "taylor", "hessian", "interval"])
def test_extremely_scaled_surface_draws_the_same_picture(backend, c, method):
    require_backend(backend)
    s = load_surface("cross-cap")
    a = frame(s, backend, method)
    b = frame(Surface(s.name, c * s.expr, s.params, s.view), backend, method)
    assert_same_picture(a, b, f"{c}·S, {method}, {backend}",
                        strays=EDGE_PIXELS if method == "taylor" else 0)


@pytest.mark.parametrize("backend", BACKENDS)
def test_shading_survives_a_huge_gradient(backend, monkeypatch):
    """`shade` in a whole picture: with the compile's rescaling off, hessian still finds
    1e20*S's roots, and the normal must not be lost to |g|^2 overflowing float32.
    Measured at 48^2: colour within 1.2e-6; a flat disc is 0.4 off."""
    import implc.scaling

    require_backend(backend)
    monkeypatch.setattr(implc.scaling, "SCALE_BEYOND", 10**6)  # S compiled as written
    s = load_surface("cross-cap")
    a = frame(s, backend, "hessian")
    b = frame(Surface(s.name, EXTREME["1e20"] * s.expr, s.params, s.view), backend, "hessian")
    assert_same_picture(a, b, f"1e20·S unscaled, hessian, {backend}")


def test_shade_takes_any_finite_gradient():
    """The drop-ins' `shade(g, rd)` (users call it with their own gradient): g scaled by
    1e-30 (|g|^2 underflows float32) or 1e30 (it overflows) shades as g itself; before,
    the first gave the fallback normal (0, 0, 1) and the second a black pixel."""
    from conftest import require_gl
    from gl_rays import shade

    require_gl()
    unit = [(0.3, -0.5, 0.8), (-0.9, 0.1, 0.4), (0.0, 0.0, -1.0), (0.6, 0.7, -0.2)]
    rd = (0.0, 0.0, -1.0)
    gradients = [tuple(c * k for c in g) for k in (1.0, 1e-30, 1e30) for g in unit]
    colors = shade(load_surface("sphere"), gradients, rd).reshape(3, len(unit), 3)
    assert np.abs(colors[1] - colors[0]).max() <= 1e-5
    assert np.abs(colors[2] - colors[0]).max() <= 1e-5
    assert np.abs(colors[0][0] - colors[0][1]).max() > 0.05  # the normals matter


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("example", SURFACES)
def test_rotated_and_translated_copies_look_the_same(backend, example):
    require_backend(backend)
    s = load_surface(example)
    a = frame(s, backend, "hessian")

    def turn(p):  # rotation R(x, y, z) = (z, x, y): 120 degrees about (1, 1, 1)
        return (p[2], p[0], p[1])

    rotated = moved(s, turn, s.expr.xreplace({X: Y, Y: Z, Z: X}), turn)  # S(R^-1 p)
    shift = (0.25, -0.5, 0.125)

    def move(p):
        return tuple(float(a_ + b_) for a_, b_ in zip(p, shift, strict=True))

    back = {X: X - sympy.Rational(1, 4), Y: Y + sympy.Rational(1, 2), Z: Z - sympy.Rational(1, 8)}
    translated = moved(s, move, s.expr.xreplace(back))
    for copy, what in ((rotated, "rotated"), (translated, "translated")):
        b = frame(copy, backend, "hessian")
        assert_masks_close(a, b, f"{what} {example} on {backend}")
        both = a.hit & b.hit
        assert np.abs(a.color - b.color)[both].max() <= COLOR_TOL, f"{what}: colour differs"


# The same polynomial written so that it reaches the shader as other text (the parser
# keeps each tree as written; tests/test_parse.py pins the rewrites it folds away, such as
# `+ 0*x^3` and `(x*y)^2` for `x^2y^2`): other operations, other float32 rounding.
REWRITES = [
    ("torus, factored against expanded", "torus",
     "(x^2 + y^2 + z^2 + 0.6)^2 - 4(x^2 + y^2)",
     "x^4 + y^4 + z^4 + 2x^2y^2 + 2y^2z^2 + 2z^2x^2 - 2.8x^2 - 2.8y^2 + 1.2z^2 + 0.36"),
    ("Cross-Cap, x^2 inside a product against x*(x ...)", "cross-cap",
     "4x^2(x^2 + y^2 + z^2 + z) + y^2(y^2 + z^2 - 1)",
     "4x(x^3 + x y^2 + x z^2 + x z) + y(y^3 + y z^2 - y)"),
    ("Roman surface, its sum grouped otherwise", "roman",
     "x^2y^2 + y^2z^2 + z^2x^2 - xyz",
     "y^2(x^2 + z^2) + x(x z^2 - y z)"),
]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize(("what", "example", "text", "rewritten"), REWRITES,
                         ids=[r[0] for r in REWRITES])
def test_rewritten_equation_gives_the_same_picture(backend, what, example, text, rewritten):
    """Two spellings of one polynomial compile to different shaders (checked) whose
    pictures agree within the boundary-pixel and t tolerances of every relation here.
    Measured at 48^2 on gl, wgpu and cl: 0 pixels differ, t within 2.4e-6 (T_TOL is
    1e-4); with the expanded torus's constant 0.36 changed to 0.30 it fails."""
    from implc.emit import emit

    require_backend(backend)
    view = load_surface(example).view
    a_surface = Surface("a", load_surface(equation=text).expr, view=view)
    b_surface = Surface("b", load_surface(equation=rewritten).expr, view=view)
    assert sympy.expand(a_surface.expr - b_surface.expr) == 0, "not the same polynomial"
    assert emit(a_surface, "glsl", "hessian") != emit(b_surface, "glsl", "hessian")
    a = frame(a_surface, backend, "hessian")
    b = frame(b_surface, backend, "hessian")
    assert_masks_close(a, b, f"{what} on {backend}")
