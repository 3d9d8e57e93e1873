"""The CPU reference's certified interval search (implc/render/reference.py, which states
its guarantee), for non-polynomial surfaces: the chord cut into dyadic nodes, a node
dropped only when the `interval` method's enclosures prove it holds no zero of F, the
first root bisected to BISECTION_WIDTH.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy

from .. import interval
from ..errors import InputError
from ..numeric import evaluate_program
from ..symbols import POINT
from .reference_eval import (
    TOUCH_TOL,
    along_ray,
    bisection_steps,
    derivative_along,
    evaluate_on,
    point_env,
)

# Certified search for non-polynomial surfaces (BISECTION_WIDTH, TOUCH_TOL: reference_eval).
DEPTH = 40  # leaves are 2^-DEPTH of the chord (~1e-12 for a chord of 3)
CERTIFIED_CHUNK_RAYS = 1 << 14  # rays searched together (their nodes are kept level by level)
CERTIFIED_CHUNK_NODES = 1 << 15  # nodes per evaluation of an enclosure program
# Functions whose every argument is in their domain and which are continuous (Abs, Min
# and Max Lipschitz): the derivative tests need no check of their arguments.
_SMOOTH = frozenset({"sin", "cos", "exp", "atan", "sinh", "cosh", "tanh", "Abs", "Min", "Max"})


def certified_first_roots(
    expr: sympy.Expr,
    origins: np.ndarray,
    dirs: np.ndarray,
    t_near: np.ndarray,
    t_far: np.ndarray,
    *,
    gradient: Sequence[sympy.Expr] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First zero of F along each ray by the certified interval search (reference.py's doc).

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
      F is monotonic on it (F' excludes 0), or it is a leaf where F is bounded (a leaf
      holding a pole, F's enclosure marked unbounded, is dropped: a jump, not a root);
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
    fa, fm, fb = along_ray(expr, o, d, np.stack([s_a, s_m, s_b], axis=-1)).T
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
    if leaf:  # by a pole (F's enclosure marked unbounded) neither a sign change is a root
        # nor a small |F| / |grad S| (F ~ 1/u: u, the distance to the pole) a touch
        bounded = ~interval.unbounded(lo, hi)
        bracket |= undecided & change & bounded
        dip |= undecided & bounded
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
    (|F| / |grad S| <= TOUCH_TOL L, the distance to the surface to first order), F' may
    vanish on the node (a node on a monotonic stretch near a crossing is not one) and |F|
    has its dip there: sign(F) F' <= 0 at the start and >= 0 at the end. (Beside a pole,
    F ~ 1/u, |F| / |grad S| ~ |u| is small too, but |F| grows toward the pole or peaks
    where the ray passes closest to it: no dip.)"""
    touch = np.zeros(s_a.shape[0], dtype=bool)
    near = np.flatnonzero(dip)
    if not near.size:
        return touch
    env = point_env(o[near] + s_m[near, None] * d[near])
    grad = np.linalg.norm(np.stack([evaluate_on(g, env, near.size) for g in gradient], axis=-1),
                          axis=-1)
    with np.errstate(invalid="ignore"):
        near = near[np.abs(fm[near]) <= TOUCH_TOL * length[near] * grad]
    if near.size and programs.slope is not None:
        dlo, dhi = _enclosure(programs.slope, o[near], d[near], s_a[near], s_b[near])
        near = near[~((dlo > 0.0) | (dhi < 0.0))]
    if near.size:
        side = np.sign(fm[near])
        down = derivative_along(gradient, o[near], d[near], s_a[near]) * side <= 0.0
        up = derivative_along(gradient, o[near], d[near], s_b[near]) * side >= 0.0
        near = near[down & up]
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
    iterations = bisection_steps(float(np.max(hi - lo, initial=0.0)))
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        f_mid = along_ray(expr, entry, d, mid[:, None])[:, 0]
        with np.errstate(invalid="ignore"):
            same = f_mid * f_lo > 0.0
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        f_lo = np.where(same, f_mid, f_lo)
    return np.where(at_lo, lo, 0.5 * (lo + hi))
