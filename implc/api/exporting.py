"""`Surface.export`: the files a host engine or tool loads (implc/hosts.py), as a record
that saves them, and the compile behind it (the method resolved as `Surface.compile`
resolves it, the float32 finding on the record)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import OptionError
from .compiling import Framable, float32_finding, resolve_method


@dataclass(frozen=True)
class HostFiles:
    """What `Surface.export(host)` wrote: `files` (name -> text, the main file first),
    the method, and the warnings a user should know (float32 that cannot hold it)."""

    host: str
    method: str
    files: Mapping[str, str]
    warnings: tuple[str, ...] = ()

    @property
    def main(self) -> str:
        """The main file's text (the one the host loads first)."""
        return next(iter(self.files.values()))

    def save(self, directory: str | Path = ".") -> list[Path]:
        """Write every file into `directory` (made if missing): all of them or, on an
        error or an interruption, none (staged beside it, then moved in); the paths."""
        from ..fileio import check_output_dir, staged_directory

        folder = check_output_dir(directory, what=f"{self.host} host's directory")
        with staged_directory(folder) as stage:
            for name, text in self.files.items():
                (stage / name).write_text(text, encoding="utf-8")
        return [folder / name for name in self.files]

    def __str__(self) -> str:
        return self.main


def export_surface(surface: Framable, host: str, method: str | None, *,
                   precision: str | None, prefix: str | None, command: str,
                   constants: Mapping[str, Any]) -> HostFiles:
    """`Surface.export`."""
    from ..export import export_files
    from ..hosts import get_host

    try:
        record = get_host(host)
    except ValueError as err:
        raise OptionError(f"--host: {err}") from None
    method, values = resolve_method(surface, method, constants)
    framed = surface.framed()[0]
    files = export_files(framed, record, method, values, precision or "float", prefix,
                         command)
    float32, _ = float32_finding(framed, method)
    return HostFiles(record.name, method, files, (float32,) if float32 else ())
