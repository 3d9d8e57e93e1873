"""S's scale for float32: the same surface with its constants near 1.

S = 0 and c*S = 0 are one surface for any c > 0, but a float32 shader is not indifferent:
`1e-25*(x^2+y^2+z^2) - 1e-25` underflows in the products every method forms (exact's
Bernstein steps, taylor's step bound, the interval's enclosures) and draws false hits and
wrong roots, and `1e20*x^2 + ...` overflows |grad S|^2 in the shading. So the compile
multiplies S by a power of two (exact in binary floating point) that brings its nominal
magnitude near 1, where that lies beyond 2^+-SCALE_BEYOND. The surface's text,
the reference and `implc show` keep S as written; the shader's header says the factor.
"""

from __future__ import annotations

import math

import sympy

from .derive import fold_tree

# |log2| of the nominal magnitude beyond which S is rescaled (2^32 ~ 4e9): there the
# squares and cubes of S's values a method forms still fit float32 (its range is about
# 2^+-126); every bundled example (at most 2^12.3) and corpus row (2^25.2) lies inside, so
# their shaders are as before
SCALE_BEYOND = 32


def magnitude_log2(expr: sympy.Expr) -> float:
    """log2 of S's nominal magnitude where |x|, |y|, |z| and every function's value are 1:
    a constant's own, the largest term's in a sum, the factors' summed in a product, the
    base's times a numeric exponent. Exponents are not values: `x^4` is 1, `1e24` is 80."""
    def combine(node: sympy.Basic, parts: list[float]) -> float:
        if node.is_Number:
            value = abs(float(node))
            return math.log2(value) if 0.0 < value < math.inf else 0.0
        if node.is_Add:
            return max(parts)
        if node.is_Mul:
            return sum(parts)
        if node.is_Pow and node.exp.is_Number:
            return float(node.exp) * parts[0]
        return 0.0  # a coordinate, a function's value, anything not a constant's scale

    return fold_tree(expr, combine)


def scale_exponent(expr: sympy.Expr) -> int:
    """k such that 2^k * S has its nominal magnitude near 1 (0 where it is already within
    2^+-SCALE_BEYOND). Only where every constant of S, before and after, is a normal
    float32 number: a constant float32 cannot hold as written is the compile's refusal
    (`too large for float32`), and a scaling that pushed one out would change S."""
    log2 = magnitude_log2(expr)
    if not math.isfinite(log2) or abs(log2) <= SCALE_BEYOND:
        return 0
    k = -round(log2)
    if not (_in_float32(expr) and _in_float32(scaled(expr, k))):
        return 0
    return k


def _in_float32(expr: sympy.Expr) -> bool:
    """Every constant of S (exponents aside) 0 or a normal float32 number in magnitude."""
    def combine(node: sympy.Basic, parts: list[bool]) -> bool:
        if node.is_Number:
            value = abs(float(node))
            return value == 0.0 or FLOAT32_MIN <= value <= FLOAT32_MAX
        if node.is_Pow:
            return parts[0]
        return all(parts)

    return fold_tree(expr, combine)


FLOAT32_MIN = 2.0 ** -126  # the smallest normal float32
FLOAT32_MAX = 3.4028234663852886e38


def scaled(expr: sympy.Expr, k: int) -> sympy.Expr:
    """2^k * S with the factor folded into S's constants (sympy distributes a number over a
    sum), so no intermediate value of the shader keeps the old magnitude."""
    if k == 0:
        return expr
    factor = sympy.Integer(2) ** k
    return sympy.expand_mul(factor * expr, deep=False) if expr.is_Add else factor * expr


def scale_note(k: int) -> str:
    """What the shader's header (after the equation) and `implc show` say of the factor;
    '' when S is as written."""
    if k == 0:
        return ""
    return (f"the shader's S is the equation times 2^{k}, the same surface: its constants "
            f"are near 2^{-k} = {2.0 ** -k:.2g}, beyond float32's comfortable range")
