"""What a user should know about a rendered picture, said rather than left to be seen.

Nothing hit (and where the surface is, if it is anywhere), rays out of steps, or a
surface cut by its clip sphere: hits on the sphere in the aux buffer, whoever chose it
(automatic framing samples S on a grid and can miss a thin part), or, for a sphere the
file or the caller gave, S taking both signs on it. The lines are
the command line's stderr lines and the API's `Rendering.warnings`.
"""

from __future__ import annotations

from .extent import SEARCHED, crosses_sphere, locate_surface
from .render.result import RenderResult
from .scene import View, pixel_rays, point_text
from .surface import Surface

CLIP_BAND = 1e-3  # relative: a hit this near the clip sphere's radius lies on it


def picture_warnings(surface: Surface, result: RenderResult, given_radius: bool,
                     max_steps: int | None = None) -> list[str]:
    """The warnings (and notes) about `result`, a picture of `surface` in its view;
    `given_radius`: the caller set the clip sphere's radius; `max_steps`: a marcher's step
    cap (None: the method takes no steps)."""
    capped = _capped(result, max_steps)
    if capped:  # the rays ran out of steps: where the surface is may be right
        return [capped]
    view = surface.view
    sphere = (f"the clip sphere (center {point_text(view.clip_center)}, radius "
              f"{view.clip_radius:g})")
    if not result.hit.any():
        extent = locate_surface(surface.expr)
        if extent is None:
            return [f"implc: warning: no pixel hits the surface, and S changes sign nowhere "
                    f"in |x|,|y|,|z| <= {SEARCHED:g}: the equation may have no real "
                    "points (S > 0 or S < 0 everywhere), or a part thinner than the search "
                    "grid; --radius, --center to look elsewhere"]
        where = f"--radius {extent.radius:g}"
        if extent.center != tuple(view.clip_center):
            where += f" --center {','.join(f'{c:g}' for c in extent.center)}"
        found = (f"is found within radius {extent.radius:g} of {point_text(extent.center)}"
                 if extent.bounded else f"passes near {point_text(extent.center)} (unbounded?)")
        return [f"implc: warning: no pixel hits the surface inside {sphere}; the surface "
                f"{found}: try {where}"]
    given = "radius" in view.given or given_radius
    cut = clipped_pixels(surface.view, result)
    if not cut and not (given and crosses_sphere(surface.expr, view.clip_center,
                                                 view.clip_radius)):
        return []
    extent = locate_surface(surface.expr, view.clip_center if given else None)
    if extent is not None and not extent.bounded:
        if not given:  # the framing's line said so
            return []
        return [f"implc: note: the surface reaches {sphere} and seems unbounded (it "
                "reaches the edge of every region the search sampled): the picture shows "
                "the part inside the sphere; --radius to show more"]
    where = f" on {cut:,} pixel{'' if cut == 1 else 's'}" if cut else ""
    if extent is not None and extent.radius > view.clip_radius * 1.01:
        hint = f"--radius {extent.radius:g} holds all of it"
    else:  # the sampling's sphere is this one: what pierces it is thinner than its grid
        hint = ("a part thinner than the sampling grid reaches farther, or the surface is "
                f"unbounded: try --radius {2 * view.clip_radius:g}")
    return [f"implc: warning: the surface reaches {sphere}{where}: the picture is cut "
            f"there; {hint}"]


def clipped_pixels(view: View, result: RenderResult) -> int:
    """Pixels whose hit lies on the clip sphere (within CLIP_BAND of its radius): there
    the sphere, not the surface, ends the picture (the aux buffer has each hit's t)."""
    import numpy as np

    origins, dirs = pixel_rays(view, result.width, result.height)
    points = origins + result.t[..., None].astype(np.float64) * dirs
    distance = np.linalg.norm(points - np.asarray(view.clip_center), axis=-1)
    return int((result.hit & (distance >= view.clip_radius * (1.0 - CLIP_BAND))).sum())


def _capped(result: RenderResult, max_steps: int | None) -> str | None:
    """The warning where rays stopped at the step cap without a hit: their pixels show
    background whether or not the surface is behind them (the aux buffer has the steps)."""
    if max_steps is None:
        return None
    stopped = int(((result.steps >= max_steps) & ~result.hit).sum())
    if stopped == 0:
        return None
    share = 100.0 * stopped / result.hit.size
    return (f"implc: warning: {stopped:,} rays ({share:.1f} % of the pixels) stopped at "
            f"--max-steps {max_steps} without finding the surface, so the picture may miss "
            "it there: raise --step (the base step) or --max-steps")
