"""The exact reference renderer against closed forms, tangent rays and the paper's surfaces."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from implc.numeric import evaluate
from implc.render.reference import (
    DIRECTION,
    ORIGIN,
    dense_first_roots,
    first_root_in_interval,
    first_roots,
    ray_polynomial,
    render_reference,
)
from implc.scene import View, clip_sphere, pixel_rays
from implc.symbols import X, Y, Z

R_SPHERE = 1.0
SPHERE = X**2 + Y**2 + Z**2 - R_SPHERE**2
R_TORUS, r_TORUS = 1.0, 0.25  # binary fractions: tangent rays stay exact
TORUS = (X**2 + Y**2 + Z**2 + R_TORUS**2 - r_TORUS**2) ** 2 - 4 * R_TORUS**2 * (X**2 + Y**2)
PAPER = {
    "cross-cap": 4 * X**2 * (X**2 + Y**2 + Z**2 + Z) + Y**2 * (Y**2 + Z**2 - 1),
    "miter": 4 * X**2 * (X**2 + Y**2 + Z**2) - Y**2 * (1 - Y**2 - Z**2),
    "steiner": X**2 * Y**2 - X**2 * Z**2 + Y**2 * Z**2 - X * Y * Z,
}
VIEW = View(eye=(3.0, 2.0, 4.0), clip_radius=1.5)


def view_rays(view: View, size: int):
    """Flattened rays of a view that meet its clip sphere, with their [t_near, t_far]."""
    origins, dirs = (a.reshape(-1, 3) for a in pixel_rays(view, size, size))
    t_near, t_far, inside = clip_sphere(origins, dirs, view.clip_center, view.clip_radius)
    return origins[inside], dirs[inside], t_near[inside], t_far[inside]


def along(expr: sympy.Expr, origin: np.ndarray, direction: np.ndarray, t: np.ndarray):
    """S at origin + t direction, for t of shape (rays, k)."""
    p = origin[:, None, :] + t[..., None] * direction[:, None, :]
    return evaluate(expr, {X: p[..., 0], Y: p[..., 1], Z: p[..., 2]})


def gradient_norm(expr: sympy.Expr, points: np.ndarray) -> np.ndarray:
    env = {X: points[:, 0], Y: points[:, 1], Z: points[:, 2]}
    grad = [np.broadcast_to(evaluate(sympy.diff(expr, v), env), len(points)) for v in (X, Y, Z)]
    return np.linalg.norm(np.stack(grad, axis=-1), axis=-1)


def sign_changes(values: np.ndarray) -> np.ndarray:
    """Per row: does F change sign between consecutive samples?"""
    return np.any(values[:, :-1] * values[:, 1:] < 0.0, axis=1)


def line(origin, direction):
    """A single ray as (N=1) arrays clipped to VIEW's sphere."""
    o = np.array([origin], dtype=np.float64)
    d = np.array([direction], dtype=np.float64)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    t_near, t_far, inside = clip_sphere(o, d, VIEW.clip_center, VIEW.clip_radius)
    assert inside.all()
    return o, d, t_near, t_far


def test_ray_polynomial_of_sphere_is_the_closed_form():
    ox, oy, oz = ORIGIN
    dx, dy, dz = DIRECTION
    c0, c1, c2 = ray_polynomial(SPHERE)
    assert sympy.expand(c0 - (ox**2 + oy**2 + oz**2 - 1)) == 0
    assert sympy.expand(c1 - 2 * (ox * dx + oy * dy + oz * dz)) == 0
    assert sympy.expand(c2 - (dx**2 + dy**2 + dz**2)) == 0


def test_ray_polynomial_rejects_non_polynomials_and_huge_degrees():
    assert ray_polynomial(sympy.sin(X) + Y) is None
    assert ray_polynomial(1 / X + Y) is None
    assert ray_polynomial(sympy.sqrt(X) - Y) is None
    assert ray_polynomial((X**2 + Y**2 + Z**2) ** 7 - 1) is None
    assert len(ray_polynomial(TORUS)) == 5


def test_first_root_in_interval_on_constructed_polynomials():
    cases = [  # (ascending coefficients, interval length, first root or None)
        (np.polynomial.polynomial.polyfromroots([0.3, 0.3, -2.0, 5.0]), 1.0, 0.3),  # double
        (np.polynomial.polynomial.polyfromroots([0.7, 0.2, 0.2]), 1.0, 0.2),
        (np.polynomial.polynomial.polyfromroots([0.9, 0.5]), 1.0, 0.5),
        ([-0.5, 1.0, 0.0, 0.0], 1.0, 0.5),  # vanishing leading coefficients
        ([1.0, 0.0, 1.0, 0.0], 1.0, None),  # s^2 + 1
        (np.polynomial.polynomial.polyfromroots([1.5]), 1.0, None),  # beyond the interval
        (np.polynomial.polynomial.polyfromroots([1.5, 2.5]), 3.0, 1.5),
        ([0.0, 0.0, 0.0], 2.0, 0.0),  # vanishes identically
    ]
    width = max(len(c) for c, _, _ in cases)
    coeffs = np.array([np.pad(np.asarray(c, float), (0, width - len(c))) for c, _, _ in cases])
    lengths = np.array([length for _, length, _ in cases])
    found, s = first_root_in_interval(coeffs, lengths)
    for k, (_, _, root) in enumerate(cases):
        assert found[k] == (root is not None), k
        if root is not None:
            assert s[k] == pytest.approx(root, abs=1e-9), k


def test_triple_root_is_found():
    found, s = first_root_in_interval(
        np.polynomial.polynomial.polyfromroots([0.4, 0.4, 0.4, 3.0])[None], np.array([1.0])
    )
    assert found[0]
    assert s[0] == pytest.approx(0.4, abs=1e-4)  # a triple root is ill-conditioned


def test_sphere_matches_closed_form():
    origins, dirs, t_near, t_far = view_rays(VIEW, 48)
    b = np.sum(origins * dirs, axis=-1)
    disc = b * b - (np.sum(origins * origins, axis=-1) - R_SPHERE**2)
    clear = np.abs(disc) > 1e-6  # leave out grazing rays: their closed form is ill-posed
    hit, t = first_roots(origins, dirs, t_near, t_far, ray_polynomial(SPHERE))
    assert np.array_equal(hit[clear], disc[clear] > 0)
    exact = -b - np.sqrt(np.where(disc > 0, disc, 0.0))
    assert hit.sum() > 500
    np.testing.assert_allclose(t[hit & clear], exact[hit & clear], rtol=0, atol=1e-9)


def test_torus_along_lines_in_its_plane():
    angles = np.linspace(0.0, 2.0 * np.pi, 37)
    origins = 4.0 * np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], axis=-1)
    dirs = -origins / 4.0
    t_near, t_far, inside = clip_sphere(origins, dirs, VIEW.clip_center, VIEW.clip_radius)
    assert inside.all()
    hit, t = first_roots(origins, dirs, t_near, t_far, ray_polynomial(TORUS))
    assert hit.all()
    np.testing.assert_allclose(t, 4.0 - (R_TORUS + r_TORUS), rtol=0, atol=1e-9)


def torus_first_root_by_np_roots(o: np.ndarray, d: np.ndarray, t0: float, t1: float):
    """Independent check: numpy's roots of the torus quartic in t, polished by Newton."""
    P = np.polynomial.Polynomial
    k = R_TORUS**2 - r_TORUS**2
    sq = P([o @ o, 2.0 * (o @ d), d @ d])  # |p(t)|^2
    sq_xy = P([o[:2] @ o[:2], 2.0 * (o[:2] @ d[:2]), d[:2] @ d[:2]])
    quartic = (sq + k) ** 2 - 4.0 * R_TORUS**2 * sq_xy
    derivative = quartic.deriv()
    roots = quartic.roots()
    real = roots[np.abs(roots.imag) < 1e-6].real
    for _ in range(20):
        real = real - quartic(real) / derivative(real)
    real = real[(real >= t0) & (real <= t1)]
    return real.min() if real.size else None


def test_torus_matches_np_roots_per_ray():
    view = View(eye=(0.5, 2.5, 3.0), clip_radius=1.5)
    origins, dirs, t_near, t_far = view_rays(view, 40)
    hit, t = first_roots(origins, dirs, t_near, t_far, ray_polynomial(TORUS))
    checked = 0
    for k in range(len(origins)):
        expected = torus_first_root_by_np_roots(origins[k], dirs[k], t_near[k], t_far[k])
        assert hit[k] == (expected is not None), k
        if expected is not None:
            assert abs(t[k] - expected) <= 1e-9, k
            checked += 1
    assert checked > 300


def test_ray_tangent_to_the_sphere_is_a_hit():
    o, d, t_near, t_far = line((-3.0, R_SPHERE, 0.0), (1.0, 0.0, 0.0))
    hit, t = first_roots(o, d, t_near, t_far, ray_polynomial(SPHERE))
    assert hit[0]
    assert t[0] == pytest.approx(3.0, abs=1e-6)
    # A sign test sees nothing: F = (t - 3)^2 never changes sign along the ray.
    samples = along(SPHERE, o, d, np.linspace(t_near, t_far, 4096).T)
    assert not sign_changes(samples)[0]


def test_ray_tangent_to_the_top_of_the_torus_hits_the_first_touch():
    # z = r over the torus' top circle: F = (x^2 - R^2)^2, touching at x = -R, then x = R.
    o, d, t_near, t_far = line((-3.0, 0.0, r_TORUS), (1.0, 0.0, 0.0))
    hit, t = first_roots(o, d, t_near, t_far, ray_polynomial(TORUS))
    assert hit[0]
    assert t[0] == pytest.approx(3.0 - R_TORUS, abs=1e-6)
    samples = along(TORUS, o, d, np.linspace(t_near, t_far, 4096).T)
    assert not sign_changes(samples)[0]


def test_ray_just_missing_the_sphere_is_a_miss():
    o, d, t_near, t_far = line((-3.0, R_SPHERE + 1e-4, 0.0), (1.0, 0.0, 0.0))
    hit, _ = first_roots(o, d, t_near, t_far, ray_polynomial(SPHERE))
    assert not hit[0]


@pytest.mark.parametrize("name", sorted(PAPER))
def test_paper_surfaces_hit_the_first_root(name):
    expr = PAPER[name]
    origins, dirs, t_near, t_far = view_rays(VIEW, 64)
    hit, t = first_roots(origins, dirs, t_near, t_far, ray_polynomial(expr))
    assert hit.sum() > 500

    points = origins[hit] + t[hit, None] * dirs[hit]
    residual = np.abs(along(expr, origins[hit], dirs[hit], t[hit, None])[:, 0])
    assert np.all(residual / gradient_norm(expr, points) < 1e-7)

    # No earlier root: F keeps its sign from t_near up to the hit (4096 samples), and
    # over the whole chord for the rays that missed.
    end = np.where(hit, t, t_far)
    grid = np.linspace(0.0, 1.0, 4096)
    ts = t_near[:, None] + (end - t_near)[:, None] * grid
    ts[hit, -1] = t[hit] - 1e-9 * (t_far - t_near)[hit]  # stop just short of the hit
    assert not sign_changes(along(expr, origins, dirs, ts)).any()


@pytest.mark.parametrize("name", sorted(PAPER))
def test_render_reference_agrees_with_first_roots(name):
    size = 64
    result = render_reference(PAPER[name], VIEW, size, size)
    origins, dirs = (a.reshape(-1, 3) for a in pixel_rays(VIEW, size, size))
    t_near, t_far, inside = clip_sphere(origins, dirs, VIEW.clip_center, VIEW.clip_radius)
    hit, t = first_roots(origins, dirs, t_near, t_far, ray_polynomial(PAPER[name]))
    assert not (hit & ~inside).any()
    assert np.array_equal(result.hit.ravel(), hit)
    assert np.array_equal(result.t.ravel(), np.where(hit, t, 0.0).astype(np.float32))
    assert result.color.shape == (size, size, 3) and result.color.dtype == np.float32
    assert np.all(result.residual[result.hit] < 1e-12)
    assert not result.steps.any()
    assert result.timing["total"] > 0


def test_dense_search_agrees_with_polynomial_roots():
    origins, dirs, t_near, t_far = view_rays(VIEW, 24)
    exact_hit, exact_t = first_roots(origins, dirs, t_near, t_far, ray_polynomial(TORUS))
    hit, t = dense_first_roots(TORUS, origins, dirs, t_near, t_far)
    assert np.array_equal(hit, exact_hit)
    np.testing.assert_allclose(t[hit], exact_t[hit], rtol=0, atol=1e-9)


def test_dense_search_finds_a_tangential_hit():
    sphere = sympy.exp(X**2 + Y**2 + Z**2) - sympy.E  # the unit sphere, not a polynomial
    assert ray_polynomial(sphere) is None
    o, d, t_near, t_far = line((-3.0, 1.0, 0.0), (1.0, 0.0, 0.0))
    hit, t = dense_first_roots(sphere, o, d, t_near, t_far)
    assert hit[0]
    assert t[0] == pytest.approx(3.0, abs=1e-6)
    o, d, t_near, t_far = line((-3.0, 1.0 + 1e-4, 0.0), (1.0, 0.0, 0.0))
    hit, _ = dense_first_roots(sphere, o, d, t_near, t_far)
    assert not hit[0]


def test_non_polynomial_surface_renders_with_small_residual():
    gyroid = (
        sympy.sin(X) * sympy.cos(Y) + sympy.sin(Y) * sympy.cos(Z) + sympy.sin(Z) * sympy.cos(X)
    )
    view = View(eye=(3.0, 2.0, 4.0), clip_radius=1.2)
    result = render_reference(gyroid, view, 48, 48)
    assert result.hit.sum() > 300
    assert np.all(result.residual[result.hit] < 1e-10)
    inside = clip_sphere(*pixel_rays(view, 48, 48), view.clip_center, view.clip_radius)[2]
    # steps: the certified search's nodes per ray, on every ray through the clip sphere
    assert np.array_equal(result.steps > 0, inside)


def test_unbound_parameter_is_an_error():
    with pytest.raises(ValueError, match="needs values for a"):
        render_reference(X**2 + Y**2 + Z**2 - sympy.Symbol("a"), VIEW, 8, 8)
