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
"""

from __future__ import annotations

import os
import shutil

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
