"""The CPU reference for polynomial surfaces (implc/render/reference.py): F along each ray
is a polynomial in s, and all its real roots in [0, L] come from its companion matrix,
polished by Newton; the first is the hit, exact up to float64 rounding.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy
from sympy.polys.rings import ring

from ..symbols import DIRECTION, POINT, T
from .reference_eval import evaluate_on

# Ray origin symbols of the coefficient expressions returned by `ray_polynomial`.
OX, OY, OZ = sympy.symbols("ox oy oz", real=True)
ORIGIN = (OX, OY, OZ)

# Above this total degree, building the ray polynomial symbolically grows too large
# (thousands of terms per coefficient); such surfaces take the certified search instead.
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

POLYNOMIAL_CHUNK = 1 << 16  # rays per batch of companion matrices


def ray_polynomial(expr: sympy.Expr) -> list[sympy.Expr] | None:
    """Coefficients c_0..c_n of F(t) = S(O + tD) in ORIGIN and DIRECTION symbols.

    None when S is not a polynomial in x, y, z, or its total degree exceeds
    MAX_RAY_POLYNOMIAL_DEGREE (then the certified search is used). The substitution is done in
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
        coeffs = np.stack([evaluate_on(c, env, rows) for c in coefficients], axis=-1)
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
