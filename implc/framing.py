"""THE framing of a surface: the one view every command and the API give it.

A surface file's [view] keys, then the options a caller gives (the command line's
--radius, --eye, ...; the API's `with_view`), then what neither sets, chosen by
`scene.apply_view`: the clip sphere around where S changes sign (implc/extent.py) and the
eye where that sphere fills the picture. `render`, `compile`, `view`, `gallery`, `bench`
and a notebook all call `frame`, so one surface looks the same from each of them.
"""

from __future__ import annotations

import dataclasses

from .derive import check_derived_size
from .errors import InputError, OptionError
from .scene import (
    Extent,
    Framing,
    Vec3,
    ViewOptions,
    apply_view,
    frame_problem,
    view_problems,
)
from .surface import Surface

# [view] key -> its command-line option (`target` is --look-at: -t/--target is the
# shader language), for messages about options that show nothing
VIEW_FLAGS = {"radius": "--radius", "center": "--center", "eye": "--eye",
              "target": "--look-at", "up": "--up", "fov": "--fov"}


def frame(surface: Surface, options: ViewOptions | None = None,
          ) -> tuple[Surface, Framing | None]:
    """`surface` with its view completed, and what framing chose (None: nothing; its
    `message()` is the line the command line prints). The same for every picture size
    (the fov spans the shorter side). A view that shows nothing raises: OptionError when
    options made it so, else InputError pointing at the surface's [view]."""
    options = options or ViewOptions()
    # refuse a too complex surface before sampling it
    check_derived_size(surface.expr, surface.limits.max_derived)
    searched = 0.0
    if "radius" not in surface.view.given | options.given():  # a sphere is to be found
        from .extent import SEARCHED as searched
    view, framing = apply_view(surface.view, options, lambda center: _locate(surface, center),
                               searched)
    problems = view_problems(view)
    if problems:
        flags = " ".join(VIEW_FLAGS[key] for key in sorted(options.given()))
        if flags:
            raise OptionError(f"{flags}: the view shows nothing: {problems[0][1]}")
        raise InputError(f"{surface.origin}: [view] {problems[0][1]}")
    return dataclasses.replace(surface, view=view), framing


def _locate(surface: Surface, center: Vec3 | None) -> Extent | None:
    """Where S changes sign (numpy's sampling: loaded only when a view is to be found, so
    a surface file with its own view compiles with sympy and jinja2 alone)."""
    from .extent import locate_surface

    return locate_surface(surface.expr, center)


def check_frame(surface: Surface, width: int, height: int) -> None:
    """A view that would render a blank `width` x `height` frame is an error, not a
    picture (the horizontal field of view depends on the size)."""
    problem = frame_problem(surface.view, width, height)
    if problem:
        raise InputError(f"{surface.origin}: [view] {problem} ({width}x{height})")
