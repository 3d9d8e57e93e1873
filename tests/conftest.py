"""Shared test fixtures: golden updating, tool requirements, bundled surfaces."""

from __future__ import annotations

import os
import shutil

import pytest

import implc.chromium as _chromium

IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true",
                     help="rewrite tests/golden/ from the current output")


@pytest.fixture
def update_golden(request) -> bool:
    return bool(request.config.getoption("--update-golden"))


def require_tool(name: str) -> str:
    """Path of an external tool; skip without it, but fail under CI=true."""
    path = shutil.which(name)
    if path is None:
        if IN_CI:
            pytest.fail(f"{name} is required under CI=true (run `make setup`)")
        pytest.skip(f"{name} not installed (run `make setup`)")
    return path


def require_gl():
    """A headless GL context; skip without one, but fail under CI=true."""
    from implc.errors import ToolError
    from implc.render.gl import context

    try:
        return context()
    except ToolError as err:
        if IN_CI:
            pytest.fail(f"headless OpenGL is required under CI=true: {err}")
        pytest.skip(f"no headless OpenGL: {err}")


def require_backend(backend: str):
    """The runtime of a render backend, opened by its record's probe (a GL context, a
    wgpu or OpenCL device); skip without it, but fail under CI=true."""
    from implc.errors import ToolError
    from implc.targets import TARGETS, resolve

    record = next(t.backends[backend] for t in TARGETS.values() if backend in t.backends)
    try:
        return resolve(record.probe)()
    except ToolError as err:
        _require(f"render backend {backend}", str(err))


def require_validator(target: str):
    """`validate(text, name)` with the target's real compiler: a missing tool or device
    (a ToolError) skips, but fails under CI=true."""
    from implc.errors import ToolError
    from implc.validate import validate_text

    def validate(text: str, name: str):
        try:
            return validate_text(text, target, name)
        except ToolError as err:
            _require(f"the {target} validator", str(err))

    return validate


# --- the real browser (tests/test_view.py, tests/test_browser.py) --------------------------
# Headless Chromium on this GPU-less machine, with implc's flags (implc/chromium.py: why
# each is needed), which the float32 probe's browser drivers use too.
CHROMIUM_FLAGS = _chromium.CHROMIUM_FLAGS


def _require(what: str, reason: str):
    if IN_CI:
        pytest.fail(f"{what} is required under CI=true: {reason} (run `make setup`)")
    pytest.skip(f"{what} not available: {reason} (run `make setup`)")


def chromium_path() -> str:
    """The system Chromium (Debian's `chromium`; IMPLC_CHROMIUM overrides)."""
    path = _chromium.chromium_path()
    if not path:
        _require("chromium", "no chromium on PATH")
    return path


@pytest.fixture(scope="session")
def browser():
    """One headless Chromium for the whole session (starting one costs ~0.5 s)."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _require("playwright", "the Python package is not installed")
    executable = chromium_path()
    with sync_playwright() as playwright:
        try:
            chromium = playwright.chromium.launch(executable_path=executable,
                                                  args=list(CHROMIUM_FLAGS))
        except Exception as err:  # playwright's Error: the browser did not start
            _require("a working chromium", f"{executable} did not start: {err}")
        try:
            yield chromium
        finally:
            chromium.close()


def check_golden(path, make_text, validate, update: bool, update_command: str) -> None:
    """Compare a freshly emitted shader with its golden file, byte for byte.

    Under --update-golden a file compared with what the test just wrote proves nothing,
    so the update run checks what it is about to pin instead: the text must be accepted
    by its language's real compiler (`validate(text)` returns a Verdict; an invalid
    golden is never written), and a second, independent emission must give the same
    bytes (deterministic output). Only a changed file is rewritten.
    """
    from pathlib import Path

    path = Path(path)
    text = make_text()
    if update:
        verdict = validate(text)
        assert verdict.ok, (f"{path.name}: the new output fails validation; not written\n"
                            + verdict.render(path.name))
        again = make_text()
        assert again == text, f"{path.name}: two emissions differ; not written"
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
        return
    assert path.exists(), f"missing golden {path}: run `{update_command}`"
    assert text == path.read_text(encoding="utf-8"), (
        f"{path.name} differs from its golden file; if the change is intended, run "
        f"`{update_command}` and say why in the commit message"
    )
