"""The command line's interrupting signals (Ctrl-C's SIGINT, SIGTERM) handled differently
for the length of a block (:func:`replaced_handlers`), and never lost in a finaliser
(:func:`interrupts_kept`)."""

from __future__ import annotations

import _thread
import contextlib
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

__all__ = ["INTERRUPTING", "interrupts_kept", "replaced_handlers"]

#: The signals the command line turns into an exception (``KeyboardInterrupt``).
INTERRUPTING = (signal.SIGINT, signal.SIGTERM)

#: How long after an interrupt lost in a finaliser it is raised again (:func:`interrupts_kept`).
REDELIVERY_DELAY_S = 1e-3


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


@contextlib.contextmanager
def interrupts_kept() -> Iterator[None]:
    """For the block, an interrupt that lands in a finaliser is delivered again, not lost.

    Python runs a signal's handler at the next bytecode, which may be inside an object's
    ``__del__`` (numba's compiler frees LLVM objects all the time). The ``KeyboardInterrupt``
    raised there cannot propagate: Python prints it as "Exception ignored in …" with a
    traceback and drops it, so Ctrl-C would print a traceback and be forgotten. This sets
    :data:`sys.unraisablehook` so that such an interrupt is not printed and is raised again
    in the main thread (:func:`_thread.interrupt_main`, SIGINT's handler) a millisecond
    later, from a daemon thread: raised from the hook itself it would be lost again. Should
    it land in a finaliser once more, it comes back once more. Every other unraisable
    exception goes to the previous hook.
    """
    previous = sys.unraisablehook

    def hook(unraisable: Any) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            again = threading.Timer(REDELIVERY_DELAY_S, _thread.interrupt_main)
            again.daemon = True
            again.start()
            return
        previous(unraisable)

    sys.unraisablehook = hook
    try:
        yield
    finally:
        sys.unraisablehook = previous
