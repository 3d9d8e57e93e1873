"""`implc gallery`: a contact sheet of many surfaces, thumbnails linking to live pages.

Each surface is loaded, framed and rendered through the public API (`implc.Surface`:
the view `implc render` gives it, its best method) at thumbnail size and given its
`implc view` page; templates/gallery/index.html.j2 lays the cells out. A surface that
fails (a bad file, an equation implc refuses, a render error) gets its error in its cell
and the run goes on; `contact-sheet.png` is the same grid as one picture (for a README).
Cells are made on an executor when one is given (local processes, a Dask cluster: each
cell is a plain function of plain values) and written here, into a staged directory that
becomes `out_dir` only when the run completes.
"""

from __future__ import annotations

import dataclasses
import re
import sys
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from ..emit import render_template
from ..errors import ImplcError
from ..fileio import staged_directory, write_atomic
from ..progress import Progress
from .records import png_bytes

SHEET_COLUMNS = 6  # cells per row of contact-sheet.png
LABEL_HEIGHT = 14  # pixels under each thumbnail for its name


@dataclass(frozen=True)
class Cell:
    """One surface of the sheet: what the page shows about it, or why it failed."""

    spec: str  # as given on the command line
    stem: str  # file names of its thumbnail and page (unique in the gallery)
    name: str = ""
    equation: str = ""
    degree: str = ""
    method: str = ""
    frame_ms: float | None = None
    hit_percent: float | None = None
    error: str = ""


@dataclass(frozen=True)
class Made:
    """A cell and its files' contents, as a worker returns them (plain, picklable)."""

    cell: Cell
    png: bytes | None = None
    page: str = ""
    notes: tuple[str, ...] = ()


def run_gallery(specs: list[str], out_dir: Path, size: int = 160, backend: str = "gl",
                webgpu: bool = False, stream: TextIO | None = sys.stderr,
                executor: Executor | None = None) -> list[Cell]:
    """Render every surface of `specs` into `out_dir` (index.html, NAME.png, NAME.html,
    contact-sheet.png), on `executor` if given, else here; the cells in order. Errors of
    one surface stay in its cell."""
    stems: set[str] = set()
    jobs = [(spec, _unique_stem(spec, stems)) for spec in specs]
    made: list[Made] = []
    with staged_directory(out_dir) as stage, \
            Progress(total=len(specs), desc="gallery", stream=stream, unit="surface") as bar:
        if executor is None:
            results = (make_cell(spec, stem, size, backend, webgpu) for spec, stem in jobs)
        else:
            futures = [executor.submit(make_cell, spec, stem, size, backend, webgpu)
                       for spec, stem in jobs]
            results = (future.result() for future in futures)
        for one in results:
            made.append(one)
            cell = one.cell
            if one.png is not None:
                write_atomic(stage / f"{cell.stem}.png", one.png)
                write_atomic(stage / f"{cell.stem}.html", one.page)
            bar.step(cell.error.splitlines()[0] if cell.error else
                     f"{cell.name or cell.spec}: {cell.method}, {cell.frame_ms:.1f} ms")
        for note in merged_notes([note for one in made for note in one.notes]):
            bar.note(note)
        cells = [one.cell for one in made]
        write_atomic(stage / "index.html", render_template(
            "gallery/index.html.j2", cells=[dataclasses.asdict(c) for c in cells],
            size=size, backend=backend))
        _write_sheet(stage / "contact-sheet.png", made, size)
    return cells


_NOTE = re.compile(r"(implc: note: )(.+?): (.*)", re.S)


def merged_notes(notes: list[str]) -> list[str]:
    """Each load note once: the same note of several files (a .jsurf file's ignored
    keys) names the files together instead of repeating itself per file."""
    files: dict[tuple[str, str], list[str]] = {}
    for note in notes:
        match = _NOTE.fullmatch(note)
        head, name, rest = match.groups() if match else ("", "", note)
        files.setdefault((head, rest), []).append(name)
    merged = []
    for (head, rest), names in files.items():
        if len(names) == 1:
            merged.append(f"{head}{names[0]}: {rest}" if names[0] else rest)
        else:
            shown = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3
                                            else "")
            merged.append(f"{head}{len(names)} files ({shown}): {rest}")
    return merged


def make_cell(spec: str, stem: str, size: int, backend: str, webgpu: bool) -> Made:
    """One surface's cell, thumbnail (PNG bytes) and page, through the public API."""
    from .surface import Surface

    cell = Cell(spec, stem, name=Path(spec).stem)
    notes: tuple[str, ...] = ()
    try:
        surface = Surface.load(spec)
        notes = surface.notes
        degree = surface.degree
        cell = dataclasses.replace(
            cell, name=surface.name, equation=surface.equation,
            degree="non-poly" if degree is None else str(degree),
            method=surface.default_method)
        rendering = surface.render(size, backend=backend)
        page = surface.view_page(webgpu=webgpu)
        frame = rendering.timing.get("frame", 0.0)
        return Made(dataclasses.replace(cell, frame_ms=1000.0 * frame,
                                        hit_percent=100.0 * rendering.hit_fraction),
                    rendering.png(), page, notes)
    except ImplcError as err:
        return Made(dataclasses.replace(cell, error=err.render()), notes=notes)
    except Exception as err:  # noqa: BLE001 - a bug in one surface must not end the sheet
        return Made(dataclasses.replace(cell, error=f"implc: internal error: "
                                                    f"{type(err).__name__}: {err}"),
                    notes=notes)


def _unique_stem(spec: str, taken: set[str]) -> str:
    base = re.sub(r"[^A-Za-z0-9_.-]+", "-", Path(spec).stem).strip("-.") or "surface"
    stem, n = base, 2
    while stem.lower() in taken or stem.lower() == "index":
        stem, n = f"{base}-{n}", n + 1
    taken.add(stem.lower())
    return stem


def _write_sheet(path: Path, made: list[Made], size: int) -> None:
    """All thumbnails in one PNG, SHEET_COLUMNS a row, each named below; a failed
    surface's cell is dark red with its name."""
    import io

    from PIL import Image, ImageDraw

    columns = max(1, min(SHEET_COLUMNS, len(made)))
    rows = max(1, -(-len(made) // columns))
    sheet = Image.new("RGB", (columns * size, rows * (size + LABEL_HEIGHT)), (20, 20, 25))
    draw = ImageDraw.Draw(sheet)
    for k, one in enumerate(made):
        cell = one.cell
        x, y = (k % columns) * size, (k // columns) * (size + LABEL_HEIGHT)
        if one.png is None:
            draw.rectangle([x, y, x + size - 1, y + size - 1], fill=(90, 20, 20))
            draw.text((x + 4, y + 4), "error", fill=(255, 200, 200))
        else:
            sheet.paste(Image.open(io.BytesIO(one.png)).convert("RGB"), (x, y))
        label = cell.name if len(cell.name) * 6 < size else cell.name[: size // 6 - 1] + "~"
        draw.text((x + 3, y + size + 1), label, fill=(220, 220, 225))
    write_atomic(path, png_bytes(sheet))
