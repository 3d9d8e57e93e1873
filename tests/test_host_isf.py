"""`implc export --host isf` (issue 46): an ISF generator, loaded by a real ISF renderer
(npm `interactive-shader-format`, pinned in tests/browser/package.json, its own lib/
files as installed) on a WebGL1 canvas in headless Chromium, as an ISF host loads it.

The renderer parses the JSON header into its controls: they must be the surface's
parameters one to one (name, default, range); setting one through the renderer redraws the
surface with that parameter. Each picture is compared with implc's own GL render of the
same view at the bounds of tests/test_browser.py (SSIM >= 0.99, hit masks agreeing on
>= 99.5 % of the pixels).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from browser_support import background_mask, file_url, open_page, screenshot, ssim, to_8bit
from conftest import _require, require_tool
from test_browser import MASK_AGREEMENT, NPM_DIR, SSIM_SAME
from test_cli import implc

import implc as api
from implc.emit import render_template
from implc.errors import OptionError
from implc.scene import SHADING

SIZE = 128
PACKAGE = NPM_DIR / "node_modules" / "interactive-shader-format"


def isf_modules() -> dict[str, str]:
    """The renderer's CommonJS sources as installed: {path in the package: text}."""
    pinned = json.loads((NPM_DIR / "package.json").read_text())["dependencies"]
    if not (PACKAGE / "lib" / "main.js").is_file():
        _require("interactive-shader-format (npm)", f"{PACKAGE} is missing: `npm ci` in "
                 f"{NPM_DIR}")
    installed = json.loads((PACKAGE / "package.json").read_text())["version"]
    assert installed == pinned["interactive-shader-format"], "run `make setup`"
    return {str(p.relative_to(PACKAGE)): p.read_text()
            for folder in ("lib", "vendor") for p in sorted((PACKAGE / folder).glob("*.js"))}


def isf_page(tmp_path: Path, source: str) -> Path:
    page = tmp_path / "isf.html"
    page.write_text(render_template("browser/isf.html.j2", data={
        "width": SIZE, "height": SIZE, "source": source, "modules": isf_modules()}))
    return page


def expected(surface: api.Surface, method: str) -> np.ndarray:
    return to_8bit(surface.render(width=SIZE, height=SIZE, backend="gl", method=method).color)


def compare(shot: np.ndarray, want: np.ndarray, what: str) -> float:
    score = ssim(shot, want)
    agree = np.mean(background_mask(shot, SHADING.background)
                    == background_mask(want, SHADING.background))
    print(f"{what}: ISF renderer vs implc's GL render: SSIM {score:.5f}, hit masks agree "
          f"on {agree:.4f}")
    assert score >= SSIM_SAME and agree >= MASK_AGREEMENT, what
    return score


@pytest.mark.parametrize("example", ["torus", "cross-cap"])
def test_the_isf_generator_renders_in_an_isf_renderer(browser, tmp_path, example):
    surface = api.Surface.example(example)
    files = surface.export("isf")
    (name, source), = files.files.items()
    assert name.endswith(".fs") and source.startswith("/*{")
    with open_page(browser, file_url(isf_page(tmp_path, source))) as (page, log):
        page.wait_for_function("window.implcISF && (implcISF.ready || implcISF.error)")
        assert page.evaluate("implcISF.error") == ""
        inputs = page.evaluate("implcISF.inputs")
        assert page.evaluate("implcISF.draw({})") == ""
        shot = screenshot(page.locator("#canvas"), f"isf-{example}")
        moved = {}
        if inputs:  # a parameter set through the renderer's control
            first = inputs[-1]
            value = first["DEFAULT"] + 0.3 * (first["MAX"] - first["DEFAULT"])
            assert page.evaluate("(v) => implcISF.draw(v)", {first["NAME"]: value}) == ""
            moved = {"label": first["LABEL"], "value": value,
                     "shot": screenshot(page.locator("#canvas"), f"isf-{example}-moved")}
        assert log.problems() == []
    # the renderer's controls are the parameters, one to one
    want = {name: value for name, value in surface.params.items()}
    assert [i["LABEL"] for i in inputs] == list(want)
    for item in inputs:
        assert item["TYPE"] == "float" and item["DEFAULT"] == want[item["LABEL"]]
        assert item["MIN"] < item["DEFAULT"] < item["MAX"]
    compare(shot, expected(surface, files.method), example)
    if moved:
        changed = surface.with_params(**{moved["label"]: moved["value"]})
        compare(moved["shot"], expected(changed, files.method),
                f"{example} with {moved['label']} = {moved['value']:.3f}")
        assert ssim(moved["shot"], shot) < 0.98, "the control changed nothing"


def test_the_isf_file_is_glsl_es_100_where_the_library_is_not_es300_only(tmp_path):
    """What the renderer builds around the file (its uniforms from INPUTS, gl_FragColor,
    no #version: GLSL ES 1.00) compiles with glslang too, for every method ISF takes."""
    import subprocess

    glslang = require_tool("glslangValidator")
    surface = api.Surface.example("cross-cap")
    for method in ("sign", "taylor", "curvature", "hessian", "hessian-approx", "exact"):
        text = surface.export("isf", method).main
        meta = json.loads(text[2:text.index("}*/") + 1])
        uniforms = "".join(f"uniform float {i['NAME']};\n" for i in meta["INPUTS"])
        shader = tmp_path / f"{method}.frag"
        shader.write_text("#version 100\nprecision highp float;\nprecision highp int;\n"
                          "uniform vec2 RENDERSIZE;\n" + uniforms + text)
        proc = subprocess.run([glslang, str(shader)], capture_output=True, text=True,
                              timeout=120)
        assert proc.returncode == 0, f"{method}: {proc.stdout}"


def test_isf_refuses_the_interval_method_with_the_reason(tmp_path):
    with pytest.raises(OptionError, match="isf host cannot take it.*bit operations"):
        api.Surface.example("torus").export("isf", "interval")
    proc = implc("export", "torus", "--host", "isf", "-m", "interval", "-o", str(tmp_path))
    assert proc.returncode == 2 and "bit operations" in proc.stderr
    assert list(tmp_path.iterdir()) == []
