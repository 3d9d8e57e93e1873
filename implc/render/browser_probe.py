"""The float32 probe's browser drivers: Chromium's WebGL2 (ANGLE on SwiftShader) and
WebGPU (Dawn, Tint, SwiftShader's Vulkan), driven headlessly by Playwright, running the
programs render/eft_probe.py runs natively (templates/browser/eft_probe.html.j2).

The browser and its pages are implc/chromium.py's.
"""

from __future__ import annotations

import numpy as np

from ..chromium import evaluate, page, use_browser
from ..emit import render_template

__all__ = ["browser_driver", "run_webgl2", "run_webgpu", "use_browser"]


def _page():
    return page("probe", render_template("browser/eft_probe.html.j2"))


def _call(script: str, *args) -> list:
    return evaluate(_page(), script, *args)


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
