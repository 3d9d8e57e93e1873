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


def cache_dir(kind: str) -> Path | None:
    """A directory of implc's own under the user's cache ($XDG_CACHE_HOME, else ~/.cache;
    $IMPLC_CACHE_DIR overrides both, and an empty value turns caching off), made on
    first use; None where none can be written (a read-only home, Pyodide): callers then
    work without it."""
    import os

    override = os.environ.get("IMPLC_CACHE_DIR")
    if override == "":
        return None
    root = (Path(override) if override else
            Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "implc")
    path = root / kind
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return path if os.access(path, os.W_OK) else None
