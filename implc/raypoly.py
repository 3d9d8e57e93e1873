"""The ray polynomial F(s) = S(o + s d) = sum c_k s^k: its coefficients once per ray
(`ray_of`), and its values and derivatives at a parameter by Estrin's scheme, printed as
shader functions and pieces of them (the ray-poly evaluation form and the exact solver
read them)."""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from functools import lru_cache
from math import comb

import sympy

from .derive import expanded_terms, fold_tree, polynomial_degree, ray_coefficients
from .errors import InputError
from .optimize import Program, count_ops, optimize
from .pieces import (
    COMPONENT,
    RETURN_TYPE,
    PrintedBody,
    ShaderFunction,
    function_name,
    printed_lets,
    sym,
)
from .symbols import DIRECTION, POINT

DERIVATIVE_ORDER = {"S": 0, "dS": 1, "d2S": 2}


@lru_cache(maxsize=32)
def coefficient_program(expr: sympy.Expr, precision: str) -> Program:
    """The ray polynomial's coefficients c_0..c_n from (o, d), for a shader computing in
    `precision`. An equation written factored keeps its factors: truncated polynomial
    arithmetic over S's own tree, jointly CSE'd. One written out at length (more than
    HORNER_ABOVE operations) takes Horner's scheme nested over x, y, z (horner_program),
    which needs no CSE; so does one in double where the tree's registers are many
    (coefficient_route)."""
    if polynomial_degree(expr) is None:
        raise InputError("the ray-poly form needs a polynomial surface")
    if coefficient_route(expr, precision) == "horner":
        return horner_program(expr, precision)
    return _tree_program(expr)


@lru_cache(maxsize=16)
def _tree_program(expr: sympy.Expr) -> Program:
    """The tree route's coefficients, jointly CSE'd (the same in either precision)."""
    return optimize(list(ray_coefficients(expr)), POINT + DIRECTION)


def coefficient_route(expr: sympy.Expr, precision: str = "float") -> str:
    """"horner" for an equation written out at length, or one whose tree route would
    write coefficients of more than TREE_ABOVE nodes (counted with repeats: what CSE
    walks), or, in double, one of degree DOUBLE_HORNER_FROM or more whose Horner's
    scheme costs at most DOUBLE_HORNER_RATIO times the tree's operations; else "tree"
    (see coefficient_program; `implc show` says which)."""
    if count_ops(expr) > HORNER_ABOVE:
        return "horner"
    coefficients = ray_coefficients(expr) or ()
    if tree_size(coefficients) > TREE_ABOVE:
        return "horner"
    if (precision == "double" and (polynomial_degree(expr) or 0) >= DOUBLE_HORNER_FROM
            and _horner_plan(expr, precision)[2]
            <= DOUBLE_HORNER_RATIO * _tree_program(expr).ops_after):
        return "horner"
    return "tree"


def tree_size(exprs: Sequence[sympy.Expr]) -> int:
    """The expressions' size in nodes with every repeat counted (a DAG's tree size), in one
    pass over their distinct nodes; saturates at TREE_CAP."""
    sizes = [fold_tree(e, lambda _, parts: min(TREE_CAP, 1 + sum(parts))) for e in exprs]
    return min(TREE_CAP, sum(sizes))


# S's size in operations, as written, above which the ray coefficients come by Horner's
# scheme. Measured on every polynomial row of the corpus: the 11 rows above it (S of
# 167-3,250 operations, written expanded) take 0.5x the tree's operations (527 against
# 1,053 on row 39; row 260 2,258 against 2,240) and the degree-18 knot of row 246 (207
# monomials) 5,639 against 32,525, in 0.8 s where the tree took 27 s, most of it CSE;
# below it the two routes' programs differ by less and the frames not at all (Steiner
# 84 against 67 operations, Clebsch 216 against 109: the same exact frame at 512^2,
# since ray_of runs once a ray).
HORNER_ABOVE = 150
# The tree route's coefficients, counted with repeats, above which Horner's is taken: a
# product of 20 linear factors, (x-1)(x-2)...(x-20) + y^2 + z^2 (43 operations as written),
# gives coefficients of 6.3 million nodes, whose CSE took 16 s; Horner's 0.06 s (452
# operations). The bundled examples' largest is Barth's decic, 4,004.
TREE_ABOVE = 50_000
TREE_CAP = 10**12
# In double a value takes two registers, and the tree route's power tables (x^2..x^n,
# dx^2..dx^n, the same for y and z) are live at once: on AMD's compiler (RADV's ACO,
# docs/results-gpu.md) Chmutov's T10-T12 spilled 9-35 VGPRs on RDNA3 in exact, taylor and
# hessian (navi21: 144-168 VGPRs), corpus rows 244 (degree 12) 47-51 and 358 (8) 5-7, x^18
# + y^18 + z^18 = 1 73 (exact). Horner's scheme holds a truncated polynomial per nesting
# level: on it none of those below degree 13 spills VGPRs (x^18 sums' exact 29, its
# walk's), and navi21 holds 88-128 at T8-T12 (rows 49, 152, 162, 244, 358, 360 8-56
# fewer). Where it costs far more operations than the tree (rows 51, 155, 239, 240, 247
# and 285: 3-8x) it held more (row 247 136 -> 248, 285 128 -> 192; Barth's decic, 3.2x,
# 128 -> 120): taken in double from DOUBLE_HORNER_FROM where it costs at most
# DOUBLE_HORNER_RATIO times the tree's operations. On llvmpipe at 512^2 (T12's exact,
# taylor, hessian; x^18 sums' exact) frames 0.87-1.01 of the tree's, the pictures the same
# (one pixel's t moved by 5e-7). Not in float: exact takes Chebyshev's basis there from
# degree 7, and float32's rounding of another route would move the other methods'
# pictures.
DOUBLE_HORNER_FROM = 8
DOUBLE_HORNER_RATIO = 2


def horner_program(expr: sympy.Expr, precision: str) -> Program:
    """c_0..c_n by Horner's scheme on the expanded polynomial, nested over the variables
    in the order that costs least: S = sum_i x^i (sum_j y^j (sum_k a_ijk z^k)), each sum
    a Horner loop on truncated polynomials in s, where a step multiplies by the ray's
    linear polynomial (x + dx s), about 3 operations a coefficient. Every coefficient of
    every step is named (q0, q1, ...), so the program needs no CSE. The orders are
    compared by counting alone (building one order's sympy expressions is the cost).
    `precision` chooses how powers standing alone are shifted (_shifted)."""
    terms, n, _, order = _horner_plan(expr, precision)
    assignments: list[tuple[sympy.Symbol, sympy.Expr]] = []

    def named(parts: list[tuple[sympy.Expr, sympy.Symbol | None]]) -> sympy.Expr:
        value = sympy.Add(*(v if factor is None else v * factor for v, factor in parts))
        if value.is_Atom:
            return value
        symbol = sympy.Symbol(f"q{len(assignments)}", real=True)
        assignments.append((symbol, value))
        return symbol

    outputs = _horner(terms, order, n, named, precision)
    outputs += [sympy.S.Zero] * (n + 1 - len(outputs))
    total = sum(count_ops(v) for _, v in assignments)
    return Program(POINT + DIRECTION, tuple(assignments), tuple(outputs), total, total)


@lru_cache(maxsize=8)
def _horner_plan(expr: sympy.Expr, precision: str) -> tuple[dict, int, int, tuple[int, ...]]:
    """S's monomials, its degree, and the operations and order of the cheapest Horner
    nesting (the first of equals: deterministic), by counting alone."""
    terms = expanded_terms(expr)
    n = max(sum(m) for m in terms)
    ops = 0

    def count(parts: list[tuple[object, sympy.Symbol | None]]) -> int:
        nonlocal ops
        ops += len(parts) - 1 + sum(1 for _, factor in parts if factor is not None)
        return 0

    costs = []
    for order in itertools.permutations(range(3)):
        ops = 0
        _horner(terms, order, n, count, precision)
        costs.append((ops, order))
    best, order = min(costs)
    return terms, n, best, order


def horner_ops(expr: sympy.Expr, precision: str = "float") -> int | None:
    """The operations of the ray coefficients' program where it takes Horner's route
    (None: the tree's route, never long: see TREE_ABOVE), known before it is built."""
    if coefficient_route(expr, precision) != "horner":
        return None
    return _horner_plan(expr, precision)[2]


def _horner(terms: dict, order: tuple[int, ...], n: int, combine, precision: str) -> list:
    """The ray coefficients of sum a_m v^m (m: exponents in POINT order) by Horner's
    scheme nested in `order`; `combine(parts)` makes the value sum value*factor (factor
    None: the value alone) of each coefficient of each step, or counts it."""
    variables = [POINT[i] for i in order]
    keys = [_permuted(m, order) for m in terms]  # each monomial's exponents in `order`

    def level(depth: int, prefix: tuple[int, ...]) -> list:
        """sum, over the monomials whose first exponents are `prefix`, of the rest."""
        below = [key[depth:] for key in keys if key[:depth] == prefix]
        exponents = {rest[0] for rest in below}
        # x^e alone (no later variable with it, e >= 1): a constant a_e, summed by a
        # Taylor shift (_shifted), the rest by Horner's loop
        plain = sorted(exponents - {rest[0] for rest in below if any(rest[1:])} - {0})
        o, d = variables[depth], DIRECTION[POINT.index(variables[depth])]
        looped = exponents - set(plain)
        q: list = []
        for e in range(max(looped, default=-1), -1, -1):
            if q:  # q * (o + d s), truncated at degree n
                q = [combine(([(q[m], o)] if m < len(q) else []) + ([(q[m - 1], d)] if m else []))
                     for m in range(min(len(q) + 1, n + 1))]
            if e in looped:
                inner = ([terms[_unpermuted(prefix + (e,), order)]] if depth == 2
                         else level(depth + 1, prefix + (e,)))
                q = [combine([(v[m], None) for v in (q, inner) if m < len(v)])
                     for m in range(max(len(q), len(inner)))]
        if plain:
            constants = {e: terms[_unpermuted(prefix + (e,) + (0,) * (2 - depth), order)]
                         for e in plain}
            q = _shifted(constants, o, d, combine, precision, q)
        return q

    return level(0, ())


def _shifted(constants: dict[int, sympy.Expr], o: sympy.Symbol, d: sympy.Symbol,
             combine, precision: str, base: list) -> list:
    """`base` (ray coefficients) plus those of sum a_e v^e over `constants` (e -> a_e,
    e >= 1) by a Taylor shift: c_j = d^j p_j(o), p_j = sum_(e >= j) a_e C(e, j) v^(e - j).
    In double each c_j is added to base_j as soon as it is made, so its p_j and d^j die
    there: made all first, then added (fused into multiply-adds, so their products moved
    to the additions too), every p_j, power of d and base_j were live at once (Chmutov
    T20: 126 of RDNA's VGPRs before the walk, 152 in all). Horner's loop over
    (o + d s) pays a product and a multiply-add for every coefficient of every step; here
    each p_j(o) costs a multiply-add a term:
    - in float32, all p_j by repeated synthetic division (Horner's rule again), which
      rounds least;
    - in double, each p_j by its own Horner's rule, in v^2 where its powers are all even
      or all odd (Chmutov's T_n, x^n sums): half the steps, and independent chains.
    Measured on Chmutov's T_n sums at 512^2 (docs/journal/2026-12-05.md), against Horner's
    loop: frames 0.93-0.97 at T13-T18 in float32 with fewer wrong roots (T16 8,303 ->
    7,509 of 262,144); in double the division 0.93-0.97 at T18 and T20, the parity
    Horner 0.94-0.98 of that (0.88-0.92 of the loop), 0 / 0 / 0 kept. In float32 the
    parity Horner put T16's wrong roots at 16,719, and sums of a_e C(e, j) o^(e - j) at
    26,615: their terms cancel where the division's partial sums stay small."""
    top = max(constants)
    if precision != "float":
        return _shifted_double(constants, o, d, combine, base)
    p: list = [constants.get(e) for e in range(top + 1)]  # None: zero
    for j in range(top):
        for e in range(top - 1, j - 1, -1):
            p[e] = combine(([] if p[e] is None else [(p[e], None)]) + [(p[e + 1], o)])
    direct = [p[0]]  # never None: the division's first pass sets every p[e] below top
    power = d
    for j in range(1, top + 1):
        if j > 1:
            power = combine([(power, d)])
        direct.append(combine([(p[j], power)]))
    return [combine([(v[m], None) for v in (base, direct) if m < len(v)])
            for m in range(max(len(base), len(direct)))]


def _shifted_double(constants: dict[int, sympy.Expr], o: sympy.Symbol, d: sympy.Symbol,
                    combine, base: list) -> list:
    """_shifted in double: each p_j by its own Horner's rule, then d^j p_j added to base_j
    at once (base_j + p_j d^j, one multiply-add)."""
    top = max(constants)
    a = {e: combine([(value, None)]) for e, value in sorted(constants.items())}
    sums = [{e - j: comb(e, j) * value for e, value in a.items() if e >= j}
            for j in range(top + 1)]
    square = (combine([(o, o)]) if any(_parity(terms)[0] == 2 for terms in sums)
              else None)
    out, power = [], None
    for j, terms in enumerate(sums):
        p = _horner_at(o, square, terms, combine)
        if j:
            power = d if j == 1 else combine([(power, d)])
        out.append(combine(([(base[j], None)] if j < len(base) else []) + [(p, power)]))
    return out + base[top + 1:]


def _parity(terms: dict[int, sympy.Expr]) -> tuple[int, int]:
    """(stride, lowest power) of Horner's rule on sum K_g o^g over `terms`: (2, 0) where
    every g is even, (2, 1) where every g is odd (steps in o^2), else (1, 0)."""
    parities = {g % 2 for g in terms}
    return (2, parities.pop()) if len(parities) == 1 and max(terms) > 1 else (1, 0)


def _horner_at(o: sympy.Symbol, square, terms: dict[int, sympy.Expr],
               combine) -> sympy.Expr:
    """sum K_g o^g over `terms` (g -> K_g) by Horner's rule, in o^2 = `square` (then
    times o where every g is odd) as _parity says."""
    stride, low = _parity(terms)
    v = square if stride == 2 else o
    top = max(terms)
    h = terms[top]
    for g in range(top - stride, low - 1, -stride):
        h = combine([(h, v)] + ([(terms[g], None)] if g in terms else []))
    return combine([(h, o)]) if low else h


def _permuted(monomial: tuple[int, ...], order: tuple[int, ...]) -> tuple[int, ...]:
    return tuple(monomial[i] for i in order)


def _unpermuted(exponents: tuple[int, ...], order: tuple[int, ...]) -> tuple[int, ...]:
    monomial = [0, 0, 0]
    for e, i in zip(exponents, order, strict=True):
        monomial[i] = e
    return tuple(monomial)


def ray_name(quantities: tuple[str, ...]) -> str:
    return "ray_" + function_name(quantities)


def ray_setup(coefficients: Program, printer, size: bool) -> tuple[tuple, PrintedBody]:
    """The ray record's fields and ray_of's body. The polynomial is expanded about the
    middle of the march interval: the record's origin is o = ro + sm rd and
    F(s) = S(o + s d) = sum c_k s^k, so |s| is at most hr, half the chord): about the
    entry point its terms would be up to 3^n times larger
    for the same sum, and float32 Horner loses that much more to cancellation. `size`,
    sum |c_k| hr^k, bounds the terms of F on the interval: the unit of the rounding
    error in the level solver's F, and only there (the Bernstein walk's F is S at the
    point, and the marchers read no bound: no `size` field). Storing the coefficients of
    F' and F'' as well measured slower on llvmpipe (a larger record, the same
    loop-invariant products)."""
    n = len(coefficients.outputs) - 1
    lets = [("real", v.name, f"oc.{c}") for v, c in zip(POINT, COMPONENT, strict=True)]
    lets += [("real", v.name, f"rd.{c}") for v, c in zip(DIRECTION, COMPONENT, strict=True)]
    lets += [("real", s.name, printer.doprint(v)) for s, v in coefficients.assignments]
    lets += [("real", f"c{k}", printer.doprint(o)) for k, o in enumerate(coefficients.outputs)]
    fields = tuple(("real", f"c{k}", f"coefficient of u^{k}") for k in range(n + 1))
    values = tuple(f"c{k}" for k in range(n + 1))
    if size:
        bound = horner([sympy.Abs(sym(f"c{k}")) for k in range(n + 1)], sym("hr"))
        lets.append(("real", "size", printer.doprint(bound)))
        fields = (("real", "size", "sum |c_k| hr^k: the size of F's terms on the interval"),
                  *fields)
        values = ("size", *values)
    return fields, PrintedBody(tuple(lets), values)


def from_ray(carried: tuple[tuple[str, str], ...]) -> list[str]:
    """The carried arguments as a function of the ray reads them: ray.params, ..."""
    return [f"ray.{name}" for _, name in carried]


def carry(carried: tuple[tuple[str, str], ...], fields: tuple,
           ray: PrintedBody) -> tuple[tuple, PrintedBody]:
    """The ray record with the carried arguments as fields (ray_of takes them)."""
    fields += tuple((kind, name, "carried for the functions that evaluate S")
                    for kind, name in carried)
    return fields, PrintedBody(ray.lets, ray.values + tuple(name for _, name in carried))


def horner(coefficients: Sequence[sympy.Expr], x: sympy.Expr) -> sympy.Expr:
    """sum_k coefficients[k] x^k as a Horner sum."""
    value: sympy.Expr = sympy.S.Zero
    for c in reversed(coefficients):
        value = value * x + c
    return value


def derivative_coefficients(n: int, m: int) -> list[sympy.Expr]:
    """The coefficients k!/(k-m)! c_k of F^(m) over the ray record's c0..cn (loop
    invariant; storing them in the record measured no faster, see ray_setup)."""
    return [sympy.ff(k, m) * sym(f"ray.c{k}") for k in range(m, n + 1)]


def estrin(coefficients: Sequence[sympy.Expr], x: sympy.Symbol,
            weights: Sequence[int] | None = None
            ) -> tuple[sympy.Expr, list[tuple[sympy.Symbol, sympy.Expr]]]:
    """sum_k weights[k] coefficients[k] x^k by Estrin's scheme, (c0 + c1 x) + x^2 (c2 + c3 x),
    pairs of pairs by x^4, ...; and the powers x^2, x^4, ... it reads, as lets. Its
    dependency chain is about 2 log2(n) operations where Horner's is 2n (GPU compilers,
    llvmpipe among them, keep a*b + c as two operations), and a march step is bound by its
    chain: with the march point of values_at (_MARCH_POINT), 2-6 % a frame
    (docs/journal/2026-12-01-marcher-and-forms.md).

    A term's integer weight is multiplied onto the power of x it meets where it meets one,
    c3*(2.0*x), not onto its coefficient: in a march loop the coefficients are loop
    invariants, and a compiler keeps every product of them in a register for the whole
    loop (see weighted_coefficients)."""
    # a term not yet combined is (coefficient, weight); a combined one is an expression
    terms: list = list(zip(coefficients, weights or [1] * len(coefficients), strict=True))
    powers, step = [], x

    def value(term) -> sympy.Expr:
        if not isinstance(term, tuple):
            return term
        c, w = term
        return c if w == 1 else sympy.Mul(w, c)

    def times(term, power: sympy.Expr) -> sympy.Expr:
        if not isinstance(term, tuple):
            return sympy.Mul(term, power, evaluate=False)
        c, w = term
        return sympy.Mul(c, power if w == 1 else sympy.Mul(w, power, evaluate=False),
                         evaluate=False)

    while len(terms) > 1:
        terms = [sympy.Add(value(terms[i]), times(terms[i + 1], step), evaluate=False)
                 if i + 1 < len(terms) else terms[i] for i in range(0, len(terms), 2)]
        if len(terms) > 1:
            square = sym(f"{x.name}_{2 ** (len(powers) + 1)}")
            powers.append((square, sympy.Mul(step, step, evaluate=False)))
            step = square
    return (value(terms[0]) if terms else sympy.S.Zero), powers


def ray_quantity_ops(n: int, quantity: str) -> int:
    """Operations of a ray quantity (dS, d2S) of a degree-n ray polynomial by Estrin's
    scheme as the march evaluates it (estrin_function), its powers of s and the integer
    factors on them included, the coefficients taken as given (`implc show`)."""
    m = DERIVATIVE_ORDER[quantity]
    weights = weighted_coefficients(n, m)[1] if n >= m else [1]
    return _chain_ops(*estrin([sym(f"a{k}") for k in range(len(weights))], sym("s"), weights))


def estrin_derivative(n: int, m: int, x: sympy.Symbol):
    """F^(m) at x by Estrin's scheme: (value, the lets of its powers of x)."""
    return estrin(derivative_coefficients(n, m), x)


def estrin_derivative_ops(n: int, m: int) -> int:
    """Operations of F^(m) of a degree-n ray polynomial by Estrin's scheme (the exact
    solver's P_k), its powers of u included (`implc show`)."""
    return _chain_ops(*estrin_derivative(n, m, sym("u")))


def _chain_ops(value: sympy.Expr, powers) -> int:
    """Operations of an Estrin chain: its value and the lets of its powers."""
    return count_ops(value) + sum(count_ops(v) for _, v in powers)


def weighted_coefficients(n: int, m: int) -> tuple[list[sympy.Expr], list[int]]:
    """F^(m)'s coefficients (m >= 1) written over those of F', k c_k, with the integer
    weights (k-1)!/(k-m)! that make them k!/(k-m)! c_k (estrin puts each weight on the
    power of s its term meets). So F'' in a march loop reads only the loop invariants F'
    holds already (up to degree 4): measured on the quartic paper surfaces (hessian,
    1024^2), the march step as fast as taylor's, where F'' over its own coefficients (6c3
    and 12c4, two more values live for the whole loop) cost 1.2-1.5 % a frame on the
    Steiner surface."""
    ks = range(m, n + 1)
    return [sympy.Mul(k, sym(f"ray.c{k}")) for k in ks], [int(sympy.ff(k - 1, m - 1)) for k in ks]


def estrin_function(quantities: tuple[str, ...], n: int, printer) -> ShaderFunction:
    """F' and/or F'' at march parameter s (measured from the ray record's origin, the
    expansion point), each by Estrin's scheme in s."""
    powers: dict[sympy.Symbol, sympy.Expr] = {}  # s^2, s^4, ...: shared by F' and F''
    outputs = []
    for q in quantities:
        coefficients, weights = weighted_coefficients(n, DERIVATIVE_ORDER[q])
        value, used = estrin(coefficients, sym("s"), weights)
        powers.update(used)
        outputs.append(printer.doprint(value))
    what = ", ".join(quantities)
    return ShaderFunction(ray_name(quantities),
                          f"{what} at march parameter s: Estrin's scheme on the ray polynomial",
                          (("Ray", "ray"), ("real", "s")), RETURN_TYPE[len(outputs)],
                          tuple(printed_lets(powers.items(), printer)), tuple(outputs))
