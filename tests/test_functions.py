"""Every function of implc/functions.py x every target: compiled and validated.

`functions.py` promises this test: one surface per table row and target, emitted as a
library and checked by that language's real compiler (glslangValidator, naga through
wgpu, PoCL), and the row's spelling must appear in the shader (so a function that a
rewrite removed, or a spelling that never reaches the printer, cannot pass unseen).
Rows only derivatives use (`step`, `delta`) come from the function whose derivative
brings them in (max -> step, sign -> delta).
"""

from __future__ import annotations

import pytest
import sympy
from conftest import require_tool

from implc.emit import emit
from implc.functions import FUNCTIONS, TARGETS, spelling
from implc.surface import Surface
from implc.symbols import X, Y, Z
from implc.validate import validate_text

ARGS = (X / 2 + sympy.Rational(1, 4), Y / 3 - sympy.Rational(1, 5))
# derivative-only rows: the user function whose derivative brings them in
VIA = {"step": "max", "delta": "sign"}
BY_NAME = {f.name: f for f in FUNCTIONS}


def surface_for(row) -> Surface:
    user = BY_NAME[VIA.get(row.name, row.name)]
    term = user.build(*ARGS[: user.arity])
    return Surface(f"function {row.name}", term + Z**2 - 1)


def require_target(target: str) -> None:
    if target == "glsl":
        require_tool("glslangValidator")
    elif target == "wgsl":
        from test_wgsl import require_wgpu

        require_wgpu()
    else:
        from test_opencl import require_opencl

        require_opencl()


CASES = [(row, target) for row in FUNCTIONS for target in TARGETS]


@pytest.mark.parametrize(("row", "target"), CASES,
                         ids=[f"{row.name}-{target}" for row, target in CASES])
def test_function_compiles_and_validates(row, target):
    require_target(target)
    text = emit(surface_for(row), target, "hessian", None, emit="library", prefix="f_")
    name = spelling(target).get(row.sympy_name)
    if row.user and name:
        assert f"{name}(" in text, f"{row.name} is not spelled {name}( in the {target} shader"
    elif row.name == "step":
        step = "step(" if target != "opencl" else " ? 1.0f : 0.0f)"
        assert step in text, f"no step of max in the {target} shader"
    verdict = validate_text(text, target, f"{row.name}.{target}")
    assert verdict.ok, verdict.render(f"{row.name}.{target}")


def test_every_row_and_target_is_covered():
    assert {row.name for row, _ in CASES} == {f.name for f in FUNCTIONS}
    assert {t for _, t in CASES} == {"glsl", "wgsl", "opencl"}
    assert len(CASES) == 3 * len(FUNCTIONS)
