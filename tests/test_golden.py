"""Golden shaders of every target in the registry: byte-identical output for every pinned
case (tests/cases.py), each accepted by its language's real compiler. Update on purpose
with `pytest tests/test_golden.py --update-golden` (or `make golden`)."""

from __future__ import annotations

from pathlib import Path

import pytest
from cases import all_golden_cases
from conftest import check_golden, require_validator

from implc.emit import emit
from implc.loaders import load_surface
from implc.methods import METHODS
from implc.targets import TARGETS

GOLDEN = Path(__file__).parent / "golden"
CASES = all_golden_cases()
UPDATE = "pytest tests/test_golden.py --update-golden` (or `make golden"


def _emit(case) -> str:
    prefix = case.example.replace("-", "_") + "_" if case.emit == "library" else ""
    constants = METHODS[case.method].constants(taylor2=case.taylor2)
    return emit(load_surface(case.example), case.target, case.method, constants, case.flavor,
                case.emit, prefix, case.precision)


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.id)
def test_golden(case, update_golden):
    validate = require_validator(case.target) if update_golden else None
    check_golden(GOLDEN / case.target / case.name, lambda: _emit(case),
                 lambda text: validate(text, case.name), update_golden, UPDATE)


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.id)
def test_golden_validates(case):
    validate = require_validator(case.target)
    path = GOLDEN / case.target / case.name
    if not path.exists():
        pytest.fail(f"missing golden {path}: run `{UPDATE}`")
    verdict = validate(path.read_text(encoding="utf-8"), case.name)
    assert verdict.ok, verdict.render(case.name)


@pytest.mark.parametrize("target", list(TARGETS))
def test_no_stale_goldens(target):
    expected = {c.name for c in CASES if c.target == target}
    present = {p.name for p in (GOLDEN / target).glob("*")}
    assert present <= expected, f"golden files no test produces: {sorted(present - expected)}"
