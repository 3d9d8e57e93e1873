"""`implc show`: what implc understood and what it will compute."""

from __future__ import annotations

import argparse

from ..errors import EXIT_OK
from ..options import METHOD_NAMES
from . import args as common


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("show", help="print the equation, degree, derivatives and op counts")
    common.surface_args(p)
    p.add_argument("-m", "--method", choices=sorted(METHOD_NAMES), default=None,
                   help="method whose shader functions to count (default: exact for "
                        "polynomials, else interval where every function has an interval "
                        "rule, else hessian)")


def run(args: argparse.Namespace) -> int:
    surface = common.surface(args)
    print(surface.describe(args.method))
    return EXIT_OK
