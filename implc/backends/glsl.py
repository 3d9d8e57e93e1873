"""GLSL target: sympy's GLSL printer with implc's shader rules, and its flavours."""

from __future__ import annotations

from sympy.printing.glsl import GLSLPrinter

from .printing import ShaderPrinterMixin

# sympy class name -> GLSL function, for every row of implc/functions.py that prints as a
# call (the others: printing.RULES). GLSL's two-argument arctangent is an overload of atan.
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


# flavour -> how the program form is framed (read by templates/glsl/program.glsl.j2)
FLAVORS = {
    "330": {"version": "330 core", "es": False, "shadertoy": False},
    "450": {"version": "450 core", "es": False, "shadertoy": False},
    "es300": {"version": "300 es", "es": True, "shadertoy": False},
    "shadertoy": {"version": "", "es": False, "shadertoy": True},
}
