"""THE table of functions implc supports: name, arity, sympy constructor, numpy semantics.

One row per function. The parser's whitelist (`USER_FUNCTIONS`), the printers' dispatch
(`BY_SYMPY_NAME`), the CPU evaluator (`numpy`) and the docs' list are all read from
`FUNCTIONS`; tests/test_targets.py checks every row against every target.

How a row is spelled in a shader language is not a column here: it lives with that
language's printer (`known_functions` in implc/backends/<target>.py, sympy's idiom), so
a new target adds one dict instead of a column to every row.

To add a function: add a row here (user name, arity, sympy constructor, the sympy class
name it prints from, numpy implementation, a semantics note, its interval rule and the
shader's error bound that widens it, and whichever of the facts below the row has: other
languages' names for it, a root it takes, growth like e^|x|, a derivative by branch) and
its spelling to every printer's
`known_functions`. Rows with `user=False` are never written by users; they appear only in
derivatives (e.g. d|x|/dx = sign(x)) or in interval rules (floor) and must still print on
every target. A row without an interval rule makes `-m interval` refuse a surface that
uses it (implc/interval.py), never bound it unsoundly.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import sympy
from sympy import Max, Min, Piecewise, floor, pi

if TYPE_CHECKING:  # numpy loads when a row is evaluated: compiling needs none (issue 43)
    import numpy as np

# An interval rule: the argument's enclosure (lo, hi), as sympy symbols, and `let` (a value
# -> a symbol naming it, for a value used twice) -> the function's enclosure over it
# (lo', hi') and the condition under which the function is undefined on the whole
# argument interval (F is then NaN there: no root; sympy.false if never).
Bound = tuple[sympy.Expr, sympy.Expr, sympy.Basic]
# The value an unbounded enclosure takes (a pole, log(0), 1/0): finite so that a later
# product with 0 stays a number; anything it overflows to (inf, NaN) is never skipped.
BIG = 1e30


@dataclass(frozen=True)
class Function:
    name: str  # as users write it
    arity: int
    build: Callable[..., sympy.Expr]  # builds the sympy node from sympy arguments
    # class name of the node `build` makes (what printers and numpy dispatch on); None for
    # sugar whose `build` makes nodes of other rows
    sympy_name: str | None
    # float64 CPU semantics, the shaders' except `step` (Heaviside) at exactly 0: 0.5 here
    # and in the reference (sympy's convention), 1 in the shaders (`step(0, x)`)
    numpy: Callable[..., np.ndarray]
    note: str
    user: bool = True
    # the interval rule (implc/interval.py), None: -m interval refuses the function
    interval: Callable[..., Bound] | None = None
    # how far a shader's value may lie from the exact one, widening the rule's bounds:
    # (units of float32's epsilon relative to the value, absolute); see implc/interval.py
    error: tuple[float, float] = (0.0, 0.0)
    # takes `arity` or more arguments (min, max: users write CSG as max(a, b, c))
    variadic: bool = False
    # built unevaluated (min, max): evaluating makes sympy compare every pair of
    # (flattened) arguments symbolically, minutes for nested calls (implc/front/build.py)
    unevaluated: bool = False
    # names other languages give it: an unknown call of one gets `did you mean` this row
    aliases: tuple[str, ...] = ()
    # takes the n-th root of its argument (sqrt 2, cbrt 3): the front end bounds the
    # digits of exact constants under nested roots (implc/front/analyse.py)
    root_degree: int = 0
    # |f(a)| is about e^|a|: a constant argument is checked against the magnitude limit
    grows: bool = False
    # u -> d f(u)/du by branch, for every u (sympy gives abs and sign a derivative only
    # where it can prove u real); derive.branch_diff differentiates the row with it
    branch_derivative: Callable[[sympy.Expr], sympy.Expr] | None = None
    # how a shader prints it (implc/backends/printing.py): "call", a call spelled by each
    # printer's `known_functions`; "fold", such calls of two arguments as a balanced tree
    # (min, max); "step", the printer's `print_step` (Heaviside: OpenCL prints a select);
    # "zero", the literal 0 (DiracDelta, 0 almost everywhere). Only "call" and "fold" rows
    # have spellings.
    printed: str = "call"


def _np(name: str) -> Callable[..., np.ndarray]:
    """numpy.<name>, looked up when called: the table is read by the compile path, which
    must not import numpy (issue 43: Pyodide), only the CPU evaluator calls it."""
    def call(*args, **kwargs):
        import numpy

        return getattr(numpy, name)(*args, **kwargs)

    call.__name__ = call.__qualname__ = f"numpy.{name}"
    return call


def _heaviside(x, *_):
    import numpy as np

    return np.where(x > 0, 1.0, np.where(x < 0, 0.0, 0.5))


def _zero(x, *_):
    import numpy as np

    return np.zeros_like(x)


def _increasing(f):
    return lambda lo, hi, let: (f(lo), f(hi), sympy.false)


def _on_domain(f, low, high=None, increasing=True):
    """A monotonic function defined on [low, high]: the argument clamped into it; undefined
    on the whole interval when it lies outside."""
    def rule(lo, hi, let):
        a = let(Max(lo, low, evaluate=False))
        b = let(Max(hi, low, evaluate=False))
        if high is not None:
            a, b = let(Min(a, high, evaluate=False)), let(Min(b, high, evaluate=False))
        dead = (hi < low) if high is None else sympy.Or(hi < low, lo > high)
        return (f(a), f(b), dead) if increasing else (f(b), f(a), dead)
    return rule


def _periodic(f, peak):
    """sin or cos: -1 or 1 where [lo, hi] holds a minimum or a maximum (maxima at
    peak + 2 pi k, minima pi after them), else the ends' values. Measured from the last
    maximum at or before lo: a in [0, 2 pi), b = a + (hi - lo). Float32's floor may put
    k one off where lo is at an extremum, where f is flat: an error of second order,
    inside the widening."""
    def rule(lo, hi, let):
        shifted = let(lo - _number(peak)) if peak else lo
        a = let(shifted - _number(2 * pi) * floor(shifted * _number(1 / (2 * pi))))
        b = let(a + (hi - lo))
        ends = (let(f(lo)), let(f(hi)))
        has_min = sympy.Or(sympy.And(a <= _number(pi), b >= _number(pi)), b >= _number(3 * pi))
        low = Piecewise((-1, has_min), (Min(*ends, evaluate=False), True))
        high = Piecewise((1, b >= _number(2 * pi)), (Max(*ends, evaluate=False), True))
        return low, high, sympy.false
    return rule


def _number(value) -> sympy.Float:
    """A constant as one literal (a printer prints 2*pi as a product)."""
    return sympy.Float(float(value), 17)


def _tan(lo, hi, let):
    """tan: increasing between its poles at pi/2 + k pi; unbounded across one."""
    same = sympy.Eq(floor(lo * _number(1 / pi) + sympy.S.Half),
                    floor(hi * _number(1 / pi) + sympy.S.Half))
    return (Piecewise((sympy.tan(lo), same), (-BIG, True)),
            Piecewise((sympy.tan(hi), same), (BIG, True)), sympy.false)


def _even(f):
    """An even function increasing on [0, oo) (cosh): its least value at 0 when it is inside."""
    def rule(lo, hi, let):
        inner = let(Max(lo, -hi, 0, evaluate=False))  # the least |x| on [lo, hi]
        return f(inner), Max(f(lo), f(hi), evaluate=False), sympy.false
    return rule


def _abs(lo, hi, let):
    return Max(lo, -hi, 0, evaluate=False), Max(-lo, hi, evaluate=False), sympy.false


def _log(lo, hi, let):
    return (Piecewise((sympy.log(lo), lo > 0), (-BIG, True)),
            Piecewise((sympy.log(hi), hi > 0), (-BIG, True)), hi <= 0)


FUNCTIONS: tuple[Function, ...] = (
    Function("sin", 1, sympy.sin, "sin", _np("sin"), "radians",
             interval=_periodic(sympy.sin, pi / 2), error=(8, 2.0**-21)),
    Function("cos", 1, sympy.cos, "cos", _np("cos"), "radians",
             interval=_periodic(sympy.cos, 0), error=(8, 2.0**-21)),
    Function("tan", 1, sympy.tan, "tan", _np("tan"), "radians", interval=_tan,
             error=(16, 2.0**-21)),
    Function("asin", 1, sympy.asin, "asin", _np("arcsin"), "domain [-1, 1]",
             interval=_on_domain(sympy.asin, -1, 1), error=(16, 2.0**-10), aliases=("arcsin",)),
    Function("acos", 1, sympy.acos, "acos", _np("arccos"), "domain [-1, 1]",
             interval=_on_domain(sympy.acos, -1, 1, increasing=False), error=(16, 2.0**-11),
             aliases=("arccos",)),
    Function("atan", 1, sympy.atan, "atan", _np("arctan"), "range (-pi/2, pi/2)",
             interval=_increasing(sympy.atan), error=(16, 2.0**-18), aliases=("arctan",)),
    # atan2 has no interval rule (its branch cut): -m interval refuses it
    Function("atan2", 2, sympy.atan2, "atan2", _np("arctan2"), "atan2(y, x), angle of (x, y)",
             aliases=("arctan2",)),
    Function("sinh", 1, sympy.sinh, "sinh", _np("sinh"), "", interval=_increasing(sympy.sinh),
             error=(16, 2.0**-21), aliases=("sh",), grows=True),
    Function("cosh", 1, sympy.cosh, "cosh", _np("cosh"), "", interval=_even(sympy.cosh),
             error=(16, 0), aliases=("ch",), grows=True),
    Function("tanh", 1, sympy.tanh, "tanh", _np("tanh"), "", interval=_increasing(sympy.tanh),
             error=(16, 2.0**-21), aliases=("th",)),
    Function("exp", 1, sympy.exp, "exp", _np("exp"), "", interval=_increasing(sympy.exp),
             error=(16, 0), grows=True),
    Function("log", 1, sympy.log, "log", _np("log"), "natural logarithm; x > 0", interval=_log,
             error=(16, 2.0**-21), aliases=("ln",)),
    Function("sqrt", 1, sympy.sqrt, "sqrt", _np("sqrt"), "x >= 0; NaN (no surface) below",
             interval=_on_domain(sympy.sqrt, 0), error=(4, 0), root_degree=2),
    # Sugar: builds sign(a)*|a|^(1/3) from other rows, so no node of its own reaches a printer.
    Function("cbrt", 1, lambda a: sympy.sign(a) * sympy.Abs(a) ** sympy.Rational(1, 3), None,
             _np("cbrt"), "real cube root, defined for negative x (same as x^(1/3))",
             root_degree=3),
    Function("abs", 1, sympy.Abs, "Abs", _np("abs"), "derivative sign(x)", interval=_abs,
             aliases=("fabs",), branch_derivative=sympy.sign),
    Function("sign", 1, sympy.sign, "sign", _np("sign"), "-1, 0 or 1; derivative 0",
             interval=lambda lo, hi, let: (sympy.sign(lo), sympy.sign(hi), sympy.false),
             aliases=("sgn",), branch_derivative=lambda u: 2 * sympy.DiracDelta(u)),
    # min and max take their arguments' bounds apart (implc/interval.py)
    Function("min", 2, sympy.Min, "Min", _np("minimum"),
             "smooth union in CSG; derivative by branch", variadic=True, unevaluated=True,
             aliases=("fmin",), printed="fold"),
    Function("max", 2, sympy.Max, "Max", _np("maximum"), "derivative by branch", variadic=True,
             unevaluated=True, aliases=("fmax",), printed="fold"),
    # Only in derivatives: the step of min/max/abs and the (ignored) spike of sign.
    Function("step", 1, sympy.Heaviside, "Heaviside", _heaviside,
             "derivative of min/max; 1 for x > 0, 0 for x < 0; at 0, 0.5 on the CPU and 1 "
             "in shaders, so at a tie a == b a shader's derivative of max(a, b) is a' + b' "
             "where the CPU's is their mean: the same direction (normals agree), F' twice "
             "as large (Newton is safeguarded)", user=False,
             interval=lambda lo, hi, let: (sympy.Heaviside(lo), sympy.Heaviside(hi),
                                           sympy.false), printed="step"),
    Function("delta", 1, sympy.DiracDelta, "DiracDelta", _zero,
             "derivative of sign(x); taken as 0 (almost everywhere)", user=False,
             printed="zero"),
    # Only in interval rules (sin, cos, tan: which period an end lies in).
    Function("floor", 1, sympy.floor, "floor", _np("floor"), "largest integer <= x", user=False),
)

USER_FUNCTIONS: dict[str, Function] = {f.name: f for f in FUNCTIONS if f.user}
BY_SYMPY_NAME: dict[str, Function] = {f.sympy_name: f for f in FUNCTIONS if f.sympy_name}

CONSTANTS: dict[str, sympy.Expr] = {"pi": sympy.pi, "e": sympy.E}
