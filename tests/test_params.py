"""`--params uniform`: parameters stay symbols and become uniforms the host sets.

- the symbolic expression is the substituted one once the values are put back (every
  bundled example with parameters, numerically at seeded random points);
- every uniform emit validates with its real compiler, and declares what the drop-in page says;
- OpenCL threads them as a Params argument: its emits validate, and a user kernel that
  pastes the library passes new values per launch and lands on the torus's exact roots;
- a runner opened once renders new parameter values through set_params without compiling
  again, and each frame is the constant-parameter render of those values (the same
  algorithm with the same values: they differ only by float32 rounding of the folded
  constants, so the hit masks agree on >= 99.9 % of the pixels and SSIM >= 0.999).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
import sympy
from conftest import require_backend, require_gl
from test_cli import implc

from implc.emit import emit, param_uniforms
from implc.errors import InputError, OptionError
from implc.front import param_symbol
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.metrics import compare
from implc.render.run import open_runner, render
from implc.surface import example_paths
from implc.symbols import X, Y, Z

WITH_PARAMS = [n for n in example_paths() if load_surface(n).params]
SIZE = 64


def hessian():
    return METHODS["hessian"].defaults


def test_examples_with_parameters_exist():
    assert {"torus", "kummer", "sphere", "gyroid", "barth-sextic"} <= set(WITH_PARAMS)


@pytest.mark.parametrize("example", WITH_PARAMS)
def test_symbolic_expression_is_the_substituted_one(example):
    surface = load_surface(example)
    assert {s.name for s in surface.symbolic.free_symbols} - {"x", "y", "z"} == set(
        surface.params)
    back = surface.symbolic.xreplace({param_symbol(k): v for k, v in surface.params.items()})
    rng = np.random.default_rng(7)
    for point in rng.uniform(-1.2, 1.2, size=(6, 3)):
        at = dict(zip((X, Y, Z), (sympy.Float(c) for c in point), strict=True))
        a, b = float(back.xreplace(at)), float(surface.expr.xreplace(at))
        assert a == pytest.approx(b, rel=1e-9, abs=1e-9)


def test_constant_exponents_keep_their_value_variable_ones_stay_symbols():
    surface = load_surface(equation="x^n + y^2 + z^2 - a^2 + exp(-k x^2)",
                           params=["n=2", "a=0.8", "k=3"])
    assert surface.uniform_params() == ["a", "k"]  # n decides what x^n means: baked
    text = emit(surface, "glsl", "sign", METHODS["sign"].defaults, params="uniform")
    assert "u_param_a" in text and "u_param_k" in text and "u_param_n" not in text
    assert "x*x" in text or "x_2" in text


def test_constant_is_the_default_and_unchanged():
    surface = load_surface("torus")
    assert emit(surface) == emit(surface, params="constant")
    assert "u_param" not in emit(surface)
    assert "uniform float u_param_R;" in emit(surface, params="uniform")


@pytest.mark.parametrize("flavor", ["330", "450", "es300"])
@pytest.mark.parametrize("example", ["torus", "kummer"])
def test_glsl_uniform_programs_validate(flavor, example):
    from implc.validate import validate_text

    surface = load_surface(example)
    text = emit(surface, "glsl", "hessian", hessian(), flavor=flavor, params="uniform")
    for p in param_uniforms(surface, "glsl"):
        assert re.search(rf"^uniform float {p.uniform};", text, re.M)
    verdict = validate_text(text, "glsl", f"{example}.frag")
    assert verdict.ok, verdict.render(f"{example}.frag")


def test_glsl_uniform_library_declares_prefixed_uniforms():
    from implc.validate import validate_text

    surface = load_surface("torus")
    text = emit(surface, "glsl", "hessian", hessian(), emit_form="library", prefix="to_",
                params="uniform")
    assert "uniform float to_u_param_R;" in text and "uniform float to_u_param_r;" in text
    assert not re.search(r"(?<![A-Za-z_])u_param_", text)
    verdict = validate_text(text, "glsl", "torus.glsl")
    assert verdict.ok, verdict.render("torus.glsl")


def test_wgsl_uniform_program_and_library_validate():
    from test_wgsl import validate

    surface = load_surface("torus")
    program = emit(surface, "wgsl", "hessian", hessian(), params="uniform")
    assert "    u_param_R: f32," in program and "// offset 76: parameter R" in program
    assert "// offset 80: parameter r" in program and "struct size 96" in program
    assert validate(program, "torus.wgsl").ok
    library = emit(surface, "wgsl", "hessian", hessian(), emit_form="library", prefix="to_",
                   params="uniform")
    assert "var<private> to_params: to_Params = to_Params(1.0f, 0.35f);" in library
    assert validate(library, "torus-lib.wgsl").ok
    assert [p.offset for p in param_uniforms(surface, "wgsl")] == [76, 80]


def test_uniform_refusals():
    surface = load_surface("torus")
    with pytest.raises(OptionError, match="shadertoy"):  # contradicting options (issue 44)
        emit(surface, "glsl", flavor="shadertoy", params="uniform")
    with pytest.raises(OptionError, match="--params"):
        emit(surface, params="baked")
    odd = load_surface(equation="x^2 + y^2 + z^2 - a__b", params=["a__b=1"])
    with pytest.raises(InputError, match="reserved"):
        emit(odd, params="uniform")
    # a surface without parameters: uniform is the constant program
    sphere = load_surface(equation="x^2 + y^2 + z^2 - 1")
    assert emit(sphere, params="uniform") == emit(sphere)


@pytest.mark.parametrize("precision", ["float", "double"])
@pytest.mark.parametrize("method", ["hessian", "exact"])
@pytest.mark.parametrize("emit_form", ["program", "library"])
def test_opencl_uniform_emits_validate(emit_form, method, precision):
    from test_opencl import require_opencl

    from implc.validate import validate_text

    device = require_opencl()
    if precision == "double" and not device.has_fp64:
        pytest.skip(f"{device.name} has no cl_khr_fp64")
    surface = load_surface("kummer")
    prefix = "k_" if emit_form == "library" else ""
    text = emit(surface, "opencl", method, METHODS[method].defaults, emit_form=emit_form,
                prefix=prefix, precision=precision, params="uniform")
    real = precision
    assert f"}} {prefix}Params;" in text and f"    {real} u_param_mu;" in text
    # the entry points take the parameters last; the program's kernel after aux
    assert f"float3 rd, {real} t0, {real} t1, {real}* t, {prefix}Params params)".replace(
        "float3", f"{real}3") in text
    assert f"{prefix}S({real}3 p, {prefix}Params params)" in text
    if emit_form == "program":
        assert f"__global float4* aux, {real} u_param_mu) {{" in text
    verdict = validate_text(text, "opencl", f"kummer-{emit_form}.cl")
    assert verdict.ok, verdict.render(f"kummer-{emit_form}.cl")


# each runner's compiled object: set_params must keep it
COMPILED = {"gl": "program", "wgpu": "pipeline", "cl": "kernel"}


@pytest.mark.parametrize("backend", ["gl", "wgpu", "cl"])
def test_runner_moves_parameters_without_compiling(backend):
    require_backend(backend)
    surface = load_surface("torus")
    runner = open_runner(surface, backend, "hessian", hessian(), SIZE, SIZE, params="uniform")
    compiled = getattr(runner, COMPILED[backend])
    steps = (({}, []), ({"r": 0.5}, ["r=0.5"]), ({"R": 0.8}, ["R=0.8", "r=0.5"]))
    frames = []
    try:
        for values, _ in steps:  # set_params keeps the values it is not given
            if values:
                runner.set_params(values)
            frames.append(runner.frame())
        assert getattr(runner, COMPILED[backend]) is compiled
    finally:
        runner.release()
    for i, ((_, params), frame) in enumerate(zip(steps, frames, strict=True)):
        expected = render(load_surface("torus", params=params), backend, "hessian", hessian(),
                          SIZE, SIZE)
        m = compare(frame, expected)
        assert m["hit_agreement"] >= 0.999 and m["ssim"] >= 0.999, (params, m)
        if i:  # the picture really changed
            assert compare(frame, frames[i - 1])["hit_agreement"] < 0.98


def test_cli_render_and_compile_take_params(tmp_path):
    require_gl()
    out = tmp_path / "u.png"
    proc = implc("render", "torus", "--params", "uniform", "--param", "r=0.5", "--size", "48",
                 "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    meta = json.loads(out.with_suffix(".json").read_text())
    assert meta["params"] == "uniform" and meta["surface"]["params"]["r"] == 0.5
    proc = implc("compile", "kummer", "-t", "wgsl", "--params", "uniform", "--validate")
    assert proc.returncode == 0, proc.stderr
    assert "u_param_mu: f32," in proc.stdout
    proc = implc("compile", "kummer", "-t", "opencl", "--params", "uniform", "--validate")
    assert proc.returncode == 0, proc.stderr
    assert "__global float4* aux, float u_param_mu)" in proc.stdout
    out = tmp_path / "cl.png"
    proc = implc("render", "torus", "-b", "cl", "--params", "uniform", "--param", "r=0.5",
                 "--size", "32", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    proc = implc("compile", "torus", "--params", "uniform", "--flavor", "shadertoy")
    # contradicting options: exit 2, the exit-code table (issue 44; it was 1)
    assert proc.returncode == 2 and "shadertoy" in proc.stderr
    assert proc.stderr.startswith("implc compile: error: --params uniform: the shadertoy")


USER_KERNEL = """
__kernel void hits(__global const float* z0, __global float* t_out, float R, float r) {
    int i = get_global_id(0);
    to_Params params = {R, r};  // the drop-in page's lines
    float t;
    bool hit = to_intersect((float3)(-3.0f, 0.0f, z0[i]), (float3)(1.0f, 0.0f, 0.0f),
                            0.0f, 6.0f, &t, params);
    float3 n = to_grad((float3)(-3.0f + t, 0.0f, z0[i]), params);
    t_out[i] = hit && n.x < 0.0f ? t : -1.0f;  // the outer wall faces the ray
}
"""


@pytest.mark.parametrize("method", ["exact", "hessian"])
def test_opencl_library_takes_parameters_at_run_time(method):
    """A user kernel pastes the library and passes its own parameter values per launch;
    along y = 0 the first hit of the torus is x = -(R + sqrt(r^2 - z0^2)), exactly."""
    from test_opencl import require_opencl

    from implc.devices import import_pyopencl, opencl_build

    dev = require_opencl()
    cl = import_pyopencl()
    library = emit(load_surface("torus"), "opencl", method, METHODS[method].defaults,
                   emit_form="library", prefix="to_", params="uniform")
    built = opencl_build(library + USER_KERNEL)
    assert built.program is not None, built.log
    kernel = cl.Kernel(built.program, "hits")
    z0 = np.linspace(-0.5, 0.5, 41).astype(np.float32)
    flags = cl.mem_flags
    z_buf = cl.Buffer(dev.context, flags.READ_ONLY | flags.COPY_HOST_PTR, hostbuf=z0)
    t_buf = cl.Buffer(dev.context, flags.WRITE_ONLY, z0.nbytes)
    for R, r in ((1.0, 0.35), (0.8, 0.45)):  # one build, two launches
        kernel(dev.queue, z0.shape, None, z_buf, t_buf, np.float32(R), np.float32(r))
        t = np.empty_like(z0)
        cl.enqueue_copy(dev.queue, t, t_buf)
        dev.queue.finish()
        inside = np.abs(z0) < r - 0.02
        outside = np.abs(z0) > r + 0.02
        expected = 3.0 - (R + np.sqrt(np.maximum(r * r - z0 * z0, 0.0)))
        assert np.all(t[outside] < 0), (R, r, t[outside])
        np.testing.assert_allclose(t[inside], expected[inside], atol=2e-4)
