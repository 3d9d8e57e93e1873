"""The choice of the box whose Chebyshev basis holds S in float32 (implc/chebyshev.py), in
plain Python: floats and lists, no numpy, so a compile without numpy (issue 43: Pyodide)
chooses the box a compile with numpy chooses and prints the same program (issue 48).

Given the surface's sampled points (sign changes, implc/extent.py or its plain twin
implc/plain_extent.py), the candidates are the boxes holding a share (QUANTILES) of the
points about the sampled centre, a grid cell wider each side: a bounded surface's whole
box, and for one that leaves the sampled cube (odd Chmutov surfaces, sheets to infinity)
the core where most of it lies. The measure is conditioning.py's, in each basis: the
terms' magnitudes at each point over |grad S|, its 90th percentile over the points
(`quantile`: numpy's default, 'linear', to the bit). The sums run over S's terms and
the box's nonzero coefficients only: a sum of univariate terms (Chmutov's) has few."""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import lru_cache

import sympy

# How many times farther the monomials must move the sampled surface than Chebyshev's
# basis (90th percentiles) for S at the point to be printed by Clenshaw's recurrence
GAIN = 16.0
# the surface's sampled points the box is chosen on, at most (every k-th sign change)
BOX_POINTS = 1500
# the box's centre and half widths are rounded outwards to multiples of 2^-BOX_BITS of
# the largest half width
BOX_BITS = 6
# the shares of the sign changes the candidate boxes hold
QUANTILES = (0.5, 0.75, 0.9, 1.0)

Box = tuple[tuple[sympy.Rational, sympy.Rational], ...]  # (centre, half width) per axis
Point = tuple[float, float, float]


def choose_box(terms: dict[tuple[int, int, int], float], center: Sequence[float],
               points: Sequence[Point], spacing: float) -> Box | None:
    """The dyadic box whose Chebyshev basis moves S's sampled surface least in float32, or
    None: too few points, or the monomials move it less than GAIN times as far."""
    if len(points) < 8:
        return None
    points = points[::max(1, len(points) // BOX_POINTS)]
    slopes = [_slope(terms, p) for p in points]
    kept = [(p, s) for p, s in zip(points, slopes, strict=True) if s > 0]
    if not kept:
        return None
    best = None
    for q in QUANTILES:
        half = [quantile([abs(p[axis] - center[axis]) for p, _ in kept], q) + spacing
                for axis in range(3)]
        box = dyadic(center, half)
        b = _float_coefficients(terms, box)
        moved = quantile([_chebyshev_magnitude(b, p, box) / s for p, s in kept], 0.9)
        if best is None or moved < best[0]:
            best = (moved, box)
    if best is None or quantile([_magnitude(terms, p) / s for p, s in kept], 0.9) \
            < GAIN * best[0]:
        return None
    return best[1]


def quantile(values: list[float], q: float) -> float:
    """np.quantile(values, q) with its default method ('linear'), to the bit: the sorted
    values at (n - 1) q, interpolated as numpy's _lerp (from the nearer end)."""
    ordered = sorted(values)
    n = len(ordered)
    virtual = (n - 1) * q
    if virtual >= n - 1:
        return ordered[-1]
    below = math.floor(virtual)
    gamma = virtual - below
    a, b = ordered[below], ordered[below + 1]
    diff = b - a
    return b - diff * (1 - gamma) if gamma >= 0.5 else a + diff * gamma


def dyadic(center: Sequence[float], half: Sequence[float]) -> Box:
    """The box [center - half, center + half] rounded outwards to multiples of
    2^-BOX_BITS of its widest half width, exactly (dyadic rationals)."""
    unit = 2.0 ** (math.floor(math.log2(float(max(half)))) - BOX_BITS)
    box = []
    for c, h in zip(center, half, strict=True):
        lo_q, hi_q = math.floor((c - h) / unit), math.ceil((c + h) / unit)
        if (hi_q - lo_q) % 2:
            hi_q += 1
        box.append((sympy.Rational((lo_q + hi_q) // 2) * sympy.Rational(unit),
                    sympy.Rational(hi_q - lo_q, 2) * sympy.Rational(unit)))
    return tuple(box)


def _powers(p: Point, top: int) -> list[list[float]]:
    """v^e for e = 0..top, per axis."""
    rows = []
    for v in p:
        row = [1.0] * (top + 1)
        for e in range(1, top + 1):
            row[e] = row[e - 1] * v
        rows.append(row)
    return rows


def _slope(terms: dict[tuple[int, int, int], float], p: Point) -> float:
    """|grad S| at p, from S's monomials."""
    top = max(max(m) for m in terms)
    px, py, pz = _powers(p, top)
    gx = gy = gz = 0.0
    for (i, j, k), a in terms.items():
        if i:
            gx += a * i * px[i - 1] * py[j] * pz[k]
        if j:
            gy += a * j * px[i] * py[j - 1] * pz[k]
        if k:
            gz += a * k * px[i] * py[j] * pz[k - 1]
    return math.sqrt(gx * gx + gy * gy + gz * gz)


def _magnitude(terms: dict[tuple[int, int, int], float], p: Point) -> float:
    """sum |a| |x|^i |y|^j |z|^k at p: the monomials' rounding's unit."""
    px, py, pz = _powers(tuple(abs(v) for v in p), max(max(m) for m in terms))
    return math.fsum(abs(a) * px[i] * py[j] * pz[k] for (i, j, k), a in terms.items())


def _float_coefficients(terms: dict[tuple[int, int, int], float],
                        box: Box) -> dict[int, dict[int, list[tuple[int, float]]]]:
    """|b_lmn| in float64, nonzero ones only, as {l: {m: [(n, |b|), ...]}}."""
    top = max(max(m) for m in terms)
    per_axis = [_power_rows(float(c), float(h), top) for c, h in box]
    b: dict[tuple[int, int, int], float] = {}
    for (i, j, k), a in terms.items():
        rows = per_axis[0][i], per_axis[1][j], per_axis[2][k]
        for ell, u in rows[0]:
            for m, v in rows[1]:
                for n, w in rows[2]:
                    b[ell, m, n] = b.get((ell, m, n), 0.0) + a * u * v * w
    nested: dict[int, dict[int, list[tuple[int, float]]]] = {}
    for (ell, m, n), value in sorted(b.items()):
        if value:
            nested.setdefault(ell, {}).setdefault(m, []).append((n, abs(value)))
    return nested


def _power_rows(c: float, h: float, top: int) -> list[list[tuple[int, float]]]:
    """Row e: v^e with v = c + h t in Chebyshev's basis of t, its nonzero (index, value)
    pairs, for e = 0..top."""
    in_t = [[1.0]]  # row e: the power coefficients of (c + h t)^e
    for _ in range(top):
        last = in_t[-1]
        row = [c * a for a in last] + [0.0]
        for k, a in enumerate(last):
            row[k + 1] += h * a
        in_t.append(row)
    rows = []
    for powers in in_t:
        out = [0.0] * len(powers)
        for k, p in enumerate(powers):
            if p:
                for j, q in enumerate(map(float, monomial_in_chebyshev(k))):
                    if q:
                        out[j] += p * q
        rows.append([(j, v) for j, v in enumerate(out) if v])
    return rows


@lru_cache(maxsize=64)
def monomial_in_chebyshev(k: int) -> tuple[sympy.Rational, ...]:
    """t^k = sum_j q_j T_j(t), exactly: q_j = 2^(1-k) C(k, (k-j)/2) for j = k, k-2, ...
    (half that at j = 0). Read, never changed (chebyshev.py's conversion uses it too)."""
    q = [sympy.Rational(0)] * (k + 1)
    for j in range(k % 2, k + 1, 2):
        q[j] = sympy.Rational(math.comb(k, (k - j) // 2), 2 ** (k - 1 if j else k))
    return tuple(q)


def _chebyshev_table(t: float, top: int) -> list[float]:
    """|T_k(t)| for k = 0..top."""
    table = [1.0, t][:top + 1]
    for k in range(2, top + 1):
        table.append(2 * t * table[k - 1] - table[k - 2])
    return [abs(v) for v in table]


def _chebyshev_magnitude(b: dict[int, dict[int, list[tuple[int, float]]]], p: Point,
                         box: Box) -> float:
    """sum |b_lmn| |T_l(X)| |T_m(Y)| |T_n(Z)| at p: Clenshaw's rounding's unit."""
    top = max(max(max(n for n, _ in zs) for zs in ys.values()) for ys in b.values())
    top = max(top, max(b), max(max(ys) for ys in b.values()))
    tx, ty, tz = (_chebyshev_table((v - float(c)) / float(h), top)
                  for v, (c, h) in zip(p, box, strict=True))
    total = 0.0
    for ell, ys in b.items():
        inner = 0.0
        for m, zs in ys.items():
            inner += ty[m] * sum(w * tz[n] for n, w in zs)
        total += tx[ell] * inner
    return total
