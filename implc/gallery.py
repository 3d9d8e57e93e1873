"""`implc gallery`: a contact sheet of many surfaces, thumbnails linking to live pages.

Each surface is loaded, framed like `implc render` frames it, rendered at thumbnail
size with its best method (`marcher.default_method`) and given its `implc view` page;
templates/gallery/index.html.j2 lays the cells out. A surface that fails (a bad file,
an equation implc refuses, a render error) gets its error in its cell and the run goes
on; `contact-sheet.png` is the same grid as one picture (for a README). Everything is
written into a staged directory that becomes `out_dir` only when the run completes.
"""

from __future__ import annotations

import dataclasses
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

import numpy as np

from .derive import polynomial_degree
from .emit import render_template
from .errors import ImplcError
from .extent import SEARCHED, locate_surface
from .fileio import staged_directory, write_atomic
from .loaders import load_surface
from .marcher import default_method
from .methods import get_method
from .progress import Progress
from .render.run import render
from .scene import ViewOptions, apply_view, frame_problem
from .surface import Surface
from .view import viewer_page

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


def run_gallery(specs: list[str], out_dir: Path, size: int = 160, backend: str = "gl",
                webgpu: bool = False, stream: TextIO | None = sys.stderr) -> list[Cell]:
    """Render every surface of `specs` into `out_dir` (index.html, NAME.png, NAME.html,
    contact-sheet.png); the cells in order. Errors of one surface stay in its cell."""
    cells: list[Cell] = []
    images: list[np.ndarray | None] = []
    stems: set[str] = set()
    with staged_directory(out_dir) as stage, \
            Progress(total=len(specs), desc="gallery", stream=stream, unit="surface") as bar:
        for spec in specs:
            stem = _unique_stem(spec, stems)
            cell, image = _one(spec, stem, stage, size, backend, webgpu, bar)
            cells.append(cell)
            images.append(image)
            bar.step(cell.error.splitlines()[0] if cell.error else
                     f"{cell.name or spec}: {cell.method}, {cell.frame_ms:.1f} ms")
        write_atomic(stage / "index.html", render_template(
            "gallery/index.html.j2", cells=[dataclasses.asdict(c) for c in cells],
            size=size, backend=backend))
        _write_sheet(stage / "contact-sheet.png", cells, images, size)
    return cells


def _one(spec: str, stem: str, stage: Path, size: int, backend: str, webgpu: bool,
         bar: Progress) -> tuple[Cell, np.ndarray | None]:
    cell = Cell(spec, stem, name=Path(spec).stem)
    try:
        loaded = load_surface(spec)
        for note in loaded.notes:
            bar.note(note)
        surface = _framed(loaded, size)
        degree = polynomial_degree(surface.expr)
        method = default_method(surface.expr)
        cell = dataclasses.replace(
            cell, name=surface.name, equation=surface.symbolic_equation,
            degree="non-poly" if degree is None else str(degree), method=method)
        result = render(surface, backend, method, get_method(method).defaults, size, size)
        image = np.round(np.clip(result.color, 0.0, 1.0) * 255.0).astype(np.uint8)
        _write_png(stage / f"{stem}.png", image)
        write_atomic(stage / f"{stem}.html", viewer_page(surface, method, webgpu=webgpu))
        frame = result.timing.get("frame", 0.0)
        return dataclasses.replace(cell, frame_ms=1000.0 * frame,
                                   hit_percent=100.0 * float(result.hit.mean())), image
    except ImplcError as err:
        return dataclasses.replace(cell, error=err.render()), None
    except Exception as err:  # noqa: BLE001 - a bug in one surface must not end the sheet
        return dataclasses.replace(cell, error=f"implc: internal error: "
                                               f"{type(err).__name__}: {err}"), None


def _framed(surface: Surface, size: int) -> Surface:
    """The view `implc render` gives it: a surface without a clip sphere is searched for."""
    view, _ = apply_view(surface.view, ViewOptions(),
                         lambda center: locate_surface(surface.expr, center), 1.0, SEARCHED)
    problem = frame_problem(view, size, size)
    if problem:
        raise ImplcError(f"{surface.origin}: {problem}")
    return dataclasses.replace(surface, view=view)


def _unique_stem(spec: str, taken: set[str]) -> str:
    base = re.sub(r"[^A-Za-z0-9_.-]+", "-", Path(spec).stem).strip("-.") or "surface"
    stem, n = base, 2
    while stem.lower() in taken or stem.lower() == "index":
        stem, n = f"{base}-{n}", n + 1
    taken.add(stem.lower())
    return stem


def _write_png(path: Path, image: np.ndarray) -> None:
    from PIL import Image

    write_atomic(path, _png_bytes(Image.fromarray(image, "RGB")))


def _png_bytes(image) -> bytes:
    import io

    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    return buffer.getvalue()


def _write_sheet(path: Path, cells: list[Cell], images: list[np.ndarray | None],
                 size: int) -> None:
    """All thumbnails in one PNG, SHEET_COLUMNS a row, each named below; a failed
    surface's cell is dark red with its name."""
    from PIL import Image, ImageDraw

    columns = max(1, min(SHEET_COLUMNS, len(cells)))
    rows = max(1, -(-len(cells) // columns))
    sheet = Image.new("RGB", (columns * size, rows * (size + LABEL_HEIGHT)), (20, 20, 25))
    draw = ImageDraw.Draw(sheet)
    for k, (cell, image) in enumerate(zip(cells, images, strict=True)):
        x, y = (k % columns) * size, (k // columns) * (size + LABEL_HEIGHT)
        if image is None:
            draw.rectangle([x, y, x + size - 1, y + size - 1], fill=(90, 20, 20))
            draw.text((x + 4, y + 4), "error", fill=(255, 200, 200))
        else:
            sheet.paste(Image.fromarray(image, "RGB"), (x, y))
        label = cell.name if len(cell.name) * 6 < size else cell.name[: size // 6 - 1] + "~"
        draw.text((x + 3, y + size + 1), label, fill=(220, 220, 225))
    write_atomic(path, _png_bytes(sheet))
