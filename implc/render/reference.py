"""The exact CPU reference renderer: the shared camera and shading, roots found in float64.

Every ray is clipped to the bounding sphere and restarted at its entry point O' (as the
shaders do), so the surface along it is F(s) = S(O' + sD), s = t - t_near in [0, L],
L = t_far - t_near, and the hit is the first zero of F in that interval.

Polynomial surfaces (total degree <= MAX_RAY_POLYNOMIAL_DEGREE): F is a polynomial in s. All
its real roots in [0, L], tangential (double) roots included, come from the eigenvalues of
its companion matrix and are polished by Newton (`first_root_in_interval`); the first is
the hit, exact up to float64 rounding. This is the ground truth the marchers are measured
against.

Other surfaces: a dense search (`dense_first_roots`) that samples F, bisects the first sign
change and checks the dips of |F| between samples for tangential hits. It is NOT exact: two
roots closer than the sample spacing with no dip between samples can be missed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence

import numpy as np
import sympy
from sympy.polys.rings import ring

from ..numeric import evaluate
from ..scene import View, clip_sphere, pixel_rays, shade
from ..symbols import DIRECTION, POINT, T, X, Y, Z
from .result import RenderResult

# Ray origin symbols of the coefficient expressions returned by `ray_polynomial`.
OX, OY, OZ = sympy.symbols("ox oy oz", real=True)
ORIGIN = (OX, OY, OZ)

# Above this total degree, building the ray polynomial symbolically grows too large
# (thousands of terms per coefficient); such surfaces take the dense search instead.
MAX_RAY_POLYNOMIAL_DEGREE = 12

# Root acceptance for polynomials, in u = s / L (so the interval is [0, 1]) with the
# coefficients scaled to max |a_k| = 1:
ROOT_TOL = 1e-12  # accept u when |F(u)| <= ROOT_TOL * sum_k |a_k| u^k: float64 rounding of
#                   F is ~1e-16 of that scale, so this leaves 10^4 for the rounding of the
#                   coefficients; 1e-9 accepted visible near misses by the double lines
IMAG_TOL = 1e-3  # eigenvalues with |Im u| <= IMAG_TOL are candidates; a double root
#                  splits into a complex pair with |Im u| ~ 1e-8, a triple one ~ 1e-5
LEAD_TOL = 1e-13  # leading coefficients below this (relative) are dropped, per ray
NEWTON_ITERATIONS = 40

# Dense search for non-polynomial surfaces.
DENSE_SAMPLES = 2048
BISECTION_WIDTH = 1e-12  # final bracket width of a sign-change root, in units of t
TOUCH_TOL = 1e-9  # tangential hit when |F| / |grad S| <= TOUCH_TOL * L at a dip of |F|

POLYNOMIAL_CHUNK = 1 << 16  # rays per batch of companion matrices
DENSE_CHUNK_VALUES = 1 << 20  # rays x samples per batch (the evaluator keeps every node)


def render_reference(
    expr: sympy.Expr, view: View, width: int, height: int, *, samples: int = DENSE_SAMPLES
) -> RenderResult:
    """Render S = 0 with the shared camera and shading; hits are exact float64 roots for
    polynomial S and come from the (inexact) dense search otherwise.

    `samples` is used only by the dense search of non-polynomial surfaces; `steps` reports
    it for every pixel that entered the clip sphere (0 for polynomial surfaces).
    """
    start = time.perf_counter()
    unbound = expr.free_symbols - set(POINT)
    if unbound:
        names = ", ".join(sorted(str(s) for s in unbound))
        raise ValueError(f"the reference needs values for {names}")
    origins, dirs = pixel_rays(view, width, height)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    t_near, t_far, inside = clip_sphere(origins, dirs, view.clip_center, view.clip_radius)
    rows = np.flatnonzero(inside)
    gradient = [sympy.diff(expr, v) for v in POINT]

    coefficients = ray_polynomial(expr)
    args = (origins[rows], dirs[rows], t_near[rows], t_far[rows])
    if coefficients is not None:
        found, t_rows = first_roots(*args, coefficients)
        steps_inside = 0
    else:
        found, t_rows = dense_first_roots(expr, *args, samples=samples, gradient=gradient)
        steps_inside = samples

    n = origins.shape[0]
    hit = np.zeros(n, dtype=bool)
    hit[rows] = found
    t = np.zeros(n)
    t[rows[found]] = t_rows[found]
    steps = np.zeros(n)
    steps[rows] = steps_inside

    env = _point_env(origins[hit] + t[hit, None] * dirs[hit])
    grad = np.zeros((n, 3))
    grad[hit] = np.stack([_on(g, env, hit.sum()) for g in gradient], axis=-1)
    residual = np.zeros(n)
    residual[hit] = np.abs(_on(expr, env, hit.sum()))

    shape = (height, width)
    color = shade(grad.reshape(*shape, 3), dirs.reshape(*shape, 3), hit.reshape(shape), view)
    return RenderResult(
        color=color.astype(np.float32),
        hit=hit.reshape(shape),
        t=t.reshape(shape).astype(np.float32),
        steps=steps.reshape(shape).astype(np.float32),
        residual=residual.reshape(shape).astype(np.float32),
        timing={"total": time.perf_counter() - start},
    )


def ray_polynomial(expr: sympy.Expr) -> list[sympy.Expr] | None:
    """Coefficients c_0..c_n of F(t) = S(O + tD) in ORIGIN and DIRECTION symbols.

    None when S is not a polynomial in x, y, z, or its total degree exceeds
    MAX_RAY_POLYNOMIAL_DEGREE (then the dense search is used). The substitution is done in
    sympy's sparse polynomial ring, which is ~100x faster than expanding the substituted
    expression and keeps exact (rational) coefficients.
    """
    try:
        poly = sympy.Poly(expr, *POINT)
    except sympy.PolynomialError:
        return None
    if poly.total_degree() > MAX_RAY_POLYNOMIAL_DEGREE:
        return None
    ring_, *gens = ring([*ORIGIN, *DIRECTION, T], poly.domain)
    ox, oy, oz, dx, dy, dz, t = gens
    lines = (ox + t * dx, oy + t * dy, oz + t * dz)
    powers: dict[tuple[int, int], object] = {}

    def line_power(axis: int, k: int):
        if (axis, k) not in powers:
            powers[axis, k] = lines[axis] ** k
        return powers[axis, k]

    along = ring_.zero
    for monom, coeff in poly.terms():
        term = ring_.ground_new(coeff)
        for axis, k in enumerate(monom):
            if k:
                term = term * line_power(axis, k)
        along += term
    by_power: dict[int, dict[tuple[int, ...], object]] = {}
    for monom, coeff in along.terms():
        by_power.setdefault(monom[-1], {})[monom[:-1] + (0,)] = coeff
    degree = max(by_power, default=0)
    return [ring_.from_dict(by_power.get(k, {})).as_expr() for k in range(degree + 1)]


def first_roots(
    origins: np.ndarray,
    dirs: np.ndarray,
    t_near: np.ndarray,
    t_far: np.ndarray,
    coefficients: Sequence[sympy.Expr],
) -> tuple[np.ndarray, np.ndarray]:
    """First root t in [t_near, t_far] of each ray's polynomial, from `ray_polynomial`.

    Arrays are (N, 3) and (N,); returns (hit, t) with t measured from `origins`. The
    coefficients are evaluated at the clip-sphere entry point, so the polynomial is in
    s = t - t_near and its values stay small; see `first_root_in_interval` for the rest.
    """
    origins, dirs = np.asarray(origins, np.float64), np.asarray(dirs, np.float64)
    t_near, t_far = np.asarray(t_near, np.float64), np.asarray(t_far, np.float64)
    n = origins.shape[0]
    hit = np.zeros(n, dtype=bool)
    t = np.zeros(n)
    for lo in range(0, n, POLYNOMIAL_CHUNK):
        part = slice(lo, lo + POLYNOMIAL_CHUNK)
        entry = origins[part] + t_near[part, None] * dirs[part]
        env = dict(zip((*ORIGIN, *DIRECTION), (*entry.T, *dirs[part].T), strict=True))
        rows = entry.shape[0]
        coeffs = np.stack([_on(c, env, rows) for c in coefficients], axis=-1)
        found, s = first_root_in_interval(coeffs, t_far[part] - t_near[part])
        hit[part] = found
        t[part] = np.where(found, t_near[part] + s, 0.0)
    return hit, t


def first_root_in_interval(
    coeffs: np.ndarray, lengths: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """First real root in [0, length] of each row's polynomial sum_k coeffs[:, k] s^k.

    Returns (found, s). Method, per row, in u = s / length with coefficients a_k scaled to
    max |a_k| = 1 (so the rounding scale of F is sum_k |a_k| u^k <= n + 1):
    - leading a_k below LEAD_TOL are dropped (their roots lie far outside [0, 1]; a
      vanishing leading coefficient lowers the degree of that ray);
    - candidates are the companion-matrix eigenvalues with |Im u| <= IMAG_TOL and real
      part in [-IMAG_TOL, 1 + IMAG_TOL]: a double root splits into a complex pair;
    - each candidate is polished twice in float64 with the full polynomial: Newton on F
      (a crossing root) and Newton on F' (the touching point of a double root);
    - a polished u in [0, 1] is a root when |F(u)| <= ROOT_TOL * sum_k |a_k| u^k. So a
      tangential ray counts as a hit, and so does a ray that misses the surface with
      min |F| that small (near a tangent point, by about sqrt(ROOT_TOL) ~ 1e-6 of the
      interval), which float64 rounding of the coefficients cannot tell from a touch.
    Near a double root the hit is accurate to about sqrt(ROOT_TOL) of the interval; at
    simple roots to float64 rounding.
    The first accepted u is the hit. A polynomial that vanishes identically (the ray lies
    in the surface) hits at s = 0; an empty interval (length <= 0) never hits.
    """
    coeffs = np.asarray(coeffs, np.float64)
    lengths = np.asarray(lengths, np.float64)
    n = coeffs.shape[1] - 1
    a = coeffs * lengths[:, None] ** np.arange(n + 1)
    size = np.max(np.abs(a), axis=1)
    a = a / np.where(size == 0.0, 1.0, size)[:, None]

    rows, u0 = _root_candidates(a)
    da = a[:, 1:] * np.arange(1, n + 1)
    dda = da[:, 1:] * np.arange(1, n)
    crossing = _newton(a[rows], da[rows], u0)
    touching = _newton(da[rows], dda[rows], u0)
    first = np.full(a.shape[0], np.inf)
    for u in (crossing, touching):
        np.fmin.at(first, rows, np.where(_is_root(a[rows], u), u, np.nan))
    first[size == 0.0] = 0.0
    found = np.isfinite(first) & (lengths > 0.0)
    return found, np.where(found, first, 0.0) * lengths


def dense_first_roots(
    expr: sympy.Expr,
    origins: np.ndarray,
    dirs: np.ndarray,
    t_near: np.ndarray,
    t_far: np.ndarray,
    *,
    samples: int = DENSE_SAMPLES,
    gradient: Sequence[sympy.Expr] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """First zero of F along each ray by dense sampling; NOT exact, for any S.

    F is sampled at `samples` uniform points of [t_near, t_far] (both ends included).
    - Crossing: the first interval whose ends have opposite signs (or a sample exactly 0)
      is bisected to a width of BISECTION_WIDTH.
    - Touching: a sample where |F| is a local minimum without a sign change, and low
      enough that the parabola through its neighbours could reach zero (|F_i| <= 1/4 of
      the second difference; an exact parabola touching zero gives at most 1/8), is
      refined by bisecting F' = grad S . D to the bottom of the dip, and is a hit when
      |F| / |grad S| there (the distance to the surface, to first order) is at most
      TOUCH_TOL times the chord length t_far - t_near.
    The earlier of the two is the hit. Missed: pairs of roots closer than the spacing
    whose dip falls between samples without lowering any sample. NaN samples (outside
    the domain of sqrt, log, ...) count as no surface.
    """
    if gradient is None:
        gradient = [sympy.diff(expr, v) for v in POINT]
    origins, dirs = np.asarray(origins, np.float64), np.asarray(dirs, np.float64)
    t_near, t_far = np.asarray(t_near, np.float64), np.asarray(t_far, np.float64)
    n = origins.shape[0]
    grid = np.linspace(0.0, 1.0, samples)
    chunk = max(1, DENSE_CHUNK_VALUES // samples)
    hit = np.zeros(n, dtype=bool)
    t = np.zeros(n)
    for lo in range(0, n, chunk):
        part = slice(lo, lo + chunk)
        entry = origins[part] + t_near[part, None] * dirs[part]
        d = dirs[part]
        length = t_far[part] - t_near[part]
        s = length[:, None] * grid
        values = _along(expr, entry, d, s)
        halvings = _halvings(float(length.max(initial=0.0)) / (samples - 1))
        cross = _first_crossing(expr, entry, d, s, values, halvings)
        touch = _first_touch(expr, gradient, entry, d, s, values, cross, halvings + 1)
        first = np.fmin(cross, touch)
        found = np.isfinite(first)
        hit[part] = found
        t[part] = np.where(found, t_near[part] + first, 0.0)
    return hit, t


def _halvings(width: float) -> int:
    """Bisection steps that shrink a bracket of `width` to BISECTION_WIDTH."""
    return max(0, math.ceil(math.log2(width / BISECTION_WIDTH))) if width > 0.0 else 0


def _root_candidates(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(row, real part) of the eigenvalues of each row's companion matrix near [0, 1]."""
    n = a.shape[1] - 1
    significant = np.abs(a) > LEAD_TOL
    degree = np.where(significant.any(axis=1), n - np.argmax(significant[:, ::-1], axis=1), 0)
    rows_out, u_out = [np.zeros(0, dtype=np.intp)], [np.zeros(0)]
    for m in np.unique(degree):
        if m == 0:
            continue
        rows = np.flatnonzero(degree == m)
        companion = np.zeros((rows.size, m, m))
        companion[:, np.arange(1, m), np.arange(m - 1)] = 1.0
        companion[:, :, -1] = -a[rows, :m] / a[rows, m, None]
        eig = np.linalg.eigvals(companion)
        keep = (
            (np.abs(eig.imag) <= IMAG_TOL)
            & (eig.real >= -IMAG_TOL)
            & (eig.real <= 1.0 + IMAG_TOL)
        )
        r, c = np.nonzero(keep)
        rows_out.append(rows[r])
        u_out.append(eig.real[r, c])
    return np.concatenate(rows_out), np.concatenate(u_out)


def _horner(coeffs: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Row-wise polynomial values, coefficients in ascending order."""
    value = np.zeros_like(u)
    for k in range(coeffs.shape[1] - 1, -1, -1):
        value = value * u + coeffs[:, k]
    return value


def _newton(f: np.ndarray, df: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Newton on row-wise polynomials f from u; returns the iterate of smallest |f|.

    Keeping the best iterate makes it safe where Newton wanders (near f' = 0).
    """
    best_u, best_f = u, np.full_like(u, np.inf)
    with np.errstate(all="ignore"):
        for _ in range(NEWTON_ITERATIONS):
            fu = _horner(f, u)
            better = np.abs(fu) < best_f
            best_u, best_f = np.where(better, u, best_u), np.where(better, np.abs(fu), best_f)
            dfu = _horner(df, u)
            step = np.divide(fu, dfu, out=np.zeros_like(u), where=dfu != 0.0)
            if not np.any(np.abs(step) > 1e-16 * (1.0 + np.abs(u))):
                break
            u = u - step
    return best_u


def _is_root(a: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The acceptance rule of `first_root_in_interval`."""
    with np.errstate(all="ignore"):
        inside = (u >= 0.0) & (u <= 1.0)
        scale = _horner(np.abs(a), np.abs(u))
        return inside & (np.abs(_horner(a, u)) <= ROOT_TOL * scale)


def _first_crossing(
    expr: sympy.Expr,
    entry: np.ndarray,
    d: np.ndarray,
    s: np.ndarray,
    values: np.ndarray,
    iterations: int,
) -> np.ndarray:
    """s of the first sign change per ray, bisected; inf where none."""
    left, right = values[:, :-1], values[:, 1:]
    crossing = (left == 0.0) | (left * right < 0.0)
    rows = np.flatnonzero(crossing.any(axis=1))
    j = np.argmax(crossing[rows], axis=1)
    lo, hi = s[rows, j], s[rows, j + 1]
    f_lo = values[rows, j]
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        f_mid = _along(expr, entry[rows], d[rows], mid[:, None])[:, 0]
        same = f_mid * f_lo > 0.0
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        f_lo = np.where(same, f_mid, f_lo)
    root = np.where(values[rows, j] == 0.0, s[rows, j], 0.5 * (lo + hi))
    out = np.full(s.shape[0], np.inf)
    out[rows] = root
    return out


def _first_touch(
    expr: sympy.Expr,
    gradient: Sequence[sympy.Expr],
    entry: np.ndarray,
    d: np.ndarray,
    s: np.ndarray,
    values: np.ndarray,
    cross: np.ndarray,
    iterations: int,
) -> np.ndarray:
    """s of the first tangential hit per ray (see `dense_first_roots`); inf where none."""
    prev, mid, nxt = values[:, :-2], values[:, 1:-1], values[:, 2:]
    with np.errstate(invalid="ignore"):
        dip = (
            (prev * mid > 0.0)
            & (mid * nxt > 0.0)
            & (np.abs(mid) <= np.abs(prev))
            & (np.abs(mid) <= np.abs(nxt))
            & (np.abs(mid) <= 0.25 * np.abs(nxt - 2.0 * mid + prev))
            & (s[:, :-2] <= cross[:, None])  # the dip starts before the first crossing
        )
    rows, i = np.nonzero(dip)
    i = i + 1
    lo, hi = s[rows, i - 1], s[rows, i + 1]
    side = np.sign(values[rows, i])  # F' goes from -side to +side across the dip
    for _ in range(iterations):
        half = 0.5 * (lo + hi)
        slope = _derivative_along(gradient, entry[rows], d[rows], half) * side
        lo, hi = np.where(slope < 0.0, half, lo), np.where(slope < 0.0, hi, half)
    bottom = 0.5 * (lo + hi)
    points = entry[rows] + bottom[:, None] * d[rows]
    env = _point_env(points)
    f = _on(expr, env, rows.size)
    grad_norm = np.linalg.norm(np.stack([_on(g, env, rows.size) for g in gradient], -1), axis=-1)
    with np.errstate(invalid="ignore"):
        touches = np.abs(f) <= TOUCH_TOL * s[rows, -1] * grad_norm
    out = np.full(s.shape[0], np.inf)
    np.fmin.at(out, rows, np.where(touches, bottom, np.inf))
    return out


def _along(expr: sympy.Expr, entry: np.ndarray, d: np.ndarray, s: np.ndarray) -> np.ndarray:
    """S at entry + s d for s of shape (rays, k)."""
    points = entry[:, None, :] + s[..., None] * d[:, None, :]
    return _on(expr, _point_env(points), s.shape)


def _derivative_along(
    gradient: Sequence[sympy.Expr], entry: np.ndarray, d: np.ndarray, s: np.ndarray
) -> np.ndarray:
    """F'(s) = grad S . D at entry + s d for s of shape (rays,)."""
    env = _point_env(entry + s[:, None] * d)
    return sum(_on(g, env, s.shape) * d[:, axis] for axis, g in enumerate(gradient))


def _point_env(points: np.ndarray) -> dict[sympy.Symbol, np.ndarray]:
    return {X: points[..., 0], Y: points[..., 1], Z: points[..., 2]}


def _on(expr: sympy.Expr, env: dict[sympy.Symbol, np.ndarray], shape) -> np.ndarray:
    """`evaluate`, broadcast to `shape` (a constant expression evaluates to a scalar)."""
    return np.broadcast_to(evaluate(expr, env), shape)
