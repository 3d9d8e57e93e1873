"""The drop-ins where users paste them, in real headless Chromium (tests/conftest.py):

- the Shadertoy flavour in a page that provides what Shadertoy provides (its uniforms and
  a main that calls mainImage: templates/glsl/harness.glsl.j2) renders as the GL program;
- every WGSL golden compiles in Chromium's WebGPU (Tint, a WGSL compiler independent of
  naga) with no error message, and the WGSL program renders there as on wgpu-py;
- in three.js (npm, pinned in tests/browser/package.json, loaded from disk) the GLSL
  library in a ShaderMaterial on a proxy sphere writes gl_FragDepth, so the surface and an
  ordinary mesh through it hide each other where each is in front.

Thresholds: SSIM >= 0.99 between two float32 runs of one algorithm (different compilers
and rasterizers; measured >= 0.999), hit masks agreeing on >= 99.5 % of the pixels, and in
three.js >= 99 % of the overlap pixels showing the nearer object (the pixels along the
line where the box pierces the surface, within DEPTH_TIE of each other, are left out: a
24-bit depth buffer cannot order them).
"""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np
import pytest
from browser_support import (
    background_mask,
    file_url,
    open_page,
    screenshot,
    ssim,
    to_8bit,
)
from conftest import _require

from implc.emit import emit, param_uniforms, render_template
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.render.run import render
from implc.render.wgpu_runner import uniform_block
from implc.scene import SHADING, pixel_rays

SMALL = 128
SSIM_SAME = 0.99
MASK_AGREEMENT = 0.995
WGSL_GOLDEN = Path(__file__).parent / "golden" / "wgsl"
NPM_DIR = Path(__file__).parent / "browser"


def hessian():
    return METHODS["hessian"].defaults


# --- Shadertoy -------------------------------------------------------------------------------
@pytest.mark.parametrize("example", ["torus", "cross-cap"])
def test_shadertoy_flavour_runs_like_on_shadertoy(browser, tmp_path, example):
    surface = load_surface(example)
    image_tab = emit(surface, "glsl", "hessian", hessian(), flavor="shadertoy")
    data = {
        "fragment": render_template("glsl/harness.glsl.j2", kind="shadertoy", body=image_tab,
                                    prefix=""),
        "vertex": render_template("glsl/fullscreen.vert.j2", version="300 es"),
        "width": SMALL, "height": SMALL, "frames": 3,
    }
    page_path = tmp_path / "shadertoy.html"
    page_path.write_text(render_template("browser/shadertoy.html.j2", data=data))
    with open_page(browser, file_url(page_path)) as (page, log):
        page.wait_for_function("window.shadertoy.done")
        state = page.evaluate("window.shadertoy")
        frame = screenshot(page.locator("#canvas"), f"shadertoy-{example}")
        problems = log.problems()
    assert state["error"] == "" and state["frames"] == 3
    assert "iResolution" in state["uniforms"]
    assert problems == []
    expected = to_8bit(render(surface, "gl", "hessian", hessian(), SMALL, SMALL).color)
    score = ssim(frame, expected)
    print(f"{example}: Shadertoy harness vs GL render: SSIM {score:.5f}")
    assert score >= SSIM_SAME
    agree = np.mean(background_mask(frame, SHADING.background)
                    == background_mask(expected, SHADING.background))
    assert agree >= MASK_AGREEMENT


# --- WebGPU ----------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def webgpu(browser, tmp_path_factory):
    path = tmp_path_factory.mktemp("webgpu") / "webgpu.html"
    path.write_text(render_template("browser/webgpu.html.j2"))
    with open_page(browser, file_url(path)) as (page, log):
        try:
            adapter = page.evaluate("implcWebGPU.device()")
        except Exception as err:  # playwright's Error carries the page's message
            _require("WebGPU in chromium", str(err).splitlines()[0])
        print(f"Chromium WebGPU adapter: {adapter}")
        yield page, log


@pytest.mark.parametrize("golden", sorted(p.name for p in WGSL_GOLDEN.glob("*.wgsl")))
def test_wgsl_golden_compiles_in_chromium(webgpu, golden):
    """Tint accepts the golden without a message; a program also builds its pipeline."""
    page, log = webgpu
    code = (WGSL_GOLDEN / golden).read_text()
    program = "@compute" in code
    result = page.evaluate("([code, pipeline]) => implcWebGPU.compile(code, pipeline)",
                           [code, program])
    errors = [m for m in result["messages"] if m["type"] == "error"]
    assert errors == [] and result["error"] == "", f"{golden}: {errors} {result['error']}"
    warnings = [m for m in result["messages"] if m["type"] != "error"]
    assert warnings == [], f"{golden}: Tint warns: {warnings}"
    assert log.problems() == []


def test_chromium_webgpu_reports_wgsl_errors(webgpu):
    """The check above can fail: a broken program gets Tint's error with its line."""
    page, _ = webgpu
    code = (WGSL_GOLDEN / "torus.hessian.wgsl").read_text().replace("let ndc", "let ndc = ;//")
    result = page.evaluate("([code]) => implcWebGPU.compile(code, true)", [code])
    errors = [m for m in result["messages"] if m["type"] == "error"]
    assert errors and errors[0]["line"] > 1 and result["error"]


def _decode(text: str, width: int, height: int) -> np.ndarray:
    return np.frombuffer(base64.b64decode(text), np.float32).reshape(height, width, 4)


@pytest.mark.parametrize("example", ["torus", "cross-cap"])
def test_wgsl_program_renders_in_chromium_like_wgpu(webgpu, example):
    from test_wgsl import require_wgpu

    require_wgpu()
    page, log = webgpu
    surface = load_surface(example)
    program = emit(surface, "wgsl", "hessian", hessian())
    uniforms = np.frombuffer(uniform_block(surface.view, SMALL, SMALL), np.float32).tolist()
    out = page.evaluate("([code, w, h, u]) => implcWebGPU.render(code, w, h, u)",
                        [program, SMALL, SMALL, uniforms])
    color, aux = _decode(out["color"], SMALL, SMALL), _decode(out["aux"], SMALL, SMALL)
    assert log.problems() == []
    expected = render(surface, "wgpu", "hessian", hessian(), SMALL, SMALL)
    hit = aux[..., 0] > 0.5
    score = ssim(color[..., :3].astype(np.float64), expected.color.astype(np.float64))
    agree = np.mean(hit == expected.hit)
    both = hit & expected.hit
    t_error = np.median(np.abs(aux[..., 1][both] - expected.t[both]))
    print(f"{example}: Chromium WebGPU vs wgpu-py: SSIM {score:.5f}, hit agreement "
          f"{agree:.4f}, median |dt| {t_error:.2e}")
    assert hit.mean() > 0.1
    assert score >= SSIM_SAME and agree >= MASK_AGREEMENT and t_error < 1e-4


# --- three.js --------------------------------------------------------------------------------
# A red box through the torus's near tube, along y: where it sticks out towards the
# camera it hides the surface, inside the tube the surface hides it.
BOX = {"size": [0.2, 3.0, 0.2], "position": [0.0, -1.0, 0.0], "color": [1.0, 0.0, 0.0]}
DEPTH_TIE = 0.02  # scene units: closer than this, the overlap pixel is not judged
THREE_SIZE = 160


def three_module() -> Path:
    pinned = json.loads((NPM_DIR / "package.json").read_text())["dependencies"]["three"]
    module = NPM_DIR / "node_modules" / "three" / "build" / "three.module.js"
    if not module.is_file():
        _require("three (npm)", f"{module} is missing: `npm ci` in {NPM_DIR}")
    installed = json.loads((NPM_DIR / "node_modules/three/package.json").read_text())["version"]
    assert installed == pinned, f"three {installed} installed, {pinned} pinned: run `make setup`"
    return module


def box_t(view, width, height) -> np.ndarray:
    """Distance along each pixel's ray to the box (inf where it misses), slab method."""
    origins, dirs = pixel_rays(view, width, height)
    low = np.subtract(BOX["position"], np.divide(BOX["size"], 2))
    high = np.add(BOX["position"], np.divide(BOX["size"], 2))
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (low - origins) / dirs, (high - origins) / dirs
    near = np.max(np.minimum(t1, t2), axis=-1)
    far = np.min(np.maximum(t1, t2), axis=-1)
    return np.where((far >= near) & (far > 0), np.maximum(near, 0), np.inf)


def three_page(tmp_path, surface, width: int, height: int) -> Path:
    """The three.js test page showing the torus library at `width` x `height`."""
    view = surface.view
    prefix = "torus_"
    library = emit(surface, "glsl", "hessian", hessian(), emit_form="library", prefix=prefix,
                   params="uniform")
    data = {
        "width": width, "height": height,
        "view": {"eye": view.eye, "target": view.target, "up": view.up, "fov_y": view.fov_y_deg,
                 "clip_center": view.clip_center, "clip_radius": view.clip_radius,
                 "background": SHADING.background},
        "vertex": render_template("three/surface.vert.glsl.j2"),
        "fragment": render_template("three/surface.frag.glsl.j2", library=library,
                                    prefix=prefix),
        "params": {u.uniform: u.value
                   for u in param_uniforms(surface, "glsl", "library", prefix)},
        "box": BOX,
    }
    page_path = tmp_path / "three.html"
    page_path.write_text(render_template("browser/three.html.j2", data=data,
                                         three_url=three_module().as_uri()))
    return page_path


def test_three_js_surface_and_mesh_hide_each_other(browser, tmp_path):
    surface = load_surface("torus")
    view = surface.view
    page_path = three_page(tmp_path, surface, THREE_SIZE, THREE_SIZE)
    shots = {}
    with open_page(browser, file_url(page_path)) as (page, log):
        page.wait_for_function("window.implcThree && (implcThree.ready || implcThree.error)")
        assert page.evaluate("implcThree.error") == ""
        revision = page.evaluate("implcThree.revision")
        for name, flags in {"both": [True, True], "surface": [True, False]}.items():
            assert page.evaluate("([s, b]) => implcThree.show(s, b)", flags) == ""
            shots[name] = screenshot(page.locator("#canvas"), f"three-{name}")
        # the library's parameter uniforms, through three's material.uniforms
        page.evaluate("implcThree.setParam('torus_u_param_r', 0.5)")
        assert page.evaluate("implcThree.show(true, false)") == ""
        shots["r=0.5"] = screenshot(page.locator("#canvas"), "three-r0.5")
        assert log.problems() == []
    assert revision == three_module().parent.parent.joinpath("package.json").read_text() \
        .split('"version": "')[1].split(".")[1]

    reference = render(surface, "reference", "hessian", hessian(), THREE_SIZE, THREE_SIZE)
    surf_t = np.where(reference.hit, reference.t, np.inf)
    mesh_t = box_t(view, THREE_SIZE, THREE_SIZE)
    expected = np.where(reference.hit[..., None], to_8bit(reference.color),
                        np.asarray(SHADING.background))
    expected = np.where((mesh_t < surf_t)[..., None], np.asarray(BOX["color"]), expected)

    both = shots["both"]
    red = np.all(np.abs(both - np.asarray(BOX["color"])) < 0.02, axis=-1)
    overlap = np.isfinite(surf_t) & np.isfinite(mesh_t)
    gap = np.abs(np.where(overlap, surf_t, 0.0) - np.where(overlap, mesh_t, 0.0))
    overlap &= gap > DEPTH_TIE
    mesh_front, surface_front = overlap & (mesh_t < surf_t), overlap & (surf_t < mesh_t)
    right = np.count_nonzero(red[mesh_front]) + np.count_nonzero(~red[surface_front])
    score_surface = ssim(shots["surface"], to_8bit(np.where(
        reference.hit[..., None], reference.color, np.asarray(SHADING.background))))
    score_both = ssim(both, expected)
    print(f"three r{revision}: surface alone vs reference SSIM {score_surface:.5f}; with the "
          f"box vs the depth-composited reference {score_both:.5f}; box in front on "
          f"{mesh_front.sum()} px, surface in front on {surface_front.sum()} px, "
          f"{right / overlap.sum():.4f} right")
    moved = render(load_surface("torus", params=["r=0.5"]), "reference", "hessian", hessian(),
                   THREE_SIZE, THREE_SIZE)
    score_moved = ssim(shots["r=0.5"], to_8bit(np.where(
        moved.hit[..., None], moved.color, np.asarray(SHADING.background))))
    print(f"three: torus_u_param_r = 0.5 vs the reference of r=0.5: SSIM {score_moved:.5f}")
    assert score_moved >= SSIM_SAME and ssim(shots["r=0.5"], shots["surface"]) < 0.95
    assert mesh_front.sum() > 100 and surface_front.sum() > 100, "the scene lost its overlap"
    assert right >= 0.99 * overlap.sum()
    assert score_surface >= SSIM_SAME and score_both >= SSIM_SAME


def test_three_js_portrait_canvas_keeps_implcs_camera(browser, tmp_path):
    """Issue 44: implc's fov spans the shorter side, three's is vertical: on a portrait
    canvas the page gives three the vertical fov that makes the same picture (with v.fov_y
    passed as it is, the torus came out larger, its sides cut)."""
    surface = load_surface("torus")
    width, height = 120, 160
    with open_page(browser, file_url(three_page(tmp_path, surface, width, height))) as (page, log):
        page.wait_for_function("window.implcThree && (implcThree.ready || implcThree.error)")
        assert page.evaluate("implcThree.error") == ""
        assert page.evaluate("implcThree.show(true, false)") == ""
        shot = screenshot(page.locator("#canvas"), "three-portrait")
        assert log.problems() == []
    reference = render(surface, "reference", "hessian", hessian(), width, height)
    expected = to_8bit(np.where(reference.hit[..., None], reference.color,
                                np.asarray(SHADING.background)))
    score = ssim(shot, expected)
    print(f"three at {width}x{height} vs reference: SSIM {score:.5f}")
    assert score >= SSIM_SAME
    background = background_mask(shot, SHADING.background)
    assert background[:, 0].all() and background[:, -1].all()
