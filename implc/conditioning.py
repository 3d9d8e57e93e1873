"""How far a float32 rounding of S moves its surface: the conditioning `implc show`
prints for a polynomial surface.

Evaluated in float32, S at a point is off by up to about 2^-24 times the sum of its
terms' magnitudes, M(p) (S as written, every constant and coordinate by its absolute
value, every subtraction an addition). Near the surface that error moves the zero set
by about d(p) = 2^-24 M(p) / |grad S(p)|. Where d reaches the distance the counts call
a wrong root (options.T_TOL), no float32 method can draw the surface right there, and
the exact method's ray polynomial, an expansion about the chord's middle, rounds worse
still. Measured (docs/journal/2026-12-04.md): on Chmutov's T_n + T_n + T_n the share of
points moved beyond T_TOL is 0 up to degree 14, 1.3 % at 16, 52 % at 18 and 66 % at 20,
where every method's picture has thousands of wrong pixels; 0 on sums of n-th powers to
degree 20 and on the gallery rows of issue 21 (corpus rows 137, 163, 244, 247, 285).

The points are the sign changes of S on the grid that frames the surface
(implc/extent.py), so this is a sampling, as the framing is.

The exact method's ray polynomial rounds worse than S (its coefficients about the chord's
middle sum larger terms), and from degree 7 its Newton reads F from them: `ray_conditioning`
measures that on the view's pixel rays, with the shader's own coefficient program run in
float32 against float64. Its share of rays moved beyond T_TOL follows exact's share of
wrong pixels at 512^2 (Chmutov's T_14: 0.28 % both, T_16 3.5 % against 3.2 %), and where
it is too large, double precision is the remedy (docs/reference/drop-ins.md, "Drop-in
contract (GLSL)").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy

from .extent import locate_surface, sign_changes
from .numeric import evaluate, evaluate_program
from .optimize import Program
from .options import T_TOL, UNIT_ROUNDOFF
from .scene import View, clip_sphere, pixel_rays
from .symbols import DIRECTION, POINT

FLOAT32_UNIT = UNIT_ROUNDOFF["float"]
# From this share of the sampled points moved beyond T_TOL, `implc show` warns: measured
# at 512^2, Chmutov's T_16 (1.3 %) has 8,313 bad pixels of 262,144 with exact, T_14 (0 %)
# 735, and Taubin's heart (0.5 %, at its tangent cone) 10.
WARN_SHARE = 0.01
# The ray polynomial's rounding is measured on the view's pixel rays, RAYS a side, its first
# root found among SAMPLES points of the chord and refined by bisection. From RAY_WARN_SHARE
# of the rays with a root moved beyond T_TOL, `implc show` warns. Measured (the sweep's
# default view) against exact's bad pixels at 512^2 (docs/journal/2026-12-04.md), when its
# Newton ended on the coefficients' root: Chmutov's T_12 0.089 % of the rays (exact: 0.074 %
# of the pixels bad), T_14 0.28 % (0.28 %), T_16 3.5 % (3.2 %), T_18 20 % (16 %), T_11 and
# T_10 0 (24 and 8 pixels); corpus rows 163, 244, 285, Barth's decic and sums of powers to
# degree 20: 0; row 247 0.05 % (7 pixels). Since then, see RAY_TO_PIXELS.
RAYS = 128
# A coefficient program longer than this (the corpus's expanded rows: row 246's degree-18
# knot has 4,036 steps; Chmutov's T_20 790) is measured on RAYS/2 a side: the measure costs
# rays x steps, and at 128^2 it took 0.5 s of that knot's 3 s compile (issue 44)
LONG_PROGRAM = 2000
SAMPLES = 256
RAY_WARN_SHARE = 4e-3
# exact's float32 program no longer ends on the ray coefficients' root: its Newton ends on S
# at the point (solver.POLISH_STEPS), and where S's monomials do not fit float32 both S and
# the coefficients come from Chebyshev's basis of its box (implc/chebyshev.py); only its
# walk reads the coefficients. Its share of wrong pixels is then a fraction of the share of
# rays the measure counts, measured against the certified reference at 256^2 on gl on
# Chmutov's T_n (the sweep's view): T_14 0.0061 % of the pixels against 0.13 % of the
# rays, T_15 0.0092 % against 0.76 %, T_16 0.037 % against 2.7 %, T_18 0.18 % against
# 9.3 %, T_20 1.2 % against 17 % (RAY_TO_PIXELS: the range of the ratio). RAY_WARN_SHARE is
# set between T_14 (right within the 0.01 % on every float32 renderer) and T_15
# (on two of four).
RAY_TO_PIXELS = "1/80 to 1/15"
# From solver.RECENTER_FROM, where exact's walk re-expands F about a node whose coefficients'
# measured error leaves it in doubt (a skip or a root node) and its Newton takes F' from the
# gradient, the measure (of one expansion about the chord's middle) no longer follows its
# pixels: against the certified reference on all six float32 renderers, Chmutov's T_14-T_20
# at 512^2 framed as every command frames it (0-2 bad pixels, less the false hits the double
# program has too; 0.19-17 % of the rays) and T_17-T_20 on the default view at 192^2 on gl
# and wgpu (0; 5.3-16.7 %) are all within issue 48's 0.01 % (docs/results-float32.md).
# RECENTER_WARN_SHARE is set above every share measured: a surface beyond it is one these
# measurements have not met, and the warning names double for it.
RECENTER_WARN_SHARE = 0.25
RECENTER_RIGHT_UP_TO = 0.17  # the largest share measured where those pictures were right


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


def ray_conditioning(coefficients: Program, view: View,
                     rays: int | None = None) -> Conditioning | None:
    """How far float32's rounding of the ray polynomial's coefficients moves the first
    root, on `view`'s pixel rays (None: no ray has a root). The coefficients c_0..c_n about
    the chord's middle are computed by `coefficients` (raypoly.coefficient_program, the
    shader's own program) from the same float32 ray once in float32 and once in float64;
    the float64 polynomial's first root u (a sign change) moves by |dF(u)| / |F'(u)|.
    Where the exact method's Newton reads F from these coefficients, its roots land there."""
    if rays is None:
        rays = RAYS if len(coefficients.assignments) <= LONG_PROGRAM else RAYS // 2
    origins, dirs = pixel_rays(view, rays, rays)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    t0, t1, inside = clip_sphere(origins, dirs, view.clip_center, view.clip_radius)
    # the shader's ray, in float32: it marches from the clip entry, about the chord's middle
    d = dirs[inside].astype(np.float32)
    entry = (origins[inside] + t0[inside, None] * dirs[inside]).astype(np.float32)
    half = (0.5 * (t1[inside] - t0[inside])).astype(np.float32)
    middle = (entry + half[:, None] * d).astype(np.float32)
    env32 = {**dict(zip(POINT, middle.T, strict=True)), **dict(zip(DIRECTION, d.T, strict=True))}
    env64 = {k: v.astype(np.float64) for k, v in env32.items()}
    shape = (len(half),)
    exact = np.array([np.broadcast_to(c, shape) for c in evaluate_program(
        coefficients.assignments, coefficients.outputs, env64)])
    rounded = np.array([np.broadcast_to(c, shape) for c in evaluate_program(
        coefficients.assignments, coefficients.outputs, env32, real=np.float32)],
        dtype=np.float64)
    root, found = _first_roots(exact, half.astype(np.float64))
    if not found.any():
        return None
    u, c, dc = root[found], exact[:, found], (rounded - exact)[:, found]
    slope = np.abs(_horner(np.arange(1, len(c))[:, None] * c[1:], u))
    with np.errstate(divide="ignore", invalid="ignore"):
        moved = np.where(slope > 0, np.abs(_horner(dc, u)) / slope, np.inf)
    return Conditioning(len(u), float(np.median(moved)), float(np.percentile(moved, 90)),
                        float(np.mean(moved > T_TOL)))


def _horner(c: np.ndarray, u: np.ndarray) -> np.ndarray:
    """sum c_k u^k for every ray (c: (n + 1, rays), u: rays or (samples, rays))."""
    value = np.zeros_like(u) + c[-1]
    for ck in c[-2::-1]:
        value = value * u + ck
    return value


def _first_roots(c: np.ndarray, half: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The first sign change of sum c_k u^k on [-half, half] per ray, among SAMPLES points
    then bisected to float64's resolution, and whether there is one."""
    grid = np.linspace(-1.0, 1.0, SAMPLES)[:, None] * half
    with np.errstate(over="ignore", invalid="ignore"):
        values = _horner(c, grid)
    change = np.signbit(values[:-1]) != np.signbit(values[1:])
    found = change.any(axis=0)
    first = np.argmax(change, axis=0)
    columns = np.arange(c.shape[1])
    lo, hi = grid[first, columns], grid[first + 1, columns]
    f_lo = values[first, columns]
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        f_mid = _horner(c, mid)
        left = np.signbit(f_mid) != np.signbit(f_lo)
        hi, lo, f_lo = np.where(left, mid, hi), np.where(left, lo, mid), np.where(left, f_lo, f_mid)
    return 0.5 * (lo + hi), found
