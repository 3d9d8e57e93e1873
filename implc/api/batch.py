"""Batch runs over many surfaces: the contact sheet, the Table 1 bench and the corpus.

Each takes a `concurrent.futures.Executor` for its work (local processes, a Dask
cluster's `Client.get_executor()`); None runs it in this process. Each surface is
framed by the same function as a single render (`Surface.framed`).
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from ..errors import InputError

if TYPE_CHECKING:
    from ..bench import BenchRun
    from ..corpus import Row, RowResult
    from ..limits import Limits
    from .contact_sheet import Cell


def gallery(surfaces: Sequence[str], out_dir: str | Path, *, size: int = 160,
            backend: str = "gl", webgpu: bool = False, executor: Executor | None = None,
            progress: TextIO | None = sys.stderr) -> list[Cell]:
    """Render each surface file or example name as a thumbnail with its default method
    and write index.html, contact-sheet.png and each surface's viewer page into
    `out_dir`; the cells (a failed surface's cell holds its error)."""
    from .contact_sheet import run_gallery

    return run_gallery(list(surfaces), Path(out_dir), size=size, backend=backend,
                       webgpu=webgpu, stream=progress, executor=executor)


def benchmark(surfaces: Sequence[str], out_dir: str | Path, *, size: int = 1024,
          methods: Sequence[str] | None = None, frames: int = 3, backend: str = "gl",
          configs: Sequence[str] | None = None, equal_step: float | None = None,
          exr: bool = False, baseline: bool = False, gpu_families: Sequence[str] = (),
          executor: Executor | None = None,
          progress: TextIO | None = sys.stderr) -> BenchRun:
    """The paper's Table 1 over `surfaces` (files or example names): every method timed
    in turns on this machine, each against the exact CPU reference (computed on
    `executor` when one is given: the timing itself always runs here, alone). With
    `gpu_families` (e.g. ("navi21",)), each cell's program compiled for HLSL also gets
    RADV/ACO's statistics on those AMD families (`BenchRun.gpu_stats`)."""
    from ..bench import CONFIG_NAMES, DEFAULT_METHODS, EQUAL_STEP, run_bench
    from .surface import Surface

    framed = {}
    for spec in surfaces:
        key = Path(spec).stem
        if key in framed:
            raise InputError(f"surface '{key}' is given twice")
        surface = Surface.load(spec)
        for note in surface.notes if progress is not None else ():
            print(note, file=progress)
        framed[key] = surface.framed()[0]
    return run_bench(framed, Path(out_dir), size=size, methods=methods or DEFAULT_METHODS,
                     frames=frames, backend=backend, configs=configs or CONFIG_NAMES,
                     equal_step=EQUAL_STEP if equal_step is None else equal_step, exr=exr,
                     baseline=baseline, gpu_families=tuple(gpu_families), progress=progress,
                     executor=executor)


def check_corpus(rows: Iterable[Row], targets: Sequence[str] | None = None, *,
           validate: bool = True, check: bool = True, limits: Limits | None = None,
           progress: object = None, executor: Executor | None = None) -> list[RowResult]:
    """implc over corpus rows (`implc.corpus.load_rows(tsv)`): load, derive, check
    numerically, emit and validate each, on `executor` when one is given."""
    from ..corpus import TARGETS, run_corpus

    return run_corpus(rows, targets or TARGETS, validate=validate, check=check,
                      limits=limits, progress=progress, executor=executor)  # type: ignore[arg-type]
