"""Run a generated GLSL program headlessly with moderngl (EGL; Mesa llvmpipe here).

The fragment shader writes two float targets: colour and aux (hit, t, steps, |S|).
Rows are flipped on readback so row 0 is the top of the image, like every runner.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from functools import lru_cache

import numpy as np

from ..emit import CompiledShader, ParamUniform, render_template
from ..errors import ToolError
from ..interrupts import signals_held
from ..scene import View
from .result import RenderResult, TimedRunner

TRIANGLES = 0x0004  # GL_TRIANGLES


@lru_cache(maxsize=1)
def context():
    """One standalone EGL context per process (creating one costs ~0.1 s)."""
    try:
        import moderngl
    except ImportError as err:  # pragma: no cover - depends on the install
        raise ToolError("moderngl is not installed (run `make setup`)") from err
    os.environ.setdefault("XDG_RUNTIME_DIR", "/tmp")
    try:
        with signals_held():
            return moderngl.create_standalone_context(backend="egl", require=330)
    except Exception as err:  # moderngl raises plain Exception subclasses
        raise ToolError(f"cannot create a headless OpenGL context (EGL): {err}") from err


def double_context():
    """The context of `context`, which must have GL_ARB_gpu_shader_fp64 (backend
    gl-double), or ToolError saying it has not."""
    ctx = context()
    if "GL_ARB_gpu_shader_fp64" not in ctx.extensions:
        raise ToolError(f"the OpenGL driver ({ctx.info.get('GL_RENDERER', 'unknown')}) has no "
                        "GL_ARB_gpu_shader_fp64: no double precision in GLSL (use -b gl)")
    return ctx


def renderer_name() -> str:
    return str(context().info.get("GL_RENDERER", "unknown"))


def camera_uniforms(view: View, width: int, height: int) -> dict[str, object]:
    """The GLSL programs' camera uniforms (docs/reference/drop-ins.md), by name."""
    return {
        "u_resolution": (float(width), float(height)),
        "u_eye": view.eye,
        "u_target": view.target,
        "u_up": view.up,
        "u_fov_y": view.fov_y_deg,
        "u_clip_center": view.clip_center,
        "u_clip_radius": view.clip_radius,
    }


class GlRunner(TimedRunner):
    """A compiled program and its framebuffer; `frame()` renders and reads back once."""

    def __init__(self, fragment: str, vertex: str, view: View, width: int, height: int,
                 params: Sequence[ParamUniform] = ()):
        ctx = context()
        try:
            with signals_held():
                self.program = ctx.program(vertex_shader=vertex, fragment_shader=fragment)
        except Exception as err:
            raise ToolError(f"the GL driver rejected the shader: {err}") from err
        self.width, self.height = width, height
        self.vao = ctx.vertex_array(self.program, [])
        self.color = ctx.texture((width, height), 4, dtype="f4")
        self.aux = ctx.texture((width, height), 4, dtype="f4")
        self.fbo = ctx.framebuffer(color_attachments=[self.color, self.aux])
        for name, value in camera_uniforms(view, width, height).items():
            if name in self.program:
                self.program[name].value = value
        self.params = {p.name: p.uniform for p in params}
        self.set_params({p.name: p.value for p in params})

    def set_params(self, values: Mapping[str, float]) -> None:
        """New parameter values for the next frames (a `--params uniform` program): set
        as uniforms, nothing is compiled again."""
        for name, value in values.items():
            uniform = self.params[name]
            if uniform in self.program:  # the driver drops a uniform the code never reads
                self.program[uniform].value = float(value)

    def draw(self) -> None:
        """Render one frame and wait for it (glFinish), without reading it back."""
        self.fbo.use()
        self.fbo.viewport = (0, 0, self.width, self.height)
        self.vao.render(mode=TRIANGLES, vertices=3)
        context().finish()

    def first_use(self) -> None:
        """One pixel drawn and waited for: llvmpipe compiles the fragment shader at its
        first draw whatever the viewport (measured: the full frame after it takes what
        every later frame takes); `draw` sets the whole viewport again."""
        with signals_held():
            self.fbo.use()
            self.fbo.viewport = (0, 0, 1, 1)
            self.vao.render(mode=TRIANGLES, vertices=3)
            context().finish()

    def read(self) -> RenderResult:
        shape = (self.height, self.width, 4)
        color = np.frombuffer(self.fbo.read(components=4, attachment=0, dtype="f4"), np.float32)
        aux = np.frombuffer(self.fbo.read(components=4, attachment=1, dtype="f4"), np.float32)
        color = color.reshape(shape)[::-1]
        aux = aux.reshape(shape)[::-1]
        return RenderResult.from_buffers(color, aux)

    def release(self) -> None:
        for obj in (self.fbo, self.color, self.aux, self.vao, self.program):
            obj.release()


def open_gl_runner(shader: CompiledShader, view: View, width: int, height: int) -> GlRunner:
    """Runner factory of backends `gl` and `gl-double`: the 330 core program over a
    full-screen triangle (a `--params uniform` shader's parameters are uniforms, moved by
    `set_params`)."""
    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    return GlRunner(shader.text, vertex, view, width, height, shader.uniforms)
