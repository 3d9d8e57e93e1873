"""Hand-written baselines: the bar implc's generated marchers must meet.

`templates/baseline/<surface>.frag.j2` is a GLSL 330 program written by hand for one
surface (not generated), doing the same work as implc's program for a method: the same
step rule and root test, the same refinement after the march loop, the same camera, clip
sphere, shading and outputs (colour + aux). Its only template fields are the base step
and the shading constants, so that both run the same scene. `implc bench --baseline` (or
`make bench-baseline`) times them in turns with the generated programs and reports
generated / baseline speed.
"""

from __future__ import annotations

from .emit import print_shading, render_template
from .methods import Constants
from .surface import Surface
from .targets import get_target

# (surface key, method) -> whether its hand-written test is second order (Eq. 4, F''
# in the interval) rather than first order (Eq. 3): the one switch of the template.
BASELINES: dict[tuple[str, str], bool] = {("cross-cap", "taylor"): False,
                                          ("cross-cap", "hessian"): True,
                                          ("barth-decic", "exact"): False}


def has_baseline(key: str, method: str) -> bool:
    return (key, method) in BASELINES


def baseline_program(key: str, method: str, constants: Constants, surface: Surface) -> str:
    """The hand-written program's text with this step and the surface's shading."""
    if not has_baseline(key, method):
        raise KeyError(f"no hand-written baseline for {key} with {method}")
    printer = get_target("glsl").printer()
    return render_template(f"baseline/{key}.frag.j2", method=method,
                           second_order=BASELINES[key, method],
                           step=printer.float_literal(constants.step),
                           shading=print_shading(surface.view, printer))


def open_baseline_runner(key: str, method: str, constants: Constants, surface: Surface,
                         width: int, height: int):
    from .render.gl import GlRunner

    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    return GlRunner(baseline_program(key, method, constants, surface), vertex, surface.view,
                    width, height)
