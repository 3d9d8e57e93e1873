"""`implc probe`: do the error-free transformations survive each float32 driver?"""

from __future__ import annotations

import argparse
import sys

from ..errors import EXIT_INVALID, EXIT_OK, ToolError
from ..targets import PROBE_BACKENDS
from .args import UsageError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "probe", help="check that each float32 driver keeps the bits error-free "
                      "transformations recover",
        description="Run the error-free transformations implc's float32 programs use "
                    "(two_sum, fast_two_sum, the split and two_prod, two_prod with fma, "
                    "compensated summation) on known inputs on each driver, read the "
                    "results back bit for bit and compare them with exact arithmetic. In "
                    "the reals their error terms are 0, so a driver whose compiler "
                    "reassociates or fuses float arithmetic folds them away: this shows "
                    "it here, not in a picture. Prints, per driver, each transformation's "
                    "error term and whether it is exact; exit 3 if a driver lost one the "
                    "programs rely on (an fma that rounds twice is reported, not a "
                    "failure: two_prod splits its factors instead where the language does "
                    "not promise one rounding), exit 4 if a driver asked for with -b "
                    "cannot run. See docs/reference/float32-probe.md.",
        epilog="examples:\n  implc probe\n  implc probe -b gl,wgpu,cl\n"
               "  implc probe -b webgl2,webgpu   # headless chromium, through playwright",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("-b", "--backend", type=_backends, default=None, metavar="LIST",
                   help=f"comma-separated drivers to probe, of {', '.join(PROBE_BACKENDS)} "
                        "(default: every one; those that cannot run here are reported and "
                        "skipped)")


def _backends(text: str) -> tuple[str, ...]:
    names = tuple(dict.fromkeys(n.strip() for n in text.split(",") if n.strip()))
    unknown = [n for n in names if n not in PROBE_BACKENDS]
    if unknown or not names:
        raise UsageError(f"-b: unknown backend '{','.join(unknown)}'; choose from "
                         f"{', '.join(PROBE_BACKENDS)}", "implc probe")
    return names


def run(args: argparse.Namespace) -> int:
    from ..render.eft_probe import probe_all

    asked = args.backend is not None
    reports = probe_all(args.backend or PROBE_BACKENDS,
                        progress=lambda p: print(f"probing {p.title} ...", file=sys.stderr,
                                                 flush=True))
    for report in reports:
        print(report.render())
    ran = [r for r in reports if not r.unavailable]
    lost = [r for r in ran if not r.ok]
    skipped = [r for r in reports if r.unavailable]
    print(f"\nthe error-free transformations survive on {len(ran) - len(lost)} of "
          f"{len(ran)} driver programs"
          + (f"; lost on {', '.join(r.probe.title.split(' (')[0] for r in lost)}" if lost else "")
          + (f"; not run: {', '.join(r.probe.backend for r in skipped)}" if skipped else ""))
    if lost:
        return EXIT_INVALID
    if (asked and skipped) or not ran:
        raise ToolError("; ".join(f"{r.probe.backend}: {r.unavailable}" for r in skipped))
    return EXIT_OK
