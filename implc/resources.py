"""Where the bundled templates and examples are: inside an installed wheel or a checkout."""

from __future__ import annotations

from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def data_dir(kind: str) -> Path:
    """`templates` or `examples`: `implc/<kind>` in a wheel, `<repo>/<kind>` in a checkout."""
    for candidate in (_PACKAGE / kind, _PACKAGE.parent / kind):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"implc's {kind} directory is missing (looked beside {_PACKAGE})")
