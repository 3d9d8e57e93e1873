"""implc.interrupts: a SIGINT or SIGTERM that comes inside `signals_held()` is acted on as
the block ends, not in its middle (where a nanobind import or Mesa's compile would abort),
whichever thread the kernel gives it to; one that Python drops (raised in a `__del__` or a
weakref callback) still ends the run, and no output is put in place after it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import pytest

from implc.interrupts import signals_held

ROOT = Path(__file__).resolve().parent.parent


class Stop(BaseException):
    pass


def _raise_stop(signum, frame):
    raise Stop()


def _busy(until) -> int:
    """Python bytecode until `until()`: where a signal's handler would raise."""
    spins = 0
    while not until():
        spins += 1
    return spins + sum(range(10000))


def test_a_signal_inside_the_block_waits_for_its_end():
    finished = []
    with pytest.raises(KeyboardInterrupt), signals_held():
        os.kill(os.getpid(), signal.SIGINT)
        _busy(lambda: True)
        finished.append(True)
    assert finished == [True]


def test_a_signal_another_thread_takes_waits_too():
    """This thread blocks the signals and the sender, started before the block, does not
    (a thread started inside it inherits the block), so the kernel gives the sender the
    signal: only the Python-level deferral keeps the handler out of the block."""
    previous = signal.signal(signal.SIGTERM, _raise_stop)
    go = threading.Event()

    def send() -> None:
        go.wait()
        os.kill(os.getpid(), signal.SIGTERM)

    sender = threading.Thread(target=send)
    sender.start()
    finished = []
    try:
        with pytest.raises(Stop), signals_held():
            go.set()
            _busy(lambda: not sender.is_alive())
            _busy(lambda: True)
            finished.append(True)
        assert signal.getsignal(signal.SIGTERM) is _raise_stop  # restored
    finally:
        sender.join()
        signal.signal(signal.SIGTERM, previous)
    assert finished == [True]


def test_nested_blocks_hand_the_signal_out_once():
    finished = []
    with pytest.raises(KeyboardInterrupt), signals_held():
        with signals_held():
            os.kill(os.getpid(), signal.SIGINT)
            _busy(lambda: True)
        finished.append("inner")
        _busy(lambda: True)
        finished.append("outer")
    assert finished == ["inner", "outer"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_python_m_implc_exits_with_its_code_after_a_caught_interrupt(tmp_path):
    """A KeyboardInterrupt that escaped an exec() of a string (as one does when Ctrl-C
    lands while a dataclass is being defined in a lazy import) made `python -m implc` die
    by SIGINT (-2) although main() caught it and returned 130."""
    proc = _python_m_implc_list(tmp_path, "def listed(args):\n"
                                          "    exec('raise KeyboardInterrupt')\n")
    assert (proc.returncode, proc.stderr) == (130, "implc: interrupted\n")


def _python_m_implc_list(tmp_path: Path, listed: str) -> subprocess.CompletedProcess:
    """`python -m implc list` with `listed` (source defining `listed(args)`) as the
    command, from a module of its own run by `python -m` (SIGINT at its default)."""
    (tmp_path / "patched_list.py").write_text(
        "import os, runpy, signal, sys\n"
        "import implc.cli\n"
        f"{listed}"
        "implc.cli.cmd_list = listed\n"
        "sys.argv = ['implc', 'list']\n"
        "runpy.run_module('implc', run_name='__main__')\n")
    return subprocess.run([sys.executable, "-m", "patched_list"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": str(ROOT)},
                          preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _interrupting(real):
    """`real` (tempfile.mkdtemp or mkstemp), then a SIGINT to this process before the
    name gets back to the caller: where the signal of a loaded machine can land."""

    def made_then_interrupted(*args, **kwargs):
        made = real(*args, **kwargs)
        os.kill(os.getpid(), signal.SIGINT)
        return made

    return made_then_interrupted


def test_an_interrupt_as_the_staging_directory_is_made_leaves_nothing(tmp_path, monkeypatch):
    """test_fault[gallery-SIGTERM] left a `.out.partial-*` directory once under load."""
    from implc.fileio import staged_directory

    monkeypatch.setattr(tempfile, "mkdtemp", _interrupting(tempfile.mkdtemp))
    with pytest.raises(KeyboardInterrupt), staged_directory(tmp_path / "out"):
        pass
    assert list(tmp_path.iterdir()) == []


def test_an_interrupt_as_a_temporary_file_is_made_leaves_nothing(tmp_path, monkeypatch):
    from implc.fileio import write_atomic

    monkeypatch.setattr(tempfile, "mkstemp", _interrupting(tempfile.mkstemp))
    with pytest.raises(KeyboardInterrupt):
        write_atomic(tmp_path / "out.txt", "text")
    assert list(tmp_path.iterdir()) == []


def _drop(kind: type[BaseException] = KeyboardInterrupt) -> None:
    """`kind` raised where Python drops it: in a `__del__` (like a weakref callback or a
    garbage-collector run, where Ctrl-C landed in test_fault[bench-SIGINT])."""

    class RaisesWhenCollected:
        def __del__(self):
            raise kind()

    RaisesWhenCollected()


def test_a_dropped_signal_is_kept_silently_and_raised_again(capsys):
    from implc.interrupts import Terminated, dropped_signals_kept, raise_dropped

    for kind in (KeyboardInterrupt, Terminated):
        with dropped_signals_kept():
            _drop(kind)
            with pytest.raises(kind):
                raise_dropped()
            raise_dropped()  # once
    assert capsys.readouterr().err == ""


def test_an_output_is_not_put_in_place_after_a_dropped_interrupt(tmp_path):
    from implc.fileio import staged_directory, write_with
    from implc.interrupts import dropped_signals_kept

    def writer(tmp: str) -> None:
        Path(tmp).write_text("complete")
        _drop()

    with dropped_signals_kept():
        with pytest.raises(KeyboardInterrupt):
            write_with(tmp_path / "out.txt", writer)
        with pytest.raises(KeyboardInterrupt), staged_directory(tmp_path / "run") as stage:
            writer(str(stage / "table.md"))
    assert list(tmp_path.iterdir()) == []


def test_implc_exits_interrupted_after_a_dropped_interrupt(tmp_path):
    """Ctrl-C in the import system's module-lock callback was dropped by Python, and `implc bench`
    finished and exited 0 (test_fault[bench-SIGINT] in CI)."""
    proc = _python_m_implc_list(
        tmp_path,
        "class InterruptedWhenCollected:\n"
        "    def __del__(self):\n"
        "        os.kill(os.getpid(), signal.SIGINT)\n"
        "        sum(range(100000))  # the handler raises here, inside __del__\n"
        "def listed(args):\n"
        "    InterruptedWhenCollected()\n"
        "    print('listed')\n"
        "    return 0\n")
    assert (proc.returncode, proc.stderr) == (130, "implc: interrupted\n")
