"""`implc view`: one self-contained HTML page that shows a surface live.

This module only assembles: it emits the `es300` GLSL program and the WGSL program
(parameters as uniforms, so the page's sliders move them without recompiling), the
full-screen vertex shader and the WebGPU blit shader from templates/, and hands them with
the camera, the parameters and the method to templates/view/viewer.html.j2, which holds
the page and its script. The page loads nothing: no network, no external script, style
or font (tests/test_view.py checks the text).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .emit import emit, param_range, param_uniforms, render_template
from .marcher import default_method
from .methods import Constants, get_method
from .surface import Surface

SLIDER_TICKS = 1000  # a slider's steps over its range (emit.param_range)


@dataclass(frozen=True)
class Slider:
    name: str  # the parameter's name in the equation
    uniform: str  # its GLSL uniform (and WGSL field) name
    wgsl_offset: int  # byte offset of its field in the WGSL program's Uniforms
    value: float
    low: float
    high: float

    @property
    def step(self) -> float:
        return (self.high - self.low) / SLIDER_TICKS


def sliders(surface: Surface) -> list[Slider]:
    """One slider per uniform parameter, centred on its value (sorted by name, like the
    uniforms; a parameter only inside constant exponents has none, see
    `Surface.uniform_params`)."""
    result = []
    wgsl = {u.name: u for u in param_uniforms(surface, "wgsl")}
    for u in param_uniforms(surface, "glsl"):
        result.append(Slider(u.name, u.uniform, wgsl[u.name].offset, u.value,
                             *param_range(u.value)))
    return result


def viewer_data(surface: Surface, method: str | None = None,
                constants: Constants | None = None, webgpu: bool = True) -> dict[str, Any]:
    """What viewer.js draws (a JSON-able dict): the surface's name and equation, the method,
    the view, the sliders and the shader texts; the page embeds it, the notebook widget
    sends it as a traitlet. The method defaults as for `implc compile`
    (marcher.default_method)."""
    method = method or default_method(surface.expr)
    meth = get_method(method)
    constants = constants or meth.defaults
    glsl = emit(surface, "glsl", method, constants, flavor="es300", params="uniform")
    wgsl = emit(surface, "wgsl", method, constants, params="uniform") if webgpu else ""
    view = surface.view
    return {
        "surface": {"name": surface.name, "equation": surface.symbolic_equation,
                    "origin": surface.origin},
        "method": {"name": meth.name, "summary": meth.summary,
                   "step": None if meth.solves or meth.bounds else constants.step,
                   "unmarched": meth.unmarched,
                   "taylor2": constants.taylor2, "uses_taylor2": meth.reads_taylor2},
        "view": {"eye": list(view.eye), "target": list(view.target), "up": list(view.up),
                 "fov_y": view.fov_y_deg, "clip_center": list(view.clip_center),
                 "clip_radius": view.clip_radius},
        "params": [
            {"name": s.name, "uniform": s.uniform, "wgsl_index": s.wgsl_offset // 4,
             "value": s.value, "low": s.low, "high": s.high, "step": s.step}
            for s in sliders(surface)
        ],
        "glsl": {
            "vertex": render_template("glsl/fullscreen.vert.j2", version="300 es"),
            "fragment": glsl,
        },
        "wgsl": {
            "program": wgsl,
            "blit": render_template("view/blit.wgsl.j2") if webgpu else "",
        },
    }


def viewer_page(surface: Surface, method: str | None = None,
                constants: Constants | None = None, webgpu: bool = True) -> str:
    """The HTML text of the viewer for `surface` (deterministic, byte for byte)."""
    data = viewer_data(surface, method, constants, webgpu)
    return render_template("view/viewer.html.j2", data=data, title=surface.name)
