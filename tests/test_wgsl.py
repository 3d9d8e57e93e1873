"""The WGSL target: the printer's WGSL rules, the validator's messages, and renders on
wgpu that agree with the GL ones (its goldens: tests/test_golden.py)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import sympy
from cases import PAPER
from conftest import IN_CI, require_gl
from test_cli import implc

from implc.backends.wgsl import RESERVED_WORDS, WgslPrinter
from implc.emit import emit
from implc.errors import ImplcError
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.metrics import compare
from implc.render.run import render
from implc.symbols import X

ROOT = Path(__file__).resolve().parent.parent
GOLDEN = Path(__file__).parent / "golden" / "wgsl"  # tests/test_golden.py pins them


def require_wgpu():
    """The wgpu device (lavapipe here); skip without one, but fail under CI=true."""
    from implc.devices import wgpu_device
    from implc.errors import ToolError

    try:
        return wgpu_device()
    except ToolError as err:
        if IN_CI:
            pytest.fail(f"a wgpu adapter is required under CI=true: {err}")
        pytest.skip(f"no wgpu adapter: {err}")


def validate(text: str, name: str):
    from implc.validate import validate_wgsl

    require_wgpu()
    return validate_wgsl(text, name)


def _emit(example: str, method: str, taylor2: str, kind: str) -> str:
    prefix = example.replace("-", "_") + "_" if kind == "library" else ""
    constants = METHODS[method].constants(taylor2=taylor2)
    return emit(load_surface(example), "wgsl", method, constants, None, kind, prefix)


# --- WGSL rules ---------------------------------------------------------------------------

def _declared_names(text: str) -> set[str]:
    """Every name a WGSL text declares: fn, let, var, const, struct, params and fields."""
    code = re.sub(r"//[^\n]*", "", text)
    names = set(re.findall(r"\b(?:fn|let|var|const|struct)\s+([A-Za-z_]\w*)", code))
    return names | set(re.findall(r"\b([A-Za-z_]\w*)\s*:(?!:)", code))


def test_no_reserved_word_is_declared():
    """Every name implc emits, over all goldens, avoids WGSL's keywords and reserved words
    (`target` is one: the program's local says `look_at`)."""
    names: set[str] = set()
    for path in GOLDEN.glob("*.wgsl"):
        names |= _declared_names(path.read_text(encoding="utf-8"))
    assert {"S", "grad", "march", "intersect", "shade", "x_2", "t0", "u_target"} <= names
    assert not names & RESERVED_WORDS
    assert not [n for n in names if n.startswith("__")]


def test_library_prefixes_every_global():
    text = _emit("cross-cap", "hessian-approx", "paper", "library")
    top = re.findall(r"^(?:fn|const|struct)\s+(\w+)", text, re.M)
    assert len(top) >= 15
    assert all(n.startswith(("cross_cap_", "CROSS_CAP_")) for n in top), top
    assert "@compute" not in text and "@group" not in text


def test_every_option_reaches_the_shader():
    """Every method with non-default constants: the constants are printed as f32/i32 and
    the shader validates; the taylor2 variant switches the Eq. 4 formula."""
    surface = load_surface("steiner")
    # exact and interval read none of these (tests/test_exact.py, tests/test_interval.py)
    for method in (m for m in METHODS if not (METHODS[m].solves or METHODS[m].bounds)):
        for taylor2 in ("paper", "consistent"):
            c = METHODS[method].constants(step=0.005, tau1=0.02, tau2=0.03, tau3=0.04,
                                          eps=2e-4, taylor2=taylor2, max_steps=777,
                                          refine_steps=7)
            text = emit(surface, "wgsl", method, c)
            for line in ("const STEP: f32 = 0.005f;", "const MAX_STEPS: i32 = 777;",
                         "const REFINE_STEPS: i32 = 7;"):
                assert line in text, (method, line)
            # the thresholds are declared where the step rule reads them (not curvature's)
            for line in ("const TAU1: f32 = 0.02f;", "const TAU2: f32 = 0.03f;",
                         "const TAU3: f32 = 0.04f;"):
                assert (line in text) == (method != "curvature"), (method, line)
            assert ("const EPS: f32 = 0.0002f;" in text) == (method == "hessian-approx")
            if method in ("hessian", "hessian-approx"):
                assert ("0.125f*sign(f0.x)*h*h*f1.z" in text) == (taylor2 == "consistent")
            name = f"steiner.{method}.{taylor2}.wgsl"
            verdict = validate(text, name)
            assert verdict.ok, verdict.render(name)


def test_printer_types_literals_and_refuses_what_wgsl_cannot_say():
    p = WgslPrinter()
    assert p.doprint(2 * X + sympy.Rational(1, 3)) == "2.0f*x + 0.3333333333333333f"
    assert p.doprint(sympy.pi) == "3.141592653589793f"
    with pytest.raises(ImplcError, match="gamma"):
        p.doprint(sympy.gamma(X))
    with pytest.raises(ImplcError, match="reserved"):
        p.doprint(sympy.Symbol("target"))


# --- validator ----------------------------------------------------------------------------

def test_validator_points_into_the_users_file(monkeypatch):
    text = _emit("cross-cap", "taylor", "paper", "program")
    lines = text.splitlines()
    line = next(i for i, t in enumerate(lines, 1) if "f1.x*sign(f0.x)" in t)
    broken = text.replace("f1.x*sign(f0.x)", "f1.x*sign(f0.w)")
    verdict = validate(broken, "mine/cc.wgsl")
    assert not verdict.ok
    assert f"mine/cc.wgsl:{line}:" in verdict.messages, verdict.messages
    assert "implc-shader" not in verdict.messages
    # wgpu's naga alone (no CLI on PATH) reports the same place
    monkeypatch.setattr("implc.validate.shutil.which", lambda name: None)
    verdict = validate(broken, "mine/cc.wgsl")
    assert not verdict.ok and verdict.tool == "naga (wgpu)"
    assert f"mine/cc.wgsl:{line}:" in verdict.messages, verdict.messages


# --- renders: WGSL on wgpu against GLSL on GL --------------------------------------------

SIZE = 96
HIT_AGREEMENT = 0.999
SSIM = 0.995


@pytest.mark.parametrize("method", list(METHODS))
@pytest.mark.parametrize("example", PAPER)
def test_wgpu_render_matches_gl(example, method):
    """Same method, same constants, 96x96: the WGSL compute shader and the GLSL fragment
    shader run the same float32 algorithm, so they agree almost bit for bit.

    Measured (lavapipe vs llvmpipe, Mesa 22.3.6): hit agreement 1.0 and no wrong roots
    on all 15 cases; SSIM 1.0 except miter/curvature 0.99942; max |dt| 7.1e-4 (miter,
    curvature), otherwise <= 3.5e-4; mean steps identical. Thresholds: hit agreement
    >= 0.999, SSIM >= 0.995, wrong roots (|dt| > 1e-3) <= 0.1% of pixels, mean steps
    within 1%.
    """
    require_gl()
    require_wgpu()
    surface = load_surface(example)
    constants = METHODS[method].defaults
    gl = render(surface, "gl", method, constants, SIZE, SIZE)
    wg = render(surface, "wgpu", method, constants, SIZE, SIZE)
    m = compare(wg, gl)
    assert gl.hit.mean() > 0.05, "the surface should cover the view"
    assert m["hit_agreement"] >= HIT_AGREEMENT, m
    assert m["ssim"] >= SSIM, m
    assert m["wrong_root"] <= 0.001 * SIZE * SIZE, m
    assert abs(wg.steps.mean() - gl.steps.mean()) <= 0.01 * gl.steps.mean(), m
    assert np.all(wg.residual[wg.hit] < 1e-3)
    assert wg.color.dtype == np.float32 and wg.color.shape == (SIZE, SIZE, 3)


def test_non_square_frame_keeps_rows_and_aspect():
    """40x24 (rows not a multiple of the 256-byte copy alignment, nor of the 8x8
    workgroup): row 0 is the top and the aspect is right, as on GL."""
    require_gl()
    require_wgpu()
    surface = load_surface("cross-cap")
    constants = METHODS["taylor"].defaults
    gl = render(surface, "gl", "taylor", constants, 40, 24)
    wg = render(surface, "wgpu", "taylor", constants, 40, 24)
    assert wg.hit.shape == (24, 40)
    assert compare(wg, gl)["hit_agreement"] >= 0.995
    assert "frame" in wg.timing


# --- command line -------------------------------------------------------------------------

def test_cli_compile_validate_render(tmp_path):
    require_wgpu()
    shader = tmp_path / "cc.wgsl"
    proc = implc("compile", "cross-cap", "-t", "wgsl", "-m", "taylor", "--validate",
                 "-o", str(shader))
    assert proc.returncode == 0, proc.stderr
    assert "@compute @workgroup_size(8, 8)" in shader.read_text()
    bad = tmp_path / "bad.wgsl"
    bad.write_text(shader.read_text().replace("fn main(", "fn main(("))
    proc = implc("validate", str(shader), str(bad))
    assert proc.returncode == 3
    assert re.search(re.escape(str(bad)) + r":\d+:\d+", proc.stderr), proc.stderr
    out = tmp_path / "cc.exr"
    proc = implc("render", "cross-cap", "-b", "wgpu", "-m", "taylor", "--size", "32",
                 "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    meta = json.loads(out.with_suffix(".json").read_text())
    assert meta["backend"] == "wgpu" and meta["timing"]["frame"] > 0


def test_same_bytes_for_every_hash_seed():
    outputs = {implc("compile", "miter", "-t", "wgsl", "-m", "curvature",
                     env={"PYTHONHASHSEED": seed}).stdout for seed in ("0", "4242")}
    assert len(outputs) == 1 and "fn march(" in outputs.pop()


def _wgsl_layout(struct: str) -> tuple[list[tuple[str, int]], int]:
    """(field, byte offset) of a WGSL uniform struct of f32, vec2<f32> and vec3<f32>
    fields, by the WGSL alignment rules, and the struct's size."""
    align = {"f32": 4, "vec2<f32>": 8, "vec3<f32>": 16}
    size = {"f32": 4, "vec2<f32>": 8, "vec3<f32>": 12}
    offset, fields = 0, []
    for name, kind in re.findall(r"^\s*(\w+): ([\w<>0-9]+),", struct, re.M):
        offset = -(-offset // align[kind]) * align[kind]
        fields.append((name, offset))
        offset += size[kind]
    largest = max(align[k] for k in re.findall(r": ([\w<>0-9]+),", struct))
    return fields, -(-offset // largest) * largest


def test_readme_rust_uniforms_match_the_wgsl_layout():
    """The `#[repr(C)]` Rust struct of docs/guide/pasting.md (wgpu / Bevy section) puts
    every field of the torus's `--params uniform` WGSL `Uniforms` at its byte offset, and
    has its size."""
    page = (ROOT / "docs" / "guide" / "pasting.md").read_text(encoding="utf-8")
    section = page.split("## wgpu / Bevy-style bind groups", 1)[1]
    rust = re.search(r"struct Uniforms \{(.*?)\n\}", section, re.S).group(1)
    offset, rust_fields = 0, {}
    for name, count in re.findall(r"(\w+): (?:f32|\[f32; (\d)\])", rust):
        rust_fields[name] = offset  # repr(C) of f32s: 4-byte aligned, no hidden padding
        offset += 4 * int(count or 1)
    program = emit(load_surface("torus"), "wgsl", "hessian", METHODS["hessian"].defaults,
                   params="uniform")
    struct = re.search(r"struct Uniforms \{(.*?)\n\}", program, re.S).group(1)
    fields, size = _wgsl_layout(struct)
    rename = {"u_param_R": "param_big_r", "u_param_r": "param_r"}
    for name, wgsl_offset in fields:
        rust_name = rename.get(name, name.removeprefix("u_"))
        assert rust_fields.get(rust_name) == wgsl_offset, (name, rust_fields)
    assert offset == size == 96
