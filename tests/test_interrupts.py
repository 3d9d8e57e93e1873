"""implc.interrupts.signals_held: a SIGINT or SIGTERM that comes inside the block is acted
on as the block ends, not in its middle (where a nanobind import or Mesa's compile would
abort), whichever thread the kernel gives it to."""

from __future__ import annotations

import os
import signal
import threading

import pytest

from implc.interrupts import signals_held


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
