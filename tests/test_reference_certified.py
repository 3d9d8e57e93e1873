"""The certified interval search of the CPU reference (non-polynomial surfaces) against
closed forms: thin shells a sampled search misses, a non-polynomial sphere, a grazing ray,
a thin CSG disc and a pole."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy

from implc.render import reference_certified as reference  # its DEPTH, monkeypatched
from implc.render.reference import (
    certified_first_roots,
    dense_first_roots,
    ray_polynomial,
    render_reference,
)
from implc.scene import View, clip_sphere, pixel_rays
from implc.symbols import X, Y, Z

VIEW = View(eye=(3.0, 2.0, 4.0), clip_radius=1.5)
R2 = X**2 + Y**2 + Z**2
EXP_SPHERE = sympy.exp(R2) - sympy.E  # the unit sphere, not a polynomial


def all_rays(view: View, size: int):
    """Every pixel's ray (flattened), its clip interval and whether it meets the clip sphere."""
    origins, dirs = (a.reshape(-1, 3) for a in pixel_rays(view, size, size))
    t_near, t_far, inside = clip_sphere(origins, dirs, view.clip_center, view.clip_radius)
    return origins, dirs, t_near, t_far, inside


def sphere_entry(origins: np.ndarray, dirs: np.ndarray, radius2: float):
    """(distance^2 of each line to the origin, t where the ray enters |p|^2 = radius2)."""
    b = np.sum(origins * dirs, axis=1)
    closest2 = np.sum(origins * origins, axis=1) - b * b
    with np.errstate(invalid="ignore"):
        return closest2, -b - np.sqrt(radius2 - closest2)


def line(origin, direction):
    """One ray as (N=1) arrays, clipped to VIEW's sphere."""
    o = np.array([origin], dtype=np.float64)
    d = np.array([direction], dtype=np.float64)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    t_near, t_far, inside = clip_sphere(o, d, VIEW.clip_center, VIEW.clip_radius)
    assert inside.all()
    return o, d, t_near, t_far


def test_thin_shell_is_hit_by_every_ray_through_the_unit_sphere():
    # |r^2 - 1| = 1e-4: two spheres 5e-5 apart, F < 0 only between them. Of the 1592 rays
    # of this view that pass the unit sphere, the dense search finds 208 with its default
    # 2048 samples per ray and 24 with 64 (its samples straddle the shell without landing
    # in it, and the V-shaped |F| has no dip that reaches 0).
    shell = sympy.Abs(R2 - 1) - sympy.Rational(1, 10**4)
    assert ray_polynomial(shell) is None
    size = 64
    result = render_reference(shell, VIEW, size, size)
    origins, dirs, t_near, t_far, inside = all_rays(VIEW, size)
    closest2, t_outer = sphere_entry(origins, dirs, 1.0 + 1e-4)
    through = closest2 < 1.0
    assert through.sum() > 1000
    hit = result.hit.ravel()
    assert np.array_equal(hit[through], np.ones(through.sum(), dtype=bool))
    assert not hit[closest2 > 1.0 + 1e-4].any()
    # the hit is the outer sphere's entry (float32 t in the result)
    np.testing.assert_allclose(result.t.ravel()[through], t_outer[through], rtol=1e-6)
    assert result.steps.ravel()[inside].min() >= 1 and not result.steps.ravel()[~inside].any()

    dense_hit, _ = dense_first_roots(
        shell, origins[inside], dirs[inside], t_near[inside], t_far[inside], samples=64
    )
    assert np.sum(through[inside] & ~dense_hit) > through.sum() // 2  # what this test guards


def test_non_polynomial_sphere_matches_the_analytic_root():
    size = 48
    origins, dirs, t_near, t_far, inside = all_rays(VIEW, size)
    hit, t, nodes = certified_first_roots(
        EXP_SPHERE, origins[inside], dirs[inside], t_near[inside], t_far[inside]
    )
    closest2, t_exact = sphere_entry(origins[inside], dirs[inside], 1.0)
    clear = np.abs(closest2 - 1.0) > 1e-6  # away from the tangent rays
    assert clear.sum() > 0.9 * closest2.size
    assert np.array_equal(hit[clear], (closest2 < 1.0)[clear])
    assert hit.sum() > 500
    np.testing.assert_allclose(t[hit & clear], t_exact[hit & clear], rtol=0, atol=1e-9)
    assert nodes.min() >= 1

    result = render_reference(EXP_SPHERE, VIEW, size, size)
    assert np.array_equal(result.hit.ravel()[inside], hit)
    assert np.all(result.residual[result.hit] < 1e-10)


@pytest.mark.parametrize("offset", [0.0, -1e-12, 1e-12, 1e-4])
def test_grazing_ray_touches_the_sphere(offset):
    # y = 1: the ray touches the unit sphere at (0, 1, 0), t = 3 (F has a double root);
    # 1e-12 inside: two roots 2.8e-6 apart; 1e-12 outside: no sign change, min F = 5e-12,
    # a touch within TOUCH_TOL; 1e-4 outside: no root, min F = 5.4e-4.
    o, d, t_near, t_far = line((-3.0, 1.0 + offset, 0.0), (1.0, 0.0, 0.0))
    hit, t, _ = certified_first_roots(EXP_SPHERE, o, d, t_near, t_far)
    if offset > 1e-9:
        assert not hit[0]
    else:
        assert hit[0]
        assert t[0] == pytest.approx(3.0 - math.sqrt(max(0.0, 1.0 - (1.0 + offset) ** 2)),
                                     abs=1e-5)


def test_thin_csg_disc_is_hit_with_its_edge():
    # max(r^2 - 1, |z| - 1e-4): the unit sphere cut to a slab 2e-4 thick, a disc. F < 0
    # inside both; the first root is where the ray has entered both (a crease of max).
    half = 1e-4
    disc = sympy.Max(R2 - 1, sympy.Abs(Z) - sympy.Rational(1, 10**4))
    size = 64
    origins, dirs, t_near, t_far, inside = all_rays(VIEW, size)
    o, d = origins[inside], dirs[inside]
    hit, t, _ = certified_first_roots(disc, o, d, t_near[inside], t_far[inside])
    closest2, t_in = sphere_entry(o, d, 1.0)
    t_out = t_in + 2.0 * np.sqrt(np.maximum(1.0 - closest2, 0.0))
    slab = np.sort(np.stack([(half - o[:, 2]) / d[:, 2], (-half - o[:, 2]) / d[:, 2]]), axis=0)
    enter = np.maximum(t_in, slab[0])
    leave = np.minimum(t_out, slab[1])
    expected = (closest2 < 1.0) & (enter <= leave)
    clear = np.abs(leave - enter) > 1e-7  # away from the disc's rim
    assert expected[clear].sum() > 500
    assert np.array_equal(hit[clear], expected[clear])
    np.testing.assert_allclose(t[clear & expected], enter[clear & expected], rtol=0, atol=1e-9)
    dense_hit, _ = dense_first_roots(disc, o, d, t_near[inside], t_far[inside], samples=256)
    assert np.sum(expected & clear & ~dense_hit) > 100  # a sampled search steps over it


def test_a_pole_is_no_monotonic_stretch():
    # tan(2x) + 100 along x from x = -1.5 (the clip sphere): F grows to +inf at the pole
    # x = -pi/4, comes back from -inf and is 0 just after it (x = -pi/4 + atan(1/100)/2).
    # F' > 0 throughout, and F > 0 at both ends of a node that spans the pole and the
    # root: only the guard (tan's argument must stay between two poles) keeps that node
    # from being skipped as monotonic without a sign change. The first sign change of F
    # is at the pole, which is no root (issue 44, 2): the hit is the root just after it
    # (a skipped node would give the next one, x = pi/4 + atan(1/100)/2).
    surface = sympy.tan(2 * X) + 100
    o, d, t_near, t_far = line((-2.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    hit, t, _ = certified_first_roots(surface, o, d, t_near, t_far)
    assert hit[0]
    assert o[0, 0] + t[0] == pytest.approx(-math.pi / 4 + math.atan(1 / 100) / 2, abs=1e-9)


def test_without_an_interval_rule_the_dense_search_is_used():
    surface = sympy.atan2(Y, X) - Z  # atan2 has no interval rule
    result = render_reference(surface, VIEW, 16, 16, samples=64)
    inside = all_rays(VIEW, 16)[4].reshape(16, 16)
    assert np.array_equal(result.steps, np.where(inside, 64, 0).astype(np.float32))
    assert result.hit.sum() > 50


def test_a_ray_lying_in_a_face_hits_where_it_enters(monkeypatch):
    # F = max(|x|, |y|, |z|) - 1/2 vanishes on the whole stretch |x| <= 1/2 of this ray
    # (y = 1/2 exactly): no enclosure can drop a node there, and every leaf has F = 0 at its
    # ends. The first exact zero ends the search on that ray; without that, all 2^DEPTH
    # leaves of the stretch would be visited (2^16 here, to fail fast).
    monkeypatch.setattr(reference, "DEPTH", 16)
    cube = sympy.Max(sympy.Abs(X), sympy.Abs(Y), sympy.Abs(Z)) - sympy.Rational(1, 2)
    o, d, t_near, t_far = line((-3.0, 0.5, 0.2), (1.0, 0.0, 0.0))
    hit, t, nodes = certified_first_roots(cube, o, d, t_near, t_far)
    assert hit[0]
    assert o[0, 0] + t[0] == pytest.approx(-0.5, abs=1e-12)
    assert nodes[0] < 200
