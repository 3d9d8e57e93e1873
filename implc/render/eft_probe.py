"""The float32 probe (`implc probe`): do the error-free transformations survive each
driver's compiler?

templates/eft.j2's EFTs return an error term that is zero in the reals, so a compiler
that reassociates or contracts float arithmetic may fold it away, and an fma that rounds
twice returns zero for it: a driver that does either would silently take back the extra
precision the exact method pays for. Each probe program (templates/<target>/eft_probe.*)
runs known inputs through the EFTs on one driver, reads the pairs back bit for bit, and
compares them with float64 arithmetic on the CPU (exact for these inputs). The inputs
reach the program as uniforms or buffers, never as constants, so no compiler can fold the
cases at compile time. The browser drivers (WebGL2 and WebGPU on SwiftShader) run the same
programs in render/browser_probe.py.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..emit import eft_probe_text, render_template
from ..errors import ToolError
from ..interrupts import signals_held
from ..targets import PROBES, Probe, get_target, resolve

# the probe's cases by number (templates/eft_probe.j2)
OPS = {"two_sum": 0, "fast_two_sum": 1, "two_prod_split": 2, "two_prod_fma": 3, "sum2": 4,
       "plain_sum": 5}
F32 = np.float32


@dataclass(frozen=True)
class Case:
    """One EFT on known float32 inputs (n: how many b a summation adds to a)."""

    eft: str
    a: float
    b: float
    n: int = 0

    @property
    def label(self) -> str:
        if self.eft in ("sum2", "plain_sum"):
            return f"{self.eft}({_num(self.a)} + {self.n} x {_num(self.b)})"
        return f"{self.eft}({_num(self.a)}, {_num(self.b)})"

    def exact(self) -> Fraction:
        """The real result the pair must sum to (exact for these inputs)."""
        a, b = Fraction(float(F32(self.a))), Fraction(float(F32(self.b)))
        if self.eft.startswith("two_prod"):
            return a * b
        if self.eft in ("sum2", "plain_sum"):
            return a + self.n * b
        return a + b

    def check(self, value: float, error: float) -> bool:
        """Whether the driver's pair is the EFT's: value rounded to nearest, value + error
        exact (plain_sum, the control, must lose what float32 loses, bit for bit)."""
        if self.eft == "plain_sum":
            s = F32(self.a)
            for _ in range(self.n):
                s = F32(s + F32(self.b))
            return value == s and error == 0.0
        total = Fraction(float(value)) + Fraction(float(error))
        if self.eft == "sum2":
            return total == self.exact()
        return value == F32(float(self.exact())) and total == self.exact()


# two_sum's and the brief's cases: 1 + 2^-30 loses 2^-30; (1 + 2^-12)^2 loses 2^-24;
# pi*e (float32 values, 24 significant bits each) needs the split's every bit; 1000 times
# 2^-25 added to 1 is lost whole in plain float32 (each is below half an ulp of 1)
CASES = (
    Case("two_sum", 1.0, 2.0**-30),
    Case("two_sum", 2.0**-30, 1.0),
    Case("fast_two_sum", 1.0, 2.0**-30),
    Case("two_prod_split", 1 + 2.0**-12, 1 + 2.0**-12),
    Case("two_prod_split", math.pi, math.e),
    Case("two_prod_fma", 1 + 2.0**-12, 1 + 2.0**-12),
    Case("two_prod_fma", math.pi, math.e),
    Case("sum2", 1.0, 2.0**-25, 1000),
    Case("plain_sum", 1.0, 2.0**-25, 1000),
)


def _num(x: float) -> str:
    """2^-30 for a power of two, 1+2^-12 for one more than one, else float32's shortest
    digits."""
    if x == 0:
        return "0"
    mantissa, exponent = math.frexp(abs(x))
    if mantissa == 0.5 and exponent != 1:
        return ("-" if x < 0 else "") + f"2^{exponent - 1}"
    if x > 1 and _num(x - 1).startswith("2^"):
        return f"1+{_num(x - 1)}"
    return str(F32(x))


@dataclass(frozen=True)
class Outcome:
    """One case on one driver: the pair read back and whether it is the EFT's."""

    case: Case
    value: float
    error: float
    ok: bool
    # the library relies on it (False: two_prod_fma where the language promises no
    # single-rounding fma, so two_prod splits instead; its outcome is a fact reported)
    relied_on: bool = True

    def render(self) -> str:
        want = self.case.exact() - Fraction(float(F32(float(self.case.exact()))))
        if self.case.eft == "plain_sum":
            what = f"sum {_num(self.value)} (control: what plain float32 keeps)"
        else:
            what = f"error {_num(self.error)} (exact: {_num(float(want))})"
            if self.case.eft == "sum2":
                what = f"sum {_num(self.value)} + {_num(self.error)}"
        verdict = "ok" if self.ok else "LOST"
        if not self.relied_on:
            verdict += " (fma rounds once)" if self.ok else " (fma rounds twice; two_prod splits)"
        return f"{self.case.label:<34} {what:<40} {verdict}"


@dataclass(frozen=True)
class Report:
    """The probe on one driver: its outcomes, or why it could not run."""

    probe: Probe
    driver: str
    outcomes: tuple[Outcome, ...] = ()
    unavailable: str = ""

    @property
    def ok(self) -> bool:
        return not self.unavailable and all(o.ok or not o.relied_on for o in self.outcomes)

    def render(self) -> str:
        head = f"{self.probe.title}\n  driver: {self.driver}"
        if self.unavailable:
            return f"{head}\n  not run: {self.unavailable}"
        return "\n".join([head, *("  " + o.render() for o in self.outcomes)])


def cases_for(target: str, flavor: str | None) -> tuple[Case, ...]:
    """The cases a flavour's program has (two_prod_fma only where it has fma)."""
    has_fma = bool(get_target(target).rules(flavor).fma)
    return tuple(c for c in CASES if c.eft != "two_prod_fma" or has_fma)


def probe_text(probe: Probe, count: int) -> str:
    return eft_probe_text(probe.target, probe.flavor, OPS, count)


def run_probe(probe: Probe, cases: Sequence[Case] | None = None) -> Report:
    """Run `probe`'s program on its driver (a ToolError from a missing driver becomes a
    report that says why it did not run)."""
    cases = tuple(cases or cases_for(probe.target, probe.flavor))
    rows = np.array([(OPS[c.eft], c.a, c.b, c.n) for c in cases], F32)
    try:
        driver = resolve(probe.driver)()
        pairs = resolve(probe.runner)(probe_text(probe, len(cases)), rows)
    except ToolError as err:
        return Report(probe, "unavailable", unavailable=str(err))
    exact_fma = get_target(probe.target).rules(probe.flavor).fma_exact
    outcomes = tuple(Outcome(c, float(v), float(e), c.check(float(v), float(e)),
                             c.eft != "two_prod_fma" or exact_fma)
                     for c, (v, e) in zip(cases, pairs, strict=True))
    return Report(probe, driver, outcomes)


def probes_for(backends: Sequence[str]) -> list[Probe]:
    return [p for p in PROBES if p.backend in backends]


# --------------------------------------------------------------------------- drivers


def _draw_uint(fragment: str, rows: np.ndarray) -> np.ndarray:
    """Draw the probe's fragment shader over a len(rows) x 1 unsigned framebuffer (the
    cases as the uniform array u_case) and read the pairs back as float32 bits."""
    from .gl import TRIANGLES, context

    ctx = context()
    vertex = render_template("glsl/fullscreen.vert.j2", version="330 core")
    try:
        with signals_held():
            program = ctx.program(vertex_shader=vertex, fragment_shader=fragment)
    except Exception as err:  # moderngl raises plain Exception subclasses
        raise ToolError(f"the GL driver rejected the probe: {err}") from err
    count = len(rows)
    texture = ctx.texture((count, 1), 4, dtype="u4")
    fbo = ctx.framebuffer(color_attachments=[texture])
    vao = ctx.vertex_array(program, [])
    try:
        program["u_case"].write(rows.astype(F32).tobytes())
        fbo.use()
        fbo.viewport = (0, 0, count, 1)
        with signals_held():
            vao.render(mode=TRIANGLES, vertices=3)
            data = fbo.read(components=4, dtype="u4")
    finally:
        for obj in (vao, fbo, texture, program):
            obj.release()
    return np.frombuffer(data, np.uint32).reshape(count, 4)[:, :2].copy().view(F32)


def run_gl(text: str, rows: np.ndarray) -> np.ndarray:
    """Backend gl: the GLSL program on OpenGL (moderngl, EGL; llvmpipe here)."""
    return _draw_uint(text, rows)


def run_hlsl(text: str, rows: np.ndarray) -> np.ndarray:
    """Backend hlsl-spirv: HLSL -> SPIR-V (glslang) -> GLSL (spirv-cross) -> OpenGL, as
    that backend renders."""
    from .hlsl_runner import hlsl_to_glsl

    return _draw_uint(hlsl_to_glsl(text), rows)


def gl_driver() -> str:
    from .gl import context

    info = context().info
    return f"{info.get('GL_RENDERER', '?')}; OpenGL {info.get('GL_VERSION', '?')}"


def run_wgpu(text: str, rows: np.ndarray) -> np.ndarray:
    """Backend wgpu: the WGSL compute shader on wgpu (Vulkan; lavapipe here)."""
    import wgpu

    from ..devices import wgpu_device

    dev = wgpu_device()
    usage = wgpu.BufferUsage
    try:
        module = dev.create_shader_module(code=text, label="implc.eft_probe")
        pipeline = dev.create_compute_pipeline(layout="auto",
                                               compute={"module": module, "entry_point": "main"})
    except Exception as err:  # wgpu's GPUError types
        raise ToolError(f"wgpu rejected the probe: {err}") from err
    cases = dev.create_buffer_with_data(data=rows.astype(F32).tobytes(), usage=usage.STORAGE)
    results = dev.create_buffer(size=len(rows) * 8, usage=usage.STORAGE | usage.COPY_SRC)
    group = dev.create_bind_group(layout=pipeline.get_bind_group_layout(0), entries=[
        {"binding": 0, "resource": {"buffer": cases}},
        {"binding": 1, "resource": {"buffer": results}}])
    encoder = dev.create_command_encoder()
    compute = encoder.begin_compute_pass()
    compute.set_pipeline(pipeline)
    compute.set_bind_group(0, group)
    compute.dispatch_workgroups(len(rows), 1, 1)
    compute.end()
    dev.queue.submit([encoder.finish()])
    data = dev.queue.read_buffer(results)
    return np.frombuffer(data, F32).reshape(len(rows), 2).copy()


def wgpu_driver() -> str:
    from ..devices import wgpu_device

    info = wgpu_device().adapter.info
    return (f"{info.get('device', '?')}; {info.get('backend_type', '')} "
            f"{info.get('description', '')} (lavapipe when the device is llvmpipe)")


def run_cl(text: str, rows: np.ndarray) -> np.ndarray:
    """Backend cl: the OpenCL C kernel in float (pyopencl; PoCL here)."""
    from ..devices import import_pyopencl, opencl_build, opencl_device

    cl = import_pyopencl()
    dev = opencl_device()
    built = opencl_build(text)
    if built.program is None:
        raise ToolError(f"the OpenCL driver rejected the probe:\n{built.log}")
    flags = cl.mem_flags
    cases = cl.Buffer(dev.context, flags.READ_ONLY | flags.COPY_HOST_PTR,
                      hostbuf=np.ascontiguousarray(rows, F32))
    out = np.zeros((len(rows), 2), F32)
    results = cl.Buffer(dev.context, flags.WRITE_ONLY, out.nbytes)
    kernel = cl.Kernel(built.program, "eft_probe")
    kernel.set_args(cases, results)
    cl.enqueue_nd_range_kernel(dev.queue, kernel, (len(rows),), None)
    cl.enqueue_copy(dev.queue, out, results)  # blocking: waits for the kernel
    return out


def cl_driver() -> str:
    from ..devices import opencl_device

    dev = opencl_device()
    platform = dev.device.platform  # type: ignore[attr-defined]
    return f"{dev.name}; {platform.version.strip()}"


def probe_all(backends: Sequence[str],
              progress: Callable[[Probe], None] | None = None) -> list[Report]:
    """The probe on every driver of `backends`, in the table's order."""
    reports = []
    for probe in probes_for(backends):
        if progress:
            progress(probe)
        reports.append(run_probe(probe))
    return reports
