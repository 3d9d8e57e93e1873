"""The process around a command: signals, a guarded standard output, and the one place an
exception becomes a message and an exit code (docs/reference/errors.md "Exit codes")."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import traceback
from collections.abc import Callable
from typing import Any

from ..errors import (
    EXIT_INPUT,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_TERMINATED,
    ImplcError,
    OptionError,
)
from ..fileio import FULL_DISK, describe_os_error
from ..interrupts import Terminated
from .args import UsageError

DEBUG_ENV = "IMPLC_DEBUG"


class StdoutError(ImplcError):
    """Standard output cannot be written (a full disk under `> file`, a closed or
    read-only descriptor): exit code 1, like any output that cannot be written."""


class GuardedStdout:
    """sys.stdout, with write errors turned into StdoutError (a closed pipe stays a
    BrokenPipeError: the reader left, which is not an error)."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def _guard(self, call: Callable[..., Any], *args: Any) -> Any:
        try:
            return call(*args)
        except BrokenPipeError:
            raise
        except OSError as err:
            raise StdoutError(f"cannot write to standard output: {describe_os_error(err)}"
                              ) from None

    def write(self, text: str) -> Any:
        return self._guard(self._stream.write, text)

    def flush(self) -> Any:
        return self._guard(self._stream.flush)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def _on_sigterm(signum: int, frame: Any) -> None:
    raise Terminated()


def install_signals() -> dict:
    """SIGTERM ends the run cleanly (exit 143); SIGXFSZ is ignored so that a file-size
    limit (RLIMIT_FSIZE) shows as an EFBIG write error instead of killing the process."""
    previous = {}
    for sig, handler in ((signal.SIGTERM, _on_sigterm), (signal.SIGXFSZ, signal.SIG_IGN)):
        with contextlib.suppress(ValueError, OSError):  # not the main thread
            previous[sig] = signal.signal(sig, handler)
    # Restart system calls the signal interrupts (SA_RESTART) instead of failing them
    # with EINTR, which C libraries may not retry: a Ctrl-C during moderngl's ctx.program
    # segfaulted (test_fault[gallery-SIGINT]: 2 runs of 6; 0 of 14 with this, but once
    # more in a loaded clean-clone run, so render/gl.py also holds the signals while the
    # driver works). Python still raises KeyboardInterrupt once the call returns.
    for sig in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(ValueError, OSError):
            signal.siginterrupt(sig, False)
    return previous


def restore_signals(previous: dict) -> None:
    for sig, handler in previous.items():
        signal.signal(sig, handler)


def exit_code(err: BaseException, command: str) -> int:
    """Print what `err` means for a user (one line or a located diagnostic, never a
    traceback unless IMPLC_DEBUG is set) and return the process's exit code."""
    if isinstance(err, OptionError):
        usage = err if isinstance(err, UsageError) else UsageError(err.message)
        if usage.command is None:
            usage.command = "implc" if command == "implc" else f"implc {command}"
        print(usage.render(), file=sys.stderr)
        return usage.exit_code
    if isinstance(err, ImplcError):
        if isinstance(err, StdoutError):
            detach_stdout()  # what is still buffered would fail again at exit
        print(err.render(), file=sys.stderr)
        return err.exit_code
    if isinstance(err, KeyboardInterrupt):
        print("implc: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    if isinstance(err, Terminated):
        print("implc: terminated", file=sys.stderr)
        return EXIT_TERMINATED
    if isinstance(err, BrokenPipeError):  # `implc show x | head`: the reader left
        detach_stdout()
        return 0
    if isinstance(err, RecursionError):
        print("implc: error: too complex: expression nesting exceeds Python's limits",
              file=sys.stderr)
        return EXIT_INPUT
    if isinstance(err, OSError) and err.errno in FULL_DISK:
        print(f"implc: error: cannot write the output: {describe_os_error(err)}",
              file=sys.stderr)
        return EXIT_INPUT
    return internal_error(command, err)


def internal_error(command: str, err: BaseException) -> int:
    """A bug: one line, the traceback on request."""
    if os.environ.get(DEBUG_ENV):
        traceback.print_exception(type(err), err, err.__traceback__)
    first = (str(err).splitlines() or [""])[0][:300]
    what = f"{type(err).__name__}: {first}" if first else type(err).__name__
    where = f"'implc {command}'" if command != "implc" else "implc"
    print(f"implc: internal error in {where}: {what} (rerun with {DEBUG_ENV}=1 for the "
          "traceback, and please report it)", file=sys.stderr)
    return EXIT_INTERNAL


def detach_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's last flush has nowhere to fail."""
    with contextlib.suppress(OSError, ValueError):
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
