"""Holding SIGINT and SIGTERM where one would break things: native code, and files being made.

A Ctrl-C or SIGTERM normally ends implc cleanly (KeyboardInterrupt, Terminated). Three
places cannot take one: Mesa's shader compile (a system call it interrupted is not
retried: moderngl's ctx.program segfaulted, test_fault[gallery-SIGINT], about 1 run in 4
under load), the import of a nanobind extension (OpenImageIO, pyopencl: an exception
raised while its module initialises aborts the process with "Critical nanobind error",
test_fault[render-SIGTERM] under a second test run), and the making of a temporary file
or directory before its name reaches the code that removes it (implc.fileio). Inside
`signals_held()` both signals wait, and the one that came is acted on as the block ends.

A fourth place drops the signal instead: Python ignores an exception raised inside a
weakref callback, a `__del__` or a garbage-collector run ("Exception ignored in ..."), and
a KeyboardInterrupt raised there is lost (test_fault[bench-SIGINT]: bench exited 0 after
Ctrl-C landed in the import system's module-lock callback). Inside
`dropped_signals_kept()` such a signal is kept silently, and `raise_dropped()` raises it
again where implc can stop: before an output is put in place (implc.fileio) and as the
command ends (implc.cli.main).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from collections.abc import Iterator
from contextlib import contextmanager

HELD = (signal.SIGINT, signal.SIGTERM)


class Terminated(BaseException):
    """SIGTERM, raised like KeyboardInterrupt so temporary files are cleaned up."""


SIGNALLED = (KeyboardInterrupt, Terminated)
_dropped: list[type[BaseException]] = []


@contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM wait until the block ends.

    Blocked in this thread (the C library is not interrupted; threads it starts inherit
    the mask) and deferred at Python's level (a signal another thread took, such as one of
    OpenBLAS's, would otherwise raise in the middle of the block's Python code). Off the
    main thread, where Python cannot set handlers, only the mask applies."""
    pending: list[int] = []

    def defer(signum, frame) -> None:
        pending.append(signum)

    previous = {}
    for sig in HELD:
        if signal.getsignal(sig) is None:  # set from C: left as it is
            continue
        with contextlib.suppress(ValueError, OSError):  # not the main thread
            previous[sig] = signal.signal(sig, defer)
    try:
        before = signal.pthread_sigmask(signal.SIG_BLOCK, HELD)
    except (AttributeError, ValueError, OSError):  # no pthreads
        before = None
    try:
        yield
    finally:
        if before is not None:
            # a signal that waited in the mask is delivered here, to `defer`
            signal.pthread_sigmask(signal.SIG_SETMASK, before)
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if pending:
            _act_on(pending[0], previous.get(pending[0]))


def _act_on(sig: int, handler) -> None:
    """Do what the signal would have done outside the block."""
    if callable(handler):
        handler(sig, None)  # KeyboardInterrupt, Terminated, or a block around this one
    elif handler == signal.SIG_DFL:
        os.kill(os.getpid(), sig)


@contextmanager
def dropped_signals_kept() -> Iterator[None]:
    """A KeyboardInterrupt or Terminated that Python would drop as unraisable (raised in
    a weakref callback, `__del__` or the garbage collector) is kept for `raise_dropped`,
    and prints nothing: implc reports it once, as it reports any interruption. Other
    unraisable exceptions go to the hook that was there."""
    previous = sys.unraisablehook

    def keep(unraisable) -> None:
        if isinstance(unraisable.exc_value, SIGNALLED):
            _dropped.append(type(unraisable.exc_value))
        else:
            previous(unraisable)

    sys.unraisablehook = keep
    try:
        yield
    finally:
        sys.unraisablehook = previous
        _dropped.clear()  # not carried into a later run in the same process (tests)


def raise_dropped() -> None:
    """Raise again the first signal Python dropped (see `dropped_signals_kept`), if any:
    the run was interrupted even though no code saw it."""
    if _dropped:
        kind = _dropped[0]
        _dropped.clear()
        raise kind()
