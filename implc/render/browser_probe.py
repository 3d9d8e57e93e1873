"""The float32 probe's browser drivers: Chromium's WebGL2 (ANGLE on SwiftShader) and
WebGPU (Dawn, Tint, SwiftShader's Vulkan), driven headlessly by Playwright, running the
programs render/eft_probe.py runs natively (templates/browser/eft_probe.html.j2).

One browser per process, started at first use (or the caller's, `use_browser`: the test
session's), closed at exit.
"""

from __future__ import annotations

import atexit
import tempfile
from pathlib import Path

import numpy as np

from ..chromium import CHROMIUM_ENV, CHROMIUM_FLAGS, chromium_path
from ..emit import render_template
from ..errors import ToolError

_state: dict[str, object] = {}
TIMEOUT_MS = 120_000  # SwiftShader on shared cores: a first compile can take seconds


def use_browser(browser) -> None:
    """Run the probe in `browser` (a Playwright Browser the caller owns) from now on."""
    _state.clear()
    _state["browser"] = browser


def _browser():
    if "browser" in _state:
        return _state["browser"]
    try:
        from playwright.sync_api import sync_playwright
    except ImportError as err:
        raise ToolError("playwright is not installed (pip install playwright; the browser "
                        "itself is the system's chromium)") from err
    path = chromium_path()
    if path is None:
        raise ToolError(f"no chromium on PATH (install it, or set {CHROMIUM_ENV})")
    playwright = sync_playwright().start()
    try:
        browser = playwright.chromium.launch(executable_path=path, args=list(CHROMIUM_FLAGS))
    except Exception as err:  # playwright's Error: the browser did not start
        playwright.stop()
        raise ToolError(f"{path} did not start: {str(err).splitlines()[0]}") from err
    atexit.register(playwright.stop)
    atexit.register(browser.close)
    _state["browser"] = browser
    return browser


def _page():
    """The probe's page, opened once per browser."""
    if "page" not in _state:
        directory = Path(tempfile.mkdtemp(prefix="implc-probe-"))
        page_file = directory / "probe.html"
        page_file.write_text(render_template("browser/eft_probe.html.j2"), encoding="utf-8")
        page = _browser().new_page()
        page.set_default_timeout(TIMEOUT_MS)
        page.goto(page_file.as_uri())
        _state["page"] = page
    return _state["page"]


def _call(script: str, *args) -> list:
    try:
        return _page().evaluate(script, list(args))
    except ToolError:
        raise
    except Exception as err:  # a JS exception: no WebGL2, no adapter, a compile error
        raise ToolError(f"chromium: {str(err).splitlines()[0]}") from err


def _pairs(bits: list, count: int) -> np.ndarray:
    return np.array(bits, np.uint32).reshape(count, 2).view(np.float32)


def run_webgl2(text: str, rows: np.ndarray) -> np.ndarray:
    """Backend webgl2: the GLSL ES 3.00 program in Chromium's WebGL2."""
    vertex = render_template("glsl/fullscreen.vert.j2", version="300 es")
    bits = _call("([v, f, c]) => implcProbe.webgl2(v, f, c)", vertex, text,
                 [float(x) for x in rows.ravel()])
    return _pairs(bits, len(rows))


def run_webgpu(text: str, rows: np.ndarray) -> np.ndarray:
    """Backend webgpu: the WGSL program in Chromium's WebGPU."""
    bits = _call("([code, c]) => implcProbe.webgpu(code, c)", text,
                 [float(x) for x in rows.ravel()])
    return _pairs(bits, len(rows))


def browser_driver() -> str:
    return str(_call("() => implcProbe.driver()"))
