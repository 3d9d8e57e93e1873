"""The command line as users run it: real processes, exit codes, files written or not."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import require_tool

ROOT = Path(__file__).resolve().parent.parent


def implc(*args: str, cwd: Path | None = None, env: dict | None = None):
    return subprocess.run(
        [sys.executable, "-m", "implc", *args],
        capture_output=True, text=True, cwd=cwd or ROOT, timeout=120,
        env={**os.environ, "PYTHONPATH": str(ROOT), **(env or {})},
    )


def test_help_teaches():
    proc = implc("--help")
    assert proc.returncode == 0
    for word in ("compile", "validate", "render", "show", "list", "exit codes"):
        assert word in proc.stdout


def test_list_shows_examples_with_degree():
    proc = implc("list")
    assert proc.returncode == 0, proc.stderr
    lines = {line.split()[0]: line for line in proc.stdout.splitlines()}
    assert "deg 4" in lines["cross-cap"]
    assert "4*x^2*(x^2 + y^2 + z^2 + z)" in lines["cross-cap"]
    assert "non-poly" in lines["gyroid"]
    assert len(lines) >= 15


def test_show_reports_op_counts():
    proc = implc("show", "cross-cap", "-m", "hessian")
    assert proc.returncode == 0, proc.stderr
    assert "degree:    4" in proc.stdout
    assert "SDH" in proc.stdout and "->" in proc.stdout
    assert "ray-poly form" in proc.stdout and "coefficients c0..c4" in proc.stdout
    proc = implc("show", "cross-cap")  # the default method for a quartic: exact
    assert proc.returncode == 0, proc.stderr
    assert "exact (root isolation" in proc.stdout


def test_compile_to_stdout_and_file(tmp_path):
    proc = implc("compile", "cross-cap", "-m", "taylor")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("#version 330 core")
    out = tmp_path / "cc.frag"
    proc = implc("compile", "cross-cap", "-m", "taylor", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    assert out.read_text() == implc("compile", "cross-cap", "-m", "taylor").stdout


def test_compile_validate_and_validate_command(tmp_path):
    require_tool("glslangValidator")
    out = tmp_path / "cc.frag"
    proc = implc("compile", "cross-cap", "--validate", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    assert "ok (glslangValidator)" in proc.stderr
    proc = implc("validate", str(out))
    assert proc.returncode == 0 and "ok" in proc.stdout
    broken = tmp_path / "broken.frag"
    broken.write_text(out.read_text().replace("float x = p.x;", "float x = p.w;", 1))
    proc = implc("validate", str(broken))
    assert proc.returncode == 3
    line = next(i for i, t in enumerate(broken.read_text().splitlines(), 1) if "p.w" in t)
    assert f"{broken}:{line}:" in proc.stderr, proc.stderr


@pytest.mark.parametrize("flavor", ["330", "450", "es300", "shadertoy"])
def test_unseen_equations_compile_and_validate(flavor, tmp_path):
    """Dialects the goldens never saw: implicit products, brackets, **, lhs = rhs, params."""
    require_tool("glslangValidator")
    equations = [
        ("2xy(x+1)[y - 2] + z**3 = x z", []),
        ("(x^2 + y^2 - 1)^2 + (z - a)^2 = 0.04", ["--param", "a=0.25"]),
        ("sqrt(x^2 + y^2) + exp(-z^2) sin(3x) = 1", []),
        ("x^(1/3) + y^(2/3) + abs(z) - 1", []),
        ("max(x^2 + y^2 + z^2 - 1, -(x + y + z))", []),
    ]
    for i, (eq, extra) in enumerate(equations):
        out = tmp_path / f"u{i}.frag"
        proc = implc("compile", "-e", eq, *extra, "--flavor", flavor, "--validate",
                     "-o", str(out))
        assert proc.returncode == 0, (eq, proc.stderr)
        assert out.exists()


def test_library_emit_validates(tmp_path):
    require_tool("glslangValidator")
    out = tmp_path / "cc.glsl"
    proc = implc("compile", "cross-cap", "--emit", "library", "--prefix", "cc_",
                 "--validate", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    text = out.read_text()
    assert not re.search(r"^#version", text, re.M) and "void main" not in text
    for sig in ("float cc_S(vec3 p)", "vec3 cc_grad(vec3 p)",
                "bool cc_intersect(vec3 ro, vec3 rd, float t0, float t1, out float t)"):
        assert sig in text


def test_bad_equation_located_no_output(tmp_path):
    out = tmp_path / "bad.frag"
    proc = implc("compile", "-e", "x^2 + sinn(y)", "-o", str(out))
    assert proc.returncode == 1
    assert proc.stderr.startswith("<equation>:1:7: error:"), proc.stderr
    assert "Traceback" not in proc.stderr
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_error_in_toml_points_into_the_file(tmp_path):
    surface = tmp_path / "bad.toml"
    surface.write_text('name = "bad"\n# comment\nequation = "x^2 + y^2 + (z - 1 = 0"\n')
    proc = implc("compile", str(surface))
    assert proc.returncode == 1
    first = proc.stderr.splitlines()[0]
    assert first.startswith(f"{surface}:3:"), proc.stderr
    col = int(first.split(":")[2])
    line = surface.read_text().splitlines()[2]
    assert line[col - 1] == "(", (first, line)


def test_toml_syntax_error_is_located(tmp_path):
    surface = tmp_path / "bad.toml"
    surface.write_text('name = "bad"\nequation = "x^2 = 1\n')
    proc = implc("show", str(surface))
    assert proc.returncode == 1
    assert proc.stderr.startswith(f"{surface}:2:"), proc.stderr
    assert "Traceback" not in proc.stderr


def test_unknown_example_and_bad_param():
    proc = implc("compile", "no-such-surface")
    assert proc.returncode == 1 and "implc list" in proc.stderr
    proc = implc("compile", "sphere", "--param", "x=2")
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    proc = implc("compile", "sphere", "--param", "r=abc")
    assert proc.returncode == 1 and "Traceback" not in proc.stderr


def test_usage_errors_exit_2():
    assert implc("compile", "cross-cap", "-m", "nope").returncode == 2
    assert implc("frobnicate").returncode == 2


@pytest.mark.parametrize("text", [
    "__import__('os').system('echo pwned')",
    "2**10**10**10",
    "(x+y+z)^100000",
    "((x+y)",
    "x + foo(y)",
    "",
    "1/0 + x",
])
def test_hostile_input_is_rejected_quickly(text, tmp_path):
    out = tmp_path / "h.frag"
    proc = implc("compile", "-e", text, "-o", str(out))
    assert proc.returncode == 1, proc.stderr
    assert "error:" in proc.stderr and "Traceback" not in proc.stderr
    assert not out.exists()
