"""Checked syntax tree -> sympy expression, built node by node.

The only stage that makes sympy nodes from the user's tree (`Add`, `Mul`, `Pow`,
`Rational(p, q)`, the constructors of `functions.USER_FUNCTIONS`), never from text;
then constants are folded to numbers (`fold_constants`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction

import sympy

from implc.errors import InputError, Source
from implc.front.analyse import NON_REAL_MESSAGES, Analyzer, NodeInfo, approximate
from implc.front.tokens import (
    LOG10_2,
    VARIABLES,
    constant_digits_error,
    show_value,
    too_many_digits,
)
from implc.front.tree import Call, Named, Neg, Node, Power, Product, Sum, Var, children, postorder
from implc.functions import CONSTANTS, FUNCTIONS, USER_FUNCTIONS, Function
from implc.limits import Limits
from implc.symbols import X, Y, Z

# sympy classes that compare all their arguments pairwise when evaluated (the table's
# `unevaluated`; see the package docstring).
_UNEVALUATED = frozenset(f.sympy_name for f in FUNCTIONS if f.unevaluated)


def param_symbol(name: str) -> sympy.Symbol:
    """The symbol of parameter `name` in a symbolic (`--params uniform`) expression."""
    return sympy.Symbol(name, real=True)


# Digits a folded constant keeps (`fold_constants`): far past float64's 17, so the float
# literal printed from it is the correctly rounded value of the constant as written.
FOLD_DIGITS = 30


def fold_constants(expr: sympy.Expr) -> sympy.Expr:
    """`expr` with every maximal sub-expression free of symbols made a number: rationals
    stay exact, anything else (`pi`, `sqrt(2)`, `cos(314159265358979/400000000000000)`)
    becomes a `FOLD_DIGITS`-digit Float, evaluated once.

    Why: sympy keeps such constants as expressions, and every polynomial operation then
    runs over its expression domain (`Poly` of the Endrass octic with `cos(pi/4)` written
    as SURFER writes pi took 66 s; over the reals it takes milliseconds). A parameter kept
    as a symbol (`--params uniform`) is not folded, nor anything holding it. Runs after
    every check of the builder (they need the exact forms); the value printed in a shader
    is the same float64 literal as before, since printers print each constant's value.
    Iterative, so a deep tree (up to --max-depth) cannot exhaust Python's stack."""
    folded: dict[sympy.Basic, sympy.Basic] = {}
    stack: list[tuple[sympy.Basic, bool]] = [(expr, False)]
    while stack:
        node, ready = stack.pop()
        if node in folded:
            continue
        if not node.free_symbols:
            folded[node] = node if node.is_Rational else _number(node)
            continue
        if not ready and node.args:
            stack.append((node, True))
            stack.extend((a, False) for a in node.args if a not in folded)
            continue
        args = tuple(folded.get(a, a) for a in node.args)
        if args == node.args:
            folded[node] = node
        elif type(node).__name__ in _UNEVALUATED:
            folded[node] = node.func(*args, evaluate=False)
        else:
            folded[node] = node.func(*args)
    return folded[expr]


def _number(constant: sympy.Expr) -> sympy.Expr:
    """A constant the builder checked (finite and real) as a FOLD_DIGITS-digit Float."""
    return constant.evalf(FOLD_DIGITS)


def build_symbolic(
    root: Node, numeric: Mapping[Node, sympy.Expr], info: Mapping[Node, NodeInfo]
) -> sympy.Expr:
    """The tree rebuilt with parameters as symbols (see `parse_equation_with_params`).

    Nodes without a parameter below them are taken from the checked numeric build;
    the others are rebuilt the way `Builder` builds them, without the value checks
    (they ran on the values already)."""
    built: dict[Node, sympy.Expr] = {}
    symbolic: set[Node] = set()
    for node in postorder(root):
        if (isinstance(node, Named) and node.is_param) or any(
                c in symbolic for c in children(node)):
            symbolic.add(node)
        if node not in symbolic:
            built[node] = numeric[node]
        elif isinstance(node, Named):
            built[node] = param_symbol(node.name)
        elif isinstance(node, Neg):
            built[node] = -built[node.operand]
        elif isinstance(node, Sum):
            built[node] = sympy.Add(*(-built[t] if neg else built[t]
                                      for t, neg in zip(node.terms, node.negative, strict=True)))
        elif isinstance(node, Product):
            built[node] = sympy.Mul(*(sympy.Pow(built[f], -1) if divide else built[f]
                                      for f, divide in zip(node.factors, node.divide,
                                                           strict=True)))
        elif isinstance(node, Power):
            power = info[node.exponent].value
            exponent = built[node.exponent] if power is None else numeric[node.exponent]
            built[node] = _symbolic_power(built[node.base], exponent, power)
        elif isinstance(node, Call):
            expr = _call_expr(USER_FUNCTIONS[node.name], [built[a] for a in node.args])
            if expr.has(sympy.cot):
                expr = expr.replace(sympy.cot, lambda u: 1 / sympy.tan(u))
            built[node] = expr
        else:  # pragma: no cover - numbers and variables hold no parameter
            raise AssertionError(f"unexpected node {node!r}")
    return built[root]


def _call_expr(function: Function, args: list[sympy.Expr]) -> sympy.Expr:
    """A table function applied to built arguments. min and max are built unevaluated (see
    implc/front/__init__.py), and with more than two arguments as a balanced tree of
    two-argument calls, the tree the printers fold them into anyway: sympy differentiates
    an n-ary Max through an evaluated Max of the other arguments, which compares them
    pairwise (max of 8 trigonometric terms: 23 s for the Hessian, 1.1 s as a tree)."""
    if function.sympy_name not in _UNEVALUATED:
        return function.build(*args)
    if len(args) <= 2:
        return function.build(*args, evaluate=False)
    half = (len(args) + 1) // 2
    return function.build(_call_expr(function, args[:half]), _call_expr(function, args[half:]),
                          evaluate=False)


def _symbolic_power(base: sympy.Expr, exponent: sympy.Expr, power: Fraction | None) -> sympy.Expr:
    """`Builder.make_power`'s result when base or exponent holds parameters; a constant
    exponent (`power` is its exact value) comes from the numeric build."""
    if power is None:
        return sympy.Pow(base, exponent)
    if power.denominator == 1:
        return sympy.Pow(base, sympy.Integer(power.numerator))
    rational = sympy.Rational(power.numerator, power.denominator)
    if power.denominator % 2 == 0:
        return sympy.Pow(base, rational)
    magnitude = sympy.Pow(sympy.Abs(base), rational)
    return sympy.sign(base) * magnitude if power.numerator % 2 else magnitude


class Builder:
    """Build the sympy expression bottom-up from a checked AST."""

    def __init__(
        self,
        source: Source,
        params: Mapping[str, tuple[sympy.Expr, Fraction | None]],
        info: Mapping[Node, NodeInfo],
        limits: Limits = Limits(),  # noqa: B008 - frozen, so a shared default is safe
    ):
        self.source = source
        self.params = params
        self.info = info
        self.limits = limits
        self.analyzer = Analyzer(source, params, limits)
        # nodes holding a rational only sympy found (abs(9e28)): the analysis' radical
        # bound did not see it, so make_power checks powers of them again
        self.late: set[Node] = set()

    def fail(self, message: str, node: Node) -> InputError:
        return InputError(message, self.source, node.start, node.end - node.start)

    def build(self, root: Node, constant: bool = False) -> sympy.Expr:
        """The expression of `root`; with `constant`, of a value (no x, y, z)."""
        built: dict[Node, sympy.Expr] = {}
        self.built = built  # every node's expression (the symbolic build reuses them)
        order = postorder(root)
        variable = next((n for n in order if isinstance(n, Var)), None)
        if constant and variable is not None:
            raise self.fail("a value must not depend on x, y or z", variable)
        for node in order:
            built[node] = self.make(node, built)
            info = self.info[node]
            if info.constant and info.value is None and built[node].is_Rational:
                # sympy found an exact value the analysis could not (abs(7e23), sin(0),
                # exp(2 log 3)): bound it like every other exact constant
                self.analyzer.checked_value(Fraction(built[node].p, built[node].q), node)
                self.late.add(node)
            elif any(c in self.late for c in children(node)):
                self.late.add(node)
        self.check_constants(order, built)
        result = built[root]
        if result.has(*(atom for atom, _ in NON_REAL_MESSAGES)):
            raise self.locate_non_real(order, built)
        self.check_numbers(order, built)
        if not constant and not result.free_symbols & {X, Y, Z}:
            raise self.fail("equation does not depend on x, y or z", root)
        return result

    def check_constants(self, order: list[Node], built: Mapping[Node, sympy.Expr]) -> None:
        """Every maximal constant sub-expression must be a finite real number of at most
        `max_constant_digits` digits (and within float range): printers fold each one to
        a float literal. Catches what only sympy can evaluate: `cos(-5/2)^(3/4)` is not
        real, `pi^64 * 10^290 * e^64` overflows (both found by tests/test_fuzz.py).
        Each constant sub-tree is evaluated once, at its top."""
        inside: set[Node] = set()
        for node in order:
            if not self.info[node].constant:
                inside.update(c for c in children(node) if self.info[c].constant)
        exponent = min(self.limits.max_constant_digits, 300)
        for node in order:
            if node not in inside or self.info[node].value is not None:
                continue
            approx = approximate(built[node])
            if approx.has(sympy.nan):
                raise self.fail("value is undefined", node)
            if approx.has(sympy.zoo, sympy.oo, -sympy.oo):
                raise self.fail("value is infinite", node)
            if approx.is_real is False or not approx.is_number:
                raise self.fail("value is not a real number", node)
            if approx.is_real and abs(approx) >= sympy.Float(10) ** exponent:
                raise constant_digits_error(
                    "constant value", self.limits, self.source, node.start,
                    node.end - node.start,
                )

    def check_numbers(self, order: list[Node], built: Mapping[Node, sympy.Expr]) -> None:
        """Every constant factor sympy split off must be real too: sqrt(tan(phi) x^2) is
        sqrt(tan(phi)) |x| to sympy, and tan(phi) < 0 (found by tests/test_fuzz.py).
        Walks the finished expression once; located at the innermost node holding it."""
        stack, seen = [built[order[-1]]], set()
        while stack:
            expr = stack.pop()
            if expr in seen:
                continue
            seen.add(expr)
            if expr.is_Rational:  # (1e30 x)^11 is 10^330 x^11: a float literal would be inf
                if too_many_digits(Fraction(expr.p, expr.q), self.limits.max_constant_digits):
                    node = next(n for n in order if built[n].has(expr))
                    raise constant_digits_error(
                        "constant value", self.limits, self.source, node.start,
                        node.end - node.start,
                    )
                continue
            if expr.is_Atom:
                continue
            if not expr.is_number:
                stack.extend(expr.args)
                continue
            approx = approximate(expr)
            if approx.is_real is not False and not approx.has(sympy.nan, sympy.zoo, sympy.oo):
                continue
            node = next(n for n in order if built[n].has(expr))
            raise self.fail("value is not a real number", node)

    def locate_non_real(self, order: list[Node], built: Mapping[Node, sympy.Expr]) -> InputError:
        """The innermost node whose value is not a finite real number."""
        for node in order:
            for atom, message in NON_REAL_MESSAGES:
                if built[node].has(atom):
                    return self.fail(message, node)
        raise AssertionError("no node holds the non-real value")  # pragma: no cover

    def make(self, node: Node, built: Mapping[Node, sympy.Expr]) -> sympy.Expr:
        value = self.info[node].value
        if value is not None:
            return sympy.Rational(value.numerator, value.denominator)
        if isinstance(node, Var):
            return VARIABLES[node.name]
        if isinstance(node, Named):
            return self.params[node.name][0] if node.is_param else CONSTANTS[node.name]
        if isinstance(node, Neg):
            return -built[node.operand]
        if isinstance(node, Sum):
            return sympy.Add(
                *(
                    -built[t] if neg else built[t]
                    for t, neg in zip(node.terms, node.negative, strict=True)
                )
            )
        if isinstance(node, Product):
            return self.make_product(node, built)
        if isinstance(node, Power):
            return self.make_power(node, built)
        if isinstance(node, Call):
            return self.make_call(node, built)
        raise AssertionError(f"unknown node {node!r}")  # pragma: no cover

    def make_product(self, node: Product, built: Mapping[Node, sympy.Expr]) -> sympy.Expr:
        factors = []
        for factor, divide in zip(node.factors, node.divide, strict=True):
            expr = built[factor]
            if divide:
                if expr == 0:
                    raise self.fail("division by zero", factor)
                expr = sympy.Pow(expr, -1)
            factors.append(expr)
        return sympy.Mul(*factors)

    def make_power(self, node: Power, built: Mapping[Node, sympy.Expr]) -> sympy.Expr:
        base = built[node.base]
        power = self.info[node.exponent].value
        exponent = built[node.exponent]
        if power is None and exponent.is_Rational:  # sympy evaluated it (2^abs(7e23))
            power = Fraction(exponent.p, exponent.q)
            self.check_late_power(node, base, power)
        elif power is not None and node.base in self.late:  # abs(9e28)^(4000000/3381921)
            self.check_late_power(node, base, power)
        if (power is not None and self.info[node.base].constant and not base.is_Rational
                and power.denominator == 1):  # pi^64 is fine; (1e20 pi)^64 is 10^1280 pi^64
            self.check_magnitude(node, exponent * sympy.log(sympy.Abs(base)), "constant power")
        if base == sympy.E or isinstance(base, sympy.exp):  # sympy makes it exp(...)
            inner = exponent if base == sympy.E else base.args[0] * exponent
            self.check_exp_argument(node, inner)
        if power is None and not self.info[node.base].constant:  # x^(1e26^6.1) is x^4e158
            approx = abs(approximate(exponent))
            if approx.is_real and approx > self.limits.max_exponent:
                raise self.analyzer.limit(
                    f"exponent about {float(approx):.3g} exceeds the limit of "
                    f"{self.limits.max_exponent} (--max-exponent)",
                    node.exponent,
                )
        if power is None:
            if self.info[node.base].constant and not self.info[node.exponent].constant:
                # b^x = exp(x log b): its derivatives need log b, so b must be positive
                # (`0^x` and `(1-pi)^x` reached the printer as nan; found by test_fuzz.py)
                approx = approximate(base)
                if not (approx.is_real and approx.is_positive):
                    raise self.fail("the base of a variable exponent must be positive", node)
                if base != 1 and abs(approximate(sympy.log(base))) < 1e-15:
                    # sympy cannot decide the sign of log(b) at working precision and
                    # raises while differentiating (tanh(32)^x; found by test_fuzz.py)
                    raise self.fail(
                        "the base of a variable exponent is 1 to 15 digits (write 1)", node
                    )
            if self.info[node.base].constant and self.info[node.exponent].constant:
                self.check_magnitude(
                    node, exponent * sympy.log(sympy.Abs(base)), "constant power"
                )
            return sympy.Pow(base, exponent)
        if power.denominator == 1:
            return sympy.Pow(base, sympy.Integer(power.numerator))
        exponent = sympy.Rational(power.numerator, power.denominator)
        if power.denominator % 2 == 0:
            return sympy.Pow(base, exponent)
        magnitude = sympy.Pow(sympy.Abs(base), exponent)
        return sympy.sign(base) * magnitude if power.numerator % 2 else magnitude

    def check_late_power(self, node: Power, base: sympy.Expr, power: Fraction) -> None:
        """The limits of `Analyzer.visit_power` for a base or exponent only sympy could
        evaluate (`x^(sin(pi) + 1000)`, `2^abs(7e23)`, `abs(9e28)^(4000000/3381921)`),
        before sympy computes the power."""
        if power.denominator != 1 and not base.is_Rational:
            # rationals inside the base combine under the root (`(abs(4e-21) x)^(1/q)`)
            roots = [a.exp.q for a in base.atoms(sympy.Pow) if a.exp.is_Rational]
            digits = max((len(str(max(abs(r.p), r.q))) for r in base.atoms(sympy.Rational)
                          if r not in (0, 1, -1)), default=0)
            if digits and power.denominator * max(roots, default=1) * digits > (
                    10 * self.limits.max_constant_digits):
                raise constant_digits_error(
                    "root of a constant", self.limits, self.source, node.start,
                    node.end - node.start,
                )
        if base.is_Rational:
            self.analyzer.fold_power(node, Fraction(base.p, base.q), power, 0)
            if power.denominator != 1:
                bits = max(abs(base.p).bit_length(), base.q.bit_length())
                digits = bits * LOG10_2 // 100_000 + 1
                if power.denominator * digits > 10 * self.limits.max_constant_digits:
                    raise constant_digits_error(
                        "root of a constant", self.limits, self.source, node.start,
                        node.end - node.start,
                    )
            return
        if abs(power) > self.limits.max_exponent:
            raise self.analyzer.limit(
                f"exponent {show_value(power)} exceeds the limit of {self.limits.max_exponent} "
                f"(--max-exponent)",
                node.exponent,
            )
        degree = abs(power.numerator) * self.info[node.base].degree
        if power.denominator == 1 and degree > self.limits.max_degree:
            raise self.analyzer.limit(
                f"degree {degree} exceeds the limit of {self.limits.max_degree} (--max-degree)",
                node,
            )

    def check_magnitude(self, node: Node, log_value: sympy.Expr, what: str) -> None:
        """Refuse a constant whose natural log is `log_value` when it has more than
        `max_constant_digits` digits: sympy may compute it exactly (`e^(1e20 log 2)`
        becomes 2^(10^20)). The estimate is numeric and cheap."""
        try:
            estimate = abs(complex(approximate(log_value)))
        except (TypeError, ValueError):  # not a plain number (nan, zoo): found later
            return
        if estimate / math.log(10) > self.limits.max_constant_digits:
            raise constant_digits_error(
                what, self.limits, self.source, node.start, node.end - node.start
            )

    def check_exp_argument(self, node: Node, arg: sympy.Expr) -> None:
        """sympy rewrites exp(a + k log(u)) as e^a u^k on construction, for any numeric k
        (`e^(10^20 log(2x))` computed 2^(10^20) and hung; found by tests/test_fuzz.py;
        `exp(100 log(x))` would be x^100, past --max-exponent). Bound k as an exponent of
        u before sympy sees it: |k| <= max_exponent when u depends on x, y, z, and the
        magnitude of u^k when it does not."""
        for term in sympy.Add.make_args(arg):
            coeff, rest = term.as_coeff_Mul()
            logs = [f for f in sympy.Mul.make_args(rest) if isinstance(f, sympy.log)]
            others = [f for f in sympy.Mul.make_args(rest) if not isinstance(f, sympy.log)]
            if len(logs) != 1 or not all(f.is_comparable for f in others):
                continue
            k, u = coeff * sympy.Mul(*others), logs[0].args[0]
            if not u.free_symbols & {X, Y, Z}:
                self.check_magnitude(node, k * sympy.log(sympy.Abs(u)), "constant power")
                continue
            try:
                magnitude = abs(float(k))
            except (TypeError, ValueError, OverflowError):
                magnitude = math.inf
            if magnitude > self.limits.max_exponent:
                raise self.analyzer.limit(
                    f"exponent about {magnitude:.3g} (exp(k log u) is u^k) exceeds the "
                    f"limit of {self.limits.max_exponent} (--max-exponent)",
                    node,
                )

    def make_call(self, node: Call, built: Mapping[Node, sympy.Expr]) -> sympy.Expr:
        function = USER_FUNCTIONS[node.name]
        args = [built[a] for a in node.args]
        if node.name == "exp":
            self.check_exp_argument(node, args[0])
        if function.grows and self.info[node.args[0]].constant:
            self.check_magnitude(node, args[0], "constant value")  # exp(k log r) is r^k
        expr = _call_expr(function, args)
        if expr.has(sympy.cot):  # tan(x + 3pi/4) is -cot(x + pi/4) to sympy; no target has cot
            expr = expr.replace(sympy.cot, lambda u: 1 / sympy.tan(u))
        if all(self.info[a].constant for a in node.args):
            # Constant arguments are bounded (every check above ran on them), so evalf is
            # cheap; it finds asin(2) or acos(pi), which sympy leaves unevaluated although
            # they are not real (found by tests/test_fuzz.py: `acos(pi) x` reached the
            # printer).
            approx = approximate(expr)
            if approx.has(sympy.nan):
                raise self.fail("value is undefined", node)
            if approx.has(sympy.zoo, sympy.oo, -sympy.oo):
                raise self.fail("value is infinite", node)
            if approx.is_real is False:
                raise self.fail("value is not a real number", node)
        return expr
