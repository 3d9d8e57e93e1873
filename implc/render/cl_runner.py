"""Run a generated OpenCL C program with pyopencl (PoCL on the CPU here).

The program's `render` kernel runs one work-item per pixel and writes two float4 buffers,
colour and aux (hit, t, steps, |S|), row 0 on top like every runner. The OpenCL device,
context and built programs are shared per process: `validate_opencl` and the runners
build through `build()`, so a source built once (e.g. a golden, then its render) is not
built again.

Precision is a backend choice, not an argument: `cl` runs the float program and
`cl-double` the double one (registry entries in run.BACKENDS), so the runner factory
signature stays the same for every backend.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..emit import emit
from ..errors import ToolError
from ..methods import Constants
from ..resources import data_dir
from ..scene import View
from ..surface import Surface
from .result import RenderResult, TimedRunner

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


def _pyopencl():
    try:
        import pyopencl
    except ImportError as err:  # pragma: no cover - depends on the install
        raise ToolError("pyopencl is not installed (run `make setup`)") from err
    return pyopencl


@lru_cache(maxsize=1)
def device() -> Device:
    """The first device, PoCL's first, that can build a kernel.

    One per process: creating a context and loading the driver costs ~0.1 s. A device
    must build a probe kernel to be chosen: the PoCL wheel's LLVM 14 cannot name recent
    CPUs (an AMD Zen 5 fails every build with "unknown target CPU 'generic'"), while
    Debian's PoCL (pocl-opencl-icd, LLVM 15) picks its nearest kernel-library variant.
    """
    cl = _pyopencl()
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
def build(source: str) -> Build:
    """Build `source` for the device (cached per text for the whole process)."""
    cl = _pyopencl()
    dev = device()
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


def _vector3(values, precision: str):
    cl = _pyopencl()
    make = cl.cltypes.make_double3 if precision == "double" else cl.cltypes.make_float3
    return make(*(float(v) for v in values))


class ClRunner(TimedRunner):
    """A built program, its kernel and output buffers; `frame()` renders and reads back."""

    def __init__(self, source: str, view: View, width: int, height: int,
                 precision: str = "float"):
        cl = _pyopencl()
        dev = device()
        if precision == "double" and not dev.has_fp64:
            raise ToolError(f"the OpenCL device ({dev.name}) has no {FP64}: "
                            "double precision cannot run on it")
        built = build(source)
        if built.program is None:
            raise ToolError(f"the OpenCL driver rejected the program:\n{built.log}")
        self.queue = dev.queue
        self.width, self.height = width, height
        self.kernel = cl.Kernel(built.program, "render")
        nbytes = width * height * 4 * np.dtype(np.float32).itemsize
        self.color = cl.Buffer(dev.context, cl.mem_flags.WRITE_ONLY, nbytes)
        self.aux = cl.Buffer(dev.context, cl.mem_flags.WRITE_ONLY, nbytes)
        real = np.float64 if precision == "double" else np.float32
        self.kernel.set_args(
            _vector3(view.eye, precision),
            _vector3(view.target, precision),
            _vector3(view.up, precision),
            real(view.fov_y_deg),
            np.int32(width),
            np.int32(height),
            _vector3(view.clip_center, precision),
            real(view.clip_radius),
            self.color,
            self.aux,
        )

    def draw(self) -> None:
        """Run the kernel over every pixel and wait for it, without reading back."""
        cl = _pyopencl()
        cl.enqueue_nd_range_kernel(self.queue, self.kernel, (self.width, self.height), None)
        self.queue.finish()

    def read(self) -> RenderResult:
        cl = _pyopencl()
        shape = (self.height, self.width, 4)
        color = np.empty(shape, np.float32)
        aux = np.empty(shape, np.float32)
        cl.enqueue_copy(self.queue, color, self.color)
        cl.enqueue_copy(self.queue, aux, self.aux)
        self.queue.finish()
        # row j of the buffers is image row j (top first): no flip
        return RenderResult.from_buffers(color, aux)

    def release(self) -> None:
        self.color.release()
        self.aux.release()


def open_cl_runner(surface: Surface, method: str, constants: Constants, width: int,
                   height: int, precision: str = "float") -> ClRunner:
    """Runner factory of backend `cl` (float) and, with precision="double", `cl-double`."""
    source = emit(surface, "opencl", method, constants, precision=precision)
    return ClRunner(source, surface.view, width, height, precision)


def open_cl_double_runner(surface: Surface, method: str, constants: Constants, width: int,
                          height: int) -> ClRunner:
    return open_cl_runner(surface, method, constants, width, height, "double")
