"""The exact CPU reference renderer: the shared camera and shading, roots found in float64.

Every ray is clipped to the bounding sphere and restarted at its entry point O' (as the
shaders do), so the surface along it is F(s) = S(O' + sD), s = t - t_near in [0, L],
L = t_far - t_near, and the hit is the first zero of F in that interval.

Polynomial surfaces (total degree <= MAX_RAY_POLYNOMIAL_DEGREE): F is a polynomial in s. All
its real roots in [0, L], tangential (double) roots included, come from the eigenvalues of
its companion matrix and are polished by Newton (`first_root_in_interval`); the first is
the hit, exact up to float64 rounding. This is the ground truth the marchers are measured
against.

Other surfaces: a certified interval search (`certified_first_roots`). The chord is cut
into dyadic nodes (halves, quarters, ..., down to leaves of 2^-DEPTH of it), and a node is
dropped only when it provably holds no zero of F: F's enclosure over it (the `interval`
method's own program, implc/interval.py, evaluated in float64 with the double widening)
excludes 0, or the mean value form F(mid) + F'(node) [-w/2, w/2] does (F' = grad S . D,
enclosed by the same program), or F' excludes 0 (F is monotonic) and F has one sign at
both ends. A monotonic node with a sign change holds exactly one root, and a leaf with a
sign change holds the first root to within its width: both are bisected to
BISECTION_WIDTH. The first root (or exact zero of F) along the ray is the hit.
Guarantee: no sign change of F is missed, whatever its roots' spacing, up to the float64
rounding of S's point values (the enclosures are widened for their own rounding); only
two roots inside one leaf (~1e-12 of the chord) show no sign change. (A jump through a
pole, of tan or 1/u, is a sign change too, as in the shaders' leaf test.) Tangential
roots, where F touches 0 without a sign change, are found within TOUCH_TOL: a node (a
dropped one where F' may vanish, or a leaf) whose |F(mid)| / |grad S| <= TOUCH_TOL L is
a touching root, so a ray that passes that close to the surface is a hit, as with the
polynomial reference. Where S is undefined (NaN: outside sqrt's or log's domain) there is
no surface. The derivative tests are used only where F is continuous on the node: the
arguments of log, fractional powers, asin, acos, tan, 1/u and sign are checked inside
their domain on it, by the same enclosures.
Surfaces with a function that has no interval rule (atan2: range_program raises
InputError) fall back to the dense search (`dense_first_roots`): F sampled at `samples`
points, the first sign change bisected, the dips of |F| between samples checked for
tangential hits. That one is NOT exact: two roots closer than the sample spacing with no
dip between samples can be missed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy
from sympy.polys.rings import ring

from .. import interval
from ..errors import InputError
from ..numeric import evaluate, evaluate_program
from ..scene import View, clip_sphere, pixel_rays, shade, shading_for
from ..symbols import DIRECTION, POINT, T, X, Y, Z
from .result import RenderResult

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

# Dense search for non-polynomial surfaces.
DENSE_SAMPLES = 2048
BISECTION_WIDTH = 1e-12  # final bracket width of a sign-change root, in units of t
TOUCH_TOL = 1e-9  # tangential hit when |F| / |grad S| <= TOUCH_TOL * L at a dip of |F|

POLYNOMIAL_CHUNK = 1 << 16  # rays per batch of companion matrices
DENSE_CHUNK_VALUES = 1 << 20  # rays x samples per batch (the evaluator keeps every node)

# Certified search for non-polynomial surfaces (BISECTION_WIDTH and TOUCH_TOL as above).
DEPTH = 40  # leaves are 2^-DEPTH of the chord (~1e-12 for a chord of 3)
CERTIFIED_CHUNK_RAYS = 1 << 14  # rays searched together (their nodes are kept level by level)
CERTIFIED_CHUNK_NODES = 1 << 15  # nodes per evaluation of an enclosure program
# Functions whose every argument is in their domain and which are continuous (Abs, Min
# and Max Lipschitz): the derivative tests need no check of their arguments.
_SMOOTH = frozenset({"sin", "cos", "exp", "atan", "sinh", "cosh", "tanh", "Abs", "Min", "Max"})


def render_reference(
    expr: sympy.Expr, view: View, width: int, height: int, *, samples: int = DENSE_SAMPLES
) -> RenderResult:
    """Render S = 0 with the shared camera and shading; hits are exact float64 roots for
    polynomial S and from the certified interval search otherwise (the inexact dense
    search for surfaces with a function that has no interval rule).

    `steps` reports, for every pixel that entered the clip sphere, the nodes the certified
    search visited (its enclosures evaluated), 0 for polynomial surfaces, and `samples`
    for the dense search (surfaces without an interval rule), the only use of `samples`.
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
        try:
            found, t_rows, steps_inside = certified_first_roots(expr, *args, gradient=gradient)
        except InputError:  # a function without an interval rule (atan2)
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
    color = shade(grad.reshape(*shape, 3), dirs.reshape(*shape, 3), hit.reshape(shape), view,
                  shading_for(view))
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


def certified_first_roots(
    expr: sympy.Expr,
    origins: np.ndarray,
    dirs: np.ndarray,
    t_near: np.ndarray,
    t_far: np.ndarray,
    *,
    gradient: Sequence[sympy.Expr] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First zero of F along each ray by the certified interval search (the module's doc).

    Arrays are (N, 3) and (N,); returns (hit, t, nodes) with t measured from `origins` and
    nodes the number of nodes whose enclosures were evaluated, per ray. Raises InputError
    when S has a function without an interval rule.

    The nodes of all rays of a chunk are searched level by level (breadth first): level k
    holds the nodes of width 2^-k of the chord that may still hold the first root. A node
    is dropped when it provably holds no zero (see `_node_verdicts`); a node that provably
    holds a root (a bracket, or a sign change of continuous F) drops every node after it on
    its ray, as the first root cannot lie there. The others are halved, down to leaves at
    level DEPTH. The first bracket, touching node or exact zero along each ray is the hit.
    """
    programs = _search_programs(expr)
    if gradient is None:
        gradient = [sympy.diff(expr, v) for v in POINT]
    origins, dirs = np.asarray(origins, np.float64), np.asarray(dirs, np.float64)
    t_near, t_far = np.asarray(t_near, np.float64), np.asarray(t_far, np.float64)
    n = origins.shape[0]
    hit = np.zeros(n, dtype=bool)
    t = np.zeros(n)
    nodes = np.zeros(n)
    for lo in range(0, n, CERTIFIED_CHUNK_RAYS):
        part = slice(lo, lo + CERTIFIED_CHUNK_RAYS)
        entry = origins[part] + t_near[part, None] * dirs[part]
        s, nodes[part] = _certified_chunk(
            expr, programs, gradient, entry, dirs[part], t_far[part] - t_near[part]
        )
        found = np.isfinite(s)
        hit[part] = found
        t[part] = np.where(found, t_near[part] + s, 0.0)
    return hit, t, nodes


@dataclass(frozen=True)
class _SearchPrograms:
    """The enclosures the certified search evaluates: F's (`value`), F' = grad S . D's
    (`slope`, None when the derivative tests are off) and `guards`, one per argument that
    must stay inside its function's domain for F to be continuous on a node (each
    enclosure's lower bound > 0)."""

    value: interval.RangeProgram
    slope: interval.RangeProgram | None
    guards: tuple[interval.RangeProgram, ...]


def _search_programs(expr: sympy.Expr) -> _SearchPrograms:
    value = interval.range_program(expr)  # InputError: no interval rule
    terms = _continuity_terms(expr)
    if terms is None:
        return _SearchPrograms(value, None, ())
    slope = sum(
        (sympy.diff(expr, v) * dv for v, dv in zip(POINT, interval.DIRECTION, strict=True)),
        sympy.S.Zero,
    )
    # d max(u, v) = u' H(u - v) + v' H(v - u): H(w) = (sign(w) + 1)/2 everywhere (both
    # 1/2 at 0); d sign(u) = 2 delta(u) u' is 0 where the guard holds (u != 0 on the node)
    slope = slope.replace(sympy.Heaviside, lambda w, *_: (sympy.sign(w) + 1) / 2)
    slope = slope.replace(sympy.DiracDelta, lambda *_: sympy.S.Zero)
    try:
        return _SearchPrograms(
            value,
            interval.range_program(slope),
            tuple(interval.range_program(term) for term in terms),
        )
    except InputError:  # F' has a node without an interval rule: F's enclosure alone
        return _SearchPrograms(value, None, ())


def _continuity_terms(expr: sympy.Expr) -> list[sympy.Expr] | None:
    """Expressions that are > 0 on a segment wherever S is continuous there, with F' its
    derivative almost everywhere: the argument of log or of a fractional power, |u| for
    1/u^n and sign(u), 1 - |u| for asin and acos, |cos u| for tan. None for a node this
    does not know (the derivative tests are then off)."""
    terms: list[sympy.Expr] = []
    for node in sympy.preorder_traversal(expr):
        if node.is_Atom or node.is_Add or node.is_Mul:
            continue
        if node.is_Pow:
            base, exp = node.args
            if exp.is_Integer:
                if exp < 0:
                    terms.append(sympy.Abs(base))
            elif exp.is_number and exp.is_real:
                terms.append(base)
            else:
                return None
            continue
        name = type(node).__name__
        if name in _SMOOTH:
            continue
        if name == "log":
            terms.append(node.args[0])
        elif name in ("asin", "acos"):
            terms.append(1 - sympy.Abs(node.args[0]))
        elif name == "tan":
            terms.append(sympy.Abs(sympy.cos(node.args[0])))
        elif name == "sign":
            terms.append(sympy.Abs(node.args[0]))
        else:
            return None
    return list(dict.fromkeys(terms))  # (cbrt's |u| twice: once)


def _certified_chunk(
    expr: sympy.Expr,
    programs: _SearchPrograms,
    gradient: Sequence[sympy.Expr],
    entry: np.ndarray,
    d: np.ndarray,
    length: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(s of the first root or inf, nodes visited) per ray of one chunk."""
    n = length.shape[0]
    visited = np.zeros(n)
    # the chord fraction at or after which no node can hold the first root
    limit = np.full(n, np.inf)
    ray = np.flatnonzero(length > 0.0)
    index = np.zeros(ray.size, dtype=np.int64)  # node [index, index + 1] 2^-level of the chord
    found: list[tuple[np.ndarray, ...]] = []  # (ray, key, lo, hi, f_lo): roots in [lo, hi]
    for level in range(DEPTH + 1):
        scale = 2.0**-level
        keep = index * scale < limit[ray]
        ray, index = ray[keep], index[keep]
        if ray.size == 0:
            break
        visited += np.bincount(ray, minlength=n)
        # dyadic fractions of the chord are exact: a node's ends are its neighbours' ends
        s_a = index * scale * length[ray]
        s_m = (index + 0.5) * scale * length[ray]
        s_b = (index + 1) * scale * length[ray]
        v = _node_verdicts(
            expr, programs, gradient, entry, d, length, ray, s_a, s_m, s_b, level == DEPTH
        )
        bracket, touch, descend, crossing = v["bracket"], v["touch"], v["descend"], v["crossing"]
        found.append((ray[bracket], s_a[bracket], s_a[bracket], s_b[bracket], v["fa"][bracket]))
        found.append((ray[touch], s_a[touch], s_m[touch], s_m[touch], np.zeros(touch.sum())))
        proven = bracket | touch | crossing
        np.minimum.at(limit, ray[proven], (index[proven] + 1) * scale)
        # F exactly 0 at an end or the middle: a root there, and none after it is first (this
        # also ends a stretch where F vanishes identically, which nothing else would drop)
        zero = v["zero"] >= 0
        at = np.choose(v["zero"][zero], (s_a[zero], s_m[zero], s_b[zero]))
        found.append((ray[zero], at, at, at, np.zeros(at.size)))
        np.minimum.at(limit, ray[zero], (index[zero] + 0.5 * v["zero"][zero]) * scale)
        ray = np.repeat(ray[descend], 2)
        index = (2 * index[descend, None] + np.arange(2)).ravel()
    if not found:
        return np.full(n, np.inf), visited
    rows, key, lo, hi, f_lo = (np.concatenate(parts) for parts in zip(*found, strict=True))
    order = np.lexsort((key, rows))  # by ray, then along it
    rows, lo, hi, f_lo = rows[order], lo[order], hi[order], f_lo[order]
    first = np.ones(rows.size, dtype=bool)
    first[1:] = rows[1:] != rows[:-1]
    rows, lo, hi, f_lo = rows[first], lo[first], hi[first], f_lo[first]
    s = np.full(n, np.inf)
    s[rows] = _bisect(expr, entry[rows], d[rows], lo, hi, f_lo)
    return s, visited


def _node_verdicts(
    expr: sympy.Expr,
    programs: _SearchPrograms,
    gradient: Sequence[sympy.Expr],
    entry: np.ndarray,
    d: np.ndarray,
    length: np.ndarray,
    ray: np.ndarray,
    s_a: np.ndarray,
    s_m: np.ndarray,
    s_b: np.ndarray,
    leaf: bool,
) -> dict[str, np.ndarray]:
    """What each node [s_a, s_b] of ray `ray` is, in batches of CERTIFIED_CHUNK_NODES:
    - "bracket": it holds a root, the first of the node, between its ends of opposite sign:
      F is monotonic on it (F' excludes 0), or it is a leaf;
    - "touch": a node without a sign change where |F(mid)| / |grad S| <= TOUCH_TOL L (the
      distance to the surface, to first order): a leaf, or a node dropped by the mean
      value form while F' may vanish on it (a near miss at a tangent: no zero, a dip);
    - "descend": it may hold a root and is halved; "crossing" (among them): F is
      continuous on it and changes sign between its ends, so it holds a root;
    - none of these: it holds no zero of F. Either F's enclosure excludes 0, or F is
      continuous on it (the guards) and the mean value form |F(mid)| > max |F'| w/2
      excludes 0, or F' excludes 0 and F has one sign at both ends. A leaf with no sign
      change that does not touch is dropped too (the search's resolution).
    "fa" is F at the node's start; "zero" 0, 1 or 2 where F is exactly 0 at its start,
    middle or end (the first of them), else -1.
    """
    parts = []
    for lo in range(0, ray.size, CERTIFIED_CHUNK_NODES):
        part = slice(lo, lo + CERTIFIED_CHUNK_NODES)
        parts.append(
            _node_verdicts_batch(
                expr, programs, gradient, entry[ray[part]], d[ray[part]], length[ray[part]],
                s_a[part], s_m[part], s_b[part], leaf,
            )
        )
    if not parts:
        empty = np.zeros(0, dtype=bool)
        return {k: empty for k in ("bracket", "touch", "descend", "crossing")} | {
            "fa": np.zeros(0), "zero": np.zeros(0, dtype=int)
        }
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def _node_verdicts_batch(
    expr, programs, gradient, o, d, length, s_a, s_m, s_b, leaf
) -> dict[str, np.ndarray]:
    m = s_a.shape[0]
    fa, fm, fb = _along(expr, o, d, np.stack([s_a, s_m, s_b], axis=-1)).T
    lo, hi = _enclosure(programs.value, o, d, s_a, s_b)
    undecided = ~((lo > 0.0) | (hi < 0.0))  # NaN never excludes
    bracket = np.zeros(m, dtype=bool)
    continuous = np.zeros(m, dtype=bool)
    # dropped (or a leaf) where |F| may have a minimum inside: a touching root if small
    dip = ~undecided  # (F' is checked below, for the few that are small)
    with np.errstate(invalid="ignore", over="ignore"):
        change = fa * fb <= 0.0
        if programs.slope is not None:
            sub = np.flatnonzero(undecided)
            ok = np.isfinite(fa[sub]) & np.isfinite(fm[sub]) & np.isfinite(fb[sub])
            args = (o[sub], d[sub], s_a[sub], s_b[sub])
            for guard in programs.guards:
                ok &= _enclosure(guard, *args)[0] > 0.0
            dlo, dhi = _enclosure(programs.slope, *args)
            ok &= np.isfinite(dlo) & np.isfinite(dhi)
            # the mean value form: F(s) in F(mid) + F'([a, b]) (s - mid), |s - mid| <= w/2
            # (the factor covers the rounding of the node's ends at the finest level)
            reach = np.maximum(np.abs(dlo), np.abs(dhi)) * (0.5 * (s_b - s_a)[sub])
            flat_out = ok & (np.abs(fm[sub]) > reach * (1.0 + 2.0**-8))
            steep = (dlo > 0.0) | (dhi < 0.0)
            monotonic = ok & ~flat_out & steep
            bracket[sub] = monotonic & change[sub]
            undecided[sub] &= ~(flat_out | monotonic)
            continuous[sub] = ok
            dip[sub] = flat_out & ~steep
    if leaf:
        bracket |= undecided & change
        dip |= undecided
        descend = np.zeros(m, dtype=bool)
    else:
        descend = undecided
    touch = _touching(programs, gradient, o, d, length, s_a, s_m, s_b, fm, dip & ~change)
    with np.errstate(invalid="ignore"):
        crossing = descend & continuous & (fa * fb < 0.0)
    zero = np.where(fa == 0.0, 0, np.where(fm == 0.0, 1, np.where(fb == 0.0, 2, -1)))
    return {"bracket": bracket, "touch": touch, "descend": descend, "crossing": crossing,
            "fa": fa, "zero": zero}


def _touching(programs, gradient, o, d, length, s_a, s_m, s_b, fm, dip) -> np.ndarray:
    """Touching roots among the `dip` nodes: F comes within TOUCH_TOL of 0 at the middle
    (|F| / |grad S| <= TOUCH_TOL L, the distance to the surface to first order) and F'
    may vanish on the node (a node on a monotonic stretch near a crossing is not one)."""
    touch = np.zeros(s_a.shape[0], dtype=bool)
    near = np.flatnonzero(dip)
    if not near.size:
        return touch
    env = _point_env(o[near] + s_m[near, None] * d[near])
    grad = np.linalg.norm(np.stack([_on(g, env, near.size) for g in gradient], axis=-1), axis=-1)
    with np.errstate(invalid="ignore"):
        near = near[np.abs(fm[near]) <= TOUCH_TOL * length[near] * grad]
    if near.size and programs.slope is not None:
        dlo, dhi = _enclosure(programs.slope, o[near], d[near], s_a[near], s_b[near])
        near = near[~((dlo > 0.0) | (dhi < 0.0))]
    touch[near] = True
    return touch


def _enclosure(
    program: interval.RangeProgram, o: np.ndarray, d: np.ndarray, a: np.ndarray, b: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A range program's [lo, hi] over the segments [a, b] of the rays o + s d."""
    ulp, tiny = interval.WIDENING["double"]
    env = {interval.A: a, interval.B: b, interval.ULP: np.float64(ulp),
           interval.TINY: np.float64(tiny)}
    env.update(zip(interval.ORIGIN, o.T, strict=True))
    env.update(zip(interval.DIRECTION, d.T, strict=True))
    lo, hi = evaluate_program(program.assignments, [program.lo, program.hi], env)
    return np.broadcast_to(lo, a.shape), np.broadcast_to(hi, a.shape)


def _bisect(
    expr: sympy.Expr,
    entry: np.ndarray,
    d: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    f_lo: np.ndarray,
) -> np.ndarray:
    """A root in each [lo, hi] whose ends have opposite signs (or f_lo = 0: lo), bisected
    to BISECTION_WIDTH (F's value at lo is f_lo)."""
    at_lo = f_lo == 0.0
    iterations = _halvings(float(np.max(hi - lo, initial=0.0)))
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        f_mid = _along(expr, entry, d, mid[:, None])[:, 0]
        with np.errstate(invalid="ignore"):
            same = f_mid * f_lo > 0.0
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        f_lo = np.where(same, f_mid, f_lo)
    return np.where(at_lo, lo, 0.5 * (lo + hi))


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
