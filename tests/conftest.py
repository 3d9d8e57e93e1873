"""Shared test fixtures: golden updating, tool requirements, bundled surfaces."""

from __future__ import annotations

import os
import shutil

import pytest

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
