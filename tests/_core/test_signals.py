"""``replaced_handlers``: SIGINT's and SIGTERM's handlers swapped for a block, put back after
it, untouched outside the main thread."""

from __future__ import annotations

import signal
import threading

import pytest

from strapdown._core.signals import INTERRUPTING, replaced_handlers


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
