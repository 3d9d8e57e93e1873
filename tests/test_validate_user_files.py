"""Issue 23, point 9: `implc validate` checks a user's own shader as what it is.

Only an implc library (its S, grad, intersect and shade, one prefix) and a Shadertoy
image shader are wrapped in implc's harness; any other GLSL file is compiled as it is,
in the stage its extension (or `--stage`) names, as GLSL 330 when it has no `#version`.
An empty file (nothing but whitespace and comments) is one verdict in every language:
an input error, before any compiler runs.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import require_tool

ROOT = Path(__file__).resolve().parent.parent


def implc(*args: str):
    return subprocess.run(
        [sys.executable, "-m", "implc", *args], capture_output=True, text=True, cwd=ROOT,
        timeout=120, env={**os.environ, "PYTHONPATH": str(ROOT)},
    )


def write(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_plain_glsl_functions_validate(tmp_path):
    require_tool("glslangValidator")
    path = write(tmp_path, "mylib.glsl", "float f(vec3 p){return p.x;}\n")
    proc = implc("validate", path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith(f"{path}: ok (glslangValidator")
    assert "intersect" not in proc.stdout + proc.stderr


def test_plain_glsl_errors_point_at_the_users_line(tmp_path):
    require_tool("glslangValidator")
    path = write(tmp_path, "bad.glsl", "// helpers\nfloat f(vec3 p) {\n    return p.w;\n}\n")
    proc = implc("validate", path)
    assert proc.returncode == 3
    assert f"ERROR: {path}:3:" in proc.stderr, proc.stderr
    assert "intersect" not in proc.stderr


def test_a_function_named_intersect_is_not_an_implc_library(tmp_path):
    require_tool("glslangValidator")
    path = write(tmp_path, "mine.frag", "bool intersect(vec3 a) { return a.x > 0.0; }\n")
    proc = implc("validate", path)
    assert proc.returncode == 0, proc.stderr


VERTEX = "#version 330 core\nvoid main() { gl_Position = vec4(0.0); }\n"


@pytest.mark.parametrize(("name", "options", "ok"), [
    ("v.vert", (), True),
    ("v.frag", (), False),  # gl_Position is not a fragment shader's
    ("v.glsl", (), False),  # .glsl is a fragment shader unless told
    ("v.glsl", ("--stage", "vert"), True),
    ("v.vert.glsl", (), True),  # glslang's compound suffix
    ("v.frag", ("--stage", "vert"), True),  # the option wins over the extension
])
def test_the_stage_comes_from_the_extension_or_stage(tmp_path, name, options, ok):
    require_tool("glslangValidator")
    path = write(tmp_path, name, VERTEX)
    proc = implc("validate", *options, path)
    assert proc.returncode == (0 if ok else 3), proc.stdout + proc.stderr


def test_stage_is_for_glsl_files_only(tmp_path):
    path = write(tmp_path, "a.wgsl", "fn f() {}\n")
    proc = implc("validate", "--stage", "vert", path)
    assert proc.returncode == 2
    assert "--stage" in proc.stderr and "a.wgsl" in proc.stderr
    assert implc("validate", "--stage", "pixel", path).returncode == 2


@pytest.mark.parametrize("text", ["", "\n  \n", "// nothing yet\n/* still\n nothing */\n"])
def test_empty_files_get_one_verdict_in_every_language(tmp_path, text):
    verdicts = set()
    for ext in (".frag", ".glsl", ".vert", ".wgsl", ".cl"):
        path = write(tmp_path, f"empty{ext}", text)
        proc = implc("validate", path)
        assert proc.returncode == 1, (ext, proc.stdout, proc.stderr)
        assert proc.stdout == ""
        verdicts.add(proc.stderr.replace(path, "FILE"))
    assert verdicts == {"implc: error: FILE: empty file: no shader code to validate (only "
                        "whitespace or comments)\n"}


def test_an_empty_file_is_refused_before_any_compiler_runs(tmp_path):
    good = write(tmp_path, "good.wgsl", "fn f() {}\n")
    empty = write(tmp_path, "empty.cl", "")
    proc = implc("validate", good, empty)
    assert proc.returncode == 1 and proc.stdout == ""


def test_implc_libraries_still_validate_through_the_harness(tmp_path):
    require_tool("glslangValidator")
    out = tmp_path / "cc.glsl"
    proc = implc("compile", "cross-cap", "--emit", "library", "--prefix", "cc_", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    proc = implc("validate", str(out))
    assert proc.returncode == 0, proc.stderr
