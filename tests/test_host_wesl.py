"""`implc export --host wesl` (issue 46): a WESL package (wesl.toml, the surface module
and a full-screen pass that imports it), linked by the npm `wesl` linker (pinned in
tests/browser/package.json, its dist/ as installed) in headless Chromium, the linked WGSL
compiled by Chromium's WebGPU (Tint) and drawn.

Each picture is compared with implc's own GL render of the same view at the bounds of
tests/test_browser.py (SSIM >= 0.99, hit masks agreeing on >= 99.5 % of the pixels), with
the parameters at the surface's values and with one moved through the pass's Params
buffer; and a @test-style module that imports the surface's functions runs them on a
view's rays against implc's exact reference.
"""

from __future__ import annotations

import base64
import json
import os
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from browser_support import background_mask, file_url, open_page, ssim, to_8bit
from conftest import _require
from test_browser import MASK_AGREEMENT, NPM_DIR, SSIM_SAME

import implc as api
from implc.emit import render_template
from implc.scene import SHADING, clip_sphere, pixel_rays

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

SIZE = 128
LINKER = NPM_DIR / "node_modules" / "wesl"


def linker_url() -> str:
    pinned = json.loads((NPM_DIR / "package.json").read_text())["dependencies"]["wesl"]
    module = LINKER / "dist" / "index.js"
    if not module.is_file():
        _require("wesl (npm)", f"{module} is missing: `npm ci` in {NPM_DIR}")
    installed = json.loads((LINKER / "package.json").read_text())["version"]
    assert installed == pinned, f"wesl {installed} installed, {pinned} pinned: run `make setup`"
    return module.as_uri()


def wesl_page(tmp_path: Path, files: dict[str, str], stem: str) -> Path:
    """The test page with the package's modules and the @test-style check module."""
    modules = {name: text for name, text in files.items() if name.endswith(".wesl")}
    modules["check.wesl"] = render_template("browser/wesl_check.wesl.j2", stem=stem)
    page_path = tmp_path / "wesl.html"
    page_path.write_text(render_template("browser/wesl.html.j2", wesl_url=linker_url(), data={
        "modules": modules, "root": f"{stem}_draw", "width": SIZE, "height": SIZE}))
    return page_path


def draw(page, params: list[float], name: str) -> tuple[dict, np.ndarray]:
    """Link, compile and draw once; the picture as float RGB (saved as NAME.png under
    $IMPLC_SCREENSHOTS when set, as browser_support.screenshot does)."""
    try:
        out = page.evaluate("(p) => implcWESL.draw(p)", params)
    except Exception as err:  # playwright's Error carries the page's message
        if "WebGPU" in str(err) and "adapter" in str(err) or "no WebGPU" in str(err):
            _require("WebGPU in chromium", str(err).splitlines()[0])
        raise
    rgba = np.frombuffer(base64.b64decode(out["rgba"]), np.uint8).reshape(SIZE, SIZE, 4)
    if os.environ.get("IMPLC_SCREENSHOTS"):
        from PIL import Image

        folder = Path(os.environ["IMPLC_SCREENSHOTS"])
        folder.mkdir(parents=True, exist_ok=True)
        Image.fromarray(rgba[..., :3].copy()).save(folder / f"{name}.png")
    return out, rgba[..., :3].astype(np.float64) / 255.0


def compare(shot: np.ndarray, surface: api.Surface, method: str, what: str) -> None:
    want = to_8bit(surface.render(width=SIZE, height=SIZE, backend="gl", method=method).color)
    score = ssim(shot, want)
    agree = np.mean(background_mask(shot, SHADING.background)
                    == background_mask(want, SHADING.background))
    print(f"{what}: linked WESL in Chromium WebGPU vs implc's GL render: SSIM {score:.5f}, "
          f"hit masks agree on {agree:.4f}")
    assert score >= SSIM_SAME and agree >= MASK_AGREEMENT, what


@pytest.mark.parametrize("example", ["torus", "cross-cap"])
def test_the_wesl_package_links_compiles_and_draws_in_chromium(browser, tmp_path, example):
    surface = api.Surface.example(example)
    files = surface.export("wesl")
    stem = next(iter(files.files)).removesuffix(".wesl")
    config = tomllib.loads(files.files["wesl.toml"])
    assert config["package"]["root"] == "." and config["package"]["edition"]
    draw_module = files.files[f"{stem}_draw.wesl"]
    assert f"import package::{stem}::" in draw_module
    page_path = wesl_page(tmp_path, files.files, stem)
    values = list(surface.params.values())
    with open_page(browser, file_url(page_path)) as (page, log):
        page.wait_for_function("window.implcWESL && implcWESL.ready")
        out, shot = draw(page, values, f"wesl-{example}")
        moved = None
        if values:  # the last parameter moved through the pass's Params buffer
            name = list(surface.params)[-1]
            value = values[-1] + 0.15
            _, moved_shot = draw(page, values[:-1] + [value], f"wesl-{example}-moved")
            moved = (name, value, moved_shot)
        problems = log.problems()
    assert out["error"] == "" and out["messages"] == [], out
    assert problems == []
    # the linker's work: one WGSL module, no imports left, both modules' declarations in it
    assert not re.search(r"^\s*import ", out["wgsl"], re.MULTILINE)
    assert "fn fs_main" in out["wgsl"] and "fn intersect" in out["wgsl"]
    compare(shot, surface, files.method, example)
    if moved:
        name, value, moved_shot = moved
        compare(moved_shot, surface.with_params(**{name: value}), files.method,
                f"{example} with {name} = {value:.3f}")
        assert ssim(moved_shot, shot) < 0.98, "the Params buffer changed nothing"


CHECK = 64  # rays per side of the @test-style check


@pytest.mark.parametrize("example", ["torus", "cross-cap"])
def test_the_wesl_module_intersects_as_the_exact_reference(browser, tmp_path, example):
    """@test-style: a module that imports package::STEM::{intersect, S} as a user's would
    (templates/browser/wesl_check.wesl.j2), linked with the package and run as a compute
    shader on the view's rays: its hits and t match implc's exact float64 reference (hit
    masks >= 99.5 %, median |t - t_ref| < 1e-4, as tests/test_browser.py's WebGPU test)."""
    surface = api.Surface.example(example)
    files = surface.export("wesl")
    stem = next(iter(files.files)).removesuffix(".wesl")
    reference = surface.render(width=CHECK, height=CHECK, backend="reference",
                               method=files.method)
    view = reference.view
    origins, dirs = pixel_rays(view, CHECK, CHECK)
    t_near, t_far, inside = clip_sphere(origins, dirs, view.clip_center, view.clip_radius)
    t_near, t_far = np.where(inside, t_near, 0.0), np.where(inside, t_far, 0.0)
    rays = np.stack([np.concatenate([origins, t_near[..., None]], axis=-1),
                     np.concatenate([dirs, t_far[..., None]], axis=-1)], axis=-2)
    with open_page(browser, file_url(wesl_page(tmp_path, files.files, stem))) as (page, log):
        page.wait_for_function("window.implcWESL && implcWESL.ready")
        try:
            out = page.evaluate("([r, data, n]) => implcWESL.run(r, data, n)",
                                ["check", rays.astype(np.float32).ravel().tolist(),
                                 CHECK * CHECK])
        except Exception as err:  # playwright's Error carries the page's message
            if "WebGPU" in str(err):
                _require("WebGPU in chromium", str(err).splitlines()[0])
            raise
        problems = log.problems()
    assert out["error"] == "" and out["messages"] == [] and problems == [], out["error"]
    result = np.asarray(out["output"]).reshape(CHECK, CHECK, 4)
    hit, t = result[..., 0] > 0.5, result[..., 1]
    ref = reference.result
    agree = np.mean(hit == ref.hit)
    both = hit & ref.hit
    t_error = np.abs(t[both] - ref.t[both])
    print(f"{example}: the linked module's intersect vs the exact reference on "
          f"{CHECK}x{CHECK} rays: hits agree on {agree:.4f}, median |dt| "
          f"{np.median(t_error):.2e}, max {t_error.max():.2e}")
    assert ref.hit.mean() > 0.1
    assert agree >= MASK_AGREEMENT and np.median(t_error) < 1e-4
