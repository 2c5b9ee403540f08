"""The command line's interrupting signals (Ctrl-C's SIGINT, SIGTERM) handled differently
for the length of a block: :func:`replaced_handlers`."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Callable, Iterator
from typing import Any

__all__ = ["INTERRUPTING", "replaced_handlers"]

#: The signals the command line turns into an exception (``KeyboardInterrupt``).
INTERRUPTING = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def replaced_handlers(handler: Callable[[int, Any], Any] | int) -> Iterator[None]:
    """SIGINT's and SIGTERM's handlers replaced by ``handler`` (a function or
    ``signal.SIG_IGN``) for the block, the previous ones put back after it.

    Only in the main thread, the one Python runs signal handlers in (elsewhere nothing
    changes); a handler not set from Python (``signal.getsignal`` gives ``None``) is left
    alone, as it could not be put back.
    """
    saved = {}
    if threading.current_thread() is threading.main_thread():
        for s in INTERRUPTING:
            if signal.getsignal(s) is not None:
                saved[s] = signal.signal(s, handler)
    try:
        yield
    finally:
        for s, previous in saved.items():
            signal.signal(s, previous)
