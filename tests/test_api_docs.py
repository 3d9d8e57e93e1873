"""Every example in docs/api.md runs, and prints what the page says it prints."""

from __future__ import annotations

import doctest
from pathlib import Path

from conftest import require_gl

DOC = Path(__file__).resolve().parent.parent / "docs" / "api.md"


def test_the_api_page_examples_run():
    require_gl()  # the page renders a picture
    result = doctest.testfile(str(DOC), module_relative=False, optionflags=doctest.ELLIPSIS,
                              verbose=False, report=True)
    assert result.attempted > 20, result
    assert result.failed == 0, f"{result.failed} of docs/api.md's examples failed (above)"


def test_the_package_docstring_example_runs():
    import implc

    result = doctest.testmod(implc, verbose=False, report=True)
    assert result.attempted >= 2 and result.failed == 0, result
