"""S at a point in Chebyshev's basis of the box that holds its surface, by Clenshaw's
recurrence: the float32 exact program's F at the point (its node ends and its Newton's
last step), where S written in monomials cannot be evaluated in float32.

Evaluated in float32, a polynomial is off by about 2^-24 times the sum of its terms'
magnitudes in the basis it is evaluated in. In monomials that sum is the polynomial's
size on the complex disc, not on the real box: Chmutov's T_20 written in monomials sums
to 2.3e7 at |x| = 1 where T_20 itself stays within 1, and float32 moves its surface by
more than 1e-3 at a third of its points. In Chebyshev's basis of the box [c - h, c + h]
that holds the surface (T_k((v - c)/h) for each variable v), the coefficients sum to
about the polynomial's size on the box (27 for T_20 on a box 2 % wider than [-1, 1]),
and Clenshaw's recurrence evaluates it with an error of a few roundings of that sum.
Measured in numpy on 20,000 points of T_n + T_n + T_n = 0 (docs/journal/2026-12-05-float32.md):
the median distance moved 4e-4 in monomials at T_20, 2e-8 here.

The box is the surface's sampled sign changes (implc/extent.py), a grid cell wider each
side and rounded outwards to a power of two's multiple, so the change of variables is
exact: chosen by implc/box_choice.py, with numpy's arrays where numpy loads, in plain
Python where it does not (the same box: the program's bytes do not depend on numpy).
Outside the box the basis grows as the polynomial does: its rounding stays a share of S's
own size there.

Only where it pays: the monomials must move the sampled surface GAIN times farther than
Chebyshev's basis (box_choice.py) (the sums of powers x^n + y^n + z^n - 1, already
well conditioned, keep their monomials)."""

from __future__ import annotations

from functools import lru_cache

import sympy

from .box_choice import Box, choose_box, monomial_in_chebyshev
from .derive import expanded_terms
from .optimize import Program, count_ops
from .symbols import DIRECTION, POINT

# S's monomials above which its monomials are kept: the exact conversion's sympy work grows
# with their number times the tensor basis's size (206 monomials of degree 10: 0.9 s with
# the box's choice, most of it sampling; Chmutov's T_20 31)
MAX_MONOMIALS = 400


def chebyshev_program(expr: sympy.Expr) -> Program | None:
    """S at the point by nested Clenshaw recurrences in Chebyshev's basis of the box that
    holds its surface, or None: not a polynomial with numeric coefficients, no surface
    found, or no GAIN in conditioning."""
    return _program(expr)


@lru_cache(maxsize=16)
def _program(expr: sympy.Expr) -> Program | None:
    converted = _converted(expr)
    return None if converted is None else _clenshaw_program(*converted[:2])


@lru_cache(maxsize=16)
def _converted(expr: sympy.Expr) -> tuple[dict, Box, int] | None:
    """(S's exact coefficients in Chebyshev's basis of its box, the box, S's degree), or
    None where S keeps its monomials; once for S at the point and the ray's coefficients
    (read, never changed)."""
    terms = expanded_terms(expr)
    if not terms or len(terms) > MAX_MONOMIALS or not all(c.is_number for c in terms.values()):
        return None
    box = surface_box(expr)
    if box is None:
        return None
    coefficients = tensor_coefficients({m: sympy.nsimplify(c) if c.is_Float else c
                                        for m, c in terms.items()}, box)
    return coefficients, box, max(sum(m) for m in terms)


def surface_box(expr: sympy.Expr) -> Box | None:
    """(centre, half width) per axis, dyadic, of the box whose Chebyshev basis moves S's
    sampled surface least in float32, or None (implc/box_choice.py): by numpy's sampling
    and measure (implc/box_numpy.py) where numpy loads, else by their plain-Python twins,
    which choose the same box (issue 48: the same program bytes without numpy)."""
    try:
        from .box_numpy import surface_box as measured
    except ImportError:  # numpy missing (Pyodide, issue 43)
        return _plain_box(expr)
    return measured(expr)


def _plain_box(expr: sympy.Expr) -> Box | None:
    from .plain_extent import locate, sign_changes

    located = locate(expr)
    if located is None:
        return None
    center, radius = located
    points, spacing, _ = sign_changes(expr, center, radius)
    terms = {m: float(c) for m, c in expanded_terms(expr).items()}
    return choose_box(terms, center, points, spacing)


def tensor_coefficients(terms: dict, box) -> dict[tuple[int, int, int], sympy.Rational]:
    """b_lmn with S = sum b_lmn T_l(X) T_m(Y) T_n(Z), X = (x - c_x)/h_x, ..., exactly."""
    X = sympy.Symbol("X")
    polys = []
    for (c, h) in box:  # v = c + h X, as a polynomial in X
        polys.append(sympy.Poly(c + h * X, X))
    shifted: dict[tuple[int, int, int], sympy.Expr] = {}
    powers: dict[tuple[int, int], list] = {}
    for m, a in terms.items():
        parts = []
        for axis, e in enumerate(m):
            key = (axis, e)
            if key not in powers:
                powers[key] = _chebyshev_of((polys[axis] ** e).all_coeffs()[::-1])
            parts.append(powers[key])
        for i, bi in enumerate(parts[0]):
            for j, bj in enumerate(parts[1]):
                for k, bk in enumerate(parts[2]):
                    if bi and bj and bk:
                        shifted[(i, j, k)] = shifted.get((i, j, k), 0) + a * bi * bj * bk
    return {m: sympy.Rational(b) for m, b in sorted(shifted.items()) if b != 0}


def _chebyshev_of(power_coefficients: list) -> list:
    """The Chebyshev coefficients of sum p_k X^k (lowest first)."""
    out = [sympy.Rational(0)] * len(power_coefficients)
    for k, p in enumerate(power_coefficients):
        if p:
            for j, q in enumerate(monomial_in_chebyshev(k)):
                out[j] += p * q
    return out


def _clenshaw_program(b: dict, box, n: int | None = None) -> Program:
    """Nested Clenshaw: for each (l, m) the sum over n in Z, then over m in Y, then over l
    in X; every step named (k0, k1, ...). A series of even terms alone (a surface
    symmetric in that variable: Chmutov's T_n of even n) takes half the steps in T_2 of
    its argument. With `n`, every value is a power series in s truncated at degree n (a
    list of coefficients, lowest first) and the outputs are F's c_0..c_n."""
    assignments: list[tuple[sympy.Symbol, sympy.Expr]] = []
    zero = sympy.S.Zero

    def named(value: sympy.Expr) -> sympy.Expr:
        if value.is_Atom:
            return value
        symbol = sympy.Symbol(f"k{len(assignments)}", real=True)
        assignments.append((symbol, value))
        return symbol

    def series(value) -> list:
        return value if isinstance(value, list) else [value]

    def add(*parts) -> list:  # sums of (factor, series)
        size = max(len(series(s)) for _, s in parts)
        return [named(sympy.Add(*(f * series(s)[i] for f, s in parts if i < len(series(s)))))
                for i in range(size)]

    def times(a, c) -> list:  # a * c, truncated at degree n
        a, c = series(a), series(c)
        size = min(len(a) + len(c) - 1, (n if n is not None else 0) + 1)
        return [named(sympy.Add(*(a[i] * c[k - i] for i in range(len(a))
                                  if 0 <= k - i < len(c))))
                for k in range(size)]

    # the argument of each axis at each level: t, then T_2(t) = 2t^2 - 1, T_2(T_2(t)), ...
    levels = []
    for axis, (c, h) in enumerate(box):
        t0 = named((POINT[axis] - _number(c)) * _number(1 / h))
        levels.append([[t0] if n is None else [t0, named(DIRECTION[axis] * _number(1 / h))]])
    twice: dict[tuple[int, int], list] = {}

    def argument(axis: int, level: int) -> tuple[list, list]:
        """The axis's argument at `level` and twice it."""
        while len(levels[axis]) <= level:
            t = levels[axis][-1]
            square = times(t, t)
            levels[axis].append(add((2, square), (-1, [sympy.S.One])))
        if (axis, level) not in twice:
            twice[axis, level] = add((2, levels[axis][level]))
        return levels[axis][level], twice[axis, level]

    def third_kind(values: dict[int, object], axis: int, level: int):
        """sum values[j] V_j(u) (V: Chebyshev's polynomials of the third kind, V_0 = 1,
        V_1 = 2u - 1, the same recurrence as T's), u the argument at `level`."""
        if max(values) == 0:
            return values[0]
        _, u2 = argument(axis, level)
        b1: object = [zero]
        b2: object = [zero]
        for k in range(max(values), 0, -1):
            b1, b2 = add((1, values.get(k, zero)), (1, times(u2, b1)), (-1, b2)), b1
        return add((1, values.get(0, zero)), (-1, b2),
                   (1, times(add((1, u2), (-1, [sympy.S.One])), b1)))

    def clenshaw(values: dict[int, object], axis: int, level: int = 0):
        """sum values[k] T_k(arg) by Clenshaw's recurrence; where every k is even, in
        T_2(arg), with half the steps (T_2j(t) = T_j(T_2(t))); where every k is odd (but
        for a constant), in T_2(arg) too, by T_(2j+1)(t) = t V_j(T_2(t))."""
        top = max(values)
        if top == 0:
            return values[0]
        if all(k % 2 == 0 for k in values):
            return clenshaw({k // 2: v for k, v in values.items()}, axis, level + 1)
        if all(k % 2 == 1 for k in values if k):
            t, _ = argument(axis, level)
            odd = times(t, third_kind({(k - 1) // 2: v for k, v in values.items() if k},
                                      axis, level + 1))
            return add((1, odd), (1, values[0])) if 0 in values else odd
        t, t2 = argument(axis, level)
        b1: object = [zero]
        b2: object = [zero]
        for k in range(top, 0, -1):
            b1, b2 = add((1, values.get(k, zero)), (1, times(t2, b1)), (-1, b2)), b1
        return add((1, values.get(0, zero)), (1, times(t, b1)), (-1, b2))

    rows: dict[int, dict[int, dict[int, sympy.Expr]]] = {}
    for (i, j, k), value in b.items():
        rows.setdefault(i, {}).setdefault(j, {})[k] = _number(value)
    outer = {i: clenshaw({j: clenshaw(zs, 2) for j, zs in sorted(ys.items())}, 1)
             for i, ys in sorted(rows.items())}
    value = series(clenshaw(outer, 0))
    ops = sum(count_ops(v) for _, v in assignments)
    if n is None:
        return Program(POINT, tuple(assignments), (value[0],), ops, ops)
    outputs = tuple(value[:n + 1]) + (zero,) * (n + 1 - len(value))
    return Program(POINT + DIRECTION, tuple(assignments), outputs, ops, ops)


def chebyshev_ray_program(expr: sympy.Expr) -> Program | None:
    """The ray polynomial's coefficients c_0..c_n of F(s) = S(o + s d) from S in
    Chebyshev's basis of its box (None where chebyshev_program is None): the nested
    Clenshaw recurrences of _clenshaw_program on truncated power series in s, each
    variable's argument X(s) = (o - c)/h + s d/h. Their terms are about the coefficients'
    own size, where S's monomials' are up to (1 + sqrt 2)^n larger: computed in float32
    here, exact's walk on T_16 (256^2, against the certified reference) has 15 bad
    pixels, as with coefficients computed in double and rounded, against 55 from the
    monomials (scripts/float32_diagnosis.py)."""
    return _ray_program(expr)


@lru_cache(maxsize=16)
def _ray_program(expr: sympy.Expr) -> Program | None:
    converted = _converted(expr)
    return None if converted is None else _clenshaw_program(*converted)


def _number(value: sympy.Rational) -> sympy.Expr:
    """A coefficient as the printer's literal: an integer, or the nearest double."""
    return sympy.Integer(value) if value.is_Integer else sympy.Float(float(value), 17)
