"""Symbolic derivation: the quantities a marcher asks for, derived once and on demand.

The point-evaluation form: every quantity is an expression in the point (x, y, z) and,
for directional ones, the unit ray direction (dx, dy, dz), so that at p(t) = O + tD
    F(t) = S(p),  F'(t) = grad S(p) . D,  F''(t) = D^T H(p) D.
The second evaluation form, the ray polynomial (implc/raypoly.py: its coefficients once per
ray, from `ray_coefficients` here, then F' and F'' by Estrin's scheme at each step),
supplies the same named quantities; methods only name what they need.
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction
from functools import cached_property, lru_cache
from typing import TypeVar

import sympy

from .errors import LimitError
from .functions import FUNCTIONS, Function
from .limits import Limits
from .symbols import DIRECTION, POINT

# Resource bound (docs/reference/errors.md "Limits"): the estimated size, in expression-tree nodes,
# of every
# quantity a marcher may ask for (S, the gradient, F', F'' and the Laplacian) before CSE.
# sympy's differentiation and `cse` take time roughly proportional to it (about 20-50 us
# a node here); the largest corpus row (a degree-18 torus knot) estimates ~340,000.
DEFAULT_MAX_DERIVED = Limits().max_derived  # a surface's own is `Surface.limits`
T = TypeVar("T")
_CAP = 10**15  # estimates saturate here, so hostile input cannot build huge integers


def estimate_derived_size(expr: sympy.Expr) -> int:
    """Estimated tree size of S, its gradient, F', F'' and the Laplacian, before CSE.

    Cheap (one pass over the distinct sub-expressions, iterative, no differentiation), so
    it runs before sympy is asked to differentiate anything. Per node it tracks (s, d1,
    d2): tree size and the sizes of a first and a second partial derivative by the
    product and chain rules, with no credit for sharing; nested compositions grow like
    depth^3 here exactly as they do in sympy (`sin(sin(...(xyz)))`, 40 deep: ~640,000).
    """
    s, d1, d2 = _estimates(expr)
    return min(_CAP, s + 4 * d1 + 7 * d2)


def _estimates(expr: sympy.Expr) -> tuple[int, int, int]:
    """(s, d1, d2) of S: its size, a first and a second partial derivative's (no credit
    for sharing)."""
    point = set(POINT)
    return fold_tree(expr, lambda node, parts: _node_estimate(node, parts, point))


def fold_tree(expr: sympy.Expr,
              combine: Callable[[sympy.Basic, list[T]], T]) -> T:
    """`combine(node, [values of its arguments])` over the distinct sub-expressions of
    `expr`, arguments first, iteratively (a deep tree does not reach Python's recursion
    limit); the value of `expr`."""
    memo: dict[sympy.Basic, T] = {}
    stack: list[tuple[sympy.Basic, bool]] = [(expr, False)]
    while stack:
        node, ready = stack.pop()
        if node in memo:
            continue
        if not ready and node.args:
            stack.append((node, True))
            stack.extend((a, False) for a in node.args if a not in memo)
            continue
        memo[node] = combine(node, [memo[a] for a in node.args])
    return memo[expr]


def _node_estimate(node, parts: list[tuple[int, int, int]], point) -> tuple[int, int, int]:
    """(s, d1, d2) of `node` from those of its arguments (see estimate_derived_size)."""
    s = min(_CAP, 1 + sum(p[0] for p in parts))
    if not parts or not node.free_symbols & point:
        return s, 1, 1
    if node.is_Add:
        d1 = 1 + sum(p[1] for p in parts)
        d2 = 1 + sum(p[2] for p in parts)
    elif node.is_Mul:  # (fg)' = f'g + fg'; (fg)'' = f''g + 2f'g' + fg''
        varying = [p for a, p in zip(node.args, parts, strict=True) if a.free_symbols & point]
        k = len(varying)
        d1 = sum(p[1] for p in varying) + k * s
        d2 = sum(p[2] + k * p[1] for p in varying) + (k + k * k) * s
    elif node.is_Pow:  # b^e: e b^(e-1) b' (+ log b terms for a varying exponent)
        d1 = sum(p[1] for p in parts) + 2 * s + 3
        d2 = sum(p[2] + 2 * p[1] for p in parts) + 4 * s + 6
    else:  # f(u): f'(u) u'; f''(u) u'^2 + f'(u) u''
        d1 = sum(p[1] + 3 * p[0] for p in parts) + 3
        d2 = sum(p[2] + 2 * p[1] + 6 * p[0] for p in parts) + 6
    return s, min(_CAP, d1), min(_CAP, d2)


def check_derived_size(expr: sympy.Expr, max_derived: int = DEFAULT_MAX_DERIVED) -> int:
    """Raise `LimitError` ("too complex: ...") when `expr`'s derivatives would be too big.

    Returns the estimate. Runs before any differentiation, so a compile that would run
    for minutes (or exhaust memory or Python's recursion limit inside sympy) stops at once.
    """
    limit = max_derived
    s, d1, d2 = _estimates(expr)
    size = min(_CAP, s + 4 * d1 + 7 * d2)  # estimate_derived_size
    weighed = 0 if expr.is_polynomial(*POINT) else min(_CAP, FUNCTION_WEIGHT * d1)
    if max(size, weighed) > limit:
        how = f" (a surface with functions: {FUNCTION_WEIGHT} a node of a partial " \
            "derivative)" if weighed > size else ""
        raise LimitError(
            f"too complex: derivatives would have about {_approx(max(size, weighed))} "
            f"nodes{how}, exceeding the limit of {limit} (--max-derived)"
        )
    return max(size, weighed)


# A surface with functions (exp, sin, sqrt, 1/u, min, ...) is also bounded by the size of
# a first partial derivative (d1 of `_node_estimate`) times this: its compile costs
# 0.45-0.9 ms of CPU per node of d1 (sums of 20-80 gaussians, sines and inverse squares,
# min of 5-20 distances, 10-40 nested sines; scripts/compile_times.py --families), since
# every function node is differentiated, enclosed (the interval method's F and F') and
# printed through sympy's slower paths, where a polynomial (differentiated as a Poly, its
# ray coefficients by Horner's scheme) costs 5.5-8 us per node of the estimate. Either
# way what passes 500,000 compiles in about 3 s; the corpus's largest with functions
# (Chain, d1 1,342) weighs 215,000.
FUNCTION_WEIGHT = 160


def _approx(n: int) -> str:
    """2 significant digits, so the message stays readable and stable: 1,300,000."""
    if n < 100:
        return str(n)
    digits = len(str(n)) - 2
    return f"{round(n, -digits):,}"

# Quantity names methods may ask for, and what each means.
QUANTITIES = {
    "S": "S(p), the surface function",
    "dS": "F'(t) = grad S(p) . D",
    "d2S": "F''(t) = D^T H(p) D",
    "grad": "grad S(p), three components",
    "lap": "the Laplacian of S at p (sign of the unnormalized mean curvature, negated)",
}


class Derivatives:
    """All derived quantities of one surface function, each computed at most once."""

    def __init__(self, expr: sympy.Expr, max_derived: int = DEFAULT_MAX_DERIVED):
        check_derived_size(expr, max_derived)
        self.expr = expr

    @cached_property
    def gradient(self) -> tuple[sympy.Expr, ...]:
        return tuple(branch_diff(self.expr, v) for v in POINT)

    @cached_property
    def hessian(self) -> tuple[tuple[sympy.Expr, ...], ...]:
        """Six derivatives, not nine: H is symmetric, and the three below the diagonal
        would cost a third of the Hessian's time (1 s on a degree-18 knot)."""
        g = self.gradient
        upper = {(i, j): branch_diff(g[i], POINT[j]) for i in range(3) for j in range(i, 3)}
        return tuple(tuple(upper[min(i, j), max(i, j)] for j in range(3)) for i in range(3))

    @cached_property
    def laplacian(self) -> sympy.Expr:
        return sympy.Add(*(self.hessian[i][i] for i in range(3)))

    @cached_property
    def directional(self) -> sympy.Expr:
        return sympy.Add(*(g * d for g, d in zip(self.gradient, DIRECTION, strict=True)))

    @cached_property
    def second_directional(self) -> sympy.Expr:
        h, d = self.hessian, DIRECTION
        return sympy.Add(*(h[i][j] * d[i] * d[j] for i in range(3) for j in range(3)))

    def quantity(self, name: str) -> tuple[sympy.Expr, ...]:
        """The expressions of a named quantity (one, or three for `grad`)."""
        if name == "S":
            return (self.expr,)
        if name == "dS":
            return (self.directional,)
        if name == "d2S":
            return (self.second_directional,)
        if name == "grad":
            return self.gradient
        if name == "lap":
            return (self.laplacian,)
        raise KeyError(f"unknown quantity {name!r}; known: {', '.join(QUANTITIES)}")


def _branch_class(row: Function) -> type[sympy.Function]:
    """A stand-in for `row`'s sympy class whose derivative is the row's
    `branch_derivative` for every argument, itself in stand-ins (so F'' branches too)."""
    def fdiff(self, argindex=1):
        return _to_branches(row.branch_derivative(self.args[0]))

    return type(f"_Branch{row.sympy_name}", (sympy.Function,), {"fdiff": fdiff})


# sympy class -> its stand-in, for the rows differentiated by branch (abs, sign)
_BRANCHES: dict[type, type] = {getattr(sympy, f.sympy_name): _branch_class(f)
                               for f in FUNCTIONS if f.branch_derivative is not None}


def _to_branches(expr: sympy.Expr) -> sympy.Expr:
    for cls, branch in _BRANCHES.items():
        expr = expr.replace(cls, branch)
    return expr


def _from_branches(expr: sympy.Expr) -> sympy.Expr:
    for cls, branch in _BRANCHES.items():
        expr = expr.replace(branch, cls)
    return expr


def branch_diff(expr: sympy.Expr, var: sympy.Symbol) -> sympy.Expr:
    """d expr / d var with abs and sign differentiated by branch whatever their argument
    (the function table's `branch_derivative`).

    sympy does so only when it can prove the argument real. It cannot for acos(x),
    log(x) or sqrt(x) (complex outside their domain), and then returns re/im/arg terms
    or an unevaluated Derivative that no target can print (found by tests/test_fuzz.py:
    `acos(x)^(1/3)`). For real arguments the result is exactly sympy's.

    An expanded polynomial with rational coefficients (mathmod writes its knots so: 207
    monomials of degree up to 18) is differentiated as a `Poly`, which gives sympy's own
    result, the same expression, ten times faster (0.02 s against 0.2 s a derivative).
    """
    if _is_expanded_rational_polynomial(expr):
        return sympy.Poly(expr, *POINT).diff(var).as_expr()
    if not expr.has(*_BRANCHES):
        return sympy.diff(expr, var)
    return _from_branches(sympy.diff(_to_branches(expr), var))


def _is_expanded_rational_polynomial(expr: sympy.Expr) -> bool:
    """A sum of monomials c x^i y^j z^k with rational c (the form `Poly.as_expr` gives
    back, so differentiating it as a Poly changes nothing but the time)."""
    for term in sympy.Add.make_args(expr):
        coeff, rest = term.as_coeff_Mul()
        if not coeff.is_Rational:
            return False
        for factor in sympy.Mul.make_args(rest) if rest != 1 else ():
            base = factor.base if factor.is_Pow and factor.exp.is_Integer else factor
            if base not in POINT or (factor.is_Pow and factor.exp < 1):
                return False
    return True


@lru_cache(maxsize=64)
def polynomial_degree(expr: sympy.Expr) -> int | None:
    """Total degree in x, y, z, or None when S is not a polynomial.

    Never by expanding S (`sympy.Poly` took 52 s on (x^2+...+1)^15, issue 44): S(a t, b t,
    c t) = sum_k H_k(a, b, c) t^k, where H_k is S's part of degree k, is computed as a
    polynomial in t by exact arithmetic over S's tree, at DEGREE_POINTS points (a, b, c)
    of large pseudo-random integers; the degree is the largest k whose H_k is not 0 at
    one of them. A nonzero H_k vanishes at a random such point with probability at most
    k / 2^62 (Schwartz-Zippel), twice in a row practically never. Cached: one compile
    asks it for the default method, the evaluation form, the exact method's check and
    the ray coefficients."""
    if not expr.is_polynomial(*POINT):
        return None
    return max(_degree_at(expr, point) for point in DEGREE_POINTS)


# fixed, so every run gives the same answer (a seeded generator's first values)
DEGREE_POINTS = (
    (3_861_104_215_836_297_113, 2_472_943_109_377_521_061, 4_088_163_735_906_174_891),
    (1_314_979_623_087_211_433, 3_957_301_846_552_713_207, 2_700_531_458_219_304_389),
)


def _degree_at(expr: sympy.Expr, point: tuple[int, int, int]) -> int:
    """deg_t S(a t, b t, c t), by exact arithmetic on lists of Fractions (index k: the
    coefficient of t^k) over the distinct sub-expressions of S."""
    values = dict(zip(POINT, point, strict=True))
    coefficients = fold_tree(expr, lambda node, parts: _t_poly(node, parts, values))
    return max((k for k, c in enumerate(coefficients) if c != 0), default=0)


def _t_poly(node: sympy.Basic, parts: list[list[Fraction]],
            values: dict[sympy.Symbol, int]) -> list[Fraction]:
    if node in values:
        return [Fraction(0), Fraction(values[node])]  # x = a t
    if not node.free_symbols & values.keys():  # a coefficient: a number, or parameters
        return [_constant(node)]
    if node.is_Add:
        result: list[Fraction] = []
        for part in parts:
            result += [Fraction(0)] * (len(part) - len(result))
            for k, c in enumerate(part):
                result[k] += c
        return result
    if node.is_Mul:
        result = [Fraction(1)]
        for part in parts:
            result = _times(result, part)
        return result
    if node.is_Pow and node.exp.is_Integer and node.exp >= 0:
        return _power(parts[0], int(node.exp), _times, [Fraction(1)])
    raise ValueError(f"not a polynomial node: {node}")  # is_polynomial said it is


def _power(base: T, n: int, times: Callable[[T, T], T], one: T) -> T:
    """base^n by squaring, in the arithmetic `times` (one: its unit)."""
    result = one
    while n:
        if n & 1:
            result = times(result, base)
        n >>= 1
        if n:
            base = times(base, base)
    return result


def _constant(node: sympy.Basic) -> Fraction:
    """A coefficient's value: exact for a rational; a parameter kept as a symbol (`--params
    uniform`) gets a large pseudo-random integer of its own, like x, y and z."""
    if node.is_Rational:
        return Fraction(int(node.p), int(node.q))
    if node.free_symbols:
        node = node.xreplace({s: sympy.Integer(_symbol_value(s.name))
                              for s in node.free_symbols})
        if node.is_Rational:
            return Fraction(int(node.p), int(node.q))
    return Fraction(float(node))


def _symbol_value(name: str) -> int:
    """A fixed large integer per name (the same in every run and process)."""
    value = 1_469_598_103_934_665_603
    for char in name.encode():
        value = ((value ^ char) * 1_099_511_628_211) % (1 << 61)
    return value | 1


def _times(a: list[Fraction], b: list[Fraction]) -> list[Fraction]:
    result = [Fraction(0)] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        if x:
            for j, y in enumerate(b):
                result[i + j] += x * y
    return result


@lru_cache(maxsize=16)
def expanded_terms(expr: sympy.Expr) -> dict[tuple[int, int, int], sympy.Expr]:
    """S's monomials {(i, j, k): c} (c x^i y^j z^k, c not 0), by polynomial arithmetic on
    monomial dictionaries over S's distinct sub-expressions: what `sympy.Poly(S).terms()`
    gives, without sympy's general expansion (a product of ten dense quadratics, 1,771
    monomials: 9.6 s there, a fraction of a second here). A sub-expression free of x, y, z
    (a number, sqrt(5), a parameter kept as a symbol) is a coefficient. Cached (framing,
    Horner's plan and Chebyshev's basis ask for the same): read, never changed."""
    point = set(POINT)
    one = 1

    def combine(node: sympy.Basic, parts: list) -> dict:
        if not node.free_symbols & point:  # rationals as Python's int and Fraction (their
            # arithmetic is 5-50x sympy's), anything else as sympy keeps it
            return {(0, 0, 0): _python_rational(node) if node.is_Rational else node}
        if node.is_Symbol:
            return {tuple(int(node == v) for v in POINT): one}
        if node.is_Add:
            return _poly_sum(parts)
        if node.is_Mul:
            result = parts[0]
            for part in parts[1:]:
                result = _poly_product(result, part)
            return result
        if node.is_Pow and node.exp.is_Integer and node.exp >= 0:
            return _power(parts[0], int(node.exp), _poly_product, {(0, 0, 0): one})
        raise ValueError(f"not a polynomial node: {node}")

    return {key: sympy.Rational(c.numerator, c.denominator) if isinstance(c, int | Fraction)
            else c for key, c in fold_tree(expr, combine).items()}


def _python_rational(r: sympy.Rational) -> int | Fraction:
    return int(r.p) if r.q == 1 else Fraction(int(r.p), int(r.q))


def _poly_sum(parts: list[dict]) -> dict:
    result: dict = {}
    for part in parts:
        for key, c in part.items():
            result[key] = result[key] + c if key in result else c
    return {k: c for k, c in result.items() if c != 0}


def _poly_product(a: dict, b: dict) -> dict:
    result: dict = {}
    for (i, j, k), c in a.items():
        for (p, q, r), d in b.items():
            key = (i + p, j + q, k + r)
            result[key] = result[key] + c * d if key in result else c * d
    return {k: c for k, c in result.items() if c != 0}


RAY_PARAMETER = sympy.Symbol("s", real=True)


@lru_cache(maxsize=16)
def ray_coefficients(expr: sympy.Expr) -> tuple[sympy.Expr, ...] | None:
    """c_0 .. c_n of the ray polynomial F(s) = S(o + s d) = sum c_k s^k, as expressions in
    the origin o = (x, y, z) and the direction d = (dx, dy, dz); None when S is not a
    polynomial. (The `ray-poly` evaluation form computes them once per ray.)

    Computed by truncated polynomial arithmetic in s over S's own expression tree, never
    by expanding: x becomes x + dx s, a product multiplies coefficient lists, a power
    squares them. The work then follows the shape of the equation as written (the
    Cross-Cap's 4x^2(x^2 + y^2 + z^2 + z) + y^2(y^2 + z^2 - 1) is two products of
    quadratics in s), as an expert writes it by hand, and expansion never runs (it takes
    minutes on the corpus's degree-12 rows)."""
    degree = polynomial_degree(expr)
    if degree is None:
        return None
    memo: dict[sympy.Basic, list[sympy.Expr]] = {}
    coefficients = _ray_poly(expr, degree, memo)
    coefficients += [sympy.S.Zero] * (degree + 1 - len(coefficients))
    return tuple(coefficients[: degree + 1])


def _ray_poly(node: sympy.Basic, n: int, memo: dict) -> list[sympy.Expr]:
    """The coefficients (lowest first) of `node` along the ray, truncated at degree n."""
    if node in memo:
        return memo[node]
    if node in POINT:
        result = [node, DIRECTION[POINT.index(node)]]
    elif not node.free_symbols & set(POINT):
        result = [node]
    elif node.is_Add:
        result = []
        for arg in node.args:
            result = _poly_add(result, _ray_poly(arg, n, memo))
    elif node.is_Mul:
        result = [sympy.S.One]
        for arg in node.args:
            result = _poly_mul(result, _ray_poly(arg, n, memo), n)
    elif node.is_Pow and node.exp.is_Integer and int(node.exp) >= 0:
        result = [sympy.S.One]
        square = _ray_poly(node.base, n, memo)
        e = int(node.exp)
        while e:
            if e & 1:
                result = _poly_mul(result, square, n)
            e >>= 1
            if e:
                square = _poly_mul(square, square, n)
    else:  # pragma: no cover - polynomial_degree() said S is a polynomial
        raise ValueError(f"not a polynomial node: {node}")
    memo[node] = result
    return result


def _poly_add(a: list, b: list) -> list:
    size = max(len(a), len(b))
    return [(a[k] if k < len(a) else 0) + (b[k] if k < len(b) else 0) for k in range(size)]


def _poly_mul(a: list, b: list, n: int) -> list:
    size = min(len(a) + len(b) - 1, n + 1)
    return [sympy.Add(*(a[i] * b[k - i] for i in range(max(0, k - len(b) + 1),
                                                        min(k, len(a) - 1) + 1)))
            for k in range(size)]
