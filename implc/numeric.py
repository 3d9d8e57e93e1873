"""Evaluate sympy trees on numpy arrays in float64, without lambdify or exec.

The CPU reference, the tests and the corpus checks use this walker, so the CPU meaning
of every node is the one written in `functions.FUNCTIONS` (the same as the shaders').
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import sympy

from .functions import BY_SYMPY_NAME
from .plain_extent import float_terms as _expanded
from .plain_extent import sum_of_monomials as _monomials
from .symbols import POINT


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
        value = _sum([_eval(a, env, cache, real) for a in node.args])
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
        if isinstance(node, sympy.exp) and node.args[0].is_Add:
            value = _exp_of_sum([_eval(a, env, cache, real) for a in node.args[0].args])
            if value is not None:
                cache[node] = value
                return value
        args = [_eval(a, env, cache, real) for a in node.args]
        if row.arity == 2 and len(args) > 2:  # Min/Max with more arguments
            value = args[0]
            for a in args[1:]:
                value = row.numpy(value, a)
        else:
            value = row.numpy(*args)
    cache[node] = value
    return value


def _sum(terms: list) -> np.ndarray:
    """terms[0] + terms[1] + ..., left to right (as the plain sum rounds), accumulated in
    place in one array of the broadcast shape rather than a new array per term."""
    shape = np.broadcast_shapes(*(np.shape(t) for t in terms))
    if not shape:
        return sum(terms[1:], terms[0])
    total = np.array(np.broadcast_to(terms[0], shape), dtype=np.result_type(*terms))
    for term in terms[1:]:
        total += term
    return total


def _exp_of_sum(terms: list) -> np.ndarray | None:
    """exp(t0 + t1 + ...) as exp(t0) exp(t1) ... where every term varies along fewer
    axes than their sum (framing's tensor grid: a gaussian's x part is a line, the sum a
    volume), so exp runs on the lines, not at every grid point; None where that does not
    hold, or where a term leaves [-700, 700] (a factor could overflow where the whole
    does not)."""
    shape = np.broadcast_shapes(*(np.shape(t) for t in terms))
    size = int(np.prod(shape)) if shape else 1
    if size < 2 or any(np.size(t) >= size for t in terms):
        return None
    if any(not np.all(np.abs(t) <= 700.0) for t in terms):  # (NaN fails this too)
        return None
    factors = [np.exp(t) for t in terms]
    return _product_small_first(factors)


def _product_small_first(factors: list) -> np.ndarray:
    """The product, smallest factors first, so only the last multiplications reach the
    full broadcast shape."""
    factors = sorted(factors, key=np.size)
    value = factors[0]
    for f in factors[1:]:
        value = value * f
    return value


_RELATIONS = {"<": np.less, "<=": np.less_equal, ">": np.greater, ">=": np.greater_equal,
              "==": np.equal, "!=": np.not_equal}


def _power_by_halves(base, n: int):
    """base^n as the shaders' power chains compute it (optimize._power_chain):
    b^n = b^(n // 2) b^(n - n // 2), each power once; about log2 n products, not n - 1."""
    have = {1: base}

    def build(k: int):
        if k not in have:
            have[k] = build(k // 2) * build(k - k // 2)
        return have[k]

    return np.ones_like(base) if n == 0 else build(n)


def _pow(base, exp, env, cache, real=np.float64):
    if exp.is_Integer:
        n = int(exp)
        if n >= 0:
            return _power_by_halves(base, n)
        inv = 1.0 / base
        result = np.ones_like(inv)
        for _ in range(-n):
            result = result * inv
        return result
    if exp == sympy.Rational(1, 2):
        return np.sqrt(base)
    return np.power(base, _eval(exp, env, cache, real))


def evaluate_on_grid(expr: sympy.Expr, axes: Sequence[np.ndarray]) -> np.ndarray:
    """S on the tensor grid axes[0] x axes[1] x axes[2], shape (len(axes[0]), ...).

    A sum of monomials c x^i y^j z^k (an equation written out at length, such as the
    corpus's degree-18 torus knot with its 207 terms) is contracted one axis at a time
    from its coefficient tensor: about n^3 (d + 1) operations for d + 1 coefficients an
    axis, where the walker forms every monomial at every one of the n^3 points (1 s
    against 0.02 s for that knot on framing's 65^3 grid). A polynomial written otherwise,
    of degree at most EXPAND_UP_TO, is expanded and contracted the same way, where the
    rounding of its expanded form cannot decide a sign (`_checked_contraction`); forty
    twelfth powers of planes: 1.1 s of framing becomes 0.2 s. Anything else: the walker,
    on the axes broadcast rather than on a mesh."""
    monomials = _monomials(expr)
    if monomials is not None:
        return _contract(monomials, axes)
    expanded = _expanded(expr)
    if expanded is not None:
        checked = _checked_contraction(expr, expanded, axes)
        if checked is not None:
            return checked
    # each axis along its own dimension: a part of S in x alone is evaluated on the x
    # axis, one in x and y on a plane, by numpy's broadcasting
    shape = tuple(len(a) for a in axes)
    env = {v: np.asarray(a, dtype=np.float64).reshape([-1 if k == i else 1
                                                         for k in range(3)])
           for i, (v, a) in enumerate(zip(POINT, axes, strict=True))}
    return np.broadcast_to(evaluate(expr, env), shape)




def _contract(monomials: Mapping[tuple[int, int, int], float],
              axes: Sequence[np.ndarray]) -> np.ndarray:
    degrees = [max(m[axis] for m in monomials) + 1 for axis in range(3)]
    tensor = np.zeros(degrees)
    for exponents, coefficient in monomials.items():
        tensor[exponents] += coefficient
    powers = [np.asarray(a, dtype=np.float64)[None, :] ** np.arange(d)[:, None]
              for a, d in zip(axes, degrees, strict=True)]
    with np.errstate(all="ignore"):
        return np.einsum("ijk,ia,jb,kc->abc", tensor, *powers, optimize=True)


def _checked_contraction(expr: sympy.Expr, monomials: dict[tuple[int, int, int], float],
                         axes: Sequence[np.ndarray]) -> np.ndarray | None:
    """The contraction of S's expanded form, with the walker's value wherever that form's
    rounding error bound (m + d units of |c| |x|^i |y|^j |z|^k summed, m monomials of
    degree up to d) reaches |S|: the sign is S's own everywhere. None when that is more
    than a tenth of the grid (the expanded form cancels too much: the walker is cheaper)."""
    values = _contract(monomials, axes)
    magnitudes = _contract({k: abs(c) for k, c in monomials.items()}, [np.abs(a) for a in axes])
    bound = (len(monomials) + max(sum(k) for k in monomials) + 8) * 2.0**-52 * magnitudes
    unsure = ~(np.abs(values) > bound)  # (NaN is unsure)
    if unsure.sum() > unsure.size // 10:
        return None
    if unsure.any():
        index = np.nonzero(unsure)
        env = {v: np.asarray(axes[k], dtype=np.float64)[index[k]] for k, v in enumerate(POINT)}
        values[index] = np.broadcast_to(evaluate(expr, env), index[0].shape)
    return values
