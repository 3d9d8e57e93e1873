"""The Table 1 harness's outputs: table.md, table.json and the figures, from a `BenchRun`.

Reporting only: what was measured is `measure.py`'s (a `BenchRun`, records.py); this
module formats it, compares it with the paper's own Table 1, and writes the files.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..fileio import write_atomic, write_with
from ..methods import METHODS
from ..metrics import T_TOL
from ..version import __version__
from .records import BenchConfig, BenchRun, Cell

# The paper's Table 1 (NVidia Quadro P5000, 1024x1024): fps and SSIM as printed. The
# Hessian-exact column has no SSIM: it is the paper's own ground truth (at a tiny step).
PAPER_TABLE1: dict[str, dict[str, tuple[float, float | None]]] = {
    "cross-cap": {"taylor": (592, 0.9628), "curvature": (150, 0.9964),
                  "hessian-approx": (152, 0.9991), "hessian": (23, None)},
    "miter": {"taylor": (580, 0.9574), "curvature": (154, 0.9957),
              "hessian-approx": (158, 0.9991), "hessian": (24, None)},
    "steiner": {"taylor": (416, 0.9214), "curvature": (151, 0.9667),
                "hessian-approx": (88, 0.9878), "hessian": (25, None)},
}


def table_json(run: BenchRun) -> dict:
    """table.json: the run's settings, machine, constants and every cell."""
    return {
        "implc": __version__,
        "machine": run.machine,
        "backend": run.backend,
        "size": run.size,
        "frames": run.frames,
        "warmup_frames": 1,
        "t_tol": T_TOL,
        "methods": run.methods,
        "surfaces": {
            key: {"name": s.name, "equation": s.equation,
                  "camera": s.view.camera_json(run.size, run.size),
                  "clip": s.view.clip_json(),
                  "reference_seconds": run.reference_seconds.get(key)}
            for key, s in run.surfaces.items()
        },
        "configs": [
            {
                "name": c.name,
                "title": c.title,
                "constants": {m: METHODS[m].constants(**c.overrides).as_dict()
                              for m in run.config_methods(c)},
                "results": {
                    key: {m: _cell_json(run, (c.name, key, m))
                          for m in run.config_methods(c) if (c.name, key, m) in run.cells}
                    for key in run.surfaces
                },
            }
            for c in run.configs
        ],
        "baseline": [{"config": c, "surface": k, "method": m, **cell.as_json(),
                      "generated_fps": run.cells[c, k, m].fps}
                     for (c, k, m), cell in run.baseline_cells.items()],
        "paper_table1": {k: {m: {"fps": v[0], "ssim": v[1]} for m, v in row.items()}
                         for k, row in PAPER_TABLE1.items()},
    }


def _cell_json(run: BenchRun, cell: tuple[str, str, str]) -> dict:
    """A cell's measurement, with its program's GPU statistics when they were asked for."""
    data = run.cells[cell].as_json()
    if cell in run.gpu_stats:
        data["gpu_stats"] = run.gpu_stats[cell]
    return data


def write_outputs(run: BenchRun, out_dir: Path) -> list[Path]:
    """table.md, table.json and the figures, each written atomically."""
    out_dir = Path(out_dir)
    paths = [out_dir / "table.md", out_dir / "table.json"]
    write_atomic(paths[0], format_markdown(run))
    write_atomic(paths[1], json.dumps(table_json(run), indent=2) + "\n")
    for index, config in enumerate(run.configs):
        path = out_dir / ("figure.png" if index == 0 else f"figure-{config.name}.png")
        figure = build_figure(run, config)
        write_with(path, lambda tmp, image=figure: image.save(tmp, format="PNG"))
        paths.append(path)
    return paths


def build_figure(run: BenchRun, config: BenchConfig):
    """Rows = surfaces, columns = the configuration's methods + the reference (Fig. 2)."""
    from ..figure import grid_figure

    methods = run.config_methods(config)
    columns = [*methods, "reference"]
    tiles, captions = {}, {}
    for key in run.surfaces:
        for method in methods:
            cell = run.cells.get((config.name, key, method))
            if cell is None:
                continue
            tiles[key, method] = run.tiles[config.name, key, method]
            captions[key, method] = (
                method, f"SSIM {cell.metrics['ssim']:.4f}",
                f"false {cell.metrics['false_hits']} missed {cell.metrics['missed_hits']} "
                f"wrong {cell.metrics['wrong_root']}")
        tiles[key, "reference"] = run.tiles["reference", key, "reference"]
        captions[key, "reference"] = ("exact reference", "(float64 roots)", "")
    title = f"implc bench {config.name}: {config.title}; {run.size}x{run.size}"
    return grid_figure(list(run.surfaces), columns, tiles, captions, title)


def _cell_text(cell: Cell | None) -> str:
    if cell is None:
        return "–"
    m = cell.metrics
    ratio = "–" if cell.ratio_to_taylor is None else f"{cell.ratio_to_taylor:.2f}"
    return (f"{cell.fps:.3g} ({ratio}) / {100 * m['ssim']:.2f}% / {m['false_hits']} / "
            f"{m['missed_hits']} / {m['wrong_root']} / {m['mean_steps']:.1f}")


def format_markdown(run: BenchRun) -> str:
    """One table per configuration (rows = surfaces, columns = methods), then the paper."""
    machine = run.machine
    lines = [
        "# implc bench",
        "",
        f"{run.size}x{run.size} pixels, backend `{run.backend}` "
        f"(GL renderer: {machine.get('gl_renderer', 'n/a')}), CPU: {machine['cpu_model']} "
        f"({machine['cpu_count']} logical CPUs). Speed: median fps over {run.frames} frame(s) "
        "after 1 warm-up frame, each a draw waited for (glFinish or queue wait; the outputs "
        "are read back once, after the timing); the methods of a surface take "
        "their frames in turns. Load average (1, 5, 15 min) at start "
        f"{machine.get('load_average_start')}, at end {machine.get('load_average_end')} "
        "(other work on the machine lowers fps).",
        "",
        "Cell: `fps (fps ratio to taylor) / SSIM / false hits / missed hits / wrong-root "
        f"pixels / mean march steps per pixel`, against the exact CPU reference "
        f"(wrong root: both hit and |t - t_ref| > {T_TOL:g}).",
        "",
        "Exact reference (CPU, float64): "
        + ", ".join(f"{k} {s:.2f} s" for k, s in run.reference_seconds.items()) + ".",
        "",
    ]
    for config in run.configs:
        methods = run.config_methods(config)
        lines += [f"## {config.name}: {config.title}", ""]
        lines += ["| surface | " + " | ".join(methods) + " |",
                  "|---|" + "---|" * len(methods)]
        for key in run.surfaces:
            cells = [_cell_text(run.cells.get((config.name, key, m))) for m in methods]
            lines.append(f"| {key} | " + " | ".join(cells) + " |")
        lines.append("")
    lines += _baseline_table(run)
    lines += _gpu_table(run)
    lines += _paper_comparison(run)
    return "\n".join(lines)


def _baseline_table(run: BenchRun) -> list[str]:
    """Generated against hand-written (implc/baseline.py), frames taken in turns."""
    if not run.baseline_cells:
        return []
    lines = [
        "## generated against hand-written",
        "",
        "The hand-written GLSL of templates/baseline/ does the same work as the generated "
        "program (same step rule, test, refinement after the loop, camera, shading and "
        "outputs); its frames were taken in the same rounds. Ratio: generated fps / "
        "hand-written fps (1.00 = as fast).",
        "",
        "| config | surface | method | step | generated fps | hand-written fps | ratio | "
        "hand-written false / missed / wrong |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for (config, key, method), hand in run.baseline_cells.items():
        generated = run.cells[config, key, method]
        step = METHODS[method].constants(
            **next(c for c in run.configs if c.name == config).overrides).step
        m = hand.metrics
        lines.append(f"| {config} | {key} | {method} | {step:g} | {generated.fps:.3g} | "
                     f"{hand.fps:.3g} | {generated.fps / hand.fps:.2f} | "
                     f"{m['false_hits']} / {m['missed_hits']} / {m['wrong_root']} |")
    lines.append("")
    return lines


def _gpu_table(run: BenchRun) -> list[str]:
    """What AMD's compiler makes of each cell's program (--gpu-stats): beside the frame
    ratio, which llvmpipe measures on a CPU, the registers that decide a GPU's speed."""
    if not run.gpu_stats:
        return []
    families = list(next(iter(run.gpu_stats.values())))
    lines = [
        "## what a GPU's compiler says (RADV/ACO, no GPU: HLSL through SPIR-V)",
        "",
        "Each cell's program compiled for HLSL with its method and constants, the fragment "
        "stage as ACO compiles it on Mesa's RADV null device per AMD family. Cell: "
        "`VGPRs / waves per SIMD / instructions`, and the spills if any. The ratio is the "
        "llvmpipe frame's, from the tables above.",
        "",
        "| config | surface | method | fps / taylor's | " + " | ".join(families) + " |",
        "|---|---|---|---|" + "---|" * len(families),
    ]
    for (config, key, method), by_family in run.gpu_stats.items():
        ratio = run.cells[config, key, method].ratio_to_taylor
        cells = []
        for family in families:
            g = by_family[family]
            spill = (f" (spills {g['spilled_vgprs']} VGPRs, {g['spilled_sgprs']} SGPRs, "
                     f"{g['scratch']} B)" if g["spilled_vgprs"] or g["spilled_sgprs"]
                     or g["scratch"] else "")
            cells.append(f"{g['vgprs']} / {g['waves']} / {g['instructions']}{spill}")
        lines.append(f"| {config} | {key} | {method} | "
                     f"{'–' if ratio is None else f'{ratio:.2f}'} | " + " | ".join(cells) + " |")
    lines.append("")
    return lines


def _paper_comparison(run: BenchRun) -> list[str]:
    """Paper Table 1 beside the `paper` configuration: fps ratio to taylor and SSIM."""
    if not any(c.name == "paper" for c in run.configs):
        return []
    keys = [k for k in run.surfaces if k in PAPER_TABLE1]
    methods = [m for m in PAPER_TABLE1["cross-cap"] if m in run.methods]
    if not keys or not methods:
        return []
    lines = [
        "## paper Table 1 beside `paper`",
        "",
        "Cell: fps ratio to taylor (SSIM), the paper's and ours. The paper's "
        "hessian column is its own ground truth, so it has no SSIM.",
        "",
        "| surface | " + " | ".join(methods) + " |",
        "|---|" + "---|" * len(methods),
    ]
    for key in keys:
        row = PAPER_TABLE1[key]
        cells = []
        for m in methods:
            fps, ssim = row[m]
            paper = f"{fps / row['taylor'][0]:.3f}" + (f" ({100 * ssim:.2f}%)" if ssim else "")
            cell = run.cells.get(("paper", key, m))
            ours = "–" if cell is None or cell.ratio_to_taylor is None else (
                f"{cell.ratio_to_taylor:.3f} ({100 * cell.metrics['ssim']:.2f}%)")
            cells.append(f"paper {paper}; ours {ours}")
        lines.append(f"| {key} | " + " | ".join(cells) + " |")
    lines.append("")
    return lines
