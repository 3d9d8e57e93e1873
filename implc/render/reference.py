"""The exact CPU reference renderer: the shared camera and shading, roots found in float64.

Every ray is clipped to the bounding sphere and restarted at its entry point O' (as the
shaders do), so the surface along it is F(s) = S(O' + sD), s = t - t_near in [0, L],
L = t_far - t_near, and the hit is the first zero of F in that interval.

Polynomial surfaces (total degree <= MAX_RAY_POLYNOMIAL_DEGREE): F is a polynomial in s. All
its real roots in [0, L], tangential (double) roots included, come from the eigenvalues of
its companion matrix and are polished by Newton (`first_root_in_interval`); the first is
the hit, exact up to float64 rounding. This is the ground truth the marchers are measured
against.

Other surfaces: a certified interval search (`certified_first_roots`). The chord is cut
into dyadic nodes (halves, quarters, ..., down to leaves of 2^-DEPTH of it), and a node is
dropped only when it provably holds no zero of F: F's enclosure over it (the `interval`
method's own program, implc/interval.py, evaluated in float64 with the double widening)
excludes 0, or the mean value form F(mid) + F'(node) [-w/2, w/2] does (F' = grad S . D,
enclosed by the same program), or F' excludes 0 (F is monotonic) and F has one sign at
both ends. A monotonic node with a sign change holds exactly one root, and a leaf with a
sign change holds the first root to within its width: both are bisected to
BISECTION_WIDTH. The first root (or exact zero of F) along the ray is the hit.
Guarantee: no sign change of F is missed, whatever its roots' spacing, up to the float64
rounding of S's point values (the enclosures are widened for their own rounding); only
two roots inside one leaf (~1e-12 of the chord) show no sign change. A jump through a
pole, of tan or 1/u, is no root: a leaf where F's enclosure is marked unbounded is
dropped, as in the `interval` method's leaf test, and the search goes on behind it. Tangential
roots, where F touches 0 without a sign change, are found within TOUCH_TOL: a node (a
dropped one where F' may vanish, or a leaf) whose |F(mid)| / |grad S| <= TOUCH_TOL L is
a touching root, so a ray that passes that close to the surface is a hit, as with the
polynomial reference. Where S is undefined (NaN: outside sqrt's or log's domain) there is
no surface. The derivative tests are used only where F is continuous on the node: the
arguments of log, fractional powers, asin, acos, tan, 1/u and sign are checked inside
their domain on it, by the same enclosures.
Surfaces with a function that has no interval rule (atan2: range_program raises
InputError) fall back to the dense search (`dense_first_roots`): F sampled at `samples`
points, the first sign change bisected (a pole when |F| grew under the bisection: then
the next one), the dips of |F| between samples checked for
tangential hits. That one is NOT exact: two roots closer than the sample spacing with no
dip between samples can be missed.

The searches are one module each, beside this one: `reference_polynomial`,
`reference_certified` and `reference_dense`, with what they share in `reference_eval`;
this module assembles the picture from their hits.
"""

from __future__ import annotations

import time

import numpy as np
import sympy

from ..errors import InputError
from ..scene import View, clip_sphere, pixel_rays, shade, shading_for
from ..symbols import DIRECTION, POINT
from .reference_certified import certified_first_roots
from .reference_dense import DENSE_SAMPLES, dense_first_roots
from .reference_eval import evaluate_on, point_env
from .reference_polynomial import ORIGIN, first_root_in_interval, first_roots, ray_polynomial
from .result import RenderResult

# what callers import from here (the searches themselves live in the modules above)
__all__ = [
    "DIRECTION",
    "ORIGIN",
    "certified_first_roots",
    "dense_first_roots",
    "first_root_in_interval",
    "first_roots",
    "ray_polynomial",
    "render_reference",
]


def render_reference(
    expr: sympy.Expr, view: View, width: int, height: int, *, samples: int = DENSE_SAMPLES
) -> RenderResult:
    """Render S = 0 with the shared camera and shading; hits are exact float64 roots for
    polynomial S and from the certified interval search otherwise (the inexact dense
    search for surfaces with a function that has no interval rule).

    `steps` reports, for every pixel that entered the clip sphere, the nodes the certified
    search visited (its enclosures evaluated), 0 for polynomial surfaces, and `samples`
    for the dense search (surfaces without an interval rule), the only use of `samples`.
    """
    start = time.perf_counter()
    unbound = expr.free_symbols - set(POINT)
    if unbound:
        names = ", ".join(sorted(str(s) for s in unbound))
        raise ValueError(f"the reference needs values for {names}")
    origins, dirs = pixel_rays(view, width, height)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    t_near, t_far, inside = clip_sphere(origins, dirs, view.clip_center, view.clip_radius)
    rows = np.flatnonzero(inside)
    gradient = [sympy.diff(expr, v) for v in POINT]

    coefficients = ray_polynomial(expr)
    args = (origins[rows], dirs[rows], t_near[rows], t_far[rows])
    if coefficients is not None:
        found, t_rows = first_roots(*args, coefficients)
        steps_inside = 0
    else:
        try:
            found, t_rows, steps_inside = certified_first_roots(expr, *args, gradient=gradient)
        except InputError:  # a function without an interval rule (atan2)
            found, t_rows = dense_first_roots(expr, *args, samples=samples, gradient=gradient)
            steps_inside = samples

    n = origins.shape[0]
    hit = np.zeros(n, dtype=bool)
    hit[rows] = found
    t = np.zeros(n)
    t[rows[found]] = t_rows[found]
    steps = np.zeros(n)
    steps[rows] = steps_inside

    env = point_env(origins[hit] + t[hit, None] * dirs[hit])
    grad = np.zeros((n, 3))
    grad[hit] = np.stack([evaluate_on(g, env, hit.sum()) for g in gradient], axis=-1)
    residual = np.zeros(n)
    residual[hit] = np.abs(evaluate_on(expr, env, hit.sum()))

    shape = (height, width)
    color = shade(grad.reshape(*shape, 3), dirs.reshape(*shape, 3), hit.reshape(shape), view,
                  shading_for(view))
    return RenderResult(
        color=color.astype(np.float32),
        hit=hit.reshape(shape),
        t=t.reshape(shape).astype(np.float32),
        steps=steps.reshape(shape).astype(np.float32),
        residual=residual.reshape(shape).astype(np.float32),
        timing={"total": time.perf_counter() - start},
    )
