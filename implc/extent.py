"""Where a surface S = 0 lies, estimated by sampling S: for framing a view automatically
(implc/scene.py `apply_view`) and for the render's warnings (clipped, nothing hit).

The search samples S on a grid of GRID^3 cells (GRID + 1 points a side, shifted by a
fraction of a cell so that grid points avoid the planes and centres of symmetry where S
is often exactly 0) in the cube |x|,|y|,|z| <= L around the centre, for L = 2, 8, 32, 128,
512, 2048, and then, when nothing was found, 0.5, 0.125 and 1/32 for surfaces smaller
than a cell. The surface is where S changes sign between neighbouring grid points. The
first cube whose sign changes all stay off its outer layer of cells holds the surface:
the search then samples once more in a cube tight around them, and the surface's points
are the sign changes, placed on each edge by linear interpolation. A surface whose sign
changes reach the edge of every cube is unbounded (a plane, a cylinder, the gyroid).

This is a sampling, not a proof: a surface thinner than a cell, one far from the centre
and smaller than the cells there, and a surface where S does not change sign (S = G^2)
are missed. The interval enclosures of implc/interval.py could certify emptiness; a
sign-change search is enough for choosing a camera and says what it did.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import sympy

from .numeric import evaluate, evaluate_on_grid
from .plain_extent import (
    GRID,
    GROWING,
    GROWTH,
    GROWTH_STEPS,
    MARGIN,
    SHIFT,
    SHRINKING,
    SPHERE_SAMPLES,
    length_quantum,
)
from .scene import Extent, Vec3
from .symbols import POINT

# the grid and the search's steps (their values and meaning in plain_extent.py, the search
# written in plain Python, which must sample what this one samples)
SEARCHED = GROWING[-1]


def locate_surface(expr: sympy.Expr, center: Vec3 | None = None) -> Extent | None:
    """The clip sphere that holds S = 0 (centre `center` when given, else the middle of
    the sign changes), or None when no sign change is found in |p - centre| <= SEARCHED
    (the cube). Deterministic: the same surface gives the same numbers, kept for the
    command's next question (framing, then float32's conditioning, ask the same)."""
    return _locate(expr, None if center is None else tuple(float(c) for c in center))


@lru_cache(maxsize=8)
def _locate(expr: sympy.Expr, center: tuple[float, ...] | None) -> Extent | None:
    origin = np.zeros(3) if center is None else np.asarray(center, dtype=np.float64)
    first_found = None
    for half in GROWING:
        points, spacing, touching = sign_changes(expr, origin, half)
        if len(points) and not touching:
            return _clear_of_sphere(expr, _bounded(expr, points, spacing, center))
        if len(points) and first_found is None:
            first_found = half
    if first_found is not None:  # unbounded: the first cube that holds a piece of it,
        # or for a periodic surface one period each way of its centre
        period = longest_period(expr)
        return Extent(_vec3(origin), max(first_found, period), bounded=False, period=period)
    for half in SHRINKING:
        points, spacing, _ = sign_changes(expr, origin, half)
        if len(points):
            return _bounded(expr, points, spacing, center)
    return None


def _clear_of_sphere(expr: sympy.Expr, extent: Extent) -> Extent:
    """`extent` grown by GROWTH, at most GROWTH_STEPS times, until S keeps one sign on its
    sphere, then by MARGIN: the grid misses a part thinner than its cells (the ends of
    x^2/100 + y^2 + z^2/0.01 = 1, a hundred times longer than thick, framed at 8 instead of
    10), the sphere's denser samples catch where it pierces. A surface that still pierces
    the sphere after that is taken as unbounded (6x^2 - 2x^4 = y^2 z^2, whose arms thin
    out along y and z): the part near the centre, as for the grid's own unbounded ones."""
    radius = extent.radius
    for _ in range(GROWTH_STEPS):
        if not crosses_sphere(expr, extent.center, radius):
            break
        radius *= GROWTH
    else:
        if crosses_sphere(expr, extent.center, radius):
            return Extent(extent.center, extent.radius, bounded=False)
    if radius == extent.radius:
        return extent
    radius *= MARGIN
    quantum = length_quantum(radius)
    return Extent(extent.center, round(math.ceil(radius / quantum - 1e-9) * quantum, 12),
                  bounded=True)


def longest_period(expr: sympy.Expr) -> float:
    """The longest wavelength of S's waves, 0 when it has none: over every sin, cos or tan
    of a linear form a.p + b, 2 pi / |a| (pi for tan). Framing shows an unbounded periodic
    surface (the gyroid) a period each way of its centre rather than the one saddle the
    first search cube holds; two significant digits."""
    longest = 0.0
    for node in expr.atoms(sympy.sin, sympy.cos, sympy.tan):
        arg = node.args[0]
        if not arg.free_symbols or not arg.free_symbols <= set(POINT):
            continue
        try:
            poly = sympy.Poly(arg, *POINT)
        except sympy.PolynomialError:
            continue
        if poly.total_degree() != 1:
            continue
        norm = math.sqrt(sum(float(poly.coeff_monomial(v)) ** 2 for v in POINT))
        longest = max(longest, (math.pi if node.func is sympy.tan else 2 * math.pi) / norm)
    if longest == 0.0:
        return 0.0
    quantum = length_quantum(longest)
    return round(math.ceil(longest / quantum - 1e-9) * quantum, 12)


def _vec3(v) -> Vec3:
    return (float(v[0]), float(v[1]), float(v[2]))


def _bounded(expr: sympy.Expr, points: np.ndarray, spacing: float,
             center: Vec3 | None) -> Extent:
    """Sample again in a cube tight around the sign changes found, then the sphere."""
    low, high = points.min(axis=0) - 2 * spacing, points.max(axis=0) + 2 * spacing
    middle = (low + high) / 2.0
    fine, fine_spacing, _ = sign_changes(expr, middle, float((high - low).max()) / 2.0)
    if len(fine):
        points, spacing = fine, fine_spacing
    if center is None:
        middle = (points.min(axis=0) + points.max(axis=0)) / 2.0
        reach = float(np.linalg.norm(points - middle, axis=1).max())
        quantum = length_quantum(reach)
        middle = np.round(middle / quantum) * quantum + 0.0  # + 0.0: no -0.0
    else:
        middle = np.asarray(center, dtype=np.float64)
    reach = float(np.linalg.norm(points - middle, axis=1).max())
    radius = MARGIN * reach + spacing
    quantum = length_quantum(radius)
    radius = math.ceil(radius / quantum - 1e-9) * quantum
    return Extent(_vec3(np.round(middle, 12) + 0.0), round(radius, 12), bounded=True)


def sign_changes(expr: sympy.Expr, center: np.ndarray,
                 half: float) -> tuple[np.ndarray, float, bool]:
    """(points where S changes sign along a grid edge, the grid spacing, whether any of
    them lies in the cube's outer layer of cells) for the cube of half-size `half`."""
    spacing = 2.0 * half / GRID
    axes = [c - half + spacing * (SHIFT + np.arange(GRID + 1)) for c in center]
    values = evaluate_on_grid(expr, axes)
    sign = np.sign(values)  # NaN stays NaN: an edge with a NaN end is no sign change
    found = []
    touching = False
    for axis in range(3):
        a = [slice(None)] * 3
        b = [slice(None)] * 3
        a[axis], b[axis] = slice(None, -1), slice(1, None)
        change = sign[tuple(a)] * sign[tuple(b)] < 0
        if not change.any():
            continue
        index = np.nonzero(change)
        if any(((i == 0) | (i >= GRID - 1)).any() for i in index):
            touching = True
        fa, fb = values[tuple(a)][index], values[tuple(b)][index]
        fraction = fa / (fa - fb)
        coords = [axes[k][index[k]] for k in range(3)]
        coords[axis] = coords[axis] + spacing * fraction
        found.append(np.stack(coords, axis=1))
    points = np.concatenate(found) if found else np.zeros((0, 3))
    return points, spacing, touching


def crosses_sphere(expr: sympy.Expr, center: Vec3, radius: float) -> bool:
    """Whether S takes both signs on the sphere (centre, radius): the surface reaches the
    clip sphere and the picture is cut there (SPHERE_SAMPLES points, a Fibonacci lattice;
    a crossing smaller than their spacing can be missed)."""
    k = np.arange(SPHERE_SAMPLES) + 0.5
    polar = np.arccos(1.0 - 2.0 * k / SPHERE_SAMPLES)
    azimuth = math.pi * (1.0 + math.sqrt(5.0)) * k
    unit = np.stack([np.cos(azimuth) * np.sin(polar), np.sin(azimuth) * np.sin(polar),
                     np.cos(polar)], axis=1)
    points = np.asarray(center, dtype=np.float64) + radius * unit
    values = evaluate(expr, dict(zip(POINT, points.T, strict=True)))
    values = np.broadcast_to(values, (SPHERE_SAMPLES,))
    return bool((values > 0).any() and (values < 0).any())
