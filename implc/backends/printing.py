"""Printing rules shared by every shader target, on top of sympy's CodePrinter family.

A target printer is `class XPrinter(ShaderPrinterMixin, <sympy printer>)` plus a few class
attributes, and its module's `known_functions` (sympy's idiom: sympy class name -> the
target's function name) as `_kf`. The mixin fixes what sympy gets wrong for shaders: typed
float literals for every number (`2` -> `2.0`), no `pow` for integer powers (the optimizer
already turned them into products), constants as literals, exactly the functions of
`functions.FUNCTIONS` (printed as the table's `printed` column says),
and an implc error (not a driver error) for anything unsupported.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import sympy
from sympy.printing.precedence import PRECEDENCE, precedence

from ..errors import ImplcError, InputError
from ..functions import BY_SYMPY_NAME

# How each row prints is the table's `printed` column: rows printed "call" or "fold" are
# spelled by every printer's `known_functions`; "step" and "zero" rows by the mixin below.
SPELLED = ("call", "fold")


FLOAT32_MAX = 3.4028234663852886e38


class ShaderPrinterMixin:
    target: str = ""
    precision: str = "float"  # a printer with several sets it (use_precision)
    float_suffix: str = ""
    _kf: dict[str, str] = {}  # the printer module's `known_functions`

    def __init__(self, settings: dict) -> None:
        super().__init__(settings)
        # sympy's printers fill `known_functions` with their own tables (C99's conditional
        # fabs/abs, GLSL's extras); implc's table decides what prints, so replace, not merge.
        self.known_functions = dict(self._kf)

    def use_precision(self, precision: str, literal_suffix: dict[str, str]) -> None:
        """Print in `precision`, one of the language's (`literal_suffix`: precision -> the
        suffix of its literals)."""
        if precision not in literal_suffix:
            raise ValueError(f"{self.target} precision must be one of "
                             f"{', '.join(literal_suffix)}")
        self.precision = precision
        self.float_suffix = literal_suffix[precision]

    @contextmanager
    def sums_as_held(self) -> Iterator[None]:
        """Within: print a sum's terms in the order sympy holds them (its canonical order,
        as deterministic as the sorted one) rather than sorted for reading. Sorting is
        most of the time of printing a long machine-made program (the interval method's
        enclosures: 0.8 s of CPU against 0.33 s for sixty gaussians' 4,358 lets)."""
        saved = self._settings.get("order")
        self._settings["order"] = "none"
        try:
            yield
        finally:
            self._settings["order"] = saved

    def float_literal(self, value: float) -> str:
        """Shortest decimal that round-trips the float64 value, typed for the target."""
        value = float(value)
        if value != value or value in (float("inf"), float("-inf")):
            raise ImplcError(f"the {self.target} printer cannot print the number {value}")
        if abs(value) > FLOAT32_MAX and self.precision == "float":
            # WGSL refuses such a literal, GLSL makes it inf: say so before either
            raise InputError(f"too large for float32: the constant {value:.6g} (in S or "
                             f"its derivatives) is beyond "
                             f"float32's range (about 3.4e38), the precision of this "
                             f"{self.target} shader: scale the equation down")
        text = repr(value)
        if "e" not in text and "." not in text:
            text += ".0"
        return text + self.float_suffix

    def _print_number(self, expr) -> str:
        return self.float_literal(float(expr))

    _print_Integer = _print_Rational = _print_Float = _print_number
    _print_Zero = _print_One = _print_NegativeOne = _print_Half = _print_number
    _print_NumberSymbol = _print_Pi = _print_Exp1 = _print_number

    def _print_Symbol(self, expr) -> str:
        return expr.name

    def _print_Mul(self, expr) -> str:
        coeff, rest = expr.as_coeff_Mul()
        sign = "-" if coeff < 0 else ""
        coeff = -coeff if coeff < 0 else coeff
        num: list[str] = [] if coeff == 1 else [self._print(coeff)]
        den: list[sympy.Expr] = []
        prec = PRECEDENCE["Mul"]
        for factor in sympy.Mul.make_args(rest) if rest != 1 else ():
            if factor.is_Pow and factor.exp.is_Rational and factor.exp.is_negative:
                den.append(sympy.Pow(factor.base, -factor.exp, evaluate=factor.exp != -1))
            elif factor.is_Mul and num:
                # a product left unevaluated inside a product fixes the order of
                # multiplication (optimize.arrange_by_depth): a*(b*c), not a*b*c
                num.append(f"({self._print(factor)})")
            else:
                num.append(self.parenthesize(factor, prec))
        text = "*".join(num) if num else self.float_literal(1.0)
        if den:
            parts = [self.parenthesize(d, prec) for d in den]
            text += "/" + (parts[0] if len(parts) == 1 else "(" + "*".join(parts) + ")")
        return sign + text

    def _print_Pow(self, expr) -> str:
        if expr.is_number:  # a constant such as sqrt(2): fold it
            return self._print_constant(expr)
        base, exp = expr.base, expr.exp
        prec = PRECEDENCE["Mul"]
        if exp.is_Integer:
            n = int(exp)
            if n == 0:
                return self.float_literal(1.0)
            body = "*".join([self.parenthesize(base, prec)] * abs(n))
            if n > 0:
                return body
            return f"{self.float_literal(1.0)}/" + (body if abs(n) == 1 else f"({body})")
        if exp == sympy.Rational(1, 2):
            return f"sqrt({self._print(base)})"
        if exp == sympy.Rational(-1, 2):
            return f"{self.float_literal(1.0)}/sqrt({self._print(base)})"
        return f"{self.pow_name}({self._print(base)}, {self._print(exp)})"

    pow_name = "pow"

    def _print_constant(self, expr) -> str:
        try:
            return self.float_literal(float(expr))
        except (TypeError, OverflowError):
            raise ImplcError(f"the constant {expr} is not a finite real number") from None

    def _print_table_function(self, expr) -> str:
        if expr.is_number:
            return self._print_constant(expr)
        name = type(expr).__name__
        row = BY_SYMPY_NAME.get(name)
        if row is None:
            raise ImplcError(f"function '{name}' cannot be printed for target {self.target}")
        if row.printed == "step":
            return self.print_step(self._print(expr.args[0]))
        if row.printed == "zero":
            return self.float_literal(0.0)
        spelled = self.known_functions.get(name)
        if not spelled:
            refused = self.refusal(row.name)
            if refused:
                raise InputError(refused)
            raise ImplcError(f"function '{row.name}' has no {self.target} spelling")
        if row.printed == "fold":
            return self._fold(spelled, expr.args)
        return f"{spelled}({', '.join(self._print(a) for a in expr.args)})"

    def refusal(self, function: str) -> str | None:
        """Why this printer refuses `function` (a table name), or None: a precision may
        lack a built-in the language has in another (GLSL's double has no sin)."""
        return None

    def _fold(self, fname: str, args) -> str:
        """min/max of several arguments as a balanced tree of two-argument calls: depth
        log2(n), not n - 1. In a march loop's root test, max(max(a, b), max(c, d)) ran 6 %
        faster a frame than max(a, max(b, max(c, d))) on llvmpipe (docs/RESULTS.md): the
        loop is bound by its dependency chain, not by its operation count."""
        if len(args) == 1:
            return self._print(args[0])
        half = (len(args) + 1) // 2
        return f"{fname}({self._fold(fname, args[:half])}, {self._fold(fname, args[half:])})"

    def print_step(self, arg: str) -> str:
        """Heaviside(x): 1 for x >= 0, else 0 (the derivative of max by branch)."""
        return f"step({self.float_literal(0.0)}, {arg})"

    # --- the methods' step rules and root tests (implc/methods.py) -------------------
    def _print_Piecewise(self, expr) -> str:
        """Nested selects; the last branch must be unconditional."""
        *branches, (last, otherwise) = expr.args
        if otherwise is not sympy.true:
            raise ImplcError(f"a Piecewise without an otherwise branch: {expr}")
        text = self._print(last)
        for value, cond in reversed(branches):
            text = self.print_select(self._print(cond), self._print(value), text)
        return text

    def print_call(self, function: str, *args: str) -> str:
        """A call of a table function (its sympy name: `Abs`) on printed arguments, as
        this target spells it: what templates/<target>/lang.j2 writes for `abs`."""
        return f"{self.known_functions[function]}({', '.join(args)})"

    def print_select(self, cond: str, if_true: str, if_false: str) -> str:
        """cond ? a : b (C family: only the chosen side is evaluated)."""
        return f"({cond} ? {if_true} : {if_false})"

    def _print_Relational(self, expr) -> str:
        prec = PRECEDENCE["Add"]
        lhs = self.parenthesize(expr.lhs, prec)
        rhs = self.parenthesize(expr.rhs, prec)
        return f"{lhs} {expr.rel_op} {rhs}"

    def _print_And(self, expr) -> str:
        return " && ".join(self._print_operand(a) for a in expr.args)

    def _print_Or(self, expr) -> str:
        return " || ".join(self._print_operand(a) for a in expr.args)

    def _print_Not(self, expr) -> str:
        return f"!({self._print(expr.args[0])})"

    def _print_operand(self, arg) -> str:
        """And/Or operands: nested boolean operators always in parentheses (WGSL requires
        it; in C it reads better)."""
        text = self._print(arg)
        return f"({text})" if isinstance(arg, (sympy.And, sympy.Or)) else text

    def _print_BooleanTrue(self, expr) -> str:
        return "true"

    def _print_BooleanFalse(self, expr) -> str:
        return "false"

    def emptyPrinter(self, expr) -> str:  # noqa: N802 (sympy's name)
        raise ImplcError(f"'{type(expr).__name__}' cannot be printed for target {self.target}")

    def parenthesize(self, item, level, strict=False) -> str:
        text = self._print(item)
        if precedence(item) < level or (not strict and precedence(item) <= level and
                                         item.is_Add):
            return f"({text})"
        if text.startswith("-") and level >= PRECEDENCE["Mul"]:
            return f"({text})"
        return text


def _install_table_functions() -> None:
    """Route every node class of the function table through the one table printer."""
    for name in BY_SYMPY_NAME:
        setattr(ShaderPrinterMixin, f"_print_{name}", ShaderPrinterMixin._print_table_function)
    ShaderPrinterMixin._print_Function = ShaderPrinterMixin._print_table_function


_install_table_functions()
