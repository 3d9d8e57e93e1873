"""Print a sympy tree back as an equation implc itself parses (for headers and JSON)."""

from __future__ import annotations

import sympy
from sympy.printing.str import StrPrinter

from .functions import FUNCTIONS

# sympy class name -> the name users write, where they differ (Abs -> abs)
_NAMES = {f.sympy_name: f.name for f in FUNCTIONS
          if f.user and f.sympy_name and f.sympy_name != f.name}


class EquationPrinter(StrPrinter):
    """sympy -> implc's input language (`jsurf` writes SURFER's dialect on top of it)."""

    def _print_Function(self, expr):
        name = _NAMES.get(type(expr).__name__, type(expr).__name__)
        return f"{name}({', '.join(self._print(a) for a in expr.args)})"

    _print_Abs = _print_Function

    def _print_Min(self, expr):
        """min(a, b, c) as written: the parser builds it as min(min(a, b), c)
        (front.build._call_expr); min and max are associative, so flattening prints the same
        function."""
        args, stack = [], list(reversed(expr.args))
        while stack:
            arg = stack.pop()
            if type(arg) is type(expr):
                stack.extend(reversed(arg.args))
            else:
                args.append(arg)
        name = _NAMES[type(expr).__name__]
        args.sort(key=sympy.default_sort_key)  # sympy's order of a flat min (x before y)
        return f"{name}({', '.join(self._print(a) for a in args)})"

    _print_Max = _print_Min

    def _print_Rational(self, expr):
        """Short fractions stay exact (`9/4`); long ones (from decimal parameters such as
        phi = 1.618033988749895) print as the shortest decimal of their float value."""
        if expr.q > 1000:
            return repr(float(expr))
        return super()._print_Rational(expr)

    def _print_Float(self, expr):
        """A folded constant (front.build.fold_constants) as the shortest decimal of its float64
        value, the value a shader gets: `sqrt(2)` reads 1.4142135623730951."""
        return repr(float(expr))

    def _print_Mul(self, expr):
        coeff, rest = expr.as_coeff_Mul()
        if coeff.is_Rational and coeff.q > 1000 and rest != 1:
            sign = "-" if coeff < 0 else ""
            return f"{sign}{repr(float(abs(coeff)))}*{self.parenthesize(rest, 50, strict=True)}"
        return super()._print_Mul(expr)

    def _print_Exp1(self, expr):
        return "e"

    def _print_Pi(self, expr):
        return "pi"

    def _print_Pow(self, expr, rational=False):
        text = super()._print_Pow(expr, rational)
        return text.replace("**", "^")


def to_text(expr: sympy.Expr) -> str:
    """`expr` as `... = 0` in implc's input language (deterministic, `^` for powers)."""
    return value_text(expr) + " = 0"


def value_text(expr: sympy.Expr) -> str:
    """`expr` in implc's input language: a parameter's value (`7/20`, `1.618033988749895`
    for a long decimal, `1/2 + sqrt(5)/2`)."""
    return EquationPrinter({"order": "lex"}).doprint(expr)
