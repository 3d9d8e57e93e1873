"""`implc bench`: the paper's Table 1, fps and accuracy of every method."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import EXIT_OK, InputError
from ..fileio import check_output_dir
from ..options import MAX_IMAGE, METHOD_NAMES
from ..render.run import BACKENDS
from . import args as common
from .args import UsageError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="the paper's Table 1: fps and accuracy of every method",
                       description="Time every method on each surface and compare it with "
                                   "the exact reference; writes table.md, table.json, "
                                   "figure.png and renders/ into -o DIR.")
    p.add_argument("surfaces", nargs="+", metavar="SURFACE",
                   help="TOML files or bundled example names (e.g. cross-cap miter steiner)")
    p.add_argument("--size", type=common.int_between(8, MAX_IMAGE), default=1024,
                   help="square image size in pixels (default 1024, the paper's)")
    p.add_argument("--methods", nargs="+", choices=list(METHOD_NAMES), metavar="METHOD",
                   help="methods to time (default: taylor curvature hessian-approx hessian sign)")
    p.add_argument("--frames", type=common.int_between(1, 1000), default=3,
                   help="timed frames per cell after 1 warm-up; fps is their median (default 3)")
    p.add_argument("-b", "--backend", choices=list(BACKENDS),
                   default="gl", help="renderer to time (default gl)")
    p.add_argument("--configs", default="paper,equal,taylor2,extremum",
                   help="comma-separated: paper (Table 1 constants), equal (one step for "
                        "all), taylor2 (Eq. 4 consistent), extremum (implc's test); "
                        "default all four")
    p.add_argument("--equal-step", type=common.positive_number, default=None,
                   help="base step of every method in the `equal` configuration (default 0.002)")
    p.add_argument("--exr", action="store_true",
                   help="also write each render as EXR (for `implc compare`; 24 MB at 1024²)")
    p.add_argument("--baseline", action="store_true",
                   help="also time the hand-written GLSL of templates/baseline/ (Cross-Cap, "
                        "taylor and hessian; gl) in turns with the generated programs and "
                        "report generated / hand-written speed")
    g = p.add_argument_group("GPU statistics (Mesa's RADV on a null device: no GPU needed)")
    g.add_argument("--gpu-stats", action="store_true", dest="gpu_stats",
                   help="also give each cell's program as AMD's compiler (ACO) makes it, "
                        "compiled for HLSL with the cell's method and constants: VGPRs, "
                        "waves per SIMD, instructions, spills (a table in table.md, and "
                        "`gpu_stats` in each cell of table.json)")
    common.gpu_family_arg(g)
    common.executor_args(p, default_jobs=1)
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                   help="output directory (created if missing)")


def run(args: argparse.Namespace) -> int:
    from ..api import benchmark
    from ..bench import make_configs

    configs = [name.strip() for name in args.configs.split(",") if name.strip()]
    try:
        make_configs(configs)
    except InputError as err:
        raise UsageError(f"--configs: {err.message}") from None
    twice = [m for i, m in enumerate(args.methods or ()) if m in args.methods[:i]]
    if twice:
        raise UsageError(f"--methods: {twice[0]} is listed twice")
    families = common.gpu_families(args)
    check_output_dir(args.output, what="bench output directory")
    with common.executor(args) as executor:
        benchmark(args.surfaces, args.output, size=args.size, methods=args.methods,
              frames=args.frames, backend=args.backend, configs=configs,
              equal_step=args.equal_step, exr=args.exr, baseline=args.baseline,
              gpu_families=families, executor=executor)
    return EXIT_OK
