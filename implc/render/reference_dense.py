"""The CPU reference's dense search (implc/render/reference.py), for surfaces with a
function that has no interval rule (atan2): F sampled along each ray, the first sign
change that is no pole bisected, the dips of |F| checked for tangential hits. NOT exact:
two roots closer than the sample spacing with no dip between samples can be missed.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy

from ..symbols import POINT
from .reference_eval import (
    TOUCH_TOL,
    along_ray,
    bisection_steps,
    derivative_along,
    evaluate_on,
    point_env,
)

# Dense search for non-polynomial surfaces (BISECTION_WIDTH and TOUCH_TOL: reference_eval).
DENSE_SAMPLES = 2048
DENSE_CHUNK_VALUES = 1 << 20  # rays x samples per batch (the evaluator keeps every node)


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
      is bisected to a width of BISECTION_WIDTH; where |F| there exceeds |F| at both its
      samples it was a pole (1/u, tan), no root, and the next such interval is tried.
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
        values = along_ray(expr, entry, d, s)
        halvings = bisection_steps(float(length.max(initial=0.0)) / (samples - 1))
        cross = _first_crossing(expr, entry, d, s, values, halvings)
        touch = _first_touch(expr, gradient, entry, d, s, values, cross, halvings + 1)
        first = np.fmin(cross, touch)
        found = np.isfinite(first)
        hit[part] = found
        t[part] = np.where(found, t_near[part] + first, 0.0)
    return hit, t


def _first_crossing(
    expr: sympy.Expr,
    entry: np.ndarray,
    d: np.ndarray,
    s: np.ndarray,
    values: np.ndarray,
    iterations: int,
) -> np.ndarray:
    """s of the first sign change per ray that is a root, bisected; inf where none. A sign
    change through a pole (|F| at the bisected point above |F| at both samples: F grew
    toward it) is no root, and the next one is tried."""
    left, right = values[:, :-1], values[:, 1:]
    with np.errstate(invalid="ignore"):
        crossing = (left == 0.0) | (left * right < 0.0)
    out = np.full(s.shape[0], np.inf)
    rows = np.flatnonzero(crossing.any(axis=1))
    while rows.size:
        j = np.argmax(crossing[rows], axis=1)
        root = _bisect_crossing(expr, entry[rows], d[rows], s[rows, j], s[rows, j + 1],
                                values[rows, j], iterations)
        f_root = along_ray(expr, entry[rows], d[rows], root[:, None])[:, 0]
        with np.errstate(invalid="ignore"):
            pole = ~(np.abs(f_root) <= np.maximum(np.abs(values[rows, j]),
                                                  np.abs(values[rows, j + 1])))
        out[rows[~pole]] = root[~pole]
        crossing[rows[pole], j[pole]] = False
        rows = rows[pole][crossing[rows[pole]].any(axis=1)]
    return out


def _bisect_crossing(expr, entry, d, lo, hi, f_lo, iterations) -> np.ndarray:
    """The sign change in each [lo, hi] (F = f_lo at lo, 0 there: lo), bisected."""
    at_lo = f_lo == 0.0
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        f_mid = along_ray(expr, entry, d, mid[:, None])[:, 0]
        same = f_mid * f_lo > 0.0
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        f_lo = np.where(same, f_mid, f_lo)
    return np.where(at_lo, lo, 0.5 * (lo + hi))


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
        slope = derivative_along(gradient, entry[rows], d[rows], half) * side
        lo, hi = np.where(slope < 0.0, half, lo), np.where(slope < 0.0, hi, half)
    bottom = 0.5 * (lo + hi)
    points = entry[rows] + bottom[:, None] * d[rows]
    env = point_env(points)
    f = evaluate_on(expr, env, rows.size)
    grad_norm = np.linalg.norm(np.stack([evaluate_on(g, env, rows.size) for g in gradient], -1),
                               axis=-1)
    with np.errstate(invalid="ignore"):
        touches = np.abs(f) <= TOUCH_TOL * s[rows, -1] * grad_norm
    out = np.full(s.shape[0], np.inf)
    np.fmin.at(out, rows, np.where(touches, bottom, np.inf))
    return out
