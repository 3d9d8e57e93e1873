"""`implc compare`: metrics of one EXR render against another."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import EXIT_OK
from . import args as common


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("compare", help="metrics of one EXR render against another",
                       description="SSIM, false/missed hits, wrong-root pixels and steps of "
                                   "render A against render B (typically the reference).")
    p.add_argument("a", type=Path, metavar="A", help="render to judge (EXR + JSON sidecar)")
    p.add_argument("b", type=Path, metavar="B", help="render to judge it by, e.g. the reference")
    p.add_argument("--t-tol", type=common.positive_number, default=None,
                   help="wrong-root tolerance on t, scene units (default 1e-3)")
    p.add_argument("--json", action="store_true", help="print the metrics as JSON")


def run(args: argparse.Namespace) -> int:
    import json

    from ..compare import compare_files, format_metrics
    from ..options import T_TOL

    t_tol = T_TOL if args.t_tol is None else args.t_tol  # its type checks the range
    metrics = compare_files(args.a, args.b, t_tol)
    print(json.dumps(metrics, indent=2) if args.json else format_metrics(metrics))
    return EXIT_OK
