"""What AMD's compiler makes of the degree sweep's programs (issue 49): RADV's ACO
statistics of Chmutov T_n's programs, n = 2-20, on a null device per family (no GPU):
VGPRs, waves per SIMD and instructions of exact and taylor (HLSL, float), and every
spill of every method (exact, taylor, hessian, interval) in float (HLSL, GLSL 450) and
double (GLSL 450; HLSL has float only). About 2 minutes.

    python scripts/gpu_stats_table.py                       print the Markdown
    python scripts/gpu_stats_table.py --write docs/results-gpu.md
        replace the part between <!-- gpu-stats:begin --> and <!-- gpu-stats:end -->
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from docs_section import replace_marked
from eval_forms import _degrees, sweep_equations

import implc
from implc.options import GPU_FAMILIES
from implc.render.gpu_stats import gpu_stats

METHODS = ("exact", "taylor", "hessian", "interval")
TABLED = ("exact", "taylor")  # the methods of the per-degree table
# (target, flavour, precision): the programs that reach SPIR-V; the first is tabled
PROGRAMS = (("hlsl", None, "float"), ("glsl", "450", "float"), ("glsl", "450", "double"))
MARKER = "gpu-stats"  # <!-- gpu-stats:begin --> ... <!-- gpu-stats:end -->


def measure(degrees: list[int], families: list[str]) -> dict:
    """(family, degree, method, program) -> GpuStats."""
    keys, shaders = [], []
    for degree in degrees:
        surface = implc.Surface(sweep_equations(degree)["chmutov"])
        for method in METHODS:
            for program in PROGRAMS:
                target, flavor, precision = program
                shaders.append(surface.compile(target, method, flavor=flavor,
                                               precision=precision))
                keys.append((degree, method, program))
        print(f"compiled degree {degree}", file=sys.stderr, flush=True)
    by_family = gpu_stats(shaders, families)
    return {(family, *key): stats for family, rows in by_family.items()
            for key, stats in zip(keys, rows, strict=True)}


def markdown(stats: dict, degrees: list[int], families: list[str], command: str) -> str:
    """The per-degree table of exact and taylor, then the spills of every program."""
    first = PROGRAMS[0]
    device = {f: stats[f, degrees[0], METHODS[0], first].device for f in families}
    lines = [f"Made by `{command}` (RADV's ACO on null devices: "
             f"{', '.join(device[f] for f in families)}; Chmutov T_n, fragment stage, HLSL "
             "through glslang, float). VGPRs / waves per SIMD / instructions:", ""]
    head = " | ".join(f"{m} {f}" for f in families for m in TABLED)
    lines += [f"| degree | {head} |", "|---|" + "---|" * (len(families) * len(TABLED))]
    for degree in degrees:
        cells = [stats[f, degree, m, first] for f in families for m in TABLED]
        lines.append(f"| {degree} | " + " | ".join(
            f"{s.vgprs} / {s.waves} / {s.instructions}" for s in cells) + " |")
    lines += ["", f"Spills (VGPRs, SGPRs spilled; scratch bytes) of {', '.join(METHODS)}, "
              f"degree {degrees[0]}-{degrees[-1]}:", ""]
    for program in PROGRAMS:
        target, flavor, precision = program
        for family in families:
            spilled = [f"{m} {d} ({s.spilled_vgprs}, {s.spilled_sgprs}; {s.scratch} B)"
                       for d in degrees for m in METHODS
                       if (s := stats[family, d, m, program]).spills]
            name = f"{target}{' ' + flavor if flavor else ''} {precision}"
            lines.append(f"- {name}, {family}: {', '.join(spilled) or 'none'}")
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--degrees", default="2-20")
    ap.add_argument("--families", default=",".join(GPU_FAMILIES))
    ap.add_argument("--write", metavar="MARKDOWN",
                    help=f"replace the text between the {MARKER} markers in this file")
    args = ap.parse_args()
    degrees, families = _degrees(args.degrees), args.families.split(",")
    command = " ".join(["python scripts/gpu_stats_table.py", *sys.argv[1:]])
    text = markdown(measure(degrees, families), degrees, families, command)
    if not args.write:
        print(text)
        return
    replace_marked(Path(args.write), MARKER, text)


if __name__ == "__main__":
    main()
