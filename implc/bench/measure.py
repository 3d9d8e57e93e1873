"""Timing a bench run: every configuration x surface x method, its frames taken in turns,
each last frame compared with the exact reference; then the run's report is written.

The package's docstring (implc/bench/__init__.py) says what is measured and why.
"""

from __future__ import annotations

import os
import platform
import statistics
import sys
import time
from collections.abc import Mapping, Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import TextIO

from ..errors import InputError
from ..fileio import staged_directory
from ..methods import METHODS
from ..metrics import compare
from ..progress import Progress
from ..render.result import RenderResult
from ..render.run import BACKENDS, metadata, open_runner
from ..surface import Surface
from .records import CONFIG_NAMES, DEFAULT_METHODS, EQUAL_STEP, BenchRun, Cell, make_configs
from .report import write_outputs

TILE = 256  # figure tile size in pixels


def machine_info(backend: str) -> dict:
    """What the fps depend on: the renderer (llvmpipe here), the CPU and its core count."""
    info = {
        "cpu_count": os.cpu_count(),
        "cpu_model": _cpu_model(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "load_average_start": _load_average(),  # other work on the machine skews fps
    }
    if backend == "gl":
        from ..render.gl import renderer_name

        info["gl_renderer"] = renderer_name()
    return info


def _load_average() -> list[float] | None:
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def time_interleaved(runners: Sequence, frames: int) -> tuple[list[list[float]], list,
                                                               list[float]]:
    """Seconds of each runner's `frames` frames after its warm-up, each runner's last
    frame, read back after the timing, and each runner's warm-up seconds (its first use,
    where the driver compiles: `TimedRunner.warm_up`).

    A timed frame is `draw()`: render and wait for completion (glFinish, queue wait). The
    read-back of two float32 RGBA targets (32 MB at 1024^2, ~10 ms on llvmpipe) is the
    same for every method and no part of what an application pays per frame, so timing
    it would pull every ratio towards 1.

    The warm-up absorbs first-use costs (driver shader compilation, allocation); one
    whole frame follows it untimed, so every timed frame starts from the same state.
    Frames are taken in rounds (one frame of every runner per round), so a burst of load
    from another process on a shared machine hits every method alike instead of one of
    them, which keeps the fps ratios fair.
    """
    compile_seconds = [runner.warm_up() for runner in runners]
    for runner in runners:
        runner.frame()
    seconds: list[list[float]] = [[] for _ in runners]
    for _ in range(frames):
        for index, runner in enumerate(runners):
            start = time.perf_counter()
            runner.draw()
            seconds[index].append(time.perf_counter() - start)
    last = [runner.read() for runner in runners]
    return seconds, last, compile_seconds


def run_bench(
    surfaces: Mapping[str, Surface],
    out_dir: Path,
    *,
    size: int = 1024,
    methods: Sequence[str] = DEFAULT_METHODS,
    frames: int = 3,
    backend: str = "gl",
    configs: Sequence[str] = CONFIG_NAMES,
    equal_step: float = EQUAL_STEP,
    exr: bool = False,
    baseline: bool = False,
    gpu_families: Sequence[str] = (),
    progress: TextIO | None = sys.stderr,
    executor: Executor | None = None,
) -> BenchRun:
    """Measure every configuration x surface x method and write the outputs to `out_dir`.

    `surfaces` maps a short key (file stem, e.g. "cross-cap") to the loaded surface.
    With `baseline`, the hand-written programs of implc/baseline.py (GL only) are timed
    in the same rounds as the generated ones.
    Progress goes to `progress`: a bar with an ETA on a terminal, numbered lines otherwise.
    The references are computed on `executor` when one is given (the frames are always
    timed here, alone). With `gpu_families`, each cell's program compiled for HLSL gets
    RADV/ACO's statistics (`BenchRun.gpu_stats`), asked once per family for all cells.
    """
    _check_args(surfaces, size, methods, frames, backend, equal_step)
    bench_configs = make_configs(configs, equal_step)
    out_dir = Path(out_dir)
    # every file goes to a staging directory that moves into out_dir at the end: an
    # error, Ctrl-C or SIGTERM midway leaves no partial run behind (implc.fileio)
    with staged_directory(out_dir) as stage:
        run = _measure(surfaces, stage, size, methods, frames, backend, bench_configs, exr,
                       progress, baseline, executor)
        if gpu_families:
            _gpu_stats(run, gpu_families, _printer(progress))
        write_outputs(run, stage)
    _printer(progress)(f"wrote {out_dir / 'table.md'}, table.json, figure.png, renders/")
    return run


def reference_frame(surface: Surface, size: int) -> tuple[RenderResult, float]:
    """The exact CPU reference of `surface` at `size`² and the seconds it took (a plain
    function of plain values, so an executor's worker can run it)."""
    start = time.perf_counter()
    unused = METHODS["taylor"].defaults  # the reference has no method constants
    ref = open_runner(surface, "reference", "", unused, size, size).frame()
    return ref, time.perf_counter() - start


def _measure(surfaces, out_dir: Path, size, methods, frames, backend, bench_configs, exr,
             progress, baseline: bool = False, executor: Executor | None = None) -> BenchRun:
    from ..figure import tile_image
    from ..render.image_io import write_render

    renders = out_dir / "renders"
    renders.mkdir(parents=True, exist_ok=True)
    run = BenchRun(size, frames, backend, list(methods), bench_configs, dict(surfaces),
                   machine_info(backend))
    run.baseline = baseline
    total = sum(len(surfaces) * len(c.applies_to(methods)) for c in bench_configs)
    bar = Progress(total, "bench", progress, unit="cell")
    bar.note(f"bench: {len(surfaces)} surface(s), {size}x{size}, {frames} frame(s) after 1 "
             f"warm-up, backend {backend} ({run.machine.get('gl_renderer', '?')})")
    try:
        references: dict[str, RenderResult] = {}
        # every reference is computed (on the executor, if any) before any frame is timed
        pending = ({key: executor.submit(reference_frame, surface, size)
                    for key, surface in surfaces.items()} if executor is not None else {})
        for key, surface in surfaces.items():
            ref, seconds = (pending[key].result() if pending
                            else reference_frame(surface, size))
            run.reference_seconds[key] = seconds
            references[key] = ref
            name = f"{key}-reference.png"
            write_render(ref, renders / name, metadata(surface, "reference", None, ref))
            run.tiles["reference", key, "reference"] = tile_image(ref.color, TILE)
            bar.note(f"reference {key}: {run.reference_seconds[key]:.2f} s")
        for config in bench_configs:
            bar.note(f"{config.name}: {config.title}")
            chosen = config.applies_to(methods)
            for key, surface in surfaces.items():
                _measure_surface(run, config, chosen, key, surface, references[key], renders,
                                 exr, bar)
    finally:
        bar.close()
    run.machine["load_average_end"] = _load_average()
    _fill_ratios(run)
    return run


def _measure_surface(run, config, chosen, key, surface, reference, renders, exr, bar) -> None:
    from ..baseline import has_baseline, open_baseline_runner
    from ..figure import tile_image
    from ..render.image_io import write_render

    size, backend = run.size, run.backend
    constants = [METHODS[m].constants(**config.overrides) for m in chosen]
    hand = [m for m in chosen if run.baseline and backend == "gl" and has_baseline(key, m)]
    runners, setup = [], []
    try:
        for method, method_constants in zip(chosen, constants, strict=True):
            start = time.perf_counter()
            runners.append(open_runner(surface, backend, method, method_constants, size, size))
            setup.append(time.perf_counter() - start)
        for method in hand:
            runners.append(open_baseline_runner(key, method, constants[chosen.index(method)],
                                                surface, size, size))
        seconds, results, compiled = time_interleaved(runners, run.frames)
        shaders = [runner.shader for runner in runners[:len(chosen)]]
    finally:
        for runner in runners:
            runner.release()
    for index, method in enumerate(chosen):
        result = results[index]
        fps = statistics.median(1.0 / max(s, 1e-9) for s in seconds[index])
        stem = f"{key}-{method}-{config.name}"
        meta = metadata(surface, backend, shaders[index], result)
        write_render(result, renders / f"{stem}.png", meta)
        if exr:
            write_render(result, renders / f"{stem}.exr", meta)
        run.cells[config.name, key, method] = Cell(
            fps, seconds[index], setup[index], compiled[index], compare(result, reference),
            f"renders/{stem}.png")
        run.tiles[config.name, key, method] = tile_image(result.color, TILE)
        bar.step(f"{key} {method} {config.name}: {fps:.3g} fps")
    for offset, method in enumerate(hand):
        index = len(chosen) + offset
        fps = statistics.median(1.0 / max(s, 1e-9) for s in seconds[index])
        run.baseline_cells[config.name, key, method] = Cell(
            fps, seconds[index], 0.0, compiled[index], compare(results[index], reference), "")
        bar.note(f"{key} {method} {config.name}, hand-written baseline: {fps:.3g} fps")


def _gpu_stats(run: BenchRun, families: Sequence[str], say) -> None:
    """RADV/ACO's statistics of every cell's program as HLSL (the path to SPIR-V that
    every method has), the cell's method and constants."""
    from ..emit import compile_shader
    from ..render.gpu_stats import gpu_stats

    keys = list(run.cells)
    configs = {c.name: c for c in run.configs}
    shaders = [compile_shader(run.surfaces[key], "hlsl", method,
                              METHODS[method].constants(**configs[config].overrides))
               for config, key, method in keys]
    say(f"gpu statistics: {len(shaders)} program(s) on {', '.join(families)} (RADV/ACO)")
    for family, rows in gpu_stats(shaders, families).items():
        for cell, stats in zip(keys, rows, strict=True):
            run.gpu_stats.setdefault(cell, {})[family] = stats.as_dict()


def _check_args(surfaces, size, methods, frames, backend, equal_step) -> None:
    if not surfaces:
        raise InputError("give at least one surface")
    if not 8 <= size <= 8192:
        raise InputError(f"--size must be between 8 and 8192 pixels (got {size})")
    if not 1 <= frames <= 1000:
        raise InputError(f"--frames must be between 1 and 1000 (got {frames})")
    if not methods:
        raise InputError("give at least one method")
    for method in methods:
        if method not in METHODS:
            raise InputError(f"unknown method '{method}'; choose from {', '.join(METHODS)}")
    if len(set(methods)) != len(methods):
        raise InputError("a method is listed twice in --methods")
    if backend not in BACKENDS:
        choices = ", ".join(BACKENDS)
        raise InputError(f"bench needs a GPU backend ({choices}), got '{backend}'")
    if not 0.0 < equal_step < 1e6:
        raise InputError(f"--equal-step must be a positive number (got {equal_step})")


def _fill_ratios(run: BenchRun) -> None:
    """fps / taylor's fps on the same surface in the same configuration (frames taken in
    turns with it); None when taylor was not selected."""
    for (config_name, key, _method), cell in run.cells.items():
        base = run.cells.get((config_name, key, "taylor"))
        cell.ratio_to_taylor = cell.fps / base.fps if base is not None else None


def _printer(stream: TextIO | None):
    def say(line: str) -> None:
        if stream is not None:
            print(line, file=stream, flush=True)

    return say
