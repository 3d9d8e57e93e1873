"""`implc view`: the page is self-contained, and in real headless Chromium its first frame
is `implc render -b reference` of the same camera, its sliders move the parameters like
`--param`, its camera turns, pans and zooms with mouse and touch, and its WebGPU frame is
the wgpu render.

Thresholds. SSIM >= 0.99 between a browser frame and a render of the same camera and
parameters: both are the same algorithm in float32 (or float32 against the exact float64
reference), so they differ only at a few silhouette pixels and in 8-bit rounding;
measured 0.9996 (torus, WebGL2 vs reference, 256^2). A different picture scores far
lower: the torus turned by the test's drag, or with r moved from 0.35 to 0.55, scores
below 0.8 against the first frame, which each test checks so it can fail. Hit masks are
compared as "pixels that show the background colour": they agree on >= 99.5 % of the
pixels (silhouette pixels may round either way).
"""

from __future__ import annotations

import json
import math
import re
from html.parser import HTMLParser

import numpy as np
import pytest
from browser_support import (
    background_mask,
    file_url,
    open_page,
    read_png,
    screenshot,
    ssim,
    to_8bit,
)
from conftest import require_tool
from test_cli import implc

from implc.loaders import load_surface
from implc.methods import METHODS
from implc.render.run import render
from implc.scene import SHADING, View
from implc.view import viewer_page

SIZE = 256  # the first-frame comparison (the size)
SMALL = 128  # every other browser frame (SwiftShader on 2 shared cores)
METHOD = "exact"  # the viewer's default method for the polynomial examples used here
SSIM_SAME = 0.99
SSIM_CHANGED = 0.95  # a frame that must differ from another scores below this
MASK_AGREEMENT = 0.995
BACKGROUND = SHADING.background


def method_constants():
    return METHODS[METHOD].defaults


# --- the page text -----------------------------------------------------------------------
class _References(HTMLParser):
    """Every attribute that could load something, and every tag."""

    def __init__(self):
        super().__init__()
        self.loads: list[tuple[str, str, str]] = []
        self.tags: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        for name, value in attrs:
            if name in ("src", "href", "srcset", "action", "poster", "data", "background"):
                self.loads.append((tag, name, value or ""))


@pytest.mark.parametrize("example", ["torus", "kummer", "cross-cap"])
def test_page_loads_nothing(example):
    page = viewer_page(load_surface(example))
    refs = _References()
    refs.feed(page)
    assert refs.loads == [], f"the page references outside resources: {refs.loads}"
    assert not {"link", "iframe", "img", "object", "embed", "base"} & set(refs.tags)
    assert not re.search(r"https?://|//[a-z0-9.-]+\.[a-z]{2,}/", page, re.I), "a URL"
    for word in ("@import", "url(", "fetch(", "XMLHttpRequest", "WebSocket", "import(",
                 "importScripts", "@font-face", "EventSource"):
        assert word not in page, f"the page uses {word}"
    # the shaders it runs are implc's own emits, embedded as JSON
    data = json.loads(re.search(r'<script type="application/json" id="implc-data">(.*?)'
                                r"</script>", page, re.S).group(1))
    assert data["glsl"]["fragment"].startswith("#version 300 es")
    assert "@compute @workgroup_size(8, 8)" in data["wgsl"]["program"]


def test_page_is_deterministic_and_escapes_names(tmp_path):
    surface = load_surface("torus")
    assert viewer_page(surface) == viewer_page(surface)
    toml = tmp_path / "evil.toml"
    toml.write_text('name = "</script><script>alert(1)</script>"\nequation = "x^2+y^2+z^2-1"\n')
    page = viewer_page(load_surface(str(toml)))
    assert "<script>alert(1)" not in page
    assert page.count("</script>") == 2  # the JSON block and the viewer's script


def test_viewer_script_parses_and_is_the_pages_script():
    """templates/view/viewer.js is the page's script as it is (a linter reads the file the
    browser runs), and node's parser accepts it (`make lint` runs the same check)."""
    import subprocess

    from implc.resources import data_dir

    script = data_dir("templates") / "view" / "viewer.js"
    page = viewer_page(load_surface("torus"))
    assert "<script>\n" + script.read_text(encoding="utf-8") + "</script>" in page
    node = require_tool("node")
    result = subprocess.run([node, "--check", str(script)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_cli_view_writes_the_page(tmp_path):
    out = tmp_path / "torus.html"
    proc = implc("view", "torus", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    assert out.read_text() == viewer_page(load_surface("torus"))
    assert f"wrote {out}" in proc.stdout
    # bad input: exit 1, no file
    bad = tmp_path / "bad.html"
    proc = implc("view", "-e", "x^2 +", "-o", str(bad))
    assert proc.returncode == 1 and not bad.exists()
    proc = implc("view", "torus", "-m", "taylor", "--step", "0.02", "--no-webgpu",
                 "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    text = out.read_text()
    assert '"step": 0.02' in text and '"program": ""' in text


# --- in the browser ------------------------------------------------------------------------
def write_page(tmp_path, example, params=(), **kwargs):
    path = tmp_path / f"{example}.html"
    path.write_text(viewer_page(load_surface(example, params=params), **kwargs))
    return path


def wait_idle(page, after: int = 0) -> int:
    """Wait until the page has drawn more than `after` frames and has none pending."""
    page.wait_for_function(
        f"() => window.implcViewer && (implcViewer.error || "
        f"(implcViewer.frames > {after} && implcViewer.idle))")
    error = page.evaluate("implcViewer.error")
    assert not error, f"the viewer failed: {error}"
    return page.evaluate("implcViewer.frames")


def canvas(page):
    return page.locator("#gpu-canvas" if page.evaluate("implcViewer.backend") == "webgpu"
                        else "#gl-canvas")


def test_first_frame_is_the_reference_render(browser, tmp_path):
    """The first WebGL2 frame at 256^2 against `implc render -b reference` (same camera)."""
    reference = tmp_path / "ref.png"
    proc = implc("render", "torus", "-b", "reference", "--size", str(SIZE), "-o", str(reference))
    assert proc.returncode == 0, proc.stderr
    expected = read_png(reference)
    page_path = write_page(tmp_path, "torus")
    requests = []
    with open_page(browser, file_url(page_path, f"size={SIZE}")) as (page, log):
        page.on("request", lambda r: requests.append(r.url))
        wait_idle(page)
        frame = screenshot(page.locator("#gl-canvas"))
        readout = page.locator("#frame-time").inner_text()
        method = page.locator("#method").inner_text()
        step = page.locator("#step").inner_text()
        page.wait_for_function("implcViewer.ready")
        webgpu = page.evaluate("implcViewer.webgpu")
        problems = log.problems()
    score = ssim(frame, expected)
    print(f"torus first frame vs reference at {SIZE}^2: SSIM {score:.5f}")
    assert score >= SSIM_SAME
    agree = np.mean(background_mask(frame, BACKGROUND) == background_mask(expected, BACKGROUND))
    assert agree >= MASK_AGREEMENT
    assert re.fullmatch(r"\d+\.\d ms \(\d+\.\d fps\)", readout), readout
    assert method == METHOD and step == "no marching: exact root isolation"
    assert webgpu == "available"
    assert problems == []
    assert all(not url.startswith(("http:", "https:")) for url in requests), requests


@pytest.mark.parametrize(("example", "method", "step"), [
    ("gyroid", None, "no marching: interval bisection"),  # its default: interval
    ("torus", "exact", "no marching: exact root isolation"),
    ("torus", "taylor", "b = 0.01"),
])
def test_each_method_names_how_it_finds_roots(browser, tmp_path, example, method, step):
    """The readout under the method: a marcher's step, else the method's own way (the
    interval method is not an exact root isolation)."""
    page_path = write_page(tmp_path, example, method=method, webgpu=False)
    with open_page(browser, file_url(page_path, f"size={SMALL}")) as (page, log):
        wait_idle(page)
        shown = page.locator("#step").inner_text()
        problems = log.problems()
    assert shown == step and problems == []


def test_a_method_without_steps_says_how_it_finds_roots():
    for method in METHODS.values():
        marches = not (method.solves or method.bounds)
        assert bool(method.unmarched) != marches, method.name


@pytest.mark.parametrize(("example", "name", "value"), [
    ("torus", "r", "0.55"),
    ("torus", "R", "0.7"),
    ("kummer", "mu", "1.3"),
])
def test_slider_moves_the_parameter_like_param(browser, tmp_path, example, name, value):
    """Moving a slider redraws with the new value, without recompiling: the frame is the
    GL render of `--param name=value`, and differs from the first frame."""
    page_path = write_page(tmp_path, example)
    with open_page(browser, file_url(page_path, f"size={SMALL}")) as (page, log):
        frames = wait_idle(page)
        before = screenshot(page.locator("#gl-canvas"))
        slider = page.locator(f"#param-{name}")
        slider.fill(value)
        frames = wait_idle(page, frames)
        actual = slider.input_value()  # the browser snaps it to the slider's steps
        tick = float(slider.get_attribute("step"))
        after = screenshot(page.locator("#gl-canvas"))
        shown = page.evaluate(f"implcViewer.params[{name!r}]")
        assert log.problems() == []
    assert abs(float(actual) - float(value)) <= tick and shown == float(actual)
    surface = load_surface(example, params=[f"{name}={actual}"])
    expected = to_8bit(render(surface, "gl", METHOD, method_constants(), SMALL, SMALL).color)
    score, changed = ssim(after, expected), ssim(after, before)
    print(f"{example} {name}={actual}: SSIM {score:.5f} vs --param render, "
          f"{changed:.3f} vs the first frame")
    assert score >= SSIM_SAME
    assert changed < SSIM_CHANGED, "moving the slider did not change the picture"


def test_mouse_turns_pans_zooms_and_resets(browser, tmp_path):
    """A drag orbits about the target (distance kept), a right-drag pans (target moves),
    the wheel zooms; the turned frame is the GL render of the camera the page reports;
    a double-click is the first frame again."""
    page_path = write_page(tmp_path, "torus")
    with open_page(browser, file_url(page_path, f"size={SMALL}")) as (page, log):
        frames = wait_idle(page)
        first = screenshot(page.locator("#gl-canvas"))
        box = page.locator("#gl-canvas").bounding_box()
        cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(cx, cy)
        page.mouse.down()
        page.mouse.move(cx + 40, cy + 15, steps=4)
        page.mouse.up()
        frames = wait_idle(page, frames)
        turned = screenshot(page.locator("#gl-canvas"))
        cam = page.evaluate("implcViewer.camera")
        view = load_surface("torus").view
        assert cam["target"] == list(view.target)
        distance = np.linalg.norm(np.subtract(cam["eye"], cam["target"]))
        assert math.isclose(distance, np.linalg.norm(np.subtract(view.eye, view.target)),
                            rel_tol=1e-9)
        assert not np.allclose(cam["eye"], view.eye)
        turned_view = View(eye=tuple(cam["eye"]), target=tuple(cam["target"]),
                           up=tuple(cam["up"]), fov_y_deg=cam["fov_y"],
                           clip_center=view.clip_center, clip_radius=view.clip_radius)
        # right-drag pans
        page.mouse.move(cx, cy)
        page.mouse.down(button="right")
        page.mouse.move(cx + 10, cy, steps=2)
        page.mouse.up(button="right")
        frames = wait_idle(page, frames)
        panned = page.evaluate("implcViewer.camera")
        assert not np.allclose(panned["target"], cam["target"])
        assert np.allclose(np.subtract(panned["eye"], panned["target"]),
                           np.subtract(cam["eye"], cam["target"]))
        # the wheel zooms out
        page.mouse.wheel(0, 200)
        frames = wait_idle(page, frames)
        zoomed = page.evaluate("implcViewer.camera")
        assert np.linalg.norm(np.subtract(zoomed["eye"], zoomed["target"])) > distance * 1.1
        page.mouse.dblclick(cx, cy)
        wait_idle(page, frames)
        reset = screenshot(page.locator("#gl-canvas"))
        assert log.problems() == []
    expected = to_8bit(_gl_frame(load_surface("torus"), turned_view))
    score, changed = ssim(turned, expected), ssim(turned, first)
    print(f"orbited frame vs GL render of its camera: SSIM {score:.5f}; "
          f"vs the first frame {changed:.3f}")
    assert score >= SSIM_SAME
    assert changed < SSIM_CHANGED
    assert np.array_equal(reset, first)


def _gl_frame(surface, camera: View, width: int = SMALL, height: int = SMALL) -> np.ndarray:
    """The GL render of the surface's program (lights fixed by its [view], like the
    page's) seen from `camera` through the program's uniforms."""
    from conftest import require_gl

    from implc.emit import emit, render_template
    from implc.render.gl import GlRunner

    require_gl()
    fragment = emit(surface, "glsl", METHOD, method_constants(), flavor="330")
    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    runner = GlRunner(fragment, vertex, camera, width, height)
    try:
        return runner.frame().color
    finally:
        runner.release()


def test_a_portrait_stage_keeps_the_sides(browser, tmp_path):
    """Issue 44: `implc view torus` in a 900 x 700 window (a 600 x 700 stage beside the
    panel) cut the torus left and right: the page's camera kept the vertical field of
    view. The fov spans the stage's shorter side: the frame is the GL render at the
    canvas's size, and the torus touches neither side."""
    page_path = write_page(tmp_path, "torus")
    with open_page(browser, file_url(page_path), width=900, height=700) as (page, log):
        wait_idle(page)
        frame = screenshot(page.locator("#gl-canvas"), "view-portrait")
        width, height = page.evaluate("[document.getElementById('gl-canvas').width, "
                                      "document.getElementById('gl-canvas').height]")
        assert log.problems() == []
    assert height > width and frame.shape == (height, width, 3)
    surface = load_surface("torus")
    expected = to_8bit(_gl_frame(surface, surface.view, width, height))
    score = ssim(frame, expected)
    print(f"torus in a {width}x{height} stage vs GL render: SSIM {score:.5f}")
    assert score >= SSIM_SAME
    background = background_mask(frame, BACKGROUND)
    assert background[:, 0].all() and background[:, -1].all()
    assert np.mean(background == background_mask(expected, BACKGROUND)) >= MASK_AGREEMENT


def test_touch_orbits_and_pinch_zooms(browser, tmp_path):
    """Real touch input (Chromium's own touch events through the DevTools protocol): one
    finger orbits, two fingers spreading apart zoom in."""
    page_path = write_page(tmp_path, "torus")
    with open_page(browser, file_url(page_path, f"size={SMALL}")) as (page, log):
        frames = wait_idle(page)
        cdp = page.context.new_cdp_session(page)
        box = page.locator("#gl-canvas").bounding_box()
        x0, y0 = box["x"], box["y"]

        def touch(kind, *points):
            cdp.send("Input.dispatchTouchEvent", {"type": kind, "touchPoints": [
                {"x": x0 + x, "y": y0 + y, "id": i} for i, (x, y) in enumerate(points)]})

        home = page.evaluate("implcViewer.camera")
        d0 = np.linalg.norm(np.subtract(home["eye"], home["target"]))
        touch("touchStart", (60, 60))
        for x in (70, 80, 90):
            touch("touchMove", (x, 60))
        touch("touchEnd")
        frames = wait_idle(page, frames)
        orbited = page.evaluate("implcViewer.camera")
        assert not np.allclose(orbited["eye"], home["eye"])
        touch("touchStart", (50, 64), (78, 64))
        for spread in (10, 20, 30):
            touch("touchMove", (50 - spread, 64), (78 + spread, 64))
        touch("touchEnd")
        wait_idle(page, frames)
        pinched = page.evaluate("implcViewer.camera")
        d1 = np.linalg.norm(np.subtract(pinched["eye"], pinched["target"]))
        assert log.problems() == []
    assert d1 < 0.6 * d0, f"pinching out should zoom in ({d0:.3f} -> {d1:.3f})"


def test_copy_button_copies_the_running_shader(browser, tmp_path):
    capture = """
        window.__copied = [];
        Object.defineProperty(navigator, 'clipboard', {value: {
            writeText: async (text) => { window.__copied.push(text); }}});
    """
    surface = load_surface("torus")
    page_path = write_page(tmp_path, "torus")
    with open_page(browser, file_url(page_path, f"size={SMALL}"),
                   init_script=capture) as (page, log):
        wait_idle(page)
        page.locator("#copy").click()
        page.wait_for_function("window.__copied.length === 1")
        page.wait_for_function("implcViewer.ready")
        page.locator("#use-webgpu").click()
        page.locator("#copy").click()
        page.wait_for_function("window.__copied.length === 2")
        copied = page.evaluate("window.__copied")
        status = page.locator("#copy-status").inner_text()
        assert log.problems() == []
    from implc.emit import emit

    assert copied[0] == emit(surface, "glsl", METHOD, method_constants(), flavor="es300",
                             params="uniform")
    assert copied[1] == emit(surface, "wgsl", METHOD, method_constants(), params="uniform")
    assert status == "copied WGSL"


def test_webgpu_frame_is_the_wgpu_render(browser, tmp_path):
    """The WebGPU toggle: Chromium's Tint compiles the WGSL program and its frame is
    wgpu-py's render of the same program (lavapipe), after a slider moved too."""
    from test_wgsl import require_wgpu

    require_wgpu()
    page_path = write_page(tmp_path, "torus")
    with open_page(browser, file_url(page_path, f"size={SMALL}&backend=webgpu")) as (page, log):
        page.wait_for_function("implcViewer.ready")
        frames = wait_idle(page)
        assert page.evaluate("implcViewer.backend") == "webgpu"
        first = screenshot(page.locator("#gpu-canvas"))
        page.locator("#param-r").fill("0.5")
        wait_idle(page, frames)
        moved = screenshot(page.locator("#gpu-canvas"))
        assert log.problems() == []
    for image, params in ((first, []), (moved, ["r=0.5"])):
        surface = load_surface("torus", params=params)
        expected = to_8bit(render(surface, "wgpu", METHOD, method_constants(), SMALL, SMALL).color)
        score = ssim(image, expected)
        print(f"torus {params}: WebGPU (Chromium) vs wgpu-py: SSIM {score:.5f}")
        assert score >= SSIM_SAME
    assert ssim(first, moved) < SSIM_CHANGED
