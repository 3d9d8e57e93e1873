"""A computer-algebra expression as implc's input: printed to implc's own language and
parsed by its own front end, so it meets the same limits, function table and messages as
text (never `sympify`: an object converts itself with `_sympy_()`, as SageMath's
symbolic expressions do, and is then only walked and printed)."""

from __future__ import annotations

from typing import Any

from ..errors import InputError, LimitError
from ..limits import Limits


def equation_text(equation: Any, limits: Limits, value: bool = False) -> str:
    """`equation` as text in implc's input language: text as it is; a sympy expression
    (S, meaning S = 0), a sympy equation (lhs = rhs) or an object with `_sympy_()` printed
    from its tree. `value`: a parameter's value (printed without `= 0`). An expression
    larger than `limits.max_nodes` is refused before it is printed."""
    if isinstance(equation, str):
        return equation
    expr = _as_sympy(equation)
    import sympy

    from ..textform import value_text

    _check_size(expr, limits)
    if value:
        return value_text(expr)
    if isinstance(expr, sympy.Equality):
        return f"{value_text(expr.lhs)} = {value_text(expr.rhs)}"
    if not isinstance(expr, sympy.Expr):
        raise InputError(f"expected an expression or an equation, got a "
                         f"{type(expr).__name__} ({expr})")
    return value_text(expr) + " = 0"


def _as_sympy(obj: Any) -> Any:
    convert = getattr(obj, "_sympy_", None)
    if callable(convert):
        obj = convert()
    module = type(obj).__module__ or ""
    if not module.startswith("sympy"):
        raise InputError(f"expected equation text, a sympy expression or an object with "
                         f"_sympy_(), got {type(obj).__name__}")
    return obj


def _check_size(expr: Any, limits: Limits) -> None:
    """Count the tree's nodes, stopping past the limit (a hostile tree is not printed)."""
    count, stack = 0, [expr]
    while stack:
        node = stack.pop()
        count += 1
        if count > limits.max_nodes:
            raise LimitError(f"too large: the expression has more than {limits.max_nodes} "
                             "nodes (--max-nodes)")
        stack.extend(getattr(node, "args", ()))
