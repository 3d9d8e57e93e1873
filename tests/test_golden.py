"""Golden shaders: byte-identical output for every pinned case, each accepted by
glslangValidator. Update on purpose with `pytest --update-golden` (or `make golden`)."""

from __future__ import annotations

from pathlib import Path

import pytest
from cases import golden_cases, golden_name
from conftest import check_golden, require_tool

from implc.emit import emit
from implc.surface import load_surface
from implc.validate import validate_glsl

GOLDEN = Path(__file__).parent / "golden" / "glsl"


def _emit(example: str, method: str, flavor: str, kind: str) -> str:
    prefix = example.replace("-", "_") + "_" if kind == "library" else ""
    return emit(load_surface(example), "glsl", method, None, flavor, kind, prefix)


@pytest.mark.parametrize("case", golden_cases(), ids=lambda c: golden_name(*c))
def test_golden(case, update_golden):
    name = golden_name(*case)
    if update_golden:
        require_tool("glslangValidator")
    check_golden(GOLDEN / name, lambda: _emit(*case), lambda text: validate_glsl(text, name),
                 update_golden, "pytest --update-golden` (or `make golden")


@pytest.mark.parametrize("case", golden_cases(), ids=lambda c: golden_name(*c))
def test_golden_validates(case):
    require_tool("glslangValidator")
    name = golden_name(*case)
    path = GOLDEN / name
    if not path.exists():
        pytest.fail(f"missing golden {path}: run `pytest --update-golden`")
    verdict = validate_glsl(path.read_text(encoding="utf-8"), name)
    assert verdict.ok, verdict.render(name)


def test_no_stale_goldens():
    expected = {golden_name(*c) for c in golden_cases()}
    present = {p.name for p in GOLDEN.glob("*")}
    assert present <= expected, f"golden files no test produces: {sorted(present - expected)}"
