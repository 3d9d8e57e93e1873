"""Run a generated HLSL pixel shader headlessly: glslangValidator's HLSL front end compiles
it to SPIR-V (as `implc validate` does), spirv-cross translates the SPIR-V to GLSL 400,
and the GL runner draws it (moderngl, EGL; llvmpipe here).

Why this path and not wgpu taking the SPIR-V on lavapipe: the SPIR-V is the HLSL
compiler's own output either way, and this one reuses the GL runner whole (full-screen
triangle, two float render targets, timing), where wgpu needed a render pipeline of its
own; spirv-cross takes ~10 ms a shader. Two translations are made here, both mechanical:
the $Globals constant buffer (a uniform struct in spirv-cross's output) becomes plain
uniforms under the names the HLSL declares, and rows are read back unflipped, because
SV_Position counts rows from the top, as GL's framebuffer stores them from the bottom:
the HLSL's row 0 is the framebuffer's first row, the top of the image.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..emit import CompiledShader, render_template
from ..errors import ToolError
from ..scene import View
from .gl import GlRunner, context
from .result import RenderResult

TOOLS = ("glslangValidator", "spirv-cross")


def toolchain() -> tuple[str, ...]:
    """The compilers and the GL context this backend needs, or a ToolError naming the
    missing one."""
    paths = tuple(shutil.which(name) for name in TOOLS)
    for name, path in zip(TOOLS, paths, strict=True):
        if path is None:
            raise ToolError(f"{name} not found on PATH (run `make setup`, or install it)")
    context()
    return paths  # type: ignore[return-value]


def hlsl_to_glsl(hlsl: str, include_dirs: Sequence[str] = ()) -> str:
    """HLSL pixel shader (entry point main) -> SPIR-V -> GLSL 400 core with plain uniforms
    (`include_dirs`: where its #include files are, as glslang's -I)."""
    glslang = toolchain()[0]
    with tempfile.TemporaryDirectory(prefix="implc-") as tmp:
        source, spirv = os.path.join(tmp, "shader.hlsl"), os.path.join(tmp, "shader.spv")
        Path(source).write_text(hlsl, encoding="utf-8")
        _run([glslang, "-D", "-S", "frag", "-e", "main", "-V",
              *(f"-I{d}" for d in include_dirs), "-o", spirv, source])
        return spirv_to_glsl(spirv)


def spirv_to_glsl(spirv: str) -> str:
    """A SPIR-V pixel shader's file (any HLSL front end's output) -> GLSL 400 core with
    plain uniforms."""
    cross = toolchain()[1]
    # 400, not 330: GLSL before 4.00 has no `precise`, and spirv-cross drops the HLSL's
    # (SPIR-V's NoContraction) in it, letting the GL driver fold the error-free
    # transformations of templates/eft.j2 (measured: `implc probe -b hlsl-spirv`)
    return plain_uniforms(_run([cross, "--version", "400", "--no-es",
                                "--glsl-emit-ubo-as-plain-uniforms", spirv]))


def _run(command: list[str]) -> str:
    """The tool's standard output; a ToolError with its messages if it fails."""
    try:
        proc = subprocess.run(command, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        raise ToolError(f"{Path(command[0]).name} did not finish within 120 s") from None
    if proc.returncode != 0:
        raise ToolError(f"{Path(command[0]).name} rejected the shader:\n"
                        f"{(proc.stdout + proc.stderr).strip()}")
    return proc.stdout


def plain_uniforms(glsl: str) -> str:
    """`struct _Global { vec3 u_eye; ... }; uniform _Global _1059;` and `_1059.u_eye` ->
    `uniform vec3 u_eye;` and `u_eye`: the names the HLSL gave its uniforms."""
    struct = re.search(r"^struct (\w*Global\w*)\n\{\n(.*?)\n\};\n", glsl, re.M | re.S)
    if struct is None:  # no uniform at all
        return glsl
    instance = re.search(rf"^uniform {struct.group(1)} (\w+);\n", glsl, re.M)
    if instance is None:
        raise ToolError("spirv-cross wrote a $Globals struct without its uniform")
    members = "".join(f"uniform {line.strip()}\n" for line in struct.group(2).splitlines())
    glsl = glsl.replace(instance.group(0), members).replace(struct.group(0), "")
    return re.sub(rf"\b{instance.group(1)}\.", "", glsl)


class HlslRunner(GlRunner):
    """The GL runner on the translated shader, reading rows back as SV_Position numbers
    them (row 0 at the top)."""

    def read(self) -> RenderResult:
        shape = (self.height, self.width, 4)
        color = np.frombuffer(self.fbo.read(components=4, attachment=0, dtype="f4"), np.float32)
        aux = np.frombuffer(self.fbo.read(components=4, attachment=1, dtype="f4"), np.float32)
        return RenderResult.from_buffers(color.reshape(shape), aux.reshape(shape))


def open_hlsl_runner(shader: CompiledShader, view: View, width: int,
                     height: int) -> HlslRunner:
    """Runner factory of backend `hlsl-spirv` (a `--params uniform` shader's parameters
    are uniforms, moved by `set_params`)."""
    fragment = hlsl_to_glsl(shader.text)
    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    return HlslRunner(fragment, vertex, view, width, height, shader.uniforms)
