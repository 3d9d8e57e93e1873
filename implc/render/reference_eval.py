"""What the CPU reference's root searches share (implc/render/reference.py): S and F' in
float64 at points and along rays, and the tolerances of a sign-change root and a
tangential hit, so that the certified and the dense search judge a root alike.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import sympy

from ..numeric import evaluate
from ..symbols import X, Y, Z

BISECTION_WIDTH = 1e-12  # final bracket width of a sign-change root, in units of t
TOUCH_TOL = 1e-9  # tangential hit when |F| / |grad S| <= TOUCH_TOL * L at a dip of |F|


def bisection_steps(width: float) -> int:
    """Bisection steps that shrink a bracket of `width` to BISECTION_WIDTH."""
    return max(0, math.ceil(math.log2(width / BISECTION_WIDTH))) if width > 0.0 else 0


def along_ray(expr: sympy.Expr, entry: np.ndarray, d: np.ndarray, s: np.ndarray) -> np.ndarray:
    """S at entry + s d for s of shape (rays, k)."""
    points = entry[:, None, :] + s[..., None] * d[:, None, :]
    return evaluate_on(expr, point_env(points), s.shape)


def point_env(points: np.ndarray) -> dict[sympy.Symbol, np.ndarray]:
    """The x, y, z of `points` (..., 3) as `evaluate` takes them."""
    return {X: points[..., 0], Y: points[..., 1], Z: points[..., 2]}


def evaluate_on(expr: sympy.Expr, env: dict[sympy.Symbol, np.ndarray], shape) -> np.ndarray:
    """`evaluate`, broadcast to `shape` (a constant expression evaluates to a scalar)."""
    return np.broadcast_to(evaluate(expr, env), shape)


def derivative_along(
    gradient: Sequence[sympy.Expr], entry: np.ndarray, d: np.ndarray, s: np.ndarray
) -> np.ndarray:
    """F'(s) = grad S . D at entry + s d for s of shape (rays,)."""
    env = point_env(entry + s[:, None] * d)
    return sum(evaluate_on(g, env, s.shape) * d[:, axis] for axis, g in enumerate(gradient))
