"""Run a generated OpenCL C program with pyopencl (PoCL on the CPU here).

The program's `render` kernel runs one work-item per pixel and writes two float4 buffers,
colour and aux (hit, t, steps, |S|), row 0 on top like every runner. The device and the
built programs are implc/devices.py's, shared with `validate_opencl`, so a source built
once (e.g. a golden, then its render) is not built again.

Precision is a backend choice, not an argument: `cl` runs the float program and
`cl-double` the double one (two backends of the opencl record in implc/targets.py), so
the runner factory signature stays the same for every backend.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..devices import FP64, import_pyopencl, opencl_build, opencl_device
from ..emit import CompiledShader, ParamUniform
from ..errors import ToolError
from ..scene import View
from .result import RenderResult, TimedRunner


def _vector3(values, precision: str):
    cl = import_pyopencl()
    make = cl.cltypes.make_double3 if precision == "double" else cl.cltypes.make_float3
    return make(*(float(v) for v in values))


class ClRunner(TimedRunner):
    """A built program, its kernel and output buffers; `frame()` renders and reads back."""

    def __init__(self, source: str, view: View, width: int, height: int,
                 precision: str = "float", params: Sequence[ParamUniform] = ()):
        cl = import_pyopencl()
        dev = opencl_device()
        if precision == "double" and not dev.has_fp64:
            raise ToolError(f"the OpenCL device ({dev.name}) has no {FP64}: "
                            "double precision cannot run on it")
        built = opencl_build(source)
        if built.program is None:
            raise ToolError(f"the OpenCL driver rejected the program:\n{built.log}")
        self.queue = dev.queue
        self.width, self.height = width, height
        self.kernel = cl.Kernel(built.program, "render")
        nbytes = width * height * 4 * np.dtype(np.float32).itemsize
        self.color = cl.Buffer(dev.context, cl.mem_flags.WRITE_ONLY, nbytes)
        self.aux = cl.Buffer(dev.context, cl.mem_flags.WRITE_ONLY, nbytes)
        self.real = real = np.float64 if precision == "double" else np.float32
        args = [
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
        ]
        # --params uniform: the parameters are the kernel arguments after aux
        self.param_index = {p.name: len(args) + i for i, p in enumerate(params)}
        self.kernel.set_args(*args, *(real(p.value) for p in params))

    def set_params(self, values: Mapping[str, float]) -> None:
        """New parameter values for the next frames (a `--params uniform` program): set
        as kernel arguments, nothing is built again."""
        for name, value in values.items():
            self.kernel.set_arg(self.param_index[name], self.real(value))

    def draw(self) -> None:
        """Run the kernel over every pixel and wait for it, without reading back."""
        cl = import_pyopencl()
        cl.enqueue_nd_range_kernel(self.queue, self.kernel, (self.width, self.height), None)
        self.queue.finish()

    def read(self) -> RenderResult:
        cl = import_pyopencl()
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


def open_cl_runner(shader: CompiledShader, view: View, width: int, height: int) -> ClRunner:
    """Runner factory of backends `cl` (float) and `cl-double` (a `--params uniform`
    shader's parameters are kernel arguments, moved by `set_params`)."""
    return ClRunner(shader.text, view, width, height, shader.precision, shader.uniforms)
