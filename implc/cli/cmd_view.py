"""`implc view`: one self-contained HTML page that shows a surface live."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import EXIT_OK
from ..fileio import check_output, write_atomic
from ..targets import backends_in
from . import args as common


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("view", help="write a self-contained HTML page that shows a surface live",
                       description="One HTML file, no network: the es300 program in WebGL2 "
                                   "(and the WGSL program on WebGPU where the browser has "
                                   "it), orbit/zoom/pan, a slider per parameter. Its first "
                                   "frame is the surface's [view] camera, like `implc render`.")
    common.surface_args(p)
    common.view_args(p)
    common.method_args(p)
    p.add_argument("--no-webgpu", action="store_true",
                   help="leave the WGSL program out of the page (WebGL2 only)")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.html",
                   help="the page to write")


def run(args: argparse.Namespace) -> int:
    from ..api.compiling import float32_finding

    check_output(args.output, (".html", ".htm"), what="the viewer page")
    surface = common.surface(args)
    record, framing = surface.framed()
    method = args.method or surface.default_method
    common.warn_ignored(args, method)
    page = surface.view_page(method, webgpu=not args.no_webgpu,
                             **common.constants_given(args))
    float32, note = float32_finding(record, method)
    write_atomic(args.output, page)
    print(f"wrote {args.output}")
    print(f"open file://{args.output.resolve()} in a browser", file=sys.stderr)
    if float32:
        common.warn(args, f"{float32}; WebGL2 and WebGPU have no double; for the picture, "
                          f"`implc render -b {' or '.join(backends_in('double'))}`")
    for line in (framing.message() if framing else None, note):
        if line:
            print(line, file=sys.stderr)
    return EXIT_OK
