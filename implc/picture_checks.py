"""What a user should know about a rendered picture, said rather than left to be seen.

Nothing hit (and where the surface is, if it is anywhere), or a surface cut by a clip
sphere the file or the caller gave (a framed sphere says so when it frames). The lines are
the command line's stderr lines and the API's `Rendering.warnings`.
"""

from __future__ import annotations

from .extent import SEARCHED, crosses_sphere, locate_surface
from .render.result import RenderResult
from .scene import point_text
from .surface import Surface


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
    if not ("radius" in view.given or given_radius):
        return []
    if not crosses_sphere(surface.expr, view.clip_center, view.clip_radius):
        return []
    extent = locate_surface(surface.expr, view.clip_center)
    if extent is not None and not extent.bounded:
        return [f"implc: note: the surface reaches {sphere}, and past |x|,|y|,|z| <= "
                f"{SEARCHED:g} (unbounded?): the picture shows the part inside the sphere; "
                "--radius to show more"]
    hint = f"--radius {extent.radius:g} holds all of it" if extent else "--radius to widen it"
    return [f"implc: warning: the surface reaches {sphere}: the picture is clipped there; "
            f"{hint}"]


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
