"""`implc export --host three` (issue 46): the ES module drawn by three.js itself (npm, pinned
in tests/browser/package.json) in headless Chromium, on each of three's renderers:
WebGLRenderer (the ShaderMaterial), WebGPURenderer on WebGPU (TSL's wgslFn) and
WebGPURenderer forced to its WebGL2 backend (TSL's glslFn), with three's defaults (colour
management on, sRGB output).

Each picture is compared with `implc render` of the same view and method (SSIM >=
SSIM_SAME, the bound of tests/test_browser.py: two float32 runs of one algorithm); a
parameter set through the module's own control moves the picture to implc's render of
that value; and a red box through the torus hides it and is hidden by it where each is in
front (the surface's depth), as in tests/test_browser.py's three.js test.

With IMPLC_SCREENSHOTS=DIR, the WebGPU picture with the box is saved as DIR/host-three.png:
the hosts guide's figure is made by `make three-picture` (IMPLC_SCREENSHOTS=docs).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from browser_support import background_mask, file_url, open_page, screenshot, ssim
from test_browser import (
    BOX,
    DEPTH_TIE,
    MASK_AGREEMENT,
    NPM_DIR,
    SSIM_SAME,
    box_t,
    three_module,
)

import implc as api
from implc.emit import render_template
from implc.scene import SHADING

SIZE = 160
RENDERERS = {"webgl": "WebGLRenderer", "webgpu": "WebGPURenderer/WebGPU",
             "webgpu-webgl2": "WebGPURenderer/WebGL2"}


def export(example: str, folder: Path) -> tuple[Path, str]:
    """The example's module, saved in `folder`; the method it was compiled with."""
    files = api.Surface.example(example).export("three")
    files.save(folder)
    return folder / next(iter(files.files)), files.method


def host_page(module: Path) -> Path:
    """The test page beside `module`, importing three from tests/browser/node_modules."""
    build = three_module().parent
    imports = {"three": build / "three.module.js", "three/webgpu": build / "three.webgpu.js",
               "three/tsl": build / "three.tsl.js", "surface": module}
    data = {"width": SIZE, "height": SIZE, "background": SHADING.background, "box": BOX}
    page = module.parent / "three_host.html"
    page.write_text(render_template("browser/three_host.html.j2", data=data,
                                    imports={k: v.as_uri() for k, v in imports.items()}))
    return page


def draw(browser, module: Path, renderer: str, shots: dict[str, tuple],
         keep: dict[str, str] | None = None) -> tuple[dict[str, np.ndarray], dict]:
    """The page's canvas after each of `shots` (label -> ([surface, box] shown, parameters
    set before[, (angle, offset) the mesh and the camera are placed at])), with the
    module's PARAMETERS; the page said no error. With IMPLC_SCREENSHOTS=DIR, the shots
    `keep` names (label -> name) are saved as DIR/name.png."""
    pictures = {}
    with open_page(browser, file_url(host_page(module), f"renderer={renderer}")) as (page, log):
        page.wait_for_function("window.implcHost && (implcHost.ready || implcHost.error)")
        assert page.evaluate("implcHost.error") == ""
        assert page.evaluate("implcHost.backend") == RENDERERS[renderer]
        params = page.evaluate("implcHost.params")
        for label, (flags, values, *placed) in shots.items():
            for param, value in values.items():  # the module's own control
                page.evaluate("([n, v]) => implcHost.setParam(n, v)", [param, value])
            if placed:
                page.evaluate("([a, o]) => implcHost.place(a, o)", placed[0])
            assert page.evaluate("([s, b]) => implcHost.show(s, b)", flags) == ""
            pictures[label] = screenshot(page.locator("#canvas"), (keep or {}).get(label, ""))
        problems = log.problems()
    assert problems == [], "\n".join(problems)
    return pictures, params


def implc_picture(example: str, method: str,
                  **params: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """`implc render` of the example (8-bit colour, hit mask, t) at SIZE, on GL."""
    surface = api.Surface.example(example)
    if params:
        surface = surface.with_params(**params)
    picture = surface.render(SIZE, backend="gl", method=method)
    return picture.image / 255.0, picture.aux["hit"], picture.aux["t"]


@pytest.mark.parametrize("renderer", list(RENDERERS))
def test_the_three_module_draws_the_torus_on_each_renderer(browser, tmp_path, renderer):
    """The picture, a parameter moving it, the surface moving with its mesh, and the
    depth against a box."""
    module, method = export("torus", tmp_path)
    shots, params = draw(browser, module, renderer, {
        "surface": ([True, False], {}), "both": ([True, True], {}),
        "r0.5": ([True, False], {"r": 0.5}),
        "placed": ([True, False], {"r": 0.35}, (0.7, [0.4, -0.3, 0.2]))},
        {"both": "host-three"} if renderer == "webgpu" else None)
    assert params == {"R": {"value": 1.0, "min": 0.0, "max": 2.0},
                      "r": {"value": 0.35, "min": -0.15, "max": 0.85}}

    expected, hit, t = implc_picture("torus", method)
    score = ssim(shots["surface"], expected)
    agree = np.mean(background_mask(shots["surface"], SHADING.background) == ~hit)
    moved, _, _ = implc_picture("torus", method, r=0.5)
    score_moved = ssim(shots["r0.5"], moved)
    score_placed = ssim(shots["placed"], expected)  # the surface is in the mesh's space
    # the box: red where it is nearer than the surface, the surface where it is nearer
    surf_t = np.where(hit, t, np.inf)
    mesh_t = box_t(api.Surface.example("torus").view, SIZE, SIZE)
    red = np.all(np.abs(shots["both"] - np.asarray(BOX["color"])) < 0.02, axis=-1)
    overlap = np.isfinite(surf_t) & np.isfinite(mesh_t)
    gap = np.abs(np.where(overlap, surf_t, 0.0) - np.where(overlap, mesh_t, 0.0))
    overlap &= gap > DEPTH_TIE
    mesh_front, surface_front = overlap & (mesh_t < surf_t), overlap & (surf_t < mesh_t)
    right = np.count_nonzero(red[mesh_front]) + np.count_nonzero(~red[surface_front])
    print(f"three {RENDERERS[renderer]} (torus, {method}): vs implc render SSIM {score:.5f}, "
          f"background agreement {agree:.4f}; r=0.5 vs implc's r=0.5 SSIM {score_moved:.5f} "
          f"(vs r=0.35 {ssim(shots['r0.5'], shots['surface']):.5f}); mesh and camera "
          f"turned and moved together: SSIM {score_placed:.5f}; box in front on "
          f"{mesh_front.sum()} px, surface on {surface_front.sum()} px, "
          f"{right / overlap.sum():.4f} right")
    assert score >= SSIM_SAME and agree >= MASK_AGREEMENT
    assert score_moved >= SSIM_SAME and ssim(shots["r0.5"], shots["surface"]) < 0.95
    assert score_placed >= SSIM_SAME
    assert mesh_front.sum() > 100 and surface_front.sum() > 100, "the scene lost its overlap"
    assert right >= 0.99 * overlap.sum()


@pytest.mark.parametrize("renderer", list(RENDERERS))
@pytest.mark.parametrize("example", ["cross-cap", "gyroid"])
def test_the_three_module_draws_other_surfaces(browser, tmp_path, example, renderer):
    """A surface without parameters (cross-cap) and one that is not a polynomial (gyroid,
    another method), each as implc renders it."""
    module, method = export(example, tmp_path)
    shots, _ = draw(browser, module, renderer, {"surface": ([True, False], {})})
    expected, hit, _ = implc_picture(example, method)
    score = ssim(shots["surface"], expected)
    agree = np.mean(background_mask(shots["surface"], SHADING.background) == ~hit)
    print(f"three {RENDERERS[renderer]} ({example}, {method}): vs implc render SSIM "
          f"{score:.5f}, background agreement {agree:.4f}")
    assert score >= SSIM_SAME and agree >= MASK_AGREEMENT


def test_the_three_module_is_pinned_three_that_exports_both_renderers():
    """The module needs 'three/webgpu' and 'three/tsl' (WebGPURenderer, wgslFn, glslFn):
    the pinned three has them."""
    build = three_module().parent
    package = (NPM_DIR / "node_modules" / "three" / "package.json").read_text()
    assert '"./webgpu": "./build/three.webgpu.js"' in package
    assert '"./tsl": "./build/three.tsl.js"' in package
    tsl = (build / "three.tsl.js").read_text()
    for name in ("wgslFn", "glslFn", "colorSpaceToWorking", "viewZToPerspectiveDepth"):
        assert f"const {name} = " in tsl


def module_strings(text: str) -> dict[str, str]:
    """The module's shader strings (`const NAME = `...`;`), unescaped."""
    found = re.findall(r"^const ([A-Z_]+) = `(.*?)`;$", text, flags=re.S | re.M)
    return {name: body.replace("\\`", "`").replace("\\${", "${").replace("\\\\", "\\")
            for name, body in found}


@pytest.mark.parametrize("target", ["glsl", "wgsl"])
def test_the_modules_libraries_and_trace_compile_without_a_browser(target):
    """What wgslFn and glslFn get (the library and the trace function), as the module holds
    it, compiles with implc's own validator of the language (glslang, naga)."""
    from conftest import require_validator

    validate = require_validator(target)
    module = api.Surface.example("torus").export("three").main
    strings = module_strings(module)
    assert set(strings) == {"GLSL_LIBRARY", "WGSL_LIBRARY", "GLSL_TRACE", "WGSL_TRACE",
                            "VERTEX_SHADER"}
    text = strings[f"{target.upper()}_LIBRARY"] + strings[f"{target.upper()}_TRACE"]
    verdict = validate(text, f"torus.{target}")
    assert verdict.ok, verdict.messages
