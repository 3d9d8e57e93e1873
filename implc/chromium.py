"""Headless Chromium as implc drives it (the float32 probe's browser drivers, the browser
tests): where the browser is, and the flags that give it WebGL2 and WebGPU on this
GPU-less machine.

WebGL2 runs through ANGLE on SwiftShader, and WebGPU through Dawn on SwiftShader's
Vulkan. `--enable-unsafe-webgpu` and `--use-webgpu-adapter=swiftshader` give WebGPU an
adapter; presenting to a WebGPU canvas also needs `--enable-features=Vulkan
--use-vulkan=swiftshader` (without them compute work runs but a canvas frame fails with
"A valid external Instance reference no longer exists"). `--allow-file-access-from-files`
lets a file:// page import the ES modules beside it (module scripts need CORS, which
file:// lacks).

One browser per process, started at first use by Playwright (or the caller's,
`use_browser`: the test session's) and closed at exit; the float32 probe and the browser
render backends open their pages in it.
"""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from pathlib import Path

from .errors import ToolError

CHROMIUM_FLAGS = (
    "--enable-unsafe-webgpu",
    "--use-webgpu-adapter=swiftshader",
    "--enable-features=Vulkan",
    "--use-vulkan=swiftshader",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--allow-file-access-from-files",
)
CHROMIUM_ENV = "IMPLC_CHROMIUM"  # the browser's path, when it is not `chromium` on PATH


def chromium_path() -> str | None:
    """The system Chromium (Debian's `chromium`; IMPLC_CHROMIUM overrides), or None."""
    return (os.environ.get(CHROMIUM_ENV) or shutil.which("chromium")
            or shutil.which("chromium-browser"))


_state: dict[str, object] = {}


def use_browser(browser) -> None:
    """Open pages in `browser` (a Playwright Browser the caller owns) from now on."""
    _state.clear()
    _state["browser"] = browser


def browser():
    """The process's headless Chromium (a Playwright Browser), started at first use."""
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
        started = playwright.chromium.launch(executable_path=path, args=list(CHROMIUM_FLAGS))
    except Exception as err:  # playwright's Error: the browser did not start
        playwright.stop()
        raise ToolError(f"{path} did not start: {str(err).splitlines()[0]}") from err
    atexit.register(playwright.stop)
    atexit.register(started.close)
    _state["browser"] = started
    return started


TIMEOUT_MS = 300_000  # SwiftShader on shared cores: a compile or a frame can take minutes


def page(name: str, html: str):
    """The page `name` (its text `html`, written to a temporary file and opened), once per
    browser: the float32 probe's, the render backends'."""
    opened = browser()  # before the pages: a first browser() starts from no state
    pages = _state.setdefault("pages", {})
    assert isinstance(pages, dict)
    if name not in pages:
        tab = opened.new_page()
        page_file = Path(tempfile.mkdtemp(prefix=f"implc-{name}-")) / f"{name}.html"
        page_file.write_text(html, encoding="utf-8")
        tab.set_default_timeout(TIMEOUT_MS)
        tab.goto(page_file.as_uri())
        pages[name] = tab
    return pages[name]


def evaluate(tab, script: str, *args):
    """`script` called with `args` in the page `tab`; a JavaScript exception (no WebGL2,
    no adapter, a compile error) becomes a ToolError carrying its first line."""
    try:
        return tab.evaluate(script, list(args))
    except ToolError:
        raise
    except Exception as err:  # playwright's Error
        raise ToolError(f"chromium: {str(err).strip().splitlines()[0]}") from err
