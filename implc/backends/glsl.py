"""GLSL target: sympy's GLSL printer with implc's shader rules (its flavours are
implc/targets.py GLSL_FLAVORS)."""

from __future__ import annotations

from sympy.printing.glsl import GLSLPrinter

from .printing import ShaderPrinterMixin

# sympy class name -> GLSL function, for every row of implc/functions.py that prints as a
# call (the others: the table's `printed` column). GLSL's two-argument arctangent is an
# overload of atan.
known_functions = {
    "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
    "atan2": "atan", "sinh": "sinh", "cosh": "cosh", "tanh": "tanh", "exp": "exp",
    "log": "log", "sqrt": "sqrt", "Abs": "abs", "sign": "sign", "Min": "min", "Max": "max",
    "floor": "floor",
}


class GlslPrinter(ShaderPrinterMixin, GLSLPrinter):
    target = "glsl"
    _kf = known_functions

    def __init__(self):
        super().__init__({"use_operators": True})
