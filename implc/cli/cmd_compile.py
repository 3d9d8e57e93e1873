"""`implc compile`: a shader program, a drop-in library or a .jsurf file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import EXIT_OK
from ..fileio import check_output, write_atomic
from ..targets import TARGETS, flavor_problem, target_of_file, where_precision
from . import args as common


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("compile", help="emit a shader for a surface",
                       formatter_class=argparse.RawDescriptionHelpFormatter,
                       description="Emit a complete shader program or a drop-in library.")
    common.surface_args(p)
    common.view_args(p)
    common.shader_args(p)
    p.add_argument("--emit", choices=("program", "library", "jsurf"), default="program",
                   help="program (default): a complete shader; library: the functions only; "
                        "jsurf: the surface and its view as a SURFER/jsurf .jsurf file")
    p.add_argument("--prefix", default="",
                   help="prefix for every global name (library drop-ins), e.g. cc_ "
                        "(default: none); an identifier start: no leading digit, no '__', "
                        "not gl_ for glsl")
    p.add_argument("-o", "--output", type=Path,
                   help="output file; its extension gives the target when -t is not given "
                        f"({common.extension_list(lambda t: t.compile_extensions)}); - or "
                        "none: standard output")
    p.add_argument("--validate", action="store_true",
                   help="validate with the language's real compiler before writing")


def run(args: argparse.Namespace) -> int:
    output = None if args.output is None or str(args.output) == "-" else args.output
    if args.emit == "jsurf":
        return _compile_jsurf(args, output)
    target = _target(args, output)
    from ..emit import check_shader_options

    check_shader_options(target, args.flavor, args.precision, args.prefix)
    if output:
        check_output(output, TARGETS[target].compile_extensions, what=f"the {target} shader")
    surface = common.surface(args)
    surface.framed()  # a view that shows nothing is refused before anything is said
    method = args.method or surface.default_method
    common.warn_ignored(args, method)
    shader = surface.compile(target, method, emit=args.emit, prefix=args.prefix,
                             flavor=args.flavor, precision=args.precision,
                             params=args.params, **common.constants_given(args))
    if args.validate:
        name = str(output) if output else f"<stdout>.{target}"
        print(shader.validate(name).render(name), file=sys.stderr)
    if output:
        write_atomic(output, shader.text)
    else:
        sys.stdout.write(shader.text)
    if shader.float32:
        common.warn(args, f"{shader.float32}; {_remedy(target, args.flavor)}")
    for note in shader.notes:
        print(note, file=sys.stderr)
    return EXIT_OK


def _target(args: argparse.Namespace, output: Path | None) -> str:
    """-t, else the language of -o's extension (read as `implc validate` reads it: `-o
    x.wgsl` is WGSL), else glsl (also for a device such as /dev/null)."""
    if args.target is not None:
        return str(args.target)
    if output is None:
        return "glsl"
    every = tuple(ext for t in TARGETS.values() for ext in t.compile_extensions)
    check_output(output, every, what="a shader")  # a directory, or no language's
    found = target_of_file(output.suffix.lower())
    return found.name if found else "glsl"  # a device (`-o /dev/null`) has no extension


def _remedy(target: str, flavor: str | None) -> str:
    tgt = TARGETS[target]
    if "double" in tgt.precisions and flavor_problem(
            tgt, flavor or tgt.default_flavor, "double") is None:
        return "try --precision double"
    return "--precision double is in " + where_precision("double")


def _compile_jsurf(args: argparse.Namespace, output: Path | None) -> int:
    """`compile --emit jsurf`: the surface, its view and colours as a .jsurf file (the
    shader options do not apply)."""
    if output:
        check_output(output, (".jsurf",), what="a .jsurf file")
    surface = common.surface(args)
    text = surface.to_jsurf()
    if output:
        write_atomic(output, text)
    else:
        sys.stdout.write(text)
    framing = surface.framed()[1]  # the framing to_jsurf wrote, said once it is written
    if framing is not None:
        print(framing.message(), file=sys.stderr)
    return EXIT_OK
