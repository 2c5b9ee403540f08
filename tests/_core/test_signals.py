"""``replaced_handlers``: SIGINT's and SIGTERM's handlers swapped for a block, put back after
it, untouched outside the main thread; ``interrupts_kept``: an interrupt landing in a
finaliser raised again, not printed and lost; ``interrupts_deferred``: a signal held back
until the block checks, then delivered to the previous handler once the block has unwound;
``OutsideLlvmlite``: no signal's exception inside llvmlite's code."""

from __future__ import annotations

import signal
import sys
import threading
import time

import pytest

from strapdown._core.signals import (
    INTERRUPTING,
    OutsideLlvmlite,
    interrupts_deferred,
    interrupts_kept,
    replaced_handlers,
)


def test_handlers_are_replaced_for_the_block_and_put_back_after_an_exception():
    before = [signal.getsignal(s) for s in INTERRUPTING]
    with pytest.raises(RuntimeError), replaced_handlers(signal.SIG_IGN):
        assert [signal.getsignal(s) for s in INTERRUPTING] == [signal.SIG_IGN] * 2
        raise RuntimeError
    assert [signal.getsignal(s) for s in INTERRUPTING] == before


def test_outside_the_main_thread_nothing_changes():
    before = [signal.getsignal(s) for s in INTERRUPTING]
    seen = []

    def run():
        with replaced_handlers(signal.SIG_IGN):
            seen.append([signal.getsignal(s) for s in INTERRUPTING])

    th = threading.Thread(target=run)
    th.start()
    th.join()
    assert seen == [before]


class _InterruptedFinaliser:
    """An object whose finaliser is where Ctrl-C lands (as it may in numba's LLVM objects)."""

    def __del__(self):
        raise KeyboardInterrupt


def test_an_interrupt_in_a_finaliser_is_raised_again_not_printed(capfd):
    """Without the guard Python prints "Exception ignored in" with a traceback and the
    interrupt is gone; with it, the main flow gets the KeyboardInterrupt and stderr is empty."""
    before = sys.unraisablehook
    # Python's own SIGINT handler, as in the command line (a test runner's worker may have
    # another, or ignore SIGINT, and then nothing is delivered)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            with interrupts_kept():
                _InterruptedFinaliser()  # dropped at once: its __del__ runs here
                deadline = time.monotonic() + 2.0  # the SIGINT is raised again a moment later
                while time.monotonic() < deadline:
                    pass
    finally:
        signal.signal(signal.SIGINT, previous)
    assert capfd.readouterr().err == ""
    assert sys.unraisablehook is before


def test_other_unraisable_exceptions_still_reach_the_previous_hook():
    seen = []
    previous, sys.unraisablehook = sys.unraisablehook, seen.append
    try:
        with interrupts_kept():
            class Broken:
                def __del__(self):
                    raise RuntimeError("finaliser bug")

            Broken()
    finally:
        sys.unraisablehook = previous
    assert [type(u.exc_value) for u in seen] == [RuntimeError]


@pytest.fixture
def python_sigint():
    """Python's own SIGINT handler for the test, as in the command line: a suite started in
    the background (``make test &``) inherits SIGINT ignored, and then nothing is deferred."""
    with replaced_handlers(signal.default_int_handler):
        yield


def test_a_deferred_ctrl_c_waits_for_the_check_and_unwinds_the_block_first(python_sigint):
    events = []
    with pytest.raises(KeyboardInterrupt):
        with interrupts_deferred() as check:
            try:
                signal.raise_signal(signal.SIGINT)
                events.append("after the signal")  # not interrupted here
                check()
                events.append("after the check")  # never
            finally:
                events.append(("cleanup", signal.getsignal(signal.SIGINT)
                               is signal.default_int_handler))  # still deferred
    assert events == ["after the signal", ("cleanup", False)]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_deferred_sigterm_reaches_the_previous_handler_once_the_block_is_left():
    got = []

    class Term(KeyboardInterrupt):
        pass

    def previous(signum, frame):
        got.append(signum)
        raise Term()

    with replaced_handlers(previous):
        with pytest.raises(Term):
            with interrupts_deferred() as check:
                signal.raise_signal(signal.SIGTERM)
                assert got == []
                check()
        assert got == [signal.SIGTERM]


def test_a_signal_noted_but_not_checked_is_delivered_at_the_block_end(python_sigint):
    reached = []
    with pytest.raises(KeyboardInterrupt):
        with interrupts_deferred():
            signal.raise_signal(signal.SIGINT)
            reached.append(True)
    assert reached == [True]


def test_a_previous_handler_that_returns_still_cuts_the_block_short():
    with replaced_handlers(lambda signum, frame: None):
        with pytest.raises(KeyboardInterrupt), interrupts_deferred() as check:
            signal.raise_signal(signal.SIGINT)
            check()


def test_without_a_signal_the_check_does_nothing_and_ignored_signals_stay_ignored():
    with replaced_handlers(signal.SIG_IGN):
        with interrupts_deferred() as check:
            assert [signal.getsignal(s) for s in INTERRUPTING] == [signal.SIG_IGN] * 2
            check()
            signal.raise_signal(signal.SIGINT)  # ignored, as before
            check()


def _defined_in(module: str, source: str, **names):
    """The function ``inside`` of ``source``, its code belonging to ``module`` (as if
    llvmlite's own), with ``names`` as its globals."""
    ns = {"__name__": module, "signal": signal, "time": time, **names}
    exec(source, ns)
    return ns["inside"]


_INSIDE = """
def inside(log):
    signal.raise_signal(signal.SIGINT)
    start = time.monotonic()
    while time.monotonic() - start < 0.05:  # many bytecodes, each a chance to raise
        pass
    log.append("returned")
"""


@pytest.mark.parametrize("module", ["llvmlite.binding.ffi", "llvmlite.binding.module"])
def test_an_interrupt_inside_llvmlite_comes_once_the_call_has_returned(module):
    inside = _defined_in(module, _INSIDE)
    log = []
    with replaced_handlers(OutsideLlvmlite(signal.default_int_handler)):
        with pytest.raises(KeyboardInterrupt):
            inside(log)
            log.append("outside")
            deadline = time.monotonic() + 5
            while time.monotonic() < deadline:  # the interrupt arrives here, retried
                time.sleep(1e-3)
    assert log == ["returned", "outside"]


_INSIDE_THEN_BLOCK = """
def inside():
    signal.raise_signal(signal.SIGINT)
"""


def test_an_interrupt_held_back_reaches_a_process_blocked_in_a_system_call():
    """After the llvmlite call the main thread blocks (a pool worker waiting for its queue's
    lock): the interrupt sent again must wake it, not wait for the block to end."""
    inside = _defined_in("llvmlite.binding.ffi", _INSIDE_THEN_BLOCK)
    held = threading.Lock()
    held.acquire()
    with replaced_handlers(OutsideLlvmlite(signal.default_int_handler)):
        with pytest.raises(KeyboardInterrupt):
            inside()
            start = time.monotonic()
            held.acquire(timeout=20)  # never released: only the interrupt ends the wait
    # woken (~RETRY_S), not run once the wait timed out (as _thread.interrupt_main would)
    assert time.monotonic() - start < 10


def test_an_interrupt_outside_llvmlite_is_raised_at_once():
    with replaced_handlers(OutsideLlvmlite(signal.default_int_handler)):
        with pytest.raises(KeyboardInterrupt):
            signal.raise_signal(signal.SIGINT)


def test_a_signal_still_held_back_at_the_end_is_run_by_settle(monkeypatch):
    """The program ends within RETRY_S of a signal held back in llvmlite: settle() runs it."""
    monkeypatch.setattr(signal, "pthread_kill", lambda *args: None)  # the retry never comes
    guard = OutsideLlvmlite(signal.default_int_handler)
    inside = _defined_in("llvmlite.binding.ffi",
                         "def inside():\n    guard(signal.SIGINT, sys._getframe())\n",
                         guard=guard, sys=sys)
    inside()  # held back
    assert guard.pending == signal.SIGINT
    with pytest.raises(KeyboardInterrupt):
        guard.settle()
    assert guard.pending is None
    guard.settle()  # nothing held back: nothing happens
