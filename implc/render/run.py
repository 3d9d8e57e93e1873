"""Render a surface with a backend: the one entry point for the API's `render` and for
`bench`. A backend is a runner factory on a compiled program: `open_runner(...)` returns an
object with `frame() -> RenderResult` (render once, wait for completion, read back),
`release()` and `shader`, the record of what it runs.

The backends are the targets' (implc/targets.py), plus the exact CPU reference, which
belongs to no target and runs no method.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from ..errors import InputError
from ..targets import TARGETS, Backend, Target, resolve

if TYPE_CHECKING:  # the command line reads BACKENDS without sympy or numpy
    from ..emit import CompiledShader
    from ..methods import Constants
    from ..scene import View
    from ..surface import Surface
    from .result import RenderResult


class Runner(Protocol):
    shader: CompiledShader | None  # the program it runs (None: the CPU reference)

    def warm_up(self) -> float | None: ...  # seconds of the first use (None: no driver)

    def frame(self) -> RenderResult: ...

    def release(self) -> None: ...


# A runner opened with params="uniform" (gl, wgpu, cl, cl-double) also has
#   set_params(values: Mapping[str, float]) -> None
# which moves the parameters for the next frames without compiling anything again.


class _ReferenceRunner:
    """The exact CPU reference; it has no method, so `method` and `constants` are ignored."""

    shader = None

    def __init__(self, surface: Surface, width: int, height: int):
        self.surface, self.width, self.height = surface, width, height

    def warm_up(self) -> None:
        """Nothing is compiled: the reference is numpy on the CPU."""
        return None

    def frame(self) -> RenderResult:
        from .reference import render_reference

        start = time.perf_counter()
        result = render_reference(self.surface.expr, self.surface.view, self.width, self.height)
        result.timing["frame"] = time.perf_counter() - start
        return result

    def release(self) -> None:
        pass


REFERENCE = "reference"
REFERENCE_ABOUT = "the exact CPU reference, float64 (no method)"
# backend name -> Backend, for every backend of every target (the reference aside)
BACKENDS: dict[str, Backend] = {
    name: backend for target in TARGETS.values() for name, backend in target.backends.items()
}


def open_runner(
    surface: Surface, backend: str, method: str, constants: Constants, width: int, height: int,
    params: str = "constant",
) -> Runner:
    """Compile the backend's program (`compile_backend_shader`) and open its runner;
    `params="uniform"`: the program reads the parameters from uniforms, set from the
    surface's values (the CPU reference always uses the values as they are)."""
    if backend == REFERENCE:
        return _ReferenceRunner(surface, width, height)
    shader = compile_backend_shader(surface, backend, method, constants, params)
    return open_shader_runner(shader, backend, surface.view, width, height)


def compile_backend_shader(surface: Surface, backend: str, method: str, constants: Constants,
                           params: str = "constant") -> CompiledShader:
    """The program `backend` runs: its flavour (the target's default unless the backend
    names one) at its precision."""
    from ..emit import compile_shader

    target = backend_target(backend)
    flavor = BACKENDS[backend].flavor or target.default_flavor
    return compile_shader(surface, target.name, method, constants, flavor,
                          precision=BACKENDS[backend].precision, params=params)


def open_shader_runner(shader: CompiledShader, backend: str, view: View, width: int,
                       height: int) -> Runner:
    """The runner of `backend` on a compiled program (`compile_backend_shader`'s)."""
    backend_target(backend)
    runner = resolve(BACKENDS[backend].runner)(shader, view, width, height)
    runner.shader = shader  # what it runs, for the sidecar and the API's record
    return runner


def backend_target(backend: str) -> Target:
    """The target whose program `backend` runs."""
    for target in TARGETS.values():
        if backend in target.backends:
            return target
    choices = ", ".join([*BACKENDS, REFERENCE])
    raise ValueError(f"unknown backend '{backend}'; choose from {choices}")


def backend_for(backend: str, precision: str | None) -> str:
    """The backend with `backend`'s runner that runs its program at `precision` (`-b cl
    --precision double` is `cl-double`; `webgl2` has no double); `precision` None keeps
    `backend`."""
    if precision is None or (backend == REFERENCE and precision == "float"):
        return backend
    for name in _siblings(backend):
        if BACKENDS[name].precision == precision:
            return name
    able = [name for name in BACKENDS
            if any(BACKENDS[s].precision == precision for s in _siblings(name))]
    raise InputError(f"--precision {precision} renders with -b {' or '.join(able)} only")


def _siblings(backend: str) -> list[str]:
    """The backends that share `backend`'s runner (one per precision), itself first."""
    if backend not in BACKENDS:
        return []
    runner = BACKENDS[backend].runner
    return [backend] + [n for n, b in BACKENDS.items() if b.runner == runner and n != backend]


def render(
    surface: Surface, backend: str, method: str, constants: Constants, width: int, height: int,
    params: str = "constant",
) -> RenderResult:
    """Image and aux buffers of one frame (`run_frame` on a runner `open_runner` opens)."""
    start = time.perf_counter()
    runner = open_runner(surface, backend, method, constants, width, height, params)
    return run_frame(runner, time.perf_counter() - start)


def run_frame(runner: Runner, setup: float) -> RenderResult:
    """One frame of `runner`, then release it. `timing` holds, in seconds, `setup`
    (implc's emit and the driver's program build, measured by the caller), `compile` (the
    program's first use, where a driver may compile it: see `TimedRunner.warm_up`; not for
    the reference) and `frame` (one frame after that first use: what every later frame
    costs)."""
    try:
        first_use = runner.warm_up()
        result = runner.frame()
    finally:
        runner.release()
    result.timing["setup"] = setup
    if first_use is not None:
        result.timing["compile"] = first_use
    return result


def metadata(
    surface: Surface, backend: str, shader: CompiledShader | None, result: RenderResult,
) -> dict:
    """The JSON sidecar: enough to recompute every pixel's ray and to reproduce the run
    (`evaluation` is the form the shader used, not `auto`; `shader` None: the reference)."""
    if shader is None:
        method_json: dict = {"name": REFERENCE}
    else:
        method_json = {"name": shader.method, **shader.constants.as_dict(),
                       "evaluation": shader.form}
    return {
        "surface": {
            "name": surface.name,
            "equation": surface.equation,
            "params": surface.params_json(),
        },
        "params": "constant" if shader is None else shader.params,
        "camera": surface.view.camera_json(result.width, result.height),
        "clip": surface.view.clip_json(),
        "method": method_json,
        "backend": backend,
        "timing": {k: round(v, 6) for k, v in sorted(result.timing.items())},
        "pixel_rule": "pixel (i, j), column i from the left, row j from the top: "
                      "ndc = (2(i+0.5)/W - 1, 1 - 2(j+0.5)/H), m = min(W, H); "
                      "dir = normalize(forward + ndc.x*tan(fov_y/2)*W/m*right + "
                      "ndc.y*tan(fov_y/2)*H/m*up) (fov_y spans the shorter side); "
                      "right = normalize(forward x up), up = right x forward; "
                      "t (EXR Z) is the distance from eye along dir",
    }


def render_surface(
    surface: Surface, backend: str, method: str, constants: Constants, width: int, height: int,
    output: Path, params: str = "constant",
) -> tuple[list[Path], RenderResult]:
    """Render and write `output` and its JSON sidecar; the paths written and the frame."""
    from .image_io import write_render

    start = time.perf_counter()
    runner = open_runner(surface, backend, method, constants, width, height, params)
    shader = runner.shader
    result = run_frame(runner, time.perf_counter() - start)
    paths = write_render(result, output, metadata(surface, backend, shader, result))
    return paths, result
