"""Evaluate sympy trees on numpy arrays in float64, without lambdify or exec.

The CPU reference, the tests and the corpus checks use this walker, so the CPU meaning
of every node is the one written in `functions.FUNCTIONS` (the same as the shaders').
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import sympy

from .functions import BY_SYMPY_NAME


def evaluate(expr: sympy.Expr, env: Mapping[sympy.Symbol, np.ndarray]) -> np.ndarray:
    """Value of `expr` with symbols bound by `env` (arrays broadcast together)."""
    cache: dict[sympy.Basic, np.ndarray] = {}
    with np.errstate(all="ignore"):
        return np.asarray(_eval(expr, env, cache), dtype=np.float64)


def evaluate_program(
    assignments: Sequence[tuple[sympy.Symbol, sympy.Expr]],
    outputs: Sequence[sympy.Expr],
    env: Mapping[sympy.Symbol, np.ndarray],
    real: type = np.float64,
) -> list[np.ndarray]:
    """Run CSE'd assignments in order, then evaluate the outputs. With `real` np.float32
    (and float32 inputs) every constant and operation rounds as a float32 shader's does,
    up to the order of a sum's terms (conditioning.py measures that rounding)."""
    scope = dict(env)
    cache: dict[sympy.Basic, np.ndarray] = {}
    with np.errstate(all="ignore"):
        for sym, value in assignments:
            scope[sym] = _eval(value, scope, cache, real)
        return [np.asarray(_eval(o, scope, cache, real), dtype=real) for o in outputs]


def _eval(node, env, cache, real=np.float64):
    if node in cache:
        return cache[node]
    if node.is_Symbol:
        value = env[node]
    elif node.is_Number or node.is_NumberSymbol:
        value = real(float(node))
    elif node.is_Add:
        value = sum((_eval(a, env, cache, real) for a in node.args[1:]),
                    _eval(node.args[0], env, cache, real))
    elif node.is_Mul:
        value = _eval(node.args[0], env, cache, real)
        for a in node.args[1:]:
            value = value * _eval(a, env, cache, real)
    elif node.is_Pow:
        value = _pow(_eval(node.base, env, cache, real), node.exp, env, cache, real)
    elif isinstance(node, sympy.Piecewise):  # interval rules (implc/interval.py)
        value = _eval(node.args[-1].expr, env, cache, real)
        for branch in reversed(node.args[:-1]):
            value = np.where(_eval(branch.cond, env, cache, real),
                             _eval(branch.expr, env, cache, real), value)
    elif node.is_Relational:
        value = _RELATIONS[node.rel_op](_eval(node.lhs, env, cache, real),
                                        _eval(node.rhs, env, cache, real))
    elif isinstance(node, (sympy.And, sympy.Or)):
        parts = [_eval(a, env, cache, real) for a in node.args]
        combine = np.logical_and if isinstance(node, sympy.And) else np.logical_or
        value = parts[0]
        for part in parts[1:]:
            value = combine(value, part)
    elif isinstance(node, sympy.Not):
        value = np.logical_not(_eval(node.args[0], env, cache, real))
    elif node in (sympy.true, sympy.false):
        value = np.bool_(node is sympy.true)
    else:
        name = type(node).__name__
        row = BY_SYMPY_NAME.get(name)
        if row is None:
            raise NotImplementedError(f"no numeric meaning for {name}")
        args = [_eval(a, env, cache, real) for a in node.args]
        if row.arity == 2 and len(args) > 2:  # Min/Max with more arguments
            value = args[0]
            for a in args[1:]:
                value = row.numpy(value, a)
        else:
            value = row.numpy(*args)
    cache[node] = value
    return value


_RELATIONS = {"<": np.less, "<=": np.less_equal, ">": np.greater, ">=": np.greater_equal,
              "==": np.equal, "!=": np.not_equal}


def _pow(base, exp, env, cache, real=np.float64):
    if exp.is_Integer:
        n = int(exp)
        result = np.ones_like(base) if n >= 0 else None
        if n >= 0:
            for _ in range(n):
                result = result * base
            return result
        inv = 1.0 / base
        result = np.ones_like(inv)
        for _ in range(-n):
            result = result * inv
        return result
    if exp == sympy.Rational(1, 2):
        return np.sqrt(base)
    return np.power(base, _eval(exp, env, cache, real))
