"""Start-up (issue 23, point 20): `implc --help`, `COMMAND --help` and `--version` need
neither sympy nor numpy. Timed by `make startup` (scripts/startup.py), not here: these
tests check what is imported, which does not depend on the machine's load."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
HEAVY = ("sympy", "numpy", "jinja2")

PROBE = """
import json, sys
from implc.cli import main
try:
    main(sys.argv[1:])
except SystemExit:
    pass
print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in {heavy!r})),
      file=sys.stderr)
"""


def heavy_modules(*argv: str) -> list[str]:
    """The heavy top-level modules loaded by `implc ARGV` (run in a fresh process)."""
    proc = subprocess.run(
        [sys.executable, "-c", PROBE.format(heavy=set(HEAVY)), *argv],
        capture_output=True, text=True, timeout=120,
        env={**os.environ, "PYTHONPATH": str(ROOT)}, cwd=ROOT,
    )
    return json.loads(proc.stderr.strip().splitlines()[-1])


def test_importing_the_cli_loads_no_sympy_or_numpy():
    assert heavy_modules() == []


GPU_STACKS = ("moderngl", "glcontext", "wgpu", "pyopencl")


def test_import_implc_loads_no_sympy_numpy_jinja2_or_gpu_stack():
    """`import implc` stays cheap (issue 43): the library's names load on first use.
    (`make startup` times it beside `implc --help`.)"""
    probe = ("import json, sys, implc\n"
             "print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in "
             f"{set(HEAVY + GPU_STACKS)!r})))")
    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, env={**os.environ, "PYTHONPATH": str(ROOT)}, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout.strip().splitlines()[-1]) == []


@pytest.mark.parametrize("argv", [
    ["--help"], ["--version"], ["compile", "--help"], ["render", "--help"],
    ["show", "--help"], ["view", "--help"], ["bench", "--help"], ["corpus", "--help"],
    ["compare", "--help"], ["validate", "--help"], ["list", "--help"],
])
def test_help_and_version_load_no_sympy_or_numpy(argv):
    assert heavy_modules(*argv) == []


def test_the_light_tables_are_the_registries():
    """What the command line offers without importing the registries (implc/options.py)
    is what the registries hold."""
    from implc.backends.opencl import PRECISIONS
    from implc.marcher import AUTO_RAY_POLY_MAX_DEGREE, EVAL_CHOICES
    from implc.methods import METHODS
    from implc.options import AUTO_RAY_POLY_MAX_DEGREE as LIGHT_AUTO
    from implc.options import EVAL_CHOICES as LIGHT_EVAL
    from implc.options import METHOD_NAMES
    from implc.targets import TARGETS

    assert tuple(METHODS) == METHOD_NAMES
    assert (EVAL_CHOICES, AUTO_RAY_POLY_MAX_DEGREE) == (LIGHT_EVAL, LIGHT_AUTO)
    assert TARGETS["opencl"].precisions == PRECISIONS
