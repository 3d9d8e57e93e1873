"""The command line's parser: the top-level `implc` parser, whose commands each add their
own arguments (implc/cli/cmd_*.py), and argparse's errors as one-line usage errors."""

from __future__ import annotations

import argparse
import difflib
import re

from ..version import __version__
from .args import UsageError

EPILOG = """\
surfaces: a TOML file, a SURFER .jsurf file, a bundled example name (see `implc list`),
or -e "EQUATION".

examples:
  implc list
  implc show cross-cap
  implc compile cross-cap -t glsl -m hessian -o cross-cap.frag --validate
  implc compile -e "x^2 + y^2 + z^2 = 1" -m taylor --flavor shadertoy
  implc compile cross-cap --emit library --prefix cc_ -o cc.glsl
  implc validate cross-cap.frag
  implc render cross-cap -m hessian --size 512 -o cross-cap.png
  implc view torus -o torus.html
  implc compare cc-hessian.exr cc-reference.exr
  implc bench cross-cap miter steiner --size 512 -o results/
  implc probe -b gl,wgpu,cl

exit codes: 0 ok, 1 bad input or output (file missing, unreadable or unwritable,
            disk full), 2 bad command line, 3 validation failed (probe: a driver
            lost an error-free transformation), 4 tool or runtime missing, 70
            internal error (IMPLC_DEBUG=1 shows the traceback),
            130 interrupted (SIGINT), 143 terminated (SIGTERM)
"""

VIEW_POINT_FLAGS = ("--center", "--eye", "--look-at", "--up")  # values may start with '-'


class Parser(argparse.ArgumentParser):
    """argparse, with its errors raised as UsageError (main prints them in one line), and
    a did-you-mean for a choice that is close to one (`implc rendr`, `-m hesian`)."""

    def error(self, message: str):  # type: ignore[override]
        choice = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)$", message)
        if choice:
            choices = re.findall(r"'([^']*)'", choice.group(2))
            message += did_you_mean(choice.group(1), choices)
        raise UsageError(message, self.prog)


def did_you_mean(word: str, choices: list[str]) -> str:
    """"; did you mean 'render'?" when one of `choices` is close to `word`, else ""."""
    close = difflib.get_close_matches(word, choices, n=1, cutoff=0.6)
    return f"; did you mean '{close[0]}'?" if close else ""


def unknown_options(parser: argparse.ArgumentParser, command: str | None,
                    extra: list[str]) -> UsageError:
    """The error for arguments no option of `command` takes, named by the command, with
    the closest option (`--sise 96`: did you mean '--size'?)."""
    prog, options = "implc", list(parser._option_string_actions)
    if command:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        prog, options = f"implc {command}", list(sub.choices[command]._option_string_actions)
    first = next((arg.split("=", 1)[0] for arg in extra if arg.startswith("-")), "")
    hint = did_you_mean(first, options) if first else ""
    return UsageError(f"unrecognized arguments: {' '.join(extra)}{hint}", prog)


def build_parser() -> argparse.ArgumentParser:
    """The whole command line; each command module adds its own sub-parser (they import
    nothing heavy at the top, so `--help` stays fast)."""
    from .cmd_bench import add_parser as add_bench
    from .cmd_compare import add_parser as add_compare
    from .cmd_compile import add_parser as add_compile
    from .cmd_corpus import add_parser as add_corpus
    from .cmd_export import add_parser as add_export
    from .cmd_gallery import add_parser as add_gallery
    from .cmd_list import add_parser as add_list
    from .cmd_probe import add_parser as add_probe
    from .cmd_render import add_parser as add_render
    from .cmd_show import add_parser as add_show
    from .cmd_validate import add_parser as add_validate
    from .cmd_view import add_parser as add_view

    parser = Parser(
        prog="implc",
        description="Compile implicit-surface equations into robust GPU ray-marching shaders.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"implc {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for add in (add_list, add_show, add_compile, add_export, add_validate, add_render,
                add_view, add_compare, add_bench, add_corpus, add_gallery, add_probe):
        add(sub)
    return parser


def join_equation_values(argv: list[str]) -> list[str]:
    """`-e "-x^2 + z"` -> `--equation=-x^2 + z`.

    argparse reads a separate value that starts with '-' as an option and reports
    "expected one argument", but equations often start with a minus sign (a quarter of
    the MathMod rows do). A value that looks like a long option (`--help`) is left alone.
    """
    joined: list[str] = []
    i = 0
    while i < len(argv):
        arg = argv[i]
        value = argv[i + 1] if i + 1 < len(argv) else None
        if (arg in ("-e", "--equation") and value is not None and value.startswith("-")
                and not re.match(r"--[A-Za-z]", value)):
            joined.append(f"--equation={value}")
            i += 2
            continue
        if arg in VIEW_POINT_FLAGS and value is not None and re.match(r"-[\d.xyzXYZ]", value):
            joined.append(f"{arg}={value}")  # `--eye -3,0,0`, `--up -z`
            i += 2
            continue
        joined.append(arg)
        i += 1
    return joined
