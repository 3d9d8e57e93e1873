"""Options a new user types (issue 23): none is ignored, a bad one is a usage error.

One rule (docs/reference/errors.md "Exit codes"): a bad command line exits 2 with one line,
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


LIMITS = ["--max-chars", "--max-depth", "--max-nodes", "--max-exponent", "--max-degree",
          "--max-terms", "--max-literal-exponent", "--max-constant-digits", "--max-derived"]
CONSTANTS = ["--step", "--tau1", "--tau2", "--tau3", "--eps"]

# (argv, what the message must say); OUT is a scratch directory
BAD_OPTIONS = [
    (["compile", "sphere", "-m", "nope"], "invalid choice: 'nope'"),
    # issue 44: an unknown option is the command's error, with the closest option or choice
    (["render", "sphere", "--sise", "96", "-o", "OUT/a.png"],
     "unrecognized arguments: --sise 96; did you mean '--size'?"),
    (["compile", "sphere", "-m", "hesian"], "; did you mean 'hessian'?"),
    (["rendr", "sphere"], "invalid choice: 'rendr' (choose from 'list', 'show', 'compile', "
                          "'export', 'validate', 'render', 'view', 'compare', 'bench', "
                          "'corpus', 'gallery', 'probe'); did you mean 'render'?"),
    (["compile", "sphere", "-t", "bogus"], "invalid choice: 'bogus'"),
    (["compile", "sphere", "--flavor", "300es"],
     "--flavor: unknown glsl flavour '300es'; choose from 330, 450, es300, shadertoy"),
    (["compile", "sphere", "-t", "wgsl", "--flavor", "es300"],
     "--flavor: wgsl has no flavours (--flavor applies to glsl only)"),
    (["compile", "sphere", "-t", "wgsl", "--precision", "double"],
     "--precision double: wgsl has float only (double: glsl, opencl)"),
    (["compile", "sphere", "--flavor", "es300", "--precision", "double"],
     "--flavor: the glsl flavour es300 has no double precision: use --precision double "
     "with 330 or 450"),
    (["compile", "sphere", "--precision", "half"], "invalid choice: 'half'"),
    (["compile", "sphere", "--params", "bogus"], "invalid choice: 'bogus'"),
    (["compile", "sphere", "--emit", "bogus"], "invalid choice: 'bogus'"),
    (["compile", "sphere", "--emit", "library", "--prefix", "c-c"],
     "--prefix must be letters, digits and '_' (got 'c-c')"),
    (["compile", "sphere", "--emit", "library", "--prefix", "1cc_"],
     "--prefix must not start with a digit: names start with it, and a name cannot "
     "(got '1cc_')"),
    (["compile", "sphere", "--emit", "library", "--prefix", "gl_"],
     "--prefix must not start with 'gl_': glsl reserves names that start with it "
     "(got 'gl_')"),
    (["compile", "sphere", "-t", "wgsl", "--emit", "library", "--prefix", "cc__"],
     "--prefix must not contain '__': GLSL reserves such names (got 'cc__')"),
    (["compile", "sphere", "--taylor2", "bogus"], "invalid choice: 'bogus'"),
    (["compile", "sphere", "--eval", "bogus"], "invalid choice: 'bogus'"),
    (["compile", "sphere", "--max-steps", "0"],
     "argument --max-steps: expected an integer from 1 to 10000000, got 0"),
    (["compile", "sphere", "--max-steps", "1.5"],
     "argument --max-steps: expected an integer, got '1.5'"),
    *[(["compile", "sphere", flag, "0"], f"argument {flag}: expected a positive number")
      for flag in CONSTANTS],
    (["compile", "sphere", "--step", "-1"], "argument --step: expected a positive number"),
    (["compile", "sphere", "--step", "nan"], "argument --step: expected a positive number"),
    (["compile", "sphere", "--step", "abc"], "argument --step: expected a positive number"),
    *[(["compile", "sphere", flag, "0"], f"argument {flag}: expected an integer from 1")
      for flag in LIMITS],
    (["compile", "sphere", "-e", "x^2 - 1"],
     "give a surface (a file or a bundled example name) or -e EQUATION, not both"),
    (["compile"], "give a surface (a file or a bundled example name) or -e EQUATION"),
    (["show"], "give a surface (a file or a bundled example name) or -e EQUATION"),
    (["show", "sphere", "-m", "nope"], "invalid choice: 'nope'"),
    (["render", "sphere", "-b", "bogus", "-o", "OUT/a.png"], "invalid choice: 'bogus'"),
    (["render", "sphere", "--size", "0", "-o", "OUT/a.png"],
     "argument --size: expected an integer from 1 to 8192, got 0"),
    (["render", "sphere", "--size", "9000", "-o", "OUT/a.png"],
     "argument --size: expected an integer from 1 to 8192, got 9000"),
    (["render", "sphere", "--width", "0", "-o", "OUT/a.png"],
     "argument --width: expected an integer from 1 to 8192, got 0"),
    (["render", "sphere", "--height", "-3", "-o", "OUT/a.png"],
     "argument --height: expected an integer from 1 to 8192, got -3"),
    (["render", "sphere", "--size", "16", "--width", "16", "-o", "OUT/a.png"],
     "give --size or --width/--height, not both"),
    (["render", "sphere", "-t", "wgsl", "-b", "gl", "-o", "OUT/a.png"],
     "-t wgsl renders with -b wgpu or webgpu, not -b gl"),
    (["render", "sphere", "-t", "glsl", "-b", "reference", "-o", "OUT/a.png"],
     "-t glsl renders with -b gl or gl-double or webgl2, not -b reference"),
    (["render", "sphere", "--flavor", "shadertoy", "-o", "OUT/a.png"],
     "--flavor shadertoy: -b gl renders the 330 program; the other flavours are for "
     "`implc compile`"),
    (["render", "sphere", "-b", "wgpu", "--flavor", "es300", "-o", "OUT/a.png"],
     "--flavor: wgsl has no flavours (--flavor applies to glsl only)"),
    (["render", "sphere", "-b", "wgpu", "--precision", "double", "-o", "OUT/a.png"],
     "--precision double renders with -b gl or gl-double or cl or cl-double only"),
    (["render", "sphere", "--step", "0", "-o", "OUT/a.png"], "argument --step"),
    (["view", "sphere", "--step", "0", "-o", "OUT/a.html"], "argument --step"),
    (["view", "sphere", "-m", "nope", "-o", "OUT/a.html"], "invalid choice: 'nope'"),
    (["compare", "OUT/a.exr", "OUT/b.exr", "--t-tol", "0"], "argument --t-tol"),
    (["bench", "sphere", "--size", "4", "-o", "OUT/b"],
     "argument --size: expected an integer from 8 to 8192, got 4"),
    (["bench", "sphere", "--frames", "0", "-o", "OUT/b"],
     "argument --frames: expected an integer from 1 to 1000, got 0"),
    (["bench", "sphere", "--equal-step", "0", "-o", "OUT/b"], "argument --equal-step"),
    (["bench", "sphere", "--configs", "paper,bogus", "-o", "OUT/b"],
     "--configs: unknown configuration 'bogus'; choose from paper, equal, taylor2, extremum"),
    (["bench", "sphere", "--methods", "taylor", "taylor", "-o", "OUT/b"],
     "--methods: taylor is listed twice"),
    (["bench", "sphere", "-b", "reference", "-o", "OUT/b"], "invalid choice: 'reference'"),
    (["corpus", "-j", "-1"], "argument -j/--jobs: expected an integer from 0 to 64, got -1"),
    (["corpus", "--rows", "abc"], "--rows: expected numbers like 1-20,35, got 'abc'"),
    (["corpus", "-t", "bogus"], "invalid choice: 'bogus'"),
    (["validate"], "the following arguments are required: FILE"),
    (["frobnicate"], "invalid choice: 'frobnicate'"),
    (["--bogus"], "unrecognized arguments: --bogus"),
]


@pytest.mark.parametrize(("argv", "expected"), BAD_OPTIONS,
                         ids=[" ".join(a) for a, _ in BAD_OPTIONS])
def test_a_bad_command_line_exits_2_with_one_line(tmp_path, argv, expected):
    argv = [a.replace("OUT", str(tmp_path)) for a in argv]
    command = argv[0] if argv[0] in ("compile", "show", "render", "view", "compare",
                                     "bench", "corpus", "validate") else ""
    message = usage_error(implc(*argv), command)
    assert expected in message, message
    assert list(tmp_path.iterdir()) == []  # nothing written, no bench directory


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
    from implc.loaders import load_surface
    from implc.surface import example_paths

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


# --- points 5 and 7: -t and -o choose the language, never ignored ------------------------

def test_compile_takes_the_target_from_the_output_extension(tmp_path):
    for name, first in (("s.wgsl", "// Generated by implc"), ("s.cl", "// Generated by implc")):
        out = tmp_path / name
        proc = implc("compile", "sphere", "-m", "taylor", "-o", str(out))
        assert proc.returncode == 0, proc.stderr
        target = "wgsl" if name.endswith("wgsl") else "opencl"
        expected = implc("compile", "sphere", "-m", "taylor", "-t", target).stdout
        assert out.read_text() == expected and expected.startswith(first)
    proc = implc("compile", "sphere", "-m", "taylor", "-o", "-")  # standard output
    assert proc.returncode == 0 and proc.stdout.startswith("#version 330 core")
    assert not (ROOT / "-").exists()
    # -t given: the extension must be its language's
    proc = implc("compile", "sphere", "-t", "glsl", "-o", str(tmp_path / "x.wgsl"))
    assert proc.returncode == 1
    assert "the glsl shader needs .frag or .glsl, not '.wgsl'" in proc.stderr


def test_prefixes_other_targets_allow_are_accepted():
    proc = implc("compile", "sphere", "-m", "taylor", "-t", "wgsl", "--emit", "library",
                 "--prefix", "gl_")
    assert proc.returncode == 0, proc.stderr
    assert "fn gl_S(" in proc.stdout


@pytest.mark.parametrize(("target", "backend"), [("wgsl", "wgpu"), ("opencl", "cl")])
def test_render_with_a_target_uses_its_backend(tmp_path, target, backend):
    from conftest import require_backend

    require_backend(backend)
    out = tmp_path / "a.png"
    proc = implc("render", "sphere", "-t", target, "--size", "16", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    assert f"with {backend}/exact" in proc.stderr
    assert json.loads(out.with_suffix(".json").read_text())["backend"] == backend


# --- point 6: a constant the method does not read is said, not dropped -------------------

def test_a_constant_the_method_does_not_read_is_a_warning():
    proc = implc("compile", "torus", "--step", "0.5", "--tau1", "7")
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.strip() == (
        "implc compile: warning: --step and --tau1 do not apply to method exact (the "
        "default for this surface), which reads none of the method constants: ignored")
    assert proc.stdout == implc("compile", "torus").stdout
    proc = implc("compile", "torus", "-m", "taylor", "--taylor2", "consistent", "--eps", "0.1")
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.strip() == (
        "implc compile: warning: --eps and --taylor2 do not apply to method taylor, which "
        "reads --step, --tau1, --tau2, --tau3, --max-steps, --eval: ignored")
    proc = implc("compile", "torus", "-m", "hessian", "--taylor2", "consistent")
    assert proc.returncode == 0 and proc.stderr == ""


def test_method_options_with_the_reference_are_a_warning(tmp_path):
    proc = implc("render", "sphere", "-b", "reference", "-m", "hessian", "--step", "0.1",
                 "--size", "8", "-o", str(tmp_path / "a.png"))
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.splitlines()[0] == (
        "implc render: warning: -m and --step do not apply to -b reference (the exact CPU "
        "reference runs no method and no shader): ignored")


CHANGED = {"step": 0.0125, "tau1": 0.02, "tau2": 0.03, "tau3": 0.04, "eps": 2e-3,
           "taylor2": "consistent", "max_steps": 123, "evaluation": "point"}


@pytest.mark.parametrize("method", ["sign", "taylor", "curvature", "hessian",
                                    "hessian-approx", "exact", "interval"])
def test_what_a_method_reads_is_what_changes_its_shader(method):
    """Method.reads (the warning's data) is exactly the set of constants whose value
    changes the method's shader (a quartic: ray-poly is auto's form)."""
    from implc.emit import emit
    from implc.loaders import load_surface
    from implc.methods import METHODS

    surface = load_surface(equation="x^4 + y^4 + z^4 - 1")
    meth = METHODS[method]
    base = emit(surface, "glsl", method, meth.constants())
    changes = {field for field, value in CHANGED.items()
               if emit(surface, "glsl", method, meth.constants(**{field: value})) != base}
    assert changes == meth.reads


# --- point 19: help and the sidecar say what is true --------------------------------------

def test_help_states_defaults_and_the_truth():
    text = " ".join(implc("compile", "--help").stdout.split())
    assert "program (default): a complete shader" in text
    assert "(default: none)" in text  # --prefix
    assert "Estrin" in text and "Horner" not in text  # --eval
    assert "extremum" in text  # --taylor2
    assert "- or none: standard output" in text
    text = " ".join(implc("render", "--help").stdout.split())
    assert "--width W image width in pixels; alone, the image is square (W x W)" in text
    assert "--height H image height in pixels; alone, the image is square (H x H)" in text
    for command in ("list", "validate"):
        proc = implc(command, "--help")
        body = proc.stdout.split("\n\n")[1]  # the description, after the usage
        assert not body.startswith(("positional", "options")), proc.stdout


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


@pytest.mark.parametrize("spec, method, form", [
    # sums of powers evaluate cheaply at a point by power chains: 29 against 40 operations
    # a step, and the point program measured 1.10x faster at 512^2 (docs/RESULTS.md)
    ("x^12 + y^12 + z^12 - 1", "taylor", "point"),
    ("x^12 + y^12 + z^12 - 1", "hessian", "point"),
    # Barth's decic: 104 against 56 (taylor), 297 against 83 (hessian); ray-poly measured
    # 1.30x and 1.95x faster
    ("barth-decic", "taylor", "ray-poly"),
    ("barth-decic", "hessian", "ray-poly"),
    ("cross-cap", "sign", "ray-poly"),
])
def test_auto_takes_the_form_whose_march_step_costs_less(spec, method, form):
    """`--eval auto` is the form with fewer operations a march step (implc show prints
    both), and the program it emits is that form's."""
    from implc.emit import emit
    from implc.loaders import load_surface
    from implc.marcher import choose_form, step_ops
    from implc.methods import METHODS
    from implc.options import FORMS

    surface = load_surface(equation=spec) if "=" in spec or "^" in spec else load_surface(spec)
    meth = METHODS[method]
    other, = set(FORMS) - {form}
    assert step_ops(meth, surface.expr, form) < step_ops(meth, surface.expr, other)
    assert choose_form(meth, surface.expr) == form
    assert emit(surface, "glsl", method) == emit(surface, "glsl", method, evaluation=form)
    assert emit(surface, "glsl", method) != emit(surface, "glsl", method, evaluation=other)


def test_auto_keeps_point_above_its_degree_bound():
    """Above AUTO_RAY_POLY_MAX_DEGREE `auto` takes point even where ray-poly's step is the
    cheaper (Chmutov's T14: 101 against 125 operations): on the degree-14 knot F' and F''
    from the ray's coefficients multiplied taylor's and hessian's bad pixels."""
    import sympy

    from implc.loaders import load_surface
    from implc.marcher import choose_form, step_ops
    from implc.methods import METHODS
    from implc.options import AUTO_RAY_POLY_MAX_DEGREE

    for degree in (AUTO_RAY_POLY_MAX_DEGREE, AUTO_RAY_POLY_MAX_DEGREE + 2):
        t = sympy.Poly(sympy.chebyshevt(degree, sympy.Symbol("x")))
        equation = " + ".join(f"({c})*{v}^{k}" for (k,), c in t.terms() for v in "xyz")
        expr = load_surface(equation=equation).expr
        taylor = METHODS["taylor"]
        assert step_ops(taylor, expr, "ray-poly") < step_ops(taylor, expr, "point")
        expected = "ray-poly" if degree <= AUTO_RAY_POLY_MAX_DEGREE else "point"
        assert choose_form(taylor, expr) == expected, degree
