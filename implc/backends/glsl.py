"""GLSL target: sympy's GLSL printer with implc's shader rules (its flavours are
implc/targets.py GLSL_FLAVORS), in float or double.

In double (GLSL 4.00, or GLSL 330 with GL_ARB_gpu_shader_fp64) a literal carries `lf`
(an unsuffixed one is a float, rounded to float32 before it is widened), and GLSL's
built-ins take double only for the rounding-free functions (of the table's: sqrt, abs,
sign, min, max). A surface with another function (sin, exp, a cube root) is refused in
double with a message that says so; a half-integer power is a product with sqrt.
"""

from __future__ import annotations

import sympy
from sympy.printing.glsl import GLSLPrinter
from sympy.printing.precedence import PRECEDENCE

from ..errors import InputError
from .printing import ShaderPrinterMixin

LITERAL_SUFFIX = {"float": "", "double": "lf"}  # precision -> its literals' suffix

# sympy class name -> GLSL function, for every row of implc/functions.py that prints as a
# call (the others: the table's `printed` column). GLSL's two-argument arctangent is an
# overload of atan.
known_functions = {
    "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
    "atan2": "atan", "sinh": "sinh", "cosh": "cosh", "tanh": "tanh", "exp": "exp",
    "log": "log", "sqrt": "sqrt", "Abs": "abs", "sign": "sign", "Min": "min", "Max": "max",
    "floor": "floor",
}


# the table's functions GLSL defines for double (GLSL 4.00 section 8: the exponential
# and trigonometric built-ins are float only; floor is, but only the interval rules of
# those use it)
DOUBLE_FUNCTIONS = ("sqrt", "Abs", "sign", "Min", "Max")


class GlslPrinter(ShaderPrinterMixin, GLSLPrinter):
    target = "glsl"
    _kf = known_functions

    def __init__(self, precision: str = "float"):
        super().__init__({"use_operators": True})
        self.use_precision(precision, LITERAL_SUFFIX)
        if precision == "double":
            self.known_functions = {k: v for k, v in known_functions.items()
                                    if k in DOUBLE_FUNCTIONS}

    def refusal(self, function: str) -> str | None:
        if self.precision != "double":
            return None
        return (f"GLSL has no double-precision {function}: --precision double takes "
                "surfaces made of polynomials, sqrt, abs, sign, min and max (or use "
                "-t opencl, whose double has every function)")

    def _print_Pow(self, expr) -> str:
        """In double, a half-integer power (a square root's derivatives) is a product with
        sqrt; any other non-integer power is refused (GLSL has no double pow)."""
        exp = expr.exp
        if self.precision != "double" or expr.is_number or exp.is_Integer:
            return super()._print_Pow(expr)
        twice = 2 * exp
        if twice in (1, -1):  # sqrt, 1/sqrt
            return super()._print_Pow(expr)
        if not twice.is_Integer:
            raise InputError(f"GLSL has no double-precision pow (for {expr}): --precision "
                             "double takes integer powers and square roots only (or use "
                             "-t opencl, whose double has pow)")
        whole = sympy.Pow(expr.base, abs(twice) // 2, evaluate=False)
        root = f"sqrt({self._print(expr.base)})"
        body = root if whole.exp == 0 else (
            f"{self.parenthesize(whole, PRECEDENCE['Mul'])}*{root}")
        return body if exp > 0 else f"{self.float_literal(1.0)}/({body})"
