"""A host's node file rendered inside a harness that calls it as the host's generated code
does (templates/hosts/<host>/harness.hlsl.j2, over implc's own camera), compiled by either
of two independent HLSL front ends: glslang (glslangValidator, as backend hlsl-spirv) or
Slang (slangc, shipped in the `slangtorch` wheel: installed with --no-deps by `make
setup`, since its torch is not needed for the compiler). Both SPIR-V outputs go through
spirv-cross to the GL runner (implc/render/hlsl_runner.py)."""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from browser_support import ssim, to_8bit
from conftest import _require, require_gl, require_tool

from implc.emit import ParamUniform, render_template
from implc.export import export_files
from implc.hosts import HOSTS
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.render.hlsl_runner import HlslRunner, hlsl_to_glsl, spirv_to_glsl
from implc.render.result import RenderResult
from implc.render.run import open_runner, render, run_frame
from implc.scene import SHADING, View
from implc.surface import Surface

FRONT_ENDS = ("glslang", "slang")
T_FAR = "TFar"  # the node's TFar in render_harness's values (1e6 unless given)


def slangc() -> str:
    """Slang's compiler: on PATH, or the one the slangtorch wheel ships."""
    path = shutil.which("slangc")
    if path is None:
        spec = importlib.util.find_spec("slangtorch")  # finds it without importing torch
        if spec is not None and spec.submodule_search_locations:
            candidate = Path(spec.submodule_search_locations[0]) / "bin" / "slangc"
            path = str(candidate) if candidate.is_file() else None
    if path is None:
        _require("slangc", "neither on PATH nor in the slangtorch wheel")
    return path  # type: ignore[return-value]


def harness(host: str, node_file: Path, stem: str, controls: Sequence[ParamUniform],
            body: str = "", real: str = "float") -> str:
    """The harness's HLSL text; `node_file` is #included, `body` is a node's Code;
    `controls`: the surface's parameters, the node's inputs in their order."""
    return render_template(f"hosts/{host}/harness.hlsl.j2", file=node_file.name, stem=stem,
                           extras=HOSTS[host].extras,
                           controls=controls, body=body, real=real,
                           background=SHADING.background)


def compile_slang(source: Path, spirv: Path) -> str:
    """slangc's messages (it warns on stderr); a failure fails the test with them. -O0:
    the wheel ships no spirv-opt (Slang emits SPIR-V itself; spirv-opt only optimizes)."""
    proc = subprocess.run([slangc(), str(source), "-lang", "hlsl", "-target", "spirv",
                           "-entry", "main", "-stage", "fragment", "-O0", "-I", str(source.parent),
                           "-o", str(spirv)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, f"slangc rejected {source.name}:\n{proc.stdout}{proc.stderr}"
    return proc.stdout + proc.stderr


def compile_glslang(source: Path, spirv: Path) -> None:
    """glslang's HLSL front end on the harness, as backend hlsl-spirv runs it."""
    proc = subprocess.run([require_tool("glslangValidator"), "-V", "-D", "-S", "frag",
                           "-e", "main", f"-I{source.parent}", str(source), "-o", str(spirv)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, f"glslang rejected {source.name}:\n{proc.stdout}{proc.stderr}"


def compile_front(front: str, text: str, directory: Path) -> None:
    """The harness text (its node files in `directory`) compiled to SPIR-V by `front`."""
    source = directory / f"harness_{front}.hlsl"
    source.write_text(text)
    if front == "slang":
        messages = compile_slang(source, directory / "harness_slang.spv")
        assert "error" not in messages.lower(), messages
    else:
        compile_glslang(source, directory / "harness_glslang.spv")


def exported(host: str, directory: Path, example: str | Surface,
             method: str = "hessian") -> tuple[dict[str, str], Surface]:
    """`host`'s files for a bundled example (or a framed surface), written into
    `directory`, and the surface."""
    surface = load_surface(example) if isinstance(example, str) else example
    files = export_files(surface, HOSTS[host], method, METHODS[method].defaults)
    for name, text in files.items():
        (directory / name).write_text(text)
    return files, surface


def render_harness(text: str, directory: Path, front: str, view: View,
                   controls: Sequence[ParamUniform], size: int,
                   values: Mapping[str, float] | None = None) -> RenderResult:
    """The harness (its node files in `directory`) compiled by `front` and drawn, with
    the parameters (the node's inputs) and TFar (T_FAR) at `values` where given, else the
    surface's and 1e6."""
    source = directory / f"harness_{front}.hlsl"
    source.write_text(text)
    if front == "glslang":
        fragment = hlsl_to_glsl(text, include_dirs=[str(directory)])
    else:
        spirv = directory / "harness_slang.spv"
        compile_slang(source, spirv)
        fragment = spirv_to_glsl(str(spirv))
    params = [ParamUniform(c.name, f"in_{i}", f"in_{i}", c.value)
              for i, c in enumerate(controls)]
    params.append(ParamUniform(T_FAR, "u_t_far", "u_t_far", 1.0e6))
    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    runner = HlslRunner(fragment, vertex, view, size, size, params)
    try:
        runner.set_params(values or {})
        return runner.frame()
    finally:
        runner.release()


SSIM_SAME = 0.99  # tests/test_browser.py's bounds
MASK_AGREEMENT = 0.995
T_CLOSE = 1e-4  # scene units, where both hit


def assert_same(got: RenderResult, expected: RenderResult, label: str) -> None:
    """The node's picture is implc's: SSIM, hit masks and t (printed, then asserted)."""
    score = ssim(to_8bit(got.color), to_8bit(expected.color))
    agree = float(np.mean(got.hit == expected.hit))
    both = got.hit & expected.hit
    t_error = float(np.max(np.abs(got.t[both] - expected.t[both]))) if both.any() else 0.0
    print(f"{label}: SSIM {score:.5f}, hit agreement {agree:.4f}, max |dt| {t_error:.2e}, "
          f"hits {got.hit.mean():.3f}")
    assert got.hit.mean() > 0.1
    assert score >= SSIM_SAME and agree >= MASK_AGREEMENT and t_error < T_CLOSE


def save_shot(color: np.ndarray, name: str) -> None:
    """With IMPLC_SCREENSHOTS=DIR, the node's picture as DIR/name (the hosts guide's
    pictures, docs/host-*.png), as tests/browser_support.py keeps its screenshots."""
    keep = os.environ.get("IMPLC_SCREENSHOTS")
    if keep:
        from PIL import Image

        Path(keep).mkdir(parents=True, exist_ok=True)
        pixels = np.round(np.clip(color[..., :3], 0.0, 1.0) * 255.0).astype(np.uint8)
        Image.fromarray(pixels).save(Path(keep) / name)


def renders_like_implc(text: str, directory: Path, front: str, surface: Surface,
                       controls: Sequence[ParamUniform], label: str, shot: str = "",
                       size: int = 128) -> None:
    """The harness's picture is implc's GL render of the same view (hessian); with
    parameters, the last one moved by 0.25 moves both pictures alike."""
    require_tool("glslangValidator")
    require_tool("spirv-cross")
    require_gl()
    constants = METHODS["hessian"].defaults
    got = render_harness(text, directory, front, surface.view, controls, size)
    if shot:
        save_shot(got.color, shot)
    assert_same(got, render(surface, "gl", "hessian", constants, size, size),
                f"{label} via {front}")
    if not controls:
        return
    moved = {controls[-1].name: controls[-1].value + 0.25}  # torus: r 0.35 -> 0.6
    got_moved = render_harness(text, directory, front, surface.view, controls, size, moved)
    runner = open_runner(surface, "gl", "hessian", constants, size, size, params="uniform")
    runner.set_params(moved)
    assert_same(got_moved, run_frame(runner, 0.0), f"  moved {moved}")
    assert np.mean(got_moved.hit != got.hit) > 0.01  # the input did move the picture


def honours_t_far(text: str, directory: Path, surface: Surface,
                  controls: Sequence[ParamUniform], label: str, size: int = 128) -> None:
    """TFar at the median hit's t (a scene depth): the node hits where implc's t is
    nearer, with implc's t, and misses where it is farther (pixels within 1e-3 of TFar
    not judged)."""
    require_gl()
    full = render_harness(text, directory, "glslang", surface.view, controls, size)
    depth = float(np.median(full.t[full.hit]))
    cut = render_harness(text, directory, "glslang", surface.view, controls, size,
                         {T_FAR: depth})
    judged = np.abs(full.t - depth) > 1e-3
    expected = full.hit & (full.t < depth)
    agree = float(np.mean((cut.hit == expected)[judged]))
    print(f"{label}: TFar {depth:.4f}: {cut.hit.mean():.3f} of the pixels hit "
          f"(uncut {full.hit.mean():.3f}), agreement {agree:.5f}")
    assert agree == 1.0 and 0.1 < cut.hit.mean() < full.hit.mean() - 0.1
    both = cut.hit & judged  # the march starts elsewhere on a shorter segment: t to T_CLOSE
    assert float(np.max(np.abs(cut.t[both] - full.t[both]))) < T_CLOSE


def clashing_surface() -> Surface:
    """A sphere whose parameters are called as a node's own names and HLSL keywords:
    the nodes take them as T_in, out_in, t_in (templates/hosts/node_inputs.j2)."""
    import implc as api

    return api.Surface("x^2+y^2+z^2 - t*out - T", params={"t": 1, "out": 0.5, "T": 0.2},
                       name="clash").framed()[0]
