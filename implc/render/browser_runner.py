"""Backends `webgl2` and `webgpu`: implc's programs in headless Chromium, where the web
runs them: the GLSL ES 3.00 program in WebGL2 (ANGLE on SwiftShader) and the WGSL program
in WebGPU (Dawn and Tint on SwiftShader's Vulkan), driven by Playwright through the page
templates/browser/render.html.j2, which hands the colour and aux targets back as float32.

They are float32 renderers of their own (issue 48 counts exact's wrong pixels on each):
SwiftShader's arithmetic is not llvmpipe's or lavapipe's. A frame's time includes the
page's round trip and the base64 copy, so it is no GPU figure.
"""

from __future__ import annotations

import base64
import itertools
from collections.abc import Mapping, Sequence

import numpy as np

from ..chromium import evaluate, page
from ..emit import CompiledShader, ParamUniform, render_template
from ..scene import View
from .gl import camera_uniforms
from .result import RenderResult, TimedRunner
from .wgpu_runner import uniform_block

_ids = itertools.count()


def _page():
    return page("render", render_template("browser/render.html.j2"))


def _call(script: str, *args):
    return evaluate(_page(), script, *args)


def _decode(text: str, width: int, height: int) -> np.ndarray:
    return np.frombuffer(base64.b64decode(text), np.float32).reshape(height, width, 4)


class BrowserRunner(TimedRunner):
    """One program's frame objects in the render page, under an id."""

    def __init__(self, width: int, height: int):
        self.id, self.width, self.height = next(_ids), width, height
        self.driver = ""

    def draw(self) -> None:
        _call("([id]) => implcRender.draw(id)", self.id)

    def read(self) -> RenderResult:
        out = _call("([id]) => implcRender.read(id)", self.id)
        return RenderResult.from_buffers(_decode(out["color"], self.width, self.height),
                                         _decode(out["aux"], self.width, self.height))

    def release(self) -> None:
        _call("([id]) => implcRender.release(id)", self.id)


class WebGL2Runner(BrowserRunner):
    def __init__(self, fragment: str, view: View, width: int, height: int,
                 params: Sequence[ParamUniform] = ()):
        super().__init__(width, height)
        vertex = render_template("glsl/fullscreen.vert.j2", version="300 es")
        self.params = {p.name: p.uniform for p in params}
        uniforms = {**camera_uniforms(view, width, height),
                    **{p.uniform: p.value for p in params}}
        self.driver = _call("([id, v, f, w, h, u]) => implcRender.webgl2(id, v, f, w, h, u)",
                            self.id, vertex, fragment, width, height,
                            {k: [float(x) for x in np.atleast_1d(v)]
                             for k, v in uniforms.items()})

    def set_params(self, values: Mapping[str, float]) -> None:
        _call("([id, u]) => implcRender.set(id, u)", self.id,
              {self.params[name]: [float(v)] for name, v in values.items()})


class WebGPURunner(BrowserRunner):
    def __init__(self, code: str, view: View, width: int, height: int,
                 params: Sequence[ParamUniform] = ()):
        super().__init__(width, height)
        self.view, self.params = view, tuple(params)
        self.values = {p.name: p.value for p in params}
        self.driver = _call("([id, c, w, h, u]) => implcRender.webgpu(id, c, w, h, u)",
                            self.id, code, width, height, self._block(None))

    def _block(self, values: Mapping[str, float] | None) -> list[float]:
        """The uniform block's floats (render/wgpu_runner.py's layout)."""
        data = uniform_block(self.view, self.width, self.height, self.params, values)
        return np.frombuffer(data, np.float32).tolist()

    def set_params(self, values: Mapping[str, float]) -> None:
        self.values.update(values)
        _call("([id, u]) => implcRender.set(id, u)", self.id, self._block(self.values))


def open_webgl2_runner(shader: CompiledShader, view: View, width: int,
                       height: int) -> WebGL2Runner:
    """Runner factory of backend `webgl2`: the es300 program over a full-screen triangle
    into two RGBA32F targets."""
    return WebGL2Runner(shader.text, view, width, height, shader.uniforms)


def open_webgpu_runner(shader: CompiledShader, view: View, width: int,
                       height: int) -> WebGPURunner:
    """Runner factory of backend `webgpu`: the WGSL compute program as wgpu-py runs it."""
    return WebGPURunner(shader.text, view, width, height, shader.uniforms)


def chromium_renderer() -> str:
    """Opens the render page, or raises ToolError saying why not (the backends' probe)."""
    _page()
    return "chromium"
