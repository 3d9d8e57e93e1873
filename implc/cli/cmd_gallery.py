"""`implc gallery`: a contact sheet of many surfaces (index.html)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import EXIT_INPUT, EXIT_OK
from ..fileio import check_output_dir
from ..render.run import BACKENDS, REFERENCE
from . import args as common


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("gallery", help="a contact sheet of many surfaces (index.html)",
                       description="Render each surface as a thumbnail with its default "
                                   "method and write index.html (name, equation, degree, "
                                   "method, frame time; each thumbnail links to the "
                                   "surface's `implc view` page), contact-sheet.png and "
                                   "the pages into -o DIR. A surface that fails shows its "
                                   "error in its cell.")
    p.add_argument("surfaces", nargs="+", metavar="SURFACE",
                   help="TOML or .jsurf files or bundled example names")
    p.add_argument("--size", type=common.int_between(8, 1024), default=160,
                   help="thumbnail side in pixels (default 160)")
    p.add_argument("-b", "--backend", choices=[b for b in BACKENDS if b != REFERENCE],
                   default="gl", help="renderer of the thumbnails (default gl)")
    p.add_argument("--webgpu", action="store_true",
                   help="give the view pages the WebGPU program too (slower to write)")
    common.executor_args(p, default_jobs=1)
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                   help="output directory (created if missing)")


def run(args: argparse.Namespace) -> int:
    from ..api import gallery

    check_output_dir(args.output, what="gallery output directory")
    with common.executor(args) as executor:
        cells = gallery(args.surfaces, args.output, size=args.size, backend=args.backend,
                        webgpu=args.webgpu, executor=executor)
    failed = sum(1 for cell in cells if cell.error)
    print(f"wrote {args.output / 'index.html'} ({len(cells)} "
          f"surface{'' if len(cells) == 1 else 's'}"
          + (f", {failed} failed: see their cells" if failed else "") + ")")
    if failed:  # the sheet is written, but not every surface is on it (docs/reference/errors.md
    # "Exit codes")
        print(f"implc gallery: error: {failed} of {len(cells)} surfaces failed (their errors "
              "are in their cells)", file=sys.stderr)
        return EXIT_INPUT
    return EXIT_OK
