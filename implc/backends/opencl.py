"""OpenCL C target: sympy's C99 printer with implc's shader rules, in float or double.

OpenCL C is C99 with vector types and its own built-ins, so the C99 printer is the right
base; the mixin does the shader rules (typed literals, products for integer powers, the
function table, spelled by `known_functions` below). The precision decides the literal
type: `1.0f` in float (an unsuffixed literal is a double in OpenCL C and would silently
promote the whole expression), plain `1.0` in double. The scalar and vector type names
(`float3` / `double3`) are chosen in templates/opencl/ from the `precision` context
variable.
"""

from __future__ import annotations

import sympy
from sympy.printing.c import C99CodePrinter

from .printing import ShaderPrinterMixin

LITERAL_SUFFIX = {"float": "f", "double": ""}  # precision -> its literals' suffix
PRECISIONS = tuple(LITERAL_SUFFIX)

# sympy class name -> OpenCL C built-in, for every row of implc/functions.py that prints as
# a call (the others: the table's `printed` column). The float forms of abs/min/max are
# fabs/fmin/fmax; every built-in here is overloaded for float and double.
known_functions = {
    "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
    "atan2": "atan2", "sinh": "sinh", "cosh": "cosh", "tanh": "tanh", "exp": "exp",
    "log": "log", "sqrt": "sqrt", "Abs": "fabs", "sign": "sign", "Min": "fmin", "Max": "fmax",
    "floor": "floor",
}


class OpenclPrinter(ShaderPrinterMixin, C99CodePrinter):
    target = "opencl"
    _kf = known_functions

    def __init__(self, precision: str = "float"):
        super().__init__({"strict": True})
        self.use_precision(precision, LITERAL_SUFFIX)

    def print_step(self, arg: str) -> str:
        """Heaviside(x) = 1 for x >= 0, else 0, as a select: the value at 0 is explicit in
        the text, and the same line reads the same in float and double."""
        one, zero = self.float_literal(1.0), self.float_literal(0.0)
        return f"({arg} >= {zero} ? {one} : {zero})"

    def _print_Pow(self, expr) -> str:
        # rsqrt is an OpenCL built-in: one instruction instead of a divide and a sqrt.
        if expr.exp == sympy.Rational(-1, 2):
            return f"rsqrt({self._print(expr.base)})"
        return super()._print_Pow(expr)
