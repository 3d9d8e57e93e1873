"""Render a surface with a backend and write the outputs: the one entry point for `render`
and `bench`. A backend is a runner factory: `open_runner(...)` returns an object with
`frame() -> RenderResult` (render once, wait for completion, read back) and `release()`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

from ..emit import emit, render_template
from ..methods import Constants
from ..surface import Surface
from .cl_runner import open_cl_double_runner, open_cl_runner
from .result import RenderResult
from .wgpu_runner import open_wgpu_runner


class Runner(Protocol):
    def frame(self) -> RenderResult: ...

    def release(self) -> None: ...


def _gl_runner(surface, method, constants, width, height) -> Runner:
    from .gl import GlRunner

    fragment = emit(surface, "glsl", method, constants, flavor="330")
    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    return GlRunner(fragment, vertex, surface.view, width, height)


class _ReferenceRunner:
    """The exact CPU reference; it has no method, so `method` and `constants` are ignored."""

    def __init__(self, surface: Surface, width: int, height: int):
        self.surface, self.width, self.height = surface, width, height

    def frame(self) -> RenderResult:
        from .reference import render_reference

        start = time.perf_counter()
        result = render_reference(self.surface.expr, self.surface.view, self.width, self.height)
        result.timing["frame"] = time.perf_counter() - start
        return result

    def release(self) -> None:
        pass


# backend name -> runner factory(surface, method, constants, width, height)
BACKENDS: dict[str, Callable[..., Runner]] = {
    "gl": _gl_runner,
    "cl": open_cl_runner,  # OpenCL C on PoCL, float; cl-double: the --precision double program
    "cl-double": open_cl_double_runner,
    "wgpu": open_wgpu_runner,  # WGSL compute shader on wgpu (Vulkan; lavapipe here)
    "reference": lambda surface, method, constants, w, h: _ReferenceRunner(surface, w, h),
}


def open_runner(
    surface: Surface, backend: str, method: str, constants: Constants, width: int, height: int
) -> Runner:
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend '{backend}'; choose from {', '.join(BACKENDS)}")
    return BACKENDS[backend](surface, method, constants, width, height)


def render(
    surface: Surface, backend: str, method: str, constants: Constants, width: int, height: int
) -> RenderResult:
    """Image and aux buffers of one frame; timing holds `setup` and `frame` seconds."""
    start = time.perf_counter()
    runner = open_runner(surface, backend, method, constants, width, height)
    setup = time.perf_counter() - start
    try:
        result = runner.frame()
    finally:
        runner.release()
    result.timing["setup"] = setup
    return result


def metadata(
    surface: Surface, backend: str, method: str, constants: Constants, result: RenderResult
) -> dict:
    """The JSON sidecar: enough to recompute every pixel's ray and to reproduce the run."""
    method_json = {"name": "reference"} if backend == "reference" else {
        "name": method, **constants.as_dict()}
    return {
        "surface": {
            "name": surface.name,
            "equation": surface.equation,
            "params": surface.params_json(),
        },
        "camera": surface.view.camera_json(result.width, result.height),
        "clip": surface.view.clip_json(),
        "method": method_json,
        "backend": backend,
        "timing": {k: round(v, 6) for k, v in sorted(result.timing.items())},
        "pixel_rule": "pixel (i, j), column i from the left, row j from the top: "
                      "ndc = (2(i+0.5)/W - 1, 1 - 2(j+0.5)/H); dir = normalize(forward + "
                      "ndc.x*tan(fov_y/2)*W/H*right + ndc.y*tan(fov_y/2)*up); "
                      "right = normalize(forward x up), up = right x forward; "
                      "t (EXR Z) is the distance from eye along dir",
    }


def render_surface(
    surface: Surface, backend: str, method: str, constants: Constants, width: int, height: int,
    output: Path,
) -> list[Path]:
    from .image_io import write_render

    result = render(surface, backend, method, constants, width, height)
    return write_render(result, output, metadata(surface, backend, method, constants, result))
