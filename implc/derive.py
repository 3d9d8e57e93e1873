"""Symbolic derivation: the quantities a marcher asks for, derived once and on demand.

The point-evaluation form: every quantity is an expression in the point (x, y, z) and,
for directional ones, the unit ray direction (dx, dy, dz), so that at p(t) = O + tD
    F(t) = S(p),  F'(t) = grad S(p) . D,  F''(t) = D^T H(p) D.
A second evaluation form (the ray polynomial's coefficients per pixel, then Horner per
step) can supply the same named quantities later; methods only name what they need.
"""

from __future__ import annotations

from functools import cached_property

import sympy

from .symbols import DIRECTION, POINT

# Quantity names methods may ask for, and what each means.
QUANTITIES = {
    "S": "S(p), the surface function",
    "dS": "F'(t) = grad S(p) . D",
    "d2S": "F''(t) = D^T H(p) D",
    "grad": "grad S(p), three components",
    "lap": "the Laplacian of S at p (sign of the unnormalized mean curvature, negated)",
}


class Derivatives:
    """All derived quantities of one surface function, each computed at most once."""

    def __init__(self, expr: sympy.Expr):
        self.expr = expr

    @cached_property
    def gradient(self) -> tuple[sympy.Expr, ...]:
        return tuple(sympy.diff(self.expr, v) for v in POINT)

    @cached_property
    def hessian(self) -> tuple[tuple[sympy.Expr, ...], ...]:
        g = self.gradient
        return tuple(tuple(sympy.diff(g[i], POINT[j]) for j in range(3)) for i in range(3))

    @cached_property
    def laplacian(self) -> sympy.Expr:
        return sympy.Add(*(self.hessian[i][i] for i in range(3)))

    @cached_property
    def directional(self) -> sympy.Expr:
        return sympy.Add(*(g * d for g, d in zip(self.gradient, DIRECTION, strict=True)))

    @cached_property
    def second_directional(self) -> sympy.Expr:
        h, d = self.hessian, DIRECTION
        return sympy.Add(*(h[i][j] * d[i] * d[j] for i in range(3) for j in range(3)))

    def quantity(self, name: str) -> tuple[sympy.Expr, ...]:
        """The expressions of a named quantity (one, or three for `grad`)."""
        if name == "S":
            return (self.expr,)
        if name == "dS":
            return (self.directional,)
        if name == "d2S":
            return (self.second_directional,)
        if name == "grad":
            return self.gradient
        if name == "lap":
            return (self.laplacian,)
        raise KeyError(f"unknown quantity {name!r}; known: {', '.join(QUANTITIES)}")


def polynomial_degree(expr: sympy.Expr) -> int | None:
    """Total degree in x, y, z, or None when S is not a polynomial."""
    if not expr.is_polynomial(*POINT):
        return None
    return int(sympy.Poly(expr, *POINT).total_degree())
