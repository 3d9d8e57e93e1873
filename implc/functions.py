"""THE table of functions implc supports: name, arity, sympy constructor, numpy semantics.

One row per function. The parser's whitelist (`USER_FUNCTIONS`), the printers' dispatch
(`BY_SYMPY_NAME`), the CPU evaluator (`numpy`) and the README's list are all read from
`FUNCTIONS`; tests/test_targets.py checks every row against every target.

How a row is spelled in a shader language is not a column here: it lives with that
language's printer (`known_functions` in implc/backends/<target>.py, sympy's idiom), so
a new target adds one dict instead of a column to every row.

To add a function: add a row here (user name, arity, sympy constructor, the sympy class
name it prints from, numpy implementation, a semantics note) and its spelling to every
printer's `known_functions`. Rows with `user=False` are never written by users; they
appear only in derivatives (e.g. d|x|/dx = sign(x)) and must still print on every target.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import sympy


@dataclass(frozen=True)
class Function:
    name: str  # as users write it
    arity: int
    build: Callable[..., sympy.Expr]  # builds the sympy node from sympy arguments
    # class name of the node `build` makes (what printers and numpy dispatch on); None for
    # sugar whose `build` makes nodes of other rows
    sympy_name: str | None
    numpy: Callable[..., np.ndarray]  # float64 CPU semantics, same as the shaders'
    note: str
    user: bool = True


def _heaviside(x, *_):
    return np.where(x > 0, 1.0, np.where(x < 0, 0.0, 0.5))


FUNCTIONS: tuple[Function, ...] = (
    Function("sin", 1, sympy.sin, "sin", np.sin, "radians"),
    Function("cos", 1, sympy.cos, "cos", np.cos, "radians"),
    Function("tan", 1, sympy.tan, "tan", np.tan, "radians"),
    Function("asin", 1, sympy.asin, "asin", np.arcsin, "domain [-1, 1]"),
    Function("acos", 1, sympy.acos, "acos", np.arccos, "domain [-1, 1]"),
    Function("atan", 1, sympy.atan, "atan", np.arctan, "range (-pi/2, pi/2)"),
    Function("atan2", 2, sympy.atan2, "atan2", np.arctan2, "atan2(y, x), angle of (x, y)"),
    Function("sinh", 1, sympy.sinh, "sinh", np.sinh, ""),
    Function("cosh", 1, sympy.cosh, "cosh", np.cosh, ""),
    Function("tanh", 1, sympy.tanh, "tanh", np.tanh, ""),
    Function("exp", 1, sympy.exp, "exp", np.exp, ""),
    Function("log", 1, sympy.log, "log", np.log, "natural logarithm; x > 0"),
    Function("sqrt", 1, sympy.sqrt, "sqrt", np.sqrt, "x >= 0; NaN (no surface) below"),
    # Sugar: builds sign(a)*|a|^(1/3) from other rows, so no node of its own reaches a printer.
    Function("cbrt", 1, lambda a: sympy.sign(a) * sympy.Abs(a) ** sympy.Rational(1, 3), None,
             np.cbrt, "real cube root, defined for negative x (same as x^(1/3))"),
    Function("abs", 1, sympy.Abs, "Abs", np.abs, "derivative sign(x)"),
    Function("sign", 1, sympy.sign, "sign", np.sign, "-1, 0 or 1; derivative 0"),
    Function("min", 2, sympy.Min, "Min", np.minimum, "smooth union in CSG; derivative by branch"),
    Function("max", 2, sympy.Max, "Max", np.maximum, "derivative by branch"),
    # Only in derivatives: the step of min/max/abs and the (ignored) spike of sign.
    Function("step", 1, sympy.Heaviside, "Heaviside", _heaviside,
             "derivative of min/max; 1 for x > 0, 0 for x < 0", user=False),
    Function("delta", 1, sympy.DiracDelta, "DiracDelta", lambda x, *_: np.zeros_like(x),
             "derivative of sign(x); taken as 0 (almost everywhere)", user=False),
)

USER_FUNCTIONS: dict[str, Function] = {f.name: f for f in FUNCTIONS if f.user}
BY_SYMPY_NAME: dict[str, Function] = {f.sympy_name: f for f in FUNCTIONS if f.sympy_name}

CONSTANTS: dict[str, sympy.Expr] = {"pi": sympy.pi, "e": sympy.E}
