"""How far a float32 rounding of S moves its surface: the conditioning `implc show`
prints for a polynomial surface.

Evaluated in float32, S at a point is off by up to about 2^-24 times the sum of its
terms' magnitudes, M(p) (S as written, every constant and coordinate by its absolute
value, every subtraction an addition). Near the surface that error moves the zero set
by about d(p) = 2^-24 M(p) / |grad S(p)|. Where d reaches the distance the counts call
a wrong root (options.T_TOL), no float32 method can draw the surface right there, and
the exact method's ray polynomial, an expansion about the chord's middle, rounds worse
still. Measured (docs/RESULTS.md section 8): on Chmutov's T_n + T_n + T_n the share of
points moved beyond T_TOL is 0 up to degree 14, 1.3 % at 16, 52 % at 18 and 66 % at 20,
where every method's picture has thousands of wrong pixels; 0 on sums of n-th powers to
degree 20 and on the gallery rows of issue 21 (corpus rows 137, 163, 244, 247, 285).

The points are the sign changes of S on the grid that frames the surface
(implc/extent.py), so this is a sampling, as the framing is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy

from .extent import locate_surface, sign_changes
from .numeric import evaluate
from .options import T_TOL
from .symbols import POINT

FLOAT32_UNIT = 2.0**-24  # the unit roundoff of float32
# From this share of the sampled points moved beyond T_TOL, `implc show` warns: measured
# at 512^2, Chmutov's T_16 (1.3 %) has 8,313 bad pixels of 262,144 with exact, T_14 (0 %)
# 735, and Taubin's heart (0.5 %, at its tangent cone) 10.
WARN_SHARE = 0.01


@dataclass(frozen=True)
class Conditioning:
    """How far float32 rounding moves the surface at its sampled points."""

    points: int  # sampled points of the surface
    median: float  # the median distance moved
    p90: float  # its 90th percentile
    far: float  # the share of points moved by more than T_TOL


def magnitude(expr: sympy.Expr) -> sympy.Expr | None:
    """M: `expr` with every constant by its absolute value and every subtraction an
    addition, to be evaluated at |x|, |y|, |z|; None where `expr` is not a polynomial
    tree (a division, a function)."""
    if expr.is_number:  # a constant, written as 3/4, pi or sqrt(2)
        return abs(expr)
    if expr.is_Symbol:
        return expr if expr in POINT else None
    if expr.is_Add or expr.is_Mul:
        parts = [magnitude(a) for a in expr.args]
        if any(p is None for p in parts):
            return None
        return (sympy.Add if expr.is_Add else sympy.Mul)(*parts)
    if expr.is_Pow and expr.exp.is_Integer and expr.exp > 0:
        base = magnitude(expr.base)
        return None if base is None else sympy.Pow(base, expr.exp)
    return None


def float32_conditioning(expr: sympy.Expr,
                         gradient: tuple[sympy.Expr, ...]) -> Conditioning | None:
    """The distances float32 rounding moves the surface of a polynomial S (its
    `gradient`: derive.Derivatives'), at the sign changes of S in the cube around its
    located extent; None when S is not a polynomial tree or no surface is found."""
    bound = magnitude(expr)
    if bound is None:
        return None
    extent = locate_surface(expr)
    if extent is None:
        return None
    points, _, _ = sign_changes(expr, np.asarray(extent.center, dtype=np.float64),
                                extent.radius)
    if not len(points):
        return None
    at = dict(zip(POINT, points.T, strict=True))
    size = evaluate(bound, dict(zip(POINT, np.abs(points.T), strict=True)))
    slope = np.sqrt(sum(evaluate(g, at) ** 2 for g in gradient))
    with np.errstate(divide="ignore", invalid="ignore"):
        moved = np.where(slope > 0, FLOAT32_UNIT * size / slope, np.inf)
    moved = np.broadcast_to(moved, (len(points),))
    return Conditioning(len(points), float(np.median(moved)),
                        float(np.percentile(moved, 90)), float(np.mean(moved > T_TOL)))
