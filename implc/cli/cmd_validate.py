"""`implc validate`: shader files checked by their languages' real compilers."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import EXIT_INVALID, EXIT_OK, InputError
from ..fileio import read_input
from ..targets import TARGETS
from . import args as common
from .args import UsageError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("validate", help="check shader files with their real compilers",
                       description="Compile each file with its language's real compiler, "
                                   "chosen by extension: "
                                   f"{common.extension_list(lambda t: t.extensions)}. Every "
                                   "file is read before any compiler runs; exit 3 if one "
                                   "fails.")
    p.add_argument("files", nargs="+", type=Path, metavar="FILE")
    p.add_argument("--stage", choices=list(dict.fromkeys(
                       stage for t in TARGETS.values() for stage in t.stages)),
                   help="GLSL files only: the shader stage (default: from the extension, "
                        ".vert, .comp, ... or .vert.glsl; .frag and .glsl are frag)")


def run(args: argparse.Namespace) -> int:
    """Every file is checked (exists, readable, known extension, UTF-8) before any
    compiler runs: a bad input is exit 1, a shader its compiler rejects exit 3."""
    from ..targets import target_of_file
    from ..validate import check_source, validate_text

    sources = []
    for path in args.files:
        target = target_of_file(path.suffix)
        if target is None:
            known = " ".join(sorted(ext for t in TARGETS.values() for ext in t.extensions))
            raise InputError(f"{path}: unknown shader extension '{path.suffix}' "
                             f"(known: {known})")
        if args.stage and args.stage not in target.stages:
            raise UsageError(f"--stage applies to GLSL files only; {path} is {target.name}")
        text = read_input_text(path)
        check_source(text, str(path))
        sources.append((path, target.name, text))
    failed = 0
    for path, target_name, text in sources:
        verdict = validate_text(text, target_name, str(path), stage=args.stage)
        print(verdict.render(str(path)), file=sys.stdout if verdict.ok else sys.stderr)
        failed += not verdict.ok
    return EXIT_INVALID if failed else EXIT_OK


def read_input_text(path: Path, limit: int = 50_000_000) -> str:
    """A text input file, or an InputError saying in one line why it cannot be read."""
    data = read_input(path, "a shader file")
    if len(data) > limit:
        raise InputError(f"{path}: larger than {limit} bytes")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputError(f"{path}: not UTF-8 text (byte {err.start})") from None
