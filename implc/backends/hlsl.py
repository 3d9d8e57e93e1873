"""HLSL target: sympy's C99 printer with implc's shader rules, for Direct3D, Unity and
Unreal shaders (Shader Model 5 and later).

HLSL's expression syntax is C's (with `?:`), its unsuffixed float literal is a float, and
its built-ins are GLSL's under a few other names (`atan2`); Heaviside prints as
`step(0.0, x)`, as in GLSL. Functions are spelled by `known_functions` below.
"""

from __future__ import annotations

from sympy.printing.c import C99CodePrinter

from .printing import ShaderPrinterMixin

# sympy class name -> HLSL intrinsic, for every row of implc/functions.py that prints as
# a call (the others: the table's `printed` column).
known_functions = {
    "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
    "atan2": "atan2", "sinh": "sinh", "cosh": "cosh", "tanh": "tanh", "exp": "exp",
    "log": "log", "sqrt": "sqrt", "Abs": "abs", "sign": "sign", "Min": "min", "Max": "max",
    "floor": "floor",
}


class HlslPrinter(ShaderPrinterMixin, C99CodePrinter):
    target = "hlsl"
    _kf = known_functions

    def __init__(self) -> None:
        super().__init__({"strict": True})
