"""``replaced_handlers``: SIGINT's and SIGTERM's handlers swapped for a block, put back after
it, untouched outside the main thread; ``interrupts_kept``: an interrupt landing in a
finaliser raised again, not printed and lost."""

from __future__ import annotations

import signal
import sys
import threading
import time

import pytest

from strapdown._core.signals import INTERRUPTING, interrupts_kept, replaced_handlers


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
