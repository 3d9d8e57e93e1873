"""How far float32 rounding moves a polynomial surface: the warning `compile`, `render`
and `view` give (and the API's records carry), and the measures `implc show` prints.

Two measures (implc/conditioning.py): S at sampled points of the surface, which speaks for
every method, and exact's ray coefficients on the view's pixel rays, which follows exact's
own share of wrong pixels. Both need numpy; `float32_warning` says when it is missing
instead of failing a compile that needs only sympy and jinja2.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy

from .conditioning import (
    RAY_TO_PIXELS,
    RAY_WARN_SHARE,
    RECENTER_RIGHT_UP_TO,
    RECENTER_WARN_SHARE,
    WARN_SHARE,
    Conditioning,
    float32_conditioning,
    ray_conditioning,
)
from .derive import polynomial_degree
from .options import EXACT_MAX_DEGREE, T_TOL
from .scaling import scale_exponent, scaled
from .scene import View
from .solver import ROBUST_NEWTON_BELOW, exact_coefficients, re_expands
from .surface import Surface
from .symbols import POINT


@dataclass(frozen=True)
class Float32Report:
    """Both measures of a polynomial surface, each None where it does not apply."""

    point: Conditioning | None  # S at sampled points of the surface: every method
    ray: Conditioning | None  # exact's ray coefficients on the view's pixel rays
    re_expands: bool = False  # exact's walk re-expands F about a node in doubt

    @property
    def ray_pixels(self) -> str:
        """What the ray measure's share says of exact's wrong pixels, where measured."""
        if self.re_expands:
            return (f"its walk re-expands F where they leave a node in doubt, and was right "
                    f"up to {100 * RECENTER_RIGHT_UP_TO:.0f} % of the rays where measured; "
                    "beyond that, expect wrong pixels")
        return f"its walk reads them: expect wrong pixels, {RAY_TO_PIXELS} of that share"

    @property
    def point_warns(self) -> bool:
        return self.point is not None and self.point.far >= WARN_SHARE

    @property
    def ray_warns(self) -> bool:
        share = RECENTER_WARN_SHARE if self.re_expands else RAY_WARN_SHARE
        return self.ray is not None and self.ray.far >= share

    def warning(self, method: str) -> str | None:
        """What float32 does to `method`'s picture where a measure says it is too far
        (None where none does): for exact its own coefficients' share, which follows its
        share of wrong pixels, else S's: the line `compile`, `render` and `view` print
        (`implc show` prints both measures in full)."""
        if method == "exact" and self.ray_warns:
            return (f"float32 cannot hold this surface: rounding exact's ray coefficients "
                    f"moves the first root by more than {T_TOL:g} on "
                    f"{100 * self.ray.far:.2f} % of the view's pixel rays (exact: "
                    f"{self.ray_pixels})")
        if self.point_warns:
            return (f"float32 cannot hold this surface: a rounding of S moves it by more "
                    f"than {T_TOL:g} at {100 * self.point.far:.1f} % of its sampled points "
                    "(expect wrong pixels from every method)")
        return None


def float32_report(expr: sympy.Expr, view: View, degree: int,
                   gradient: tuple[sympy.Expr, ...] | None = None,
                   point: bool = True, ray: bool = True) -> Float32Report:
    """The ray coefficients' measure where exact's Newton reads F from them (degree
    ROBUST_NEWTON_BELOW to EXACT_MAX_DEGREE) unless `ray` is False (what a warning for
    another method does not need), and S's at any degree unless `point` is False
    (0.04-0.3 s: what a warning for exact alone does not need). Both measure S as the
    shader has it: brought near 1 by a power of two where its constants are extreme."""
    scale = scale_exponent(expr)  # measured as the shader computes it (implc/scaling.py)
    expr = scaled(expr, scale)
    if gradient is not None:
        gradient = tuple(scaled(g, scale) for g in gradient)
    rays = (ray_conditioning(exact_coefficients(expr, "float"), view)
            if ray and ROBUST_NEWTON_BELOW <= degree <= EXACT_MAX_DEGREE else None)
    recenters = rays is not None and re_expands(expr, "float")
    if not point:
        return Float32Report(None, rays, recenters)
    if gradient is None:
        gradient = tuple(sympy.diff(expr, v) for v in POINT)
    return Float32Report(float32_conditioning(expr, gradient), rays, recenters)


def float32_warning(surface: Surface, method: str) -> str | None:
    """The warning where float32 cannot hold a polynomial surface for `method` (None where
    it can, or the surface is not a polynomial). exact's warning from degree
    ROBUST_NEWTON_BELOW is its own coefficients' (S's measure at sampled points costs
    0.04-0.3 s more and speaks for every method)."""
    degree = polynomial_degree(surface.expr)
    if degree is None:
        return None
    report = float32_report(surface.expr, surface.view, degree,
                            point=method != "exact" or degree < ROBUST_NEWTON_BELOW,
                            ray=method == "exact")  # another method reads no coefficients
    return report.warning(method)
