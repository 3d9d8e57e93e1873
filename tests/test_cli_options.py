"""Options a new user types (issue 23): none is ignored, a bad one is a usage error.

One rule (README "Exit codes"): a bad command line exits 2 with one line,
`implc COMMAND: error: ...`, and a pointer to `implc COMMAND --help` (not the whole
usage); bad input (the equation, a file, a parameter, an output path) exits 1.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def implc(*args: str, cwd: Path | None = None):
    return subprocess.run(
        [sys.executable, "-m", "implc", *args],
        capture_output=True, text=True, cwd=cwd or ROOT, timeout=300,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )


def usage_error(proc, command: str) -> str:
    """The message of a usage error of `implc COMMAND` (checking its form)."""
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr and "usage:" not in proc.stderr, proc.stderr
    lines = proc.stderr.strip().splitlines()
    prog = f"implc {command}".strip()
    assert len(lines) == 2, proc.stderr
    assert lines[0].startswith(f"{prog}: error: "), proc.stderr
    assert lines[1] == f"see '{prog} --help' for the options", proc.stderr
    return lines[0][len(f"{prog}: error: "):]


# --- point 4: a parameter the equation does not use is an error, not ignored ----------

def test_a_param_the_equation_does_not_use_is_an_error():
    proc = implc("compile", "torus", "--param", "q=0.6")
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.splitlines() == [
        "--param:1:1: error: parameter 'q' is not in the equation (its parameters: R, r)",
        "  q=0.6",
        "  ^",
    ]
    proc = implc("show", "torus", "--param", "rr=0.3")
    assert proc.returncode == 1
    assert proc.stderr.splitlines()[0] == (
        "--param:1:1: error: parameter 'rr' is not in the equation; did you mean 'r'? "
        "(its parameters: R, r)")
    proc = implc("show", "-e", "x^2 + y^2 + z^2 - 1", "--param", "a=2")
    assert proc.returncode == 1
    assert proc.stderr.splitlines()[0] == (
        "--param:1:1: error: parameter 'a' is not in the equation, which has no parameters")


def test_an_unused_param_in_a_surface_file_is_located(tmp_path):
    surface = tmp_path / "s.toml"
    surface.write_text('equation = "x^2 + y^2 + z^2 - a"\n[params]\na = 1\nb = 2\n')
    proc = implc("show", str(surface))
    assert proc.returncode == 1
    assert proc.stderr.splitlines() == [
        f"{surface}:4:1: error: [params] b is not in the equation (its parameters: a): "
        "remove it, or use it",
        "  b = 2",
        "  ^",
    ]


def test_a_param_only_in_a_constant_exponent_or_beside_a_number_counts_as_used(tmp_path):
    """`x^n` (the value decides the power) and `2R` use the parameter; `1e3` is a number,
    not the name e3."""
    proc = implc("show", "-e", "x^n + y^2 + z^2 - 2R", "--param", "n=2", "--param", "R=1")
    assert proc.returncode == 0, proc.stderr
    proc = implc("show", "-e", "x^2 + y^2 + z^2 - 1e3", "--param", "e3=1")
    assert proc.returncode == 1 and "parameter 'e3' is not in the equation" in proc.stderr


def test_every_bundled_example_uses_its_params():
    from implc.surface import example_paths, load_surface

    for name in example_paths():
        load_surface(name)  # raises on an unused [params] entry


# --- point 15: did you mean, for example names ------------------------------------------

@pytest.mark.parametrize(("name", "hint"), [
    ("Torus", "did you mean 'torus'?"),
    ("barth", "did you mean 'barth-decic' or 'barth-sextic'?"),
    ("crosscap", "did you mean 'cross-cap'?"),
    ("tourus", "did you mean 'torus'?"),
])
def test_an_unknown_example_name_gets_a_hint(name, hint):
    proc = implc("show", name)
    assert proc.returncode == 1
    assert proc.stderr.strip() == (
        f"implc: error: no file or bundled example named '{name}'; {hint} (see `implc list`)")


# --- point 6 (data) and 19 (sidecar): what a method reads, what a render used -----------

CHANGED = {"step": 0.0125, "tau1": 0.02, "tau2": 0.03, "tau3": 0.04, "eps": 2e-3,
           "taylor2": "consistent", "max_steps": 123, "evaluation": "point"}


@pytest.mark.parametrize("method", ["sign", "taylor", "curvature", "hessian",
                                    "hessian-approx", "exact", "interval"])
def test_what_a_method_reads_is_what_changes_its_shader(method):
    """Method.reads (the warning's data) is exactly the set of constants whose value
    changes the method's shader (a quartic: ray-poly is auto's form)."""
    from implc.emit import emit
    from implc.methods import METHODS
    from implc.surface import load_surface

    surface = load_surface(equation="x^4 + y^4 + z^4 - 1")
    meth = METHODS[method]
    base = emit(surface, "glsl", method, meth.constants())
    changes = {field for field, value in CHANGED.items()
               if emit(surface, "glsl", method, meth.constants(**{field: value})) != base}
    assert changes == meth.reads


def test_the_sidecar_records_the_form_used(tmp_path):
    from conftest import require_gl

    require_gl()
    for method, form in (("taylor", "ray-poly"), ("exact", "ray-poly"),
                         ("interval", "point")):
        out = tmp_path / f"{method}.png"
        proc = implc("render", "sphere", "-m", method, "--size", "8", "-o", str(out))
        assert proc.returncode == 0, proc.stderr
        sidecar = json.loads(out.with_suffix(".json").read_text())
        assert sidecar["method"]["evaluation"] == form, method
