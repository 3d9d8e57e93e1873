"""THE table of functions implc supports.

One row per function. The parser's whitelist (`USER_FUNCTIONS`), every target printer's
spellings (`spelling(target)`), the CPU evaluator (`numpy`) and the README's table are
all read from `FUNCTIONS`; the "every function x every target" test loops over it.

To add a function: add a row here (user name, arity, sympy constructor, the sympy class
name it prints from, numpy implementation, a semantics note and the spelling in every
target). Rows with `user=False` are never written by users; they appear only in
derivatives (e.g. d|x|/dx = sign(x)) and must still print on every target.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import sympy

TARGETS = ("glsl", "wgsl", "opencl")


@dataclass(frozen=True)
class Function:
    name: str  # as users write it
    arity: int
    build: Callable[..., sympy.Expr]  # builds the sympy node from sympy arguments
    sympy_name: str  # class name of the node `build` makes (what printers dispatch on)
    numpy: Callable[..., np.ndarray]  # float64 CPU semantics, same as the shaders'
    note: str
    glsl: str
    wgsl: str
    opencl: str
    user: bool = True


def _heaviside(x, *_):
    return np.where(x > 0, 1.0, np.where(x < 0, 0.0, 0.5))


FUNCTIONS: tuple[Function, ...] = (
    Function("sin", 1, sympy.sin, "sin", np.sin, "radians", "sin", "sin", "sin"),
    Function("cos", 1, sympy.cos, "cos", np.cos, "radians", "cos", "cos", "cos"),
    Function("tan", 1, sympy.tan, "tan", np.tan, "radians", "tan", "tan", "tan"),
    Function("asin", 1, sympy.asin, "asin", np.arcsin, "domain [-1, 1]", "asin", "asin", "asin"),
    Function("acos", 1, sympy.acos, "acos", np.arccos, "domain [-1, 1]", "acos", "acos", "acos"),
    Function("atan", 1, sympy.atan, "atan", np.arctan, "range (-pi/2, pi/2)", "atan", "atan",
             "atan"),
    Function("atan2", 2, sympy.atan2, "atan2", np.arctan2, "atan2(y, x), angle of (x, y)",
             "atan", "atan2", "atan2"),
    Function("sinh", 1, sympy.sinh, "sinh", np.sinh, "", "sinh", "sinh", "sinh"),
    Function("cosh", 1, sympy.cosh, "cosh", np.cosh, "", "cosh", "cosh", "cosh"),
    Function("tanh", 1, sympy.tanh, "tanh", np.tanh, "", "tanh", "tanh", "tanh"),
    Function("exp", 1, sympy.exp, "exp", np.exp, "", "exp", "exp", "exp"),
    Function("log", 1, sympy.log, "log", np.log, "natural logarithm; x > 0", "log", "log", "log"),
    Function("sqrt", 1, sympy.sqrt, "sqrt", np.sqrt, "x >= 0; NaN (no surface) below",
             "sqrt", "sqrt", "sqrt"),
    Function("cbrt", 1, lambda a: sympy.sign(a) * sympy.Abs(a) ** sympy.Rational(1, 3), "cbrt",
             np.cbrt, "real cube root, defined for negative x (same as x^(1/3))",
             "", "", "", user=True),
    Function("abs", 1, sympy.Abs, "Abs", np.abs, "derivative sign(x)", "abs", "abs", "fabs"),
    Function("sign", 1, sympy.sign, "sign", np.sign, "-1, 0 or 1; derivative 0", "sign", "sign",
             "sign"),
    Function("min", 2, sympy.Min, "Min", np.minimum, "smooth union in CSG; derivative by branch",
             "min", "min", "fmin"),
    Function("max", 2, sympy.Max, "Max", np.maximum, "derivative by branch", "max", "max",
             "fmax"),
    # Only in derivatives: the step of min/max/abs and the (ignored) spike of sign.
    Function("step", 1, sympy.Heaviside, "Heaviside", _heaviside,
             "derivative of min/max; 1 for x > 0, 0 for x < 0", "step", "step", "step",
             user=False),
    Function("delta", 1, sympy.DiracDelta, "DiracDelta", lambda x, *_: np.zeros_like(x),
             "derivative of sign(x); taken as 0 (almost everywhere)", "", "", "", user=False),
)

# `cbrt` is sugar: it builds sign(a)*|a|^(1/3), so it never reaches a printer itself.
USER_FUNCTIONS: dict[str, Function] = {f.name: f for f in FUNCTIONS if f.user}
BY_SYMPY_NAME: dict[str, Function] = {f.sympy_name: f for f in FUNCTIONS if f.name != "cbrt"}

CONSTANTS: dict[str, sympy.Expr] = {"pi": sympy.pi, "e": sympy.E}


def spelling(target: str) -> dict[str, str]:
    """sympy class name -> function name in `target`, for rows printed as plain calls."""
    return {
        f.sympy_name: getattr(f, target)
        for f in FUNCTIONS
        if getattr(f, target) and f.name != "cbrt"
    }
