"""The command line's interrupting signals (Ctrl-C's SIGINT, SIGTERM) handled differently
for the length of a block (:func:`replaced_handlers`), and never lost in a finaliser
(:func:`interrupts_kept`), never acted on inside llvmlite (:class:`OutsideLlvmlite`),
or held back until the code asks (:func:`interrupts_deferred`)."""

from __future__ import annotations

import _thread
import contextlib
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

__all__ = ["INTERRUPTING", "OutsideLlvmlite", "after", "interrupts_deferred", "interrupts_kept",
           "replaced_handlers"]

#: The signals the command line turns into an exception (``KeyboardInterrupt``).
INTERRUPTING = (signal.SIGINT, signal.SIGTERM)

#: How long after an interrupt lost in a finaliser it is raised again (:func:`interrupts_kept`).
REDELIVERY_DELAY_S = 1e-3
#: The top-level packages whose Python code a signal's exception is never raised in
#: (:class:`OutsideLlvmlite`).
NOT_INTERRUPTIBLE = ("llvmlite",)
#: How soon a signal held back by :class:`OutsideLlvmlite` is sent again (seconds).
RETRY_S = 1e-3


def after(delay_s: float, call: Callable[..., Any], *args: Any) -> threading.Timer:
    """``call(*args)`` in ``delay_s`` seconds, from a daemon thread (started; ``cancel()``
    it to drop the call). A daemon: it never keeps a process alive that is done."""
    timer = threading.Timer(delay_s, call, args)
    timer.daemon = True
    timer.start()
    return timer


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
            while True:
                try:
                    after(REDELIVERY_DELAY_S, _thread.interrupt_main)
                    return
                except KeyboardInterrupt:  # the redelivery landed in this hook (a loaded
                    continue  # machine starts the thread slowly): Python would drop it too
        previous(unraisable)

    sys.unraisablehook = hook
    try:
        yield
    finally:
        sys.unraisablehook = previous


class _Deferred(BaseException):
    """Raised by :func:`interrupts_deferred`'s check: unwinds the block to where the signal
    is delivered again. Never seen outside it."""


@contextlib.contextmanager
def interrupts_deferred() -> Iterator[Callable[[], None]]:
    """For the block, SIGINT and SIGTERM are noted, not acted on, until the block calls the
    check it is given; the signal is then delivered again, to its previous handler, once
    the block has unwound.

    Python raises Ctrl-C's ``KeyboardInterrupt`` at whatever bytecode runs next, which may be
    inside a ``with lock:`` of the standard library, between the acquire and the block: the
    lock then stays held. In a ``multiprocessing.Pool``'s result iterator that lock is one
    the pool's result-handler thread needs, and the pool's ``terminate()`` would wait for
    that thread for ever. Here the interrupt is raised from
    ``check()``, in the block's own code: an internal exception unwinds the block (cleanup
    inside it, such as a pool's terminate(), runs still shielded), then the signal is raised
    again (:func:`signal.raise_signal`) with the previous handlers back, so it becomes the
    ``KeyboardInterrupt`` (or the command line's SIGTERM exception) the caller expects, or,
    for a handler that returns, a ``KeyboardInterrupt``. A signal noted but not checked
    before the block ends is delivered the same way at its end.

    Only in the main thread and only for handlers set from Python and not ignored; elsewhere
    ``check()`` does nothing and signals act as before. A process forked inside the block
    (a pool's replacement worker) gets the default action. Callers must call ``check()``
    often (a loop waiting with a timeout): a deferred Ctrl-C waits for it.
    """
    got: list[int] = []
    owner = os.getpid()

    def note(signum: int, frame: Any) -> None:
        if os.getpid() != owner:  # a process forked inside the block (a pool's replacement
            signal.signal(signum, signal.SIG_DFL)  # worker): the signal acts as by default,
            os.kill(os.getpid(), signum)  # so a pool's terminate() still ends it
            return
        got.append(signum)

    def check() -> None:
        if got:
            raise _Deferred()

    saved = {}
    if threading.current_thread() is threading.main_thread():
        for s in INTERRUPTING:
            if signal.getsignal(s) not in (None, signal.SIG_IGN):
                saved[s] = signal.signal(s, note)
    try:
        yield check
    except _Deferred:
        pass
    finally:
        for s, previous in saved.items():
            signal.signal(s, previous)
    if got:
        signal.raise_signal(got[0])  # its handler raises here, in this frame
        raise KeyboardInterrupt()  # a handler that returned: the block was still cut short


class OutsideLlvmlite:
    """A signal handler that never runs while Python is inside llvmlite; ``settle()`` runs
    one that is still held back.

    numba builds and loads kernels through llvmlite, whose disposal of LLVM objects (often
    a finaliser) is not safe against an exception raised at an arbitrary bytecode: a
    ``KeyboardInterrupt`` landing there is dropped by Python (a finaliser's exception) and
    leaves the object half disposed; the process then died of a segmentation fault at the
    next kernel it loaded (a sweep given Ctrl-C with ``--workers 1``, exit -11), or, in a
    pool worker, lost the exit it was asked for. When the interrupted frame or one that
    called it belongs to a package of :data:`NOT_INTERRUPTIBLE`, this does nothing now and
    sends the signal again :data:`RETRY_S` later, as a real signal to the main thread
    (:func:`signal.pthread_kill`; :func:`_thread.interrupt_main` only marks the handler as
    due, and a process blocked in a system call meanwhile would never run it). numba's own
    Python code is interrupted as before (Ctrl-C during a compile stops it at once).

    A signal still held back when the program is about to end would be lost with the
    retry's daemon thread: the caller runs :meth:`settle` at its end, which runs the handler
    for it then (as if the signal had come just after the work finished).
    """

    def __init__(self, handler: Callable[[int, Any], Any]) -> None:
        self.handler = handler
        self.pending: int | None = None

    def __call__(self, signum: int, frame: Any) -> Any:
        f = frame
        while f is not None:
            if f.f_globals.get("__name__", "").partition(".")[0] in NOT_INTERRUPTIBLE:
                self.pending = signum
                # handlers run in the main thread: get_ident() is the thread to send it to
                after(RETRY_S, signal.pthread_kill, threading.get_ident(), signum)
                return None
            f = f.f_back
        self.pending = None
        return self.handler(signum, frame)

    def settle(self) -> None:
        """Run the handler for a signal still held back (it raises, as a rule)."""
        if self.pending is not None:
            signum, self.pending = self.pending, None
            self.handler(signum, None)
