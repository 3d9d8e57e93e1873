"""Hang guards that a slow or busy machine cannot trip: CPU time, not wall time.

A test that must tell a hang from a case that finishes uses `cpu_limit` (in-process, the
process's own user + system time, through ITIMER_PROF), `cpu_seconds` around a call, or
`run_child` (a child process's user + system time). A second `make test` beside this one
doubles wall times but leaves CPU times nearly as they are, so each bound is set at 20x
or more of the measured typical case and still catches a real hang (minutes of work) at
once.
"""

from __future__ import annotations

import resource
import signal
import subprocess
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager


class Hang(BaseException):
    """A case used more CPU time than its bound (BaseException: nothing under test may
    swallow it with `except Exception`)."""


@contextmanager
def cpu_limit(seconds: float, what: str) -> Iterator[None]:
    """Raise `Hang` inside the block once this process has spent `seconds` of CPU time in
    it (SIGPROF; the main thread only, like every signal handler)."""

    def expired(signum, frame):
        raise Hang(f"{what} used more than {seconds} s of CPU time")

    previous = signal.signal(signal.SIGPROF, expired)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, previous)


def cpu_seconds() -> float:
    """This process's CPU time so far (user + system, every thread)."""
    return time.process_time()


def run_child(argv: Sequence[str], timeout: float = 600,
              **popen) -> tuple[subprocess.CompletedProcess, float]:
    """`subprocess.run(argv, capture_output=True, text=True, ...)` and the child's CPU
    time (user + system): the growth of RUSAGE_CHILDREN across the run, which is this
    child's alone because tests run one at a time. `timeout` is wall time, only a last
    resort against a child that never ends, so it is minutes."""
    before = _children_cpu()
    proc = subprocess.run(argv, capture_output=True, text=True, timeout=timeout, **popen)
    return proc, _children_cpu() - before


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime
