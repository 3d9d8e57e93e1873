"""numpy's choice of the box of Chebyshev's basis (implc/chebyshev.py): the steps of
implc/box_choice.py on numpy's arrays, on extent.py's sampling. Where numpy cannot load,
box_choice.py's plain-Python measure on plain_extent.py's sampling chooses the same box
(tests/test_box_choice.py and scripts/box_choice_check.py check it): numpy's is
kept where it loads for its speed (the plain measure took 2.8 s against 0.4 s on the
corpus's 207-monomial torus knot)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy

from .box_choice import BOX_POINTS, GAIN, QUANTILES, Box, dyadic
from .derive import expanded_terms
from .extent import locate_surface, sign_changes


def surface_box(expr: sympy.Expr) -> Box | None:
    """(centre, half width) per axis, dyadic, of the box whose Chebyshev basis moves S's
    sampled surface least in float32, or None: no surface found, or the monomials move it
    less than GAIN times as far. The candidates are the boxes holding a share
    (QUANTILES) of the sign changes about their centre, a grid cell wider each side: a
    bounded surface's whole box, and for one that leaves the sampled cube (odd Chmutov
    surfaces, sheets to infinity) the core where most of it lies. The measure is
    conditioning.py's, in each basis: the terms' magnitudes at each point over |grad S|,
    its 90th percentile over the points."""
    terms = expanded_terms(expr)
    extent = locate_surface(expr)
    if extent is None:
        return None
    center = np.asarray(extent.center, dtype=np.float64)
    points, spacing, _ = sign_changes(expr, center, extent.radius)
    if len(points) < 8:
        return None
    points = points[::max(1, len(points) // BOX_POINTS)]
    monomials = np.array(list(terms), dtype=np.int64)
    values = np.array([float(c) for c in terms.values()])
    slope = _slope(monomials, values, points)
    keep = slope > 0
    points, slope = points[keep], slope[keep]
    if not len(points):
        return None
    magnitude = np.abs(values) @ np.prod(np.abs(points[:, None, :]) ** monomials[None], axis=2).T
    best = None
    for q in QUANTILES:
        half = np.quantile(np.abs(points - center), q, axis=0) + spacing
        box = dyadic(center, half)
        b = _float_coefficients(monomials, values, box)
        moved = float(np.quantile(_chebyshev_magnitude(b, points, box) / slope, 0.9))
        if best is None or moved < best[0]:
            best = (moved, box)
    if best is None or float(np.quantile(magnitude / slope, 0.9)) < GAIN * best[0]:
        return None
    return best[1]


def _slope(monomials: np.ndarray, values: np.ndarray, points: np.ndarray) -> np.ndarray:
    """|grad S| at the points, from S's monomials (each power of each coordinate once)."""
    top = int(monomials.max())
    powers = points[:, None, :] ** np.arange(top + 1)[None, :, None]  # (points, k, axis)
    grad = []
    for axis in range(3):
        e = monomials[:, axis]
        lowered = monomials.copy()
        lowered[:, axis] = np.maximum(e - 1, 0)
        terms = (powers[:, lowered[:, 0], 0] * powers[:, lowered[:, 1], 1]
                 * powers[:, lowered[:, 2], 2])
        grad.append(terms @ (values * e))
    return np.sqrt(sum(g * g for g in grad))


def _chebyshev_table(t: np.ndarray, top: int) -> np.ndarray:
    """|T_k(t)| for k = 0..top at each t: (len(t), top + 1)."""
    table = np.ones((len(t), top + 1))
    if top:
        table[:, 1] = t
    for k in range(2, top + 1):
        table[:, k] = 2 * t * table[:, k - 1] - table[:, k - 2]
    return np.abs(table)


def _float_coefficients(monomials: np.ndarray, values: np.ndarray, box) -> np.ndarray:
    """b_lmn in float64 (a dense array), for choosing the box."""
    top = int(monomials.max())
    per_axis = [_power_rows(float(c), float(h), top) for c, h in box]
    b = np.zeros((top + 1,) * 3)
    for (i, j, k), a in zip(monomials, values, strict=True):
        b += a * np.einsum("l,m,n->lmn", per_axis[0][i], per_axis[1][j], per_axis[2][k])
    return b


def _power_rows(c: float, h: float, top: int) -> np.ndarray:
    """Row e: v^e with v = c + h t in Chebyshev's basis of t, for e = 0..top."""
    in_t = np.zeros((top + 1, top + 1))  # row e: the power coefficients of (c + h t)^e
    in_t[0, 0] = 1.0
    for e in range(1, top + 1):
        in_t[e, 1:] = h * in_t[e - 1, :-1]
        in_t[e] += c * in_t[e - 1]
    return in_t @ _powers_in_chebyshev(top)


@lru_cache(maxsize=8)
def _powers_in_chebyshev(top: int) -> np.ndarray:
    """Row j: t^j in Chebyshev's basis, j = 0..top (read, never changed)."""
    from numpy.polynomial import chebyshev

    table = np.zeros((top + 1, top + 1))
    for j in range(top + 1):
        row = chebyshev.poly2cheb(np.eye(top + 1)[j])
        table[j, :len(row)] = row
    return table


def _chebyshev_magnitude(b: np.ndarray, points: np.ndarray, box) -> np.ndarray:
    """sum |b_lmn| |T_l(X)| |T_m(Y)| |T_n(Z)| at each point: Clenshaw's rounding's unit."""
    top = b.shape[0] - 1
    tables = [_chebyshev_table((points[:, a] - float(c)) / float(h), top)
              for a, (c, h) in enumerate(box)]
    size = b.shape[0]
    inner = np.abs(b).reshape(size * size, size) @ tables[2].T  # over n: (l m, points)
    inner = (inner.reshape(size, size, -1) * tables[1].T[None]).sum(axis=1)  # over m
    return (inner * tables[0].T).sum(axis=0)
