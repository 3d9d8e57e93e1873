"""Atomic file writes: a reader (or an interrupted run) never sees a partial output file."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

from .errors import InputError


def write_atomic(path: Path, data: str | bytes) -> None:
    """Write `data` to `path` through a temporary file in the same directory + rename."""
    payload = data.encode("utf-8") if isinstance(data, str) else data
    write_with(path, lambda tmp: Path(tmp).write_bytes(payload))


def write_with(path: Path, writer: Callable[[str], object]) -> None:
    """Let `writer(temp_path)` produce the file, then rename it onto `path` atomically.

    The temporary keeps the target's extension (image writers choose the format by it).
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise InputError(f"cannot write {path}: directory {directory} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=directory)
    os.close(fd)
    try:
        writer(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; outputs are ordinary files
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
