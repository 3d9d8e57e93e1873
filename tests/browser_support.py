"""Helpers of the browser tests: open a page with its console watched, read pixels back.

The `browser` fixture (tests/conftest.py) is one headless Chromium per session; each test
opens its own page (a fresh context, so no state leaks between tests) and closes it.
"""

from __future__ import annotations

import io
import os
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from skimage.metrics import structural_similarity

# SwiftShader is a CPU renderer on 2 shared cores: a first frame with shader compile can
# take seconds, and with a second test suite running beside it a WebGPU pipeline
# took over 120 s: waits are generous; a healthy page finishes far sooner.
TIMEOUT_MS = 300_000


@dataclass
class PageLog:
    """What the page said: console errors and warnings, uncaught exceptions."""

    errors: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    exceptions: list[str] = field(default_factory=list)

    def problems(self) -> list[str]:
        return self.exceptions + self.errors


@contextmanager
def open_page(browser, url: str, width: int = 900, height: int = 700,
              init_script: str | None = None):
    context = browser.new_context(viewport={"width": width, "height": height},
                                  device_scale_factor=1)
    page = context.new_page()
    page.set_default_timeout(TIMEOUT_MS)
    log = PageLog()

    def console(message) -> None:
        if message.type == "error":
            log.errors.append(message.text)
        elif message.type == "warning":
            log.warnings.append(message.text)

    page.on("console", console)
    page.on("pageerror", lambda err: log.exceptions.append(str(err)))
    if init_script:
        page.add_init_script(init_script)
    try:
        page.goto(url)
        yield page, log
    finally:
        context.close()


def file_url(path: Path, query: str = "") -> str:
    return Path(path).resolve().as_uri() + (f"?{query}" if query else "")


def screenshot(locator, name: str = "") -> np.ndarray:
    """An element as the user sees it: float RGB in [0, 1], shape (H, W, 3), row 0 on top.

    With IMPLC_SCREENSHOTS=DIR set, a named screenshot is also saved there as NAME.png
    (to look at what a test saw)."""
    from PIL import Image

    png = locator.screenshot()
    keep = os.environ.get("IMPLC_SCREENSHOTS")
    if keep and name:
        Path(keep).mkdir(parents=True, exist_ok=True)
        (Path(keep) / f"{name}.png").write_bytes(png)
    image = Image.open(io.BytesIO(png)).convert("RGB")
    return np.asarray(image, dtype=np.float64) / 255.0


def read_png(path: Path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255.0


def to_8bit(color: np.ndarray) -> np.ndarray:
    """A float render as the PNG writer stores it (round(clip(c) * 255) / 255)."""
    return np.round(np.clip(color, 0.0, 1.0) * 255.0) / 255.0


def ssim(a: np.ndarray, b: np.ndarray) -> float:
    assert a.shape == b.shape, f"image sizes differ: {a.shape} vs {b.shape}"
    return float(structural_similarity(a, b, channel_axis=-1, data_range=1.0))


def background_mask(image: np.ndarray, background, tol: float = 1.5 / 255) -> np.ndarray:
    """Pixels that show the background colour (within 8-bit rounding)."""
    return np.all(np.abs(image - np.asarray(background)) <= tol, axis=-1)
