"""The interval method's widening, measured on the real targets.

`-m interval` (implc/interval.py) widens each function's enclosure by its row's `error`
in implc/functions.py: ulps * 2^-22 * |value| + absolute. That is sound only if every
target's implementation of the function errs less, so each function is evaluated here in
float32 on Mesa llvmpipe (GLSL 330 through moderngl, a fullscreen pass into a one-channel
float framebuffer) and on PoCL (OpenCL C through pyopencl, `out[i] = f(in[i])`), spelled
as each target's printer spells it, at 262,144 float32 inputs per function (a dense
sample of the domain that matters for surfaces plus hard points: multiples of pi/2, 0,
+-1, tiny values), and compared with float64 numpy at the same float32 input.

The worst cases measured (llvmpipe: LLVM 15.0.6, 256 bits; PoCL 3, pthread, LLVM 15):
`rel` is the largest error relative to |exact| in units of 2^-23 where |exact| >= 1/2,
`abs` the largest absolute error where |exact| < 1/2, and `budget` the largest
|gpu - exact| / (ulps 2^-22 |exact| + absolute) over all inputs (the test's bound: <= 1).

| f    | error       | llvmpipe rel | abs     | budget | PoCL rel | abs     | budget |
|------|-------------|--------------|---------|--------|----------|---------|--------|
| acos | (16, 2^-11) | 1048.1       | 3.4e-05 | 0.32   | 0.6      | 1.7e-08 | 0.00   |
| asin | (16, 2^-10) | 3401.9       | 2.0e-04 | 0.40   | 0.7      | 1.9e-08 | 0.00   |
| atan | (16, 2^-18) | 35.9         | 1.5e-06 | 0.49   | 0.5      | 1.7e-08 | 0.01   |
| cos  | (8, 2^-21)  | 0.9          | 4.3e-08 | 0.04   | 0.9      | 4.1e-08 | 0.04   |
| cosh | (16, 0)     | 8.5          | 0       | 0.27   | 1.5      | 0       | 0.05   |
| exp  | (16, 0)     | 8.4          | 1.1e-07 | 0.30   | 0.6      | 2.3e-08 | 0.02   |
| log  | (16, 2^-21) | 1.9          | 9.2e-08 | 0.18   | 0.5      | 1.7e-08 | 0.02   |
| sin  | (8, 2^-21)  | 0.9          | 4.2e-08 | 0.04   | 1.0      | 4.1e-08 | 0.05   |
| sinh | (16, 2^-21) | 8.5          | 1.3e-07 | 0.27   | 1.5      | 1.6e-08 | 0.05   |
| sqrt | (4, 0)      | 0.5          | 1.5e-08 | 0.06   | 0.5      | 1.5e-08 | 0.06   |
| tan  | (16, 2^-21) | 1.8          | 6.3e-08 | 0.05   | 1.9      | 6.8e-08 | 0.05   |
| tanh | (16, 2^-21) | 1.8          | 1.4e-07 | 0.18   | 0.7      | 2.0e-08 | 0.02   |

WGSL on lavapipe (wgpu's Vulkan, a compute shader `out[i] = f(xs[i])`) measured as
llvmpipe to the digit (the same Mesa code generation): budgets 0.04-0.49, asin 0.40,
acos 0.32, atan 0.49. Chromium's SwiftShader is not measured here.

Mesa's asin, acos and atan are polynomial approximations (largest absolute errors on
llvmpipe 3.9e-4, 1.6e-4 and 3.4e-6): beyond the (16, 2^-21) these rows first had (budgets
85, 30 and 1.7), so their absolute part was raised to the least power of two that keeps
the measured error within half the widening (a 2x margin). PoCL errs by less than 2
units of 2^-23 relative everywhere. The sample stays on normal floats: a target may flush
subnormals to 0, which the widening's TINY (2^-126) covers, not a row's error.

Plain arithmetic, which implc/interval.py takes as IEEE 754 (+, -, * correctly rounded,
/ within 3 ulps): a*b and a+b equal numpy's correctly rounded float32 results bit for bit
on both targets, and 1/b is within 3 ulps of numpy's (random normal inputs; measured: 1/b
too is correctly rounded on both, 0 ulps).

Without moderngl's EGL context, PoCL or a wgpu adapter the tests of that backend skip,
and fail under CI=true (tests/conftest.py).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from conftest import require_gl
from test_opencl import require_opencl
from test_wgsl import require_wgpu

from implc.backends.glsl import GlslPrinter
from implc.backends.opencl import OpenclPrinter
from implc.functions import FUNCTIONS
from implc.interval import WIDENING

ULP = WIDENING["float"][0]  # 2^-22: the widening's unit, relative
EPS = 2.0**-23  # float32's epsilon: the unit the measurements are stated in
WIDTH, HEIGHT = 1024, 256  # the GL framebuffer; N inputs per function
N = WIDTH * HEIGHT
BACKENDS = ("gl", "cl", "wgpu")
X, Y = sympy.symbols("x y", real=True)

# Every row with an interval rule; those in DOMAINS (every row with a nonzero `error`, and
# one whose error were set to (0, 0) still) are measured.
ROWS = {row.name: row for row in FUNCTIONS if row.interval is not None}
# The sample's domain of each function: where surfaces use it, finite in float32.
DOMAINS = {
    "sin": (-50, 50), "cos": (-50, 50), "atan": (-50, 50), "tanh": (-50, 50),
    "tan": (-50, 50), "exp": (-20, 20), "sinh": (-20, 20), "cosh": (-20, 20),
    "asin": (-1, 1), "acos": (-1, 1), "log": (0, 1e4), "sqrt": (0, 1e4),
}
TAN_POLE_GAP = 1e-3  # tan is sampled at least this far from its poles pi/2 + k pi


# --------------------------------------------------------------------------- inputs


def _hard_points(low: float, high: float) -> np.ndarray:
    """Multiples of pi/2 and their float32 neighbours, 0, +-1, tiny values: in [low, high]."""
    k = np.arange(-40, 41)
    points = [k * np.pi / 2, k * np.pi / 4, [0.0, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0]]
    tiny = 2.0 ** np.arange(-126, 0, 3, dtype=np.float64)
    points += [tiny, -tiny, [1e-30, 1e-20, 1e-10, 1e-7, 1e-5, 1e-3]]
    points += [np.array([-1e-30, -1e-20, -1e-10, -1e-7, -1e-5, -1e-3])]
    values = np.concatenate([np.asarray(p, np.float64) for p in points]).astype(np.float32)
    steps = [values]
    for _ in range(3):  # three float32 neighbours on each side
        steps.append(np.nextafter(steps[-1], np.float32(np.inf)))
        steps.append(np.nextafter(steps[-2], np.float32(-np.inf)))
    values = np.unique(np.concatenate(steps))
    # no subnormals: a target may flush them to 0 (TINY's part of the widening)
    normal = (values == 0) | (np.abs(values) >= np.finfo(np.float32).tiny)
    return values[normal & (values >= low) & (values <= high)]


def sample(name: str) -> np.ndarray:
    """N float32 inputs for `name`: hard points, an even grid and seeded uniform points
    (log-spaced too on (0, 1e4] for log and sqrt)."""
    low, high = DOMAINS[name]
    rng = np.random.default_rng(sum(map(ord, name)))
    hard = _hard_points(low, high)
    rest = N - hard.size
    if low == 0:  # log, sqrt: (0, 1e4], dense in every binade down to float32's least normal
        grid = np.geomspace(2.0**-126, high, rest // 2)
        uniform = np.concatenate([10.0 ** rng.uniform(-6, 4, rest // 4),
                                  rng.uniform(0, high, rest - rest // 2 - rest // 4)])
    else:
        grid = np.linspace(low, high, rest // 2)
        uniform = rng.uniform(low, high, rest - rest // 2)
    x = np.concatenate([hard, grid.astype(np.float32), uniform.astype(np.float32)])
    if low == 0:
        x = np.where(x > 0, x, np.float32(1.0))
    if name == "tan":  # nudge points near a pole out to TAN_POLE_GAP from it
        x64 = x.astype(np.float64)
        pole = (np.floor(x64 / np.pi) + 0.5) * np.pi
        near = np.abs(x64 - pole) < TAN_POLE_GAP
        x = np.where(near, (pole + np.copysign(TAN_POLE_GAP, x64 - pole)), x64)
        x = x.astype(np.float32)
    assert x.shape == (N,) and np.isfinite(x).all()
    return x


# --------------------------------------------------------------------------- the targets


FRAGMENT = """#version 330 core
uniform sampler2D u_in;
out float result;
void main() {
    vec2 v = texelFetch(u_in, ivec2(gl_FragCoord.xy), 0).rg;
    float x = v.r;
    float y = v.g;
    result = EXPR;
}
"""

COMPUTE = """@group(0) @binding(0) var<storage, read> xs: array<f32>;
@group(0) @binding(1) var<storage, read> ys: array<f32>;
@group(0) @binding(2) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = xs[id.x];
    let y = ys[id.x];
    out[id.x] = EXPR;
}
"""

KERNEL = """__kernel void eval(__global const float *xs, __global const float *ys,
                   __global float *out) {
    size_t i = get_global_id(0);
    float x = xs[i];
    float y = ys[i];
    out[i] = EXPR;
}
"""


def run_gl(expr: sympy.Expr, x: np.ndarray, y: np.ndarray | None = None) -> np.ndarray:
    """`expr` of x (and y) in a GLSL 330 fragment shader on llvmpipe, one pixel per input."""
    from implc.emit import render_template

    ctx = require_gl()
    source = FRAGMENT.replace("EXPR", GlslPrinter().doprint(expr))
    y = np.zeros_like(x) if y is None else y
    data = np.stack([x, y], axis=-1).astype(np.float32).reshape(HEIGHT, WIDTH, 2)
    program = ctx.program(vertex_shader=render_template("glsl/fullscreen.vert.j2",
                                                        version="330 core"),
                          fragment_shader=source)
    vao = ctx.vertex_array(program, [])
    texture = ctx.texture((WIDTH, HEIGHT), 2, data.tobytes(), dtype="f4")
    target = ctx.texture((WIDTH, HEIGHT), 1, dtype="f4")
    fbo = ctx.framebuffer(color_attachments=[target])
    try:
        texture.use(0)
        if "u_in" in program:
            program["u_in"].value = 0
        fbo.use()
        fbo.viewport = (0, 0, WIDTH, HEIGHT)
        vao.render(mode=0x0004, vertices=3)  # GL_TRIANGLES
        ctx.finish()
        # row j of the framebuffer (gl_FragCoord.y = j + 0.5) read texture row j
        return np.frombuffer(fbo.read(components=1, dtype="f4"), np.float32).copy()
    finally:
        for obj in (fbo, target, texture, vao, program):
            obj.release()


def run_cl(expr: sympy.Expr, x: np.ndarray, y: np.ndarray | None = None) -> np.ndarray:
    """`expr` of x (and y) in an OpenCL C kernel on PoCL, one work-item per input, built
    as implc builds its programs (implc/devices.py)."""
    from implc.devices import import_pyopencl, opencl_build

    dev = require_opencl()
    cl = import_pyopencl()
    source = KERNEL.replace("EXPR", OpenclPrinter("float").doprint(expr))
    built = opencl_build(source)
    assert built.program is not None, f"PoCL rejected the kernel:\n{built.log}\n{source}"
    y = np.zeros_like(x) if y is None else y
    flags = cl.mem_flags
    xs = cl.Buffer(dev.context, flags.READ_ONLY | flags.COPY_HOST_PTR,
                   hostbuf=np.ascontiguousarray(x, np.float32))
    ys = cl.Buffer(dev.context, flags.READ_ONLY | flags.COPY_HOST_PTR,
                   hostbuf=np.ascontiguousarray(y, np.float32))
    out = np.empty(x.size, np.float32)
    result = cl.Buffer(dev.context, flags.WRITE_ONLY, out.nbytes)
    try:
        kernel = cl.Kernel(built.program, "eval")
        kernel.set_args(xs, ys, result)
        cl.enqueue_nd_range_kernel(dev.queue, kernel, (x.size,), None)
        cl.enqueue_copy(dev.queue, out, result)
        dev.queue.finish()
    finally:
        for buffer in (xs, ys, result):
            buffer.release()
    return out


def run_wgpu(expr: sympy.Expr, x: np.ndarray, y: np.ndarray | None = None) -> np.ndarray:
    """`expr` of x (and y) in a WGSL compute shader on lavapipe (wgpu's Vulkan), one
    invocation per input, on the device implc renders with (implc/devices.py)."""
    import wgpu

    from implc.backends.wgsl import WgslPrinter
    from implc.devices import wgpu_device

    require_wgpu()
    dev = wgpu_device()
    source = COMPUTE.replace("EXPR", WgslPrinter().doprint(expr))
    y = np.zeros_like(x) if y is None else y
    usage = wgpu.BufferUsage
    xs = dev.create_buffer_with_data(data=np.ascontiguousarray(x, np.float32),
                                     usage=usage.STORAGE)
    ys = dev.create_buffer_with_data(data=np.ascontiguousarray(y, np.float32),
                                     usage=usage.STORAGE)
    out = dev.create_buffer(size=4 * x.size, usage=usage.STORAGE | usage.COPY_SRC)
    pipeline = dev.create_compute_pipeline(
        layout="auto", compute={"module": dev.create_shader_module(code=source),
                                "entry_point": "main"})
    bind = dev.create_bind_group(layout=pipeline.get_bind_group_layout(0), entries=[
        {"binding": i, "resource": {"buffer": b, "offset": 0, "size": b.size}}
        for i, b in enumerate((xs, ys, out))])
    encoder = dev.create_command_encoder()
    compute = encoder.begin_compute_pass()
    compute.set_pipeline(pipeline)
    compute.set_bind_group(0, bind)
    compute.dispatch_workgroups(-(-x.size // 64))
    compute.end()
    dev.queue.submit([encoder.finish()])
    return np.frombuffer(dev.queue.read_buffer(out), np.float32).copy()


RUN = {"gl": run_gl, "cl": run_cl, "wgpu": run_wgpu}


# --------------------------------------------------------------------------- the check


def measure(name: str, got: np.ndarray, x: np.ndarray, error: tuple[float, float]) -> dict:
    """The errors of `got` (float32 results at inputs x) against float64 numpy at the same
    inputs: the worst relative (units of 2^-23, where |exact| >= 1/2), absolute (where
    |exact| < 1/2) and budget (error / the widening `error` allows), with its input."""
    exact = ROWS[name].numpy(x.astype(np.float64))
    got = got.astype(np.float64)
    err = np.abs(got - exact)
    err = np.where(np.isfinite(got), err, np.inf)  # a NaN or inf where exact is finite
    ulps, absolute = error
    allowed = ulps * ULP * np.abs(exact) + absolute
    with np.errstate(divide="ignore", invalid="ignore"):
        budget = np.where(err == 0, 0.0, err / allowed)
    big = np.abs(exact) >= 0.5
    worst = int(np.argmax(budget))
    return {
        "rel": float((err[big] / (np.abs(exact[big]) * EPS)).max()) if big.any() else 0.0,
        "abs": float(err[~big].max()) if (~big).any() else 0.0,
        "budget": float(budget[worst]),
        "at": float(x[worst]),
        "got": float(got[worst]),
        "exact": float(exact[worst]),
    }


def describe(backend: str, name: str, m: dict, error) -> str:
    return (f"{name} on {backend}: worst {m['rel']:.1f} ulps (2^-23, |f| >= 1/2), "
            f"{m['abs']:.3g} absolute (|f| < 1/2); budget {m['budget']:.3g} of the widening "
            f"{error} at x = {m['at']!r} (got {m['got']!r}, exact {m['exact']!r})")


def test_every_widened_row_is_measured():
    """A new row with an interval rule and an error gets a domain here (else unmeasured)."""
    widened = {name for name, row in ROWS.items() if any(row.error)}
    assert widened <= set(DOMAINS) <= set(ROWS), "give every widened row a domain (DOMAINS)"


@pytest.mark.parametrize("name", sorted(DOMAINS))
@pytest.mark.parametrize("backend", BACKENDS)
def test_function_errs_within_its_widening(backend, name):
    row = ROWS[name]
    x = sample(name)
    got = RUN[backend](row.build(X), x)
    m = measure(name, got, x, row.error)
    message = describe(backend, name, m, row.error)
    print(message)
    assert m["budget"] <= 1.0, f"beyond the widening of implc/functions.py: {message}"


def test_the_check_fails_beyond_the_widening():
    """The check can fail: float32-rounded sin (half an ulp off) exceeds a zero widening,
    and a result off by 2^-20 exceeds sin's own."""
    x = sample("sin")
    rounded = np.sin(x.astype(np.float64)).astype(np.float32)
    assert measure("sin", rounded, x, (0, 0))["budget"] > 1.0
    assert measure("sin", rounded, x, ROWS["sin"].error)["budget"] <= 1.0
    off = (rounded + np.float32(2.0**-20)).astype(np.float32)
    assert measure("sin", off, x, ROWS["sin"].error)["budget"] > 1.0
    nan = rounded.copy()
    nan[7] = np.nan
    assert measure("sin", nan, x, ROWS["sin"].error)["budget"] > 1.0


# --------------------------------------------------------------------------- arithmetic


def _operands() -> tuple[np.ndarray, np.ndarray]:
    """Random float32 pairs of either sign, magnitudes 2^-20 .. 2^20 (normal results)."""
    rng = np.random.default_rng(22)
    a = rng.uniform(1, 2, N) * 2.0 ** rng.integers(-20, 21, N) * rng.choice([-1, 1], N)
    b = rng.uniform(1, 2, N) * 2.0 ** rng.integers(-20, 21, N) * rng.choice([-1, 1], N)
    return a.astype(np.float32), b.astype(np.float32)


@pytest.mark.parametrize("op", ["a*b", "a+b", "1/b"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_arithmetic_is_correctly_rounded(backend, op):
    """implc/interval.py widens + and * by one rounding and / by 3 ulps."""
    a, b = _operands()
    expr, want, ulps = {
        "a*b": (X * Y, a * b, 0),
        "a+b": (X + Y, a + b, 0),
        "1/b": (1 / Y, np.float32(1) / b, 3),
    }[op]
    got = RUN[backend](expr, a, b)
    off = np.abs(got.astype(np.float64) - want.astype(np.float64)) / np.spacing(np.abs(want))
    off = np.where(np.isfinite(off), off, np.inf)
    worst = int(np.argmax(off))
    message = (f"{op} on {backend}: worst {off[worst]:.3g} ulps from the correctly rounded "
               f"result (a = {a[worst]!r}, b = {b[worst]!r}: got {got[worst]!r}, "
               f"numpy {want[worst]!r})")
    print(message)
    assert off[worst] <= ulps, message
