"""`implc export`: the files a host engine or tool loads (implc/hosts.py)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import EXIT_OK
from ..fileio import check_output_dir
from ..hosts import HOSTS
from . import args as common


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export", help="write the files a host (three.js, Unity, ...) loads",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Write the files a host engine or tool loads: the drop-in library in "
                    "the host's language, wrapped as the host wants it, the parameters as "
                    "the host's own controls, and how to use it at the top of the main "
                    "file. Hosts:\n" + "\n".join(f"  {h.name:<8} {h.about}"
                                                 for h in HOSTS.values()))
    common.surface_args(p)
    common.view_args(p)
    common.method_args(p)
    p.add_argument("--host", required=True, metavar="HOST",
                   help=f"the host: {', '.join(HOSTS)}")
    p.add_argument("--precision", default=None, help="float (default); what the host's "
                   "language can solve in")
    p.add_argument("--prefix", default=None, help="prefix of the library's global names "
                   "(default: the surface's name and _)")
    p.add_argument("-o", "--output", type=Path, default=Path("."), metavar="DIR",
                   help="the directory to write the files into (made if missing; default .)")


def run(args: argparse.Namespace) -> int:
    from ..hosts import get_host

    try:
        get_host(args.host)  # an unknown host is a bad command line, before any work
    except ValueError as err:
        raise common.UsageError(f"--host: {err}", "implc export") from None
    check_output_dir(args.output, what="output directory")  # before any work
    surface = common.surface(args)
    method = args.method or surface.default_method
    common.warn_ignored(args, method)
    files = surface.export(args.host, method, precision=args.precision, prefix=args.prefix,
                           **common.constants_given(args))
    for path in files.save(args.output):
        print(f"wrote {path}")
    for warning in files.warnings:
        common.warn(args, warning)
    framing = surface.framed()[1]
    if framing is not None:
        print(framing.message(), file=sys.stderr)
    return EXIT_OK
