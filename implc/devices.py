"""The driver sessions that validate and render share: one OpenCL device (with a cache of
built programs) and one wgpu device per process.

Both stages compile the same shader text on the same driver (`implc compile --validate`
then `render`, a golden's build then its render), so the sessions sit below both of them
(docs/explanation/architecture.md "Layers") instead of in one stage and imported by the
other. Opening them
costs 0.1-0.5 s, hence one each per process; a missing driver is a `ToolError`.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache

from .errors import ToolError
from .interrupts import signals_held
from .resources import data_dir

# --------------------------------------------------------------------------- OpenCL

POCL = "Portable Computing Language"
FP64 = "cl_khr_fp64"


@dataclass(frozen=True)
class Device:
    """The OpenCL device implc builds and runs on, with its context and queue."""

    context: object  # pyopencl.Context
    queue: object  # pyopencl.CommandQueue
    device: object  # pyopencl.Device

    @property
    def name(self) -> str:
        return f"{self.device.platform.name.strip()}: {self.device.name.strip()}"

    @property
    def has_fp64(self) -> bool:
        return FP64 in self.device.extensions.split()


def import_pyopencl():
    try:
        with signals_held():  # a nanobind module: a signal inside its import aborts
            import pyopencl
    except ImportError as err:  # pragma: no cover - depends on the install
        raise ToolError("pyopencl is not installed (run `make setup`)") from err
    return pyopencl


@lru_cache(maxsize=1)
def opencl_device() -> Device:
    """The first device, PoCL's first, that can build a kernel.

    One per process: creating a context and loading the driver costs ~0.1 s. A device
    must build a probe kernel to be chosen: the PoCL wheel's LLVM 14 cannot name recent
    CPUs (an AMD Zen 5 fails every build with "unknown target CPU 'generic'"), while
    Debian's PoCL (pocl-opencl-icd, LLVM 15) picks its nearest kernel-library variant.
    """
    cl = import_pyopencl()
    try:
        platforms = cl.get_platforms()
    except cl.Error as err:
        raise ToolError(f"no OpenCL platform found ({err}); install pocl-binary-distribution "
                        "(run `make setup`)") from err
    platforms = sorted(platforms, key=lambda p: p.name.strip() != POCL)
    probe = (data_dir("templates") / "opencl" / "probe.cl").read_text(encoding="utf-8")
    failures = []
    for platform in platforms:
        for dev in platform.get_devices():
            context = cl.Context(devices=[dev])
            try:
                with _quiet_stderr():
                    cl.Program(context, probe).build()
            except cl.Error as err:
                failures.append(f"{dev.name.strip()}: {str(err).strip().splitlines()[-1]}")
                continue
            return Device(context, cl.CommandQueue(context), dev)
    detail = "; ".join(failures) if failures else "none found"
    raise ToolError(f"no OpenCL device that builds kernels ({detail}); install Debian's "
                    "pocl-opencl-icd or pocl-binary-distribution (`make setup`)")


@dataclass(frozen=True)
class Build:
    """The outcome of building one source: the program (None on failure) and the log."""

    program: object | None
    log: str


@contextmanager
def _quiet_stderr() -> Iterator[None]:
    """Hide what the driver prints straight to fd 2 ("1 error generated."): the same
    messages are in the build log, which is what implc reports."""
    saved = os.dup(2)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
            yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


@lru_cache(maxsize=64)
def opencl_build(source: str) -> Build:
    """Build `source` for the device (cached per text for the whole process)."""
    cl = import_pyopencl()
    dev = opencl_device()
    program = cl.Program(dev.context, source)
    with warnings.catch_warnings(), _quiet_stderr():
        warnings.simplefilter("ignore")  # pyopencl's CompilerWarning repeats the log
        try:
            program.build()
            ok = True
        except cl.Error:
            ok = False
    log = program.get_build_info(dev.device, cl.program_build_info.LOG) or ""
    return Build(program if ok else None, log.strip())


# --------------------------------------------------------------------------- wgpu


@lru_cache(maxsize=1)
def wgpu_device():
    """One wgpu device per process (creating one costs ~0.5 s on lavapipe).

    Asks for the adapter's largest storage binding so big frames fit the aux buffer.
    """
    os.environ.setdefault("XDG_RUNTIME_DIR", "/tmp")
    try:
        import wgpu
    except ImportError as err:  # pragma: no cover - depends on the install
        raise ToolError("wgpu is not installed (run `make setup`)") from err
    _vulkan_only()
    try:
        adapter = wgpu.gpu.request_adapter_sync(power_preference="low-power")
    except Exception as err:  # wgpu raises RuntimeError or its own GPUError types
        raise ToolError(f"no wgpu adapter (install mesa-vulkan-drivers): {err}") from err
    if adapter is None:
        raise ToolError("no wgpu adapter (install mesa-vulkan-drivers for lavapipe)")
    limits = {
        key: adapter.limits[key]
        for key in ("max-storage-buffer-binding-size", "max-buffer-size")
        if key in adapter.limits
    }
    try:
        return adapter.request_device_sync(required_limits=limits)
    except Exception as err:
        raise ToolError(f"cannot create a wgpu device: {err}") from err


def _vulkan_only() -> None:
    """Keep wgpu off its GL backend: probing it through EGL makes wgpu's own context
    current and breaks moderngl's in the same process (GL and wgpu render side by side in
    tests and `bench`). Only possible before wgpu creates its instance."""
    try:
        from wgpu.backends.wgpu_native.extras import set_instance_extras

        set_instance_extras(backends=["Vulkan"])
    except (ImportError, RuntimeError):  # another wgpu user created the instance first
        pass

