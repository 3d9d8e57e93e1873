"""The limit checks on the syntax tree, before sympy builds anything.

Bottom-up: literal magnitude, integer exponent size, size of exactly computed constants
(`9^9^9` is refused, never computed), estimated polynomial degree and estimated number of
monomials after expansion, with rational constants folded exactly.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from fractions import Fraction
from functools import cache

import sympy

from implc.errors import InputError, LimitError, Source
from implc.front.tokens import LOG10_2, constant_digits_error, show_value, too_many_digits
from implc.front.tree import (
    Call,
    Named,
    Neg,
    Node,
    Num,
    Power,
    Product,
    Sum,
    Var,
    children,
    postorder,
)
from implc.functions import FUNCTIONS, USER_FUNCTIONS
from implc.limits import Limits

_RADICAL_CAP = 10**12  # root degrees saturate here (see Analyzer.check_radicals)

# table functions that take a root of their argument, and its degree
_ROOT_FUNCTIONS = {f.name: f.root_degree for f in FUNCTIONS if f.root_degree}
NON_REAL_MESSAGES: tuple[tuple[sympy.Basic, str], ...] = (
    (sympy.nan, "value is undefined"),
    (sympy.zoo, "value is infinite"),
    (sympy.oo, "value is infinite"),
    (-sympy.oo, "value is infinite"),
    (sympy.I, "value is not a real number"),
)


@dataclass(frozen=True)
class NodeInfo:
    """What the limit checks know about a node before any sympy object exists."""

    constant: bool  # does not depend on x, y, z
    value: Fraction | None  # its exact value, when it is a rational constant
    degree: int  # estimated total degree in x, y, z (opaque parts count 1)
    terms: int  # estimated monomials after expansion, capped at max_terms + 1
    polynomial: bool  # a polynomial in x, y, z with rational coefficients
    size: int  # estimated sympy tree size (the real-root rule copies its base)


@cache
def _argument_copies(name: str) -> tuple[int, ...]:
    """How many times a table function's sympy form repeats each argument (cbrt: twice)."""
    function = USER_FUNCTIONS[name]
    dummies = [sympy.Dummy(real=True) for _ in range(function.arity)]
    built = function.build(*dummies)
    return tuple(max(1, built.count(d)) for d in dummies)


class Analyzer:
    """Bottom-up limit checks and exact folding of rational constants."""

    def __init__(
        self,
        source: Source,
        params: Mapping[str, tuple[sympy.Expr, Fraction | None]],
        limits: Limits,
    ):
        self.source = source
        self.params = params
        self.limits = limits

    def analyze(self, root: Node) -> dict[Node, NodeInfo]:
        info: dict[Node, NodeInfo] = {}
        radicals: dict[Node, tuple[int, int]] = {}
        for node in postorder(root):
            result = self.visit(node, info)
            self.check_growth(node, result)
            info[node] = result
            radicals[node] = self.check_radicals(node, info, radicals)
        return info

    def check_radicals(
        self,
        node: Node,
        info: Mapping[Node, NodeInfo],
        radicals: Mapping[Node, tuple[int, int]],
    ) -> tuple[int, int]:
        """(root, digits) of `node`: the root degree under which sympy may combine
        rational constants in it (`(4/10^21)^(1/10^4)`, `(2^(1/64))^(1/64)`,
        `sqrt(r^(1/q))`, `(2x)^(1/q)` = 2^(1/q) |x|^(1/q)), and the most digits of a
        rational constant that would take part.

        sympy evaluates a rational to a rational power by factoring and builds integers
        of about root x digits decimal digits: 10^4 x 22 hangs or fails (Python refuses to
        print integers over 4300 digits; found by tests/test_fuzz.py). So root x digits
        is bounded by ten times `max_constant_digits`. Only products, powers and roots
        combine; a sum, or a function other than sqrt and cbrt, keeps its parts apart.
        """
        parts = [radicals[c] for c in children(node)]
        value = info[node].value
        if value is not None:
            if value in (0, 1, -1):
                return 1, 0
            bits = max(abs(value.numerator).bit_length(), value.denominator.bit_length())
            return 1, bits * LOG10_2 // 100_000 + 1
        if isinstance(node, Neg) or (isinstance(node, Call) and node.name == "abs"):
            return parts[0]  # |9e28 y| is 9e28 |y| to sympy
        if isinstance(node, Product):
            root, digits = 1, 0
            for r, d in parts:
                root, digits = min(math.lcm(root, r), _RADICAL_CAP), max(digits, d)
        elif isinstance(node, Power):  # the exponent's own radicals were checked at its nodes
            root, digits = radicals[node.base]
            power = info[node.exponent].value
            if digits and power is not None and power.denominator != 1:
                root = min(root * power.denominator, _RADICAL_CAP)
        elif isinstance(node, Call) and node.name in _ROOT_FUNCTIONS:
            root, digits = parts[0]
            if digits:
                root = min(root * _ROOT_FUNCTIONS[node.name], _RADICAL_CAP)
        else:  # atoms, sums and other calls: nothing combines across them
            return 1, 0
        if root > 1 and digits and root * digits > 10 * self.limits.max_constant_digits:
            raise constant_digits_error(
                "root of a constant", self.limits, self.source, node.start, node.end - node.start
            )
        return root, digits

    def fail(self, message: str, node: Node) -> InputError:
        return InputError(message, self.source, node.start, node.end - node.start)

    def limit(self, message: str, node: Node) -> LimitError:
        return LimitError(f"too complex: {message}", self.source, node.start, node.end - node.start)

    def check_growth(self, node: Node, info: NodeInfo) -> None:
        limits = self.limits
        if info.size > limits.max_nodes:
            raise self.limit(
                f"expression size exceeds the limit of {limits.max_nodes} nodes (--max-nodes)",
                node,
            )
        if info.degree > limits.max_degree:
            raise self.limit(
                f"degree {info.degree} exceeds the limit of {limits.max_degree} (--max-degree)",
                node,
            )
        if info.terms > limits.max_terms:
            raise self.limit(
                f"expansion would exceed the limit of {limits.max_terms} terms (--max-terms)",
                node,
            )

    def checked_value(self, value: Fraction, node: Node) -> Fraction:
        if too_many_digits(value, self.limits.max_constant_digits):
            raise constant_digits_error(
                "constant value", self.limits, self.source, node.start, node.end - node.start
            )
        return value

    def cap_terms(self, terms: int, degree: int, polynomial: bool) -> int:
        """Cap a term estimate: at max_terms + 1, and for a polynomial in x, y, z at the
        number of monomials of its degree, C(degree + 3, 3)."""
        if polynomial:
            terms = min(terms, math.comb(degree + 3, 3))
        return min(terms, self.limits.max_terms + 1)

    def visit(self, node: Node, info: Mapping[Node, NodeInfo]) -> NodeInfo:
        if isinstance(node, Num):
            return NodeInfo(True, node.value, 0, 1, True, 1)
        if isinstance(node, Var):
            return NodeInfo(False, None, 1, 1, True, 1)
        if isinstance(node, Named):
            exact = self.params[node.name][1] if node.is_param else None
            return NodeInfo(True, exact, 0, 1, exact is not None, 1)
        if isinstance(node, Neg):
            inner = info[node.operand]
            value = None if inner.value is None else -inner.value
            return NodeInfo(
                inner.constant, value, inner.degree, inner.terms, inner.polynomial, inner.size + 1
            )
        if isinstance(node, Sum):
            return self.visit_sum(node, [info[t] for t in node.terms])
        if isinstance(node, Product):
            return self.visit_product(node, [info[f] for f in node.factors])
        if isinstance(node, Power):
            return self.visit_power(node, info[node.base], info[node.exponent])
        if isinstance(node, Call):
            return self.visit_call(node, [info[a] for a in node.args])
        raise AssertionError(f"unknown node {node!r}")  # pragma: no cover

    def visit_sum(self, node: Sum, parts: list[NodeInfo]) -> NodeInfo:
        value: Fraction | None = Fraction(0)
        for part, negative in zip(parts, node.negative, strict=True):
            if value is None or part.value is None:
                value = None
                continue
            value = self.checked_value(value - part.value if negative else value + part.value, node)
        degree = max(p.degree for p in parts)
        polynomial = all(p.polynomial for p in parts)
        terms = self.cap_terms(sum(p.terms for p in parts), degree, polynomial)
        return NodeInfo(
            all(p.constant for p in parts),
            value,
            degree,
            terms,
            polynomial,
            1 + sum(p.size for p in parts),
        )

    def visit_product(self, node: Product, parts: list[NodeInfo]) -> NodeInfo:
        value: Fraction | None = Fraction(1)
        terms = 1
        for factor, part, divide in zip(node.factors, parts, node.divide, strict=True):
            if divide and part.value == 0:
                raise self.fail("division by zero", factor)
            terms = min(terms * part.terms, self.limits.max_terms + 1)
            if value is None or part.value is None:
                value = None
                continue
            value = self.checked_value(value / part.value if divide else value * part.value, node)
        degree = sum(p.degree for p in parts)
        polynomial = all(
            p.polynomial and (not divide or p.constant)
            for p, divide in zip(parts, node.divide, strict=True)
        )
        return NodeInfo(
            all(p.constant for p in parts),
            value,
            degree,
            self.cap_terms(terms, degree, polynomial),
            polynomial,
            1 + sum(p.size for p in parts),
        )

    def visit_power(self, node: Power, base: NodeInfo, exponent: NodeInfo) -> NodeInfo:
        size = 1 + base.size + exponent.size
        negative_base = base.value is not None and base.value < 0
        real_base_message = (
            "negative base needs an integer exponent or a fraction with an odd denominator"
        )
        if exponent.value is None:
            if not exponent.constant and not base.constant:
                raise self.fail(
                    "exponent must not depend on x, y, z when the base does", node.exponent
                )
            if negative_base:
                raise self.fail(real_base_message, node)
            constant = base.constant and exponent.constant
            return NodeInfo(constant, None, 0 if constant else 1, 1, False, size)
        power = exponent.value
        if power.denominator % 2 == 0 and negative_base:
            raise self.fail(real_base_message, node)
        if base.value is not None:
            return self.fold_power(node, base.value, power, size)
        if abs(power) > self.limits.max_exponent:
            raise self.limit(
                f"exponent {show_value(power)} exceeds the limit of {self.limits.max_exponent} "
                f"(--max-exponent)",
                node.exponent,
            )
        if power.denominator != 1:
            if power.denominator % 2:  # real root: sign(b) * |b|^(p/q) repeats b
                size = 4 + 2 * base.size + exponent.size
            constant = base.constant
            return NodeInfo(constant, None, 0 if constant else 1, 1, False, size)
        n = abs(power.numerator)
        degree = n * base.degree
        polynomial = base.polynomial and power >= 0
        terms = self.cap_terms(
            _power_terms(base.terms, n, self.limits.max_terms), degree, polynomial
        )
        return NodeInfo(base.constant, None, degree, terms, polynomial, size)

    def fold_power(self, node: Power, base: Fraction, power: Fraction, size: int) -> NodeInfo:
        """A rational constant to a rational power: bound the result's size, then fold."""
        if base not in (0, 1, -1):
            bits = max(abs(base.numerator).bit_length(), base.denominator.bit_length())
            # an integer power is computed and checked exactly below, so a lower bound on
            # log2(base) does; a root is not, so it needs the upper one (3^647.1 is 1e308:
            # it reached the printer as inf; found by tests/test_fuzz.py)
            bits -= power.denominator == 1
            digits_bound = self.limits.max_constant_digits * 100_000 * power.denominator
            if abs(power.numerator) * bits * LOG10_2 > digits_bound:
                raise constant_digits_error(
                    "constant power", self.limits, self.source, node.start, node.end - node.start
                )
        if power.denominator != 1:  # e.g. 2^(1/3): sympy keeps it exact
            return NodeInfo(True, None, 0, 1, False, size)
        if base == 0 and power < 0:
            raise self.fail("division by zero", node)
        value = self.checked_value(base**power.numerator, node)
        return NodeInfo(True, value, 0, 1, True, size)

    def visit_call(self, node: Call, args: list[NodeInfo]) -> NodeInfo:
        constant = all(a.constant for a in args)
        copies = _argument_copies(node.name)
        copies += copies[-1:] * (len(args) - len(copies))  # min and max take more
        calls = max(1, len(args) - 1)  # max(a, b, c) is two calls (`_call_expr`)
        size = calls + sum(n * a.size for n, a in zip(copies, args, strict=True))
        return NodeInfo(constant, None, 0 if constant else 1, 1, False, size)


def approximate(expr: sympy.Expr) -> sympy.Expr:
    """`expr.evalf(15)`, or the imaginary unit when sympy cannot evaluate it: it raises
    when it compares a non-real value inside min/max (`max(2, cos(2)^0.5)`, found by
    tests/test_fuzz.py), and every caller then reports "not a real number"."""
    try:
        return expr.evalf(15)
    except (TypeError, ValueError, ArithmeticError):
        return sympy.I


def _power_terms(terms: int, n: int, max_terms: int) -> int:
    """Monomials of (t terms)^n, C(t + n - 1, n), stopping as soon as it passes max_terms."""
    result = 1
    for i in range(1, n + 1):
        result = result * (terms + i - 1) // i
        if result > max_terms:
            return max_terms + 1
    return result
