"""Where batch work runs (`gallery`, `bench`'s references, `corpus`): any
`concurrent.futures.Executor`. Local worker processes by default (the command line's
`-j N`), or a Dask distributed cluster (`--scheduler ADDRESS`, the `implc[dask]` extra)
where one machine is not enough. Work items are plain functions of plain records, so
they pickle to any of them."""

from __future__ import annotations

import contextlib
from concurrent.futures import Executor, ProcessPoolExecutor
from multiprocessing import get_context

from .errors import ToolError


def local_executor(jobs: int) -> ProcessPoolExecutor:
    """`jobs` worker processes. spawn, not fork: wgpu, PoCL and the GL stack hold threads
    and handles. Workers ignore SIGINT (Ctrl-C reaches the whole process group): the
    parent alone decides, stops them (`stop_executor`) and reports once."""
    return ProcessPoolExecutor(jobs, mp_context=get_context("spawn"),
                               initializer=worker_signals)


def dask_executor(address: str) -> Executor:
    """An executor on the Dask distributed scheduler at `address` (tcp://host:8786)."""
    try:
        from distributed import Client
    except ImportError:
        raise ToolError("--scheduler needs Dask distributed: pip install 'implc[dask]'"
                        ) from None
    try:
        client = Client(address, timeout=10)
    except OSError as err:
        raise ToolError(f"cannot reach the Dask scheduler at {address}: {err}") from None
    return client.get_executor()


def worker_signals() -> None:
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def stop_executor(executor: Executor) -> None:
    """Cancel what has not started and, for local processes, end the workers now (an
    interrupted run), then wait for the pool's manager thread: left running, it closed
    its wake-up pipe while concurrent.futures' exit hook wrote to it, and the run ended
    on a traceback after "implc: terminated" (test_fault[corpus-SIGTERM], once in a
    clean-clone run)."""
    processes = list((getattr(executor, "_processes", None) or {}).values())  # no public handle
    manager = getattr(executor, "_executor_manager_thread", None)
    executor.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        with contextlib.suppress(Exception):
            process.terminate()
    for process in processes:
        with contextlib.suppress(Exception):
            process.join(5)
    if manager is not None:
        manager.join(5)


def effective_jobs(jobs: int | None) -> int:
    """`-j 0` (or none) means one worker per CPU, at most 4."""
    import os

    if jobs:
        return max(1, jobs)
    return max(1, min(4, os.cpu_count() or 1))
