"""Run a generated WGSL program headlessly with wgpu-py (Vulkan; lavapipe here).

The compute shader (templates/wgsl/program.wgsl.j2) writes colour into an rgba32float
storage texture and (hit, t, steps, |S|) into a storage buffer; `frame()` dispatches it,
copies both into mappable buffers in the same submission and maps them, which waits for
the GPU. Texture row 0 is the top of the image (WebGPU's texel (0, 0) is the first row in
memory), so nothing is flipped, unlike GL.

This module is not named `wgpu.py`: that would shadow the wgpu package.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..devices import wgpu_device
from ..emit import CompiledShader, ParamUniform
from ..errors import ToolError
from ..scene import View
from .result import RenderResult, TimedRunner

WORKGROUP = 8  # the workgroup size (8 x 8) in templates/wgsl/program.wgsl.j2
COLOR_FORMAT = "rgba32float"  # storage-writable in core WebGPU, and exact like GL's f4
UNIFORM_FLOATS = 20  # struct Uniforms: 80 bytes (docs/reference/drop-ins.md "Drop-in contract
# (WGSL)")


def uniform_block(view: View, width: int, height: int,
              params: Sequence[ParamUniform] = (), values: Mapping[str, float] | None = None,
              ) -> bytes:
    """The `Uniforms` block, laid out as the WGSL uniform address space requires
    (vec3<f32> aligned to 16 bytes): offsets 0 resolution, 8 fov_y (across the shorter
    side), 12 clip_radius, 16 eye, 32 target, 48 up, 64 clip_center (80 bytes); with
    `--params uniform` one f32 per parameter from offset 76 (`ParamUniform.offset`),
    rounded up to 16 bytes."""
    end = max([UNIFORM_FLOATS * 4] + [p.offset + 4 for p in params])
    data = np.zeros(-(-end // 16) * 4, np.float32)
    data[0:2] = (width, height)
    data[2] = view.fov_y_deg
    data[3] = view.clip_radius
    data[4:7] = view.eye
    data[8:11] = view.target
    data[12:15] = view.up
    data[16:19] = view.clip_center
    for p in params:
        data[p.offset // 4] = p.value if values is None else values[p.name]
    return data.tobytes()


class WgpuRunner(TimedRunner):
    """A compiled compute pipeline and its output resources; `frame()` renders once."""

    def __init__(self, program: str, view: View, width: int, height: int,
                 params: Sequence[ParamUniform] = ()):
        import wgpu

        dev = wgpu_device()
        self.device, self.width, self.height = dev, width, height
        self.view, self.params = view, tuple(params)
        self.values = {p.name: p.value for p in self.params}  # set_params keeps the rest
        aux_bytes = width * height * 16
        if aux_bytes > dev.limits["max-storage-buffer-binding-size"]:
            raise ToolError(f"wgpu: a {width}x{height} aux buffer ({aux_bytes} bytes) exceeds "
                            "the device's storage binding limit; render a smaller image")
        try:
            module = dev.create_shader_module(code=program, label="implc.wgsl")
            layout = dev.create_bind_group_layout(entries=[
                {"binding": 0, "visibility": wgpu.ShaderStage.COMPUTE,
                 "buffer": {"type": wgpu.BufferBindingType.uniform}},
                {"binding": 1, "visibility": wgpu.ShaderStage.COMPUTE,
                 "storage_texture": {"access": wgpu.StorageTextureAccess.write_only,
                                     "format": COLOR_FORMAT, "view_dimension": "2d"}},
                {"binding": 2, "visibility": wgpu.ShaderStage.COMPUTE,
                 "buffer": {"type": wgpu.BufferBindingType.storage}},
            ])
            self.pipeline = dev.create_compute_pipeline(
                layout=dev.create_pipeline_layout(bind_group_layouts=[layout]),
                compute={"module": module, "entry_point": "main"},
            )
        except Exception as err:
            raise ToolError(f"wgpu rejected the shader: {err}") from err
        usage = wgpu.BufferUsage
        self.uniforms = dev.create_buffer_with_data(
            data=uniform_block(view, width, height, self.params),
            usage=usage.UNIFORM | usage.COPY_DST)
        self.color = dev.create_texture(
            size=(width, height, 1), format=COLOR_FORMAT,
            usage=wgpu.TextureUsage.STORAGE_BINDING | wgpu.TextureUsage.COPY_SRC)
        self.aux = dev.create_buffer(size=aux_bytes, usage=usage.STORAGE | usage.COPY_SRC)
        # texture-to-buffer copies need rows padded to 256 bytes
        self.row_bytes = -(-width * 16 // 256) * 256
        self.color_read = dev.create_buffer(
            size=self.row_bytes * height, usage=usage.MAP_READ | usage.COPY_DST)
        self.aux_read = dev.create_buffer(size=aux_bytes, usage=usage.MAP_READ | usage.COPY_DST)
        self.bind_group = dev.create_bind_group(layout=layout, entries=[
            {"binding": 0, "resource": {"buffer": self.uniforms}},
            {"binding": 1, "resource": self.color.create_view()},
            {"binding": 2, "resource": {"buffer": self.aux}},
        ])

    def set_params(self, values: Mapping[str, float]) -> None:
        """New parameter values for the next frames (a `--params uniform` program): the
        uniform buffer is rewritten, nothing is compiled again."""
        unknown = set(values) - set(self.values)
        if unknown:
            raise KeyError(f"not a uniform parameter: {', '.join(sorted(unknown))}")
        self.values.update({k: float(v) for k, v in values.items()})
        self.device.queue.write_buffer(self.uniforms, 0, uniform_block(
            self.view, self.width, self.height, self.params, self.values))

    def draw(self) -> None:
        """Record and submit one frame, the compute pass and the copies out of it, and
        wait for it (a submit returns at once: without the wait, a timed frame would be
        the submit's cost, and the next one would wait for this one)."""
        encoder = self.device.create_command_encoder()
        compute = encoder.begin_compute_pass()
        compute.set_pipeline(self.pipeline)
        compute.set_bind_group(0, self.bind_group)
        compute.dispatch_workgroups(-(-self.width // WORKGROUP), -(-self.height // WORKGROUP), 1)
        compute.end()
        encoder.copy_texture_to_buffer(
            {"texture": self.color},
            {"buffer": self.color_read, "bytes_per_row": self.row_bytes,
             "rows_per_image": self.height},
            (self.width, self.height, 1),
        )
        encoder.copy_buffer_to_buffer(self.aux, 0, self.aux_read, 0, self.aux.size)
        self.device.queue.submit([encoder.finish()])
        # queue.on_submitted_work_done_sync fails inside wgpu-py 0.32 (a callback type
        # mismatch); reading 16 bytes back waits for the submitted work just as well
        self.device.queue.read_buffer(self.aux, 0, 16)

    def read(self) -> RenderResult:
        """Map the copies (this waits for the frame) into a RenderResult, row 0 on top."""
        import wgpu

        arrays = []
        for buffer, row in ((self.color_read, self.row_bytes), (self.aux_read, self.width * 16)):
            buffer.map_sync(wgpu.MapMode.READ)
            raw = np.frombuffer(buffer.read_mapped(), np.float32).reshape(self.height, row // 4)
            arrays.append(raw[:, : self.width * 4].reshape(self.height, self.width, 4).copy())
            buffer.unmap()
        color, aux = arrays
        return RenderResult.from_buffers(color, aux)

    def release(self) -> None:
        for buffer in (self.uniforms, self.aux, self.color_read, self.aux_read):
            buffer.destroy()
        self.color.destroy()


def open_wgpu_runner(shader: CompiledShader, view: View, width: int,
                     height: int) -> WgpuRunner:
    """Runner factory of backend `wgpu`: compile the WGSL program (a `--params uniform`
    shader's parameters are uniform fields, moved by `set_params`)."""
    return WgpuRunner(shader.text, view, width, height, shader.uniforms)
