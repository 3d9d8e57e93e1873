"""implc's generated `exact` against the strongest published solver (issue 49, point 3):
Yuksel's first-root solver in GLSL, written spill-free (templates/baseline/yuksel.frag.j2,
implc/baseline.py SOLVERS), on the same ray polynomial, camera and shading
(docs/results-gpu.md, "The strongest published solver as a baseline").

    python scripts/yuksel_baseline.py --size 512 --degrees 4,10,16,20 barth-decic
    python scripts/yuksel_baseline.py --count-size 512,16=128,20=96 --write docs/results-gpu.md

Per row (Chmutov's T_n of eval_forms' sweep, or a named surface): both programs, and
Barth's hand-written decic where the surface has one, timed in turns on llvmpipe (one
warm-up frame, then --frames, medians), each in float32 where float32 holds S and in
double where it does not (eval_forms.float32_holds: implc's own warning); false / missed
/ wrong-root pixels of each against the certified reference at --count-size (the
reference takes ~6 minutes at 96^2 for T_20, so smaller sizes there); and RADV's ACO
statistics of both programs (GLSL 450 through glslang) on navi21 and gfx1100.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from docs_section import commit, machine, replace_marked
from eval_forms import float32_holds, sweep_equations
from gpu_bench import median_ms

from implc.baseline import (
    has_baseline,
    open_baseline_runner,
    open_solver_runner,
    solver_shader,
)
from implc.derive import polynomial_degree
from implc.emit import compile_shader
from implc.loaders import load_surface
from implc.methods import get_method
from implc.metrics import compare
from implc.options import GPU_FAMILIES
from implc.render.gpu_stats import gpu_stats
from implc.render.run import open_runner

SOLVER = "yuksel"
MARKER = "yuksel-baseline"  # <!-- yuksel-baseline:begin --> ... :end -->


def surfaces(degrees: list[int], names: list[str]) -> list[tuple[str, object]]:
    """(label, surface): Chmutov's T_n at each degree, then the named surfaces."""
    rows = [(f"Chmutov T{d}", load_surface(equation=sweep_equations(d)["chmutov"]))
            for d in degrees]
    return rows + [(name, load_surface(name)) for name in names]


def timed(key: str, surface, precision: str, size: int, frames: int) -> list[float]:
    """Median ms of exact, the solver and (where `key` has one) the hand-written exact
    baseline, timed in the same rounds."""
    constants = get_method("exact").defaults
    backend = "gl" if precision == "float" else "gl-double"
    runners = [open_runner(surface, backend, "exact", constants, size, size),
               open_solver_runner(SOLVER, surface, constants, size, size, precision)]
    if precision == "float" and has_baseline(key, "exact"):
        runners.append(open_baseline_runner(key, "exact", constants, surface, size, size))
    return median_ms(runners, frames)


def counted(surface, precision: str, size: int) -> list[dict]:
    """compare() of exact and of the solver against the certified reference at `size`."""
    constants = get_method("exact").defaults
    reference = open_runner(surface, "reference", "", constants, size, size).frame()
    backend = "gl" if precision == "float" else "gl-double"
    results = []
    for runner in (open_runner(surface, backend, "exact", constants, size, size),
                   open_solver_runner(SOLVER, surface, constants, size, size, precision)):
        try:
            results.append(compare(runner.frame(), reference))
        finally:
            runner.release()
    return results


def aco(rows: list[tuple[str, object, str]]) -> dict:
    """(label, family) -> (exact's GpuStats, the solver's), GLSL 450 in the row's precision."""
    constants = get_method("exact").defaults
    shaders = []
    for _, surface, precision in rows:
        shaders += [compile_shader(surface, "glsl", "exact", constants, flavor="450",
                                   precision=precision),
                    solver_shader(SOLVER, surface, constants, precision)]
    stats = gpu_stats(shaders, GPU_FAMILIES)
    return {(label, family): (stats[family][2 * i], stats[family][2 * i + 1])
            for family in GPU_FAMILIES for i, (label, _, _) in enumerate(rows)}


def count_size(spec: str, degree: int) -> int:
    """--count-size "512,16=128,20=96": 512, but 128 at degree 16 and 96 at 20."""
    size, *overrides = spec.split(",")
    for item in overrides:
        d, _, s = item.partition("=")
        if int(d) == degree:
            return int(s)
    return int(size)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("surfaces", nargs="*", help="named surfaces after the Chmutov rows")
    ap.add_argument("--degrees", default="4,10,16,20")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--count-size", default="", help='"512,16=128,20=96" (default --size)')
    ap.add_argument("--write", metavar="MARKDOWN",
                    help=f"replace the text between the {MARKER} markers in this file")
    args = ap.parse_args()
    degrees = [int(d) for d in args.degrees.split(",") if d]
    spec = args.count_size or str(args.size)
    rows = [(label, s, "float" if float32_holds(s) else "double")
            for label, s in surfaces(degrees, args.surfaces)]
    stats = aco(rows)
    print("ACO statistics done", file=sys.stderr, flush=True)
    command = " ".join(["python scripts/yuksel_baseline.py", *sys.argv[1:]])
    lines = [f"Made by `{command}` at commit {commit()} on {machine()} (llvmpipe; "
             f"{args.frames} frames in turns after a warm-up, medians; counts against the "
             "certified reference; ACO: RADV's null devices, GLSL 450). "
             "VGPRs / waves per SIMD / instructions, spills where there are any:", "",
             "| surface | degree | solved in | exact ms | Yuksel ms | exact speed / Yuksel "
             "| hand-written decic ms | counted at | exact false / missed / wrong | Yuksel "
             "false / missed / wrong | Yuksel steps a pixel | "
             + " | ".join(f"exact {f} | Yuksel {f}" for f in GPU_FAMILIES) + " |",
             "|---|---|---|---|---|---|---|---|---|---|---|" + "---|" * 2 * len(GPU_FAMILIES)]
    print("\n".join(lines), flush=True)
    for label, surface, precision in rows:
        degree = polynomial_degree(surface.expr)
        key = label if label in args.surfaces else ""
        ms = timed(key, surface, precision, args.size, args.frames)
        size = count_size(spec, degree)
        exact, yuksel = counted(surface, precision, size)
        cells = [label, str(degree), "float32" if precision == "float" else "double",
                 f"{ms[0]:.1f}", f"{ms[1]:.1f}", f"{ms[1] / ms[0]:.2f}",
                 f"{ms[2]:.1f}" if len(ms) > 2 else "–", f"{size}²"]
        cells += [f"{m['false_hits']} / {m['missed_hits']} / {m['wrong_root']}"
                  for m in (exact, yuksel)]
        cells.append(f"{yuksel['mean_steps']:.1f}")
        for family in GPU_FAMILIES:
            for s in stats[label, family]:
                spill = (f", spills {s.spilled_vgprs} + {s.spilled_sgprs} SGPRs, "
                         f"{s.scratch} B" if s.spills else "")
                cells.append(f"{s.vgprs} / {s.waves} / {s.instructions}{spill}")
        line = "| " + " | ".join(cells) + " |"
        lines.append(line)
        print(line, flush=True)
    if args.write:
        replace_marked(Path(args.write), MARKER, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
