"""The `implc` command: a thin shell over the public API (implc/api/).

One module per command (`cmd_<name>.py`: its arguments and its `run`, which imports the
API only when it runs, so `--help` loads no sympy), the parser in
`parser.py`, the arguments several commands share in `args.py`, and process handling and
the mapping of exceptions to exit codes in `process.py` and `main` below, nowhere else.

Exit codes (docs/reference/errors.md "Exit codes"): 0 ok; 1 bad input or output (equation, surface
file,
parameter, a missing or unreadable input, an output that cannot be written, a full disk);
2 bad command line; 3 a shader failed validation; 4 a tool or runtime is missing or
failed; 70 internal error (a bug: rerun with IMPLC_DEBUG=1 for the traceback);
130 interrupted (SIGINT); 143 terminated (SIGTERM). Every output path is checked before
any work starts (implc.fileio.check_output).
"""

from __future__ import annotations

import argparse
import sys

from ..errors import EXIT_OK
from ..interrupts import Terminated, dropped_signals_kept, raise_dropped
from .args import LIMIT_FLAGS, UsageError
from .cmd_bench import run as cmd_bench
from .cmd_compare import run as cmd_compare
from .cmd_compile import run as cmd_compile
from .cmd_corpus import run as cmd_corpus
from .cmd_export import run as cmd_export
from .cmd_gallery import run as cmd_gallery
from .cmd_list import run as cmd_list
from .cmd_probe import run as cmd_probe
from .cmd_render import run as cmd_render
from .cmd_show import run as cmd_show
from .cmd_validate import run as cmd_validate
from .cmd_view import run as cmd_view
from .parser import build_parser, join_equation_values, unknown_options
from .process import GuardedStdout, exit_code, install_signals, restore_signals


def main(argv: list[str] | None = None) -> int:
    with dropped_signals_kept():
        return _main(argv)


def _main(argv: list[str] | None) -> int:
    previous = install_signals()
    command = "implc"
    stdout = sys.stdout
    sys.stdout = GuardedStdout(stdout)
    try:
        raise_dropped()  # one that came while the modules loaded
        parser = build_parser()
        args, extra = parser.parse_known_args(
            join_equation_values(sys.argv[1:] if argv is None else argv))
        command = args.command or "implc"
        if extra:
            raise unknown_options(parser, args.command, extra)
        if not args.command:
            parser.print_help()
            return EXIT_OK
        code = _run(args)
        raise_dropped()
        sys.stdout.flush()  # a full disk under `> file` is reported here, not at exit
        return code
    except (Exception, KeyboardInterrupt, Terminated) as err:
        return exit_code(err, command)
    finally:
        sys.stdout = stdout
        restore_signals(previous)


def _run(args: argparse.Namespace) -> int:
    """The command's `run`, found by name here (`cmd_list` ...), where a test may put
    its own."""
    run = globals()["cmd_" + args.command]
    return int(run(args))


__all__ = [
    "LIMIT_FLAGS", "UsageError", "build_parser", "cmd_bench", "cmd_compare", "cmd_compile",
    "cmd_corpus", "cmd_export", "cmd_gallery", "cmd_list", "cmd_probe", "cmd_render",
    "cmd_show", "cmd_validate", "cmd_view", "main",
]
