"""One line on stderr when numba is about to compile strapdown's kernels.

The compiled loops (:mod:`strapdown.algorithms._kernels`, :mod:`strapdown.ahrs._kernel`) are
``cache=True``: the first call in a fresh environment compiles them (seconds, half a minute
for the AHRS), later calls load the machine code from numba's cache. :func:`notice` listens to
numba's ``"numba:compile"`` event, which numba broadcasts only when a dispatcher really
compiles — after its cache lookup failed — so the line appears on a cold cache (first use, a
changed kernel source, a new numba) and never on a warm run. Nothing is read from disk to
decide, and the kernel modules need no change.

:func:`worker_initializer` carries the notice into a process pool's workers (``strapdown
sweep``), printed once for the whole pool.
"""

from __future__ import annotations

import signal
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["MESSAGE", "active", "notice", "worker_initializer"]

#: The line printed before the first compilation of the package's kernels.
MESSAGE = "compiling the numba kernels once (cached afterwards)…"

_PACKAGE = __name__.split(".")[0]
#: The listeners of the :func:`notice` blocks now open in this process (innermost last).
_OPEN: list[Any] = []


def _stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def _listener(say: Callable[[str], None], package: str, shared: Any = None):
    """A numba listener printing ``MESSAGE`` once, at the first compile of ``package``.

    ``shared`` (a ``multiprocessing.Value('b')``) makes the "once" hold across processes.
    """
    from numba.core import event

    class Listener(event.Listener):
        def __init__(self) -> None:
            self.said = False

        def on_start(self, ev) -> None:
            module = getattr(ev.data["dispatcher"].py_func, "__module__", "") or ""
            if self.said or module.split(".")[0] != package:
                return  # numba's own helpers compile too; only ours are announced
            self.said = True
            if shared is not None:
                with shared.get_lock():
                    if shared.value:
                        return
                    shared.value = 1
            say(MESSAGE)

        def on_end(self, ev) -> None:
            pass

    return Listener()


@contextmanager
def notice(say: Callable[[str], None] = _stderr, *, package: str = _PACKAGE) -> Iterator[None]:
    """Within the block, print :data:`MESSAGE` once if numba compiles a kernel of ``package``.

    Parameters
    ----------
    say : callable
        Where the line goes (default: stderr).
    package : str
        Top-level package whose jitted functions are announced (default ``strapdown``;
        numba's internal dispatchers compile too and are never announced).
    """
    from numba.core import event

    listener = _listener(say, package)
    event.register("numba:compile", listener)
    _OPEN.append(listener)
    try:
        yield
    finally:
        _OPEN.remove(listener)
        event.unregister("numba:compile", listener)


def active() -> bool:
    """Whether a :func:`notice` block is open in this process."""
    return bool(_OPEN)


def worker_initializer(shared: Any, announce: bool, package: str = _PACKAGE) -> None:
    """Initialise a pool worker: ignore Ctrl-C and, if ``announce``, carry the notice.

    The parent handles SIGINT alone (it stops the pool and reports); workers would otherwise
    each print a traceback. Listeners inherited from a forked parent are dropped, and one
    listener sharing ``shared`` (``multiprocessing.Value('b', 0)``) is registered, so a cold
    cache is announced once for the whole pool.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if not (announce or _OPEN):
        return
    from numba.core import event

    for inherited in _OPEN:
        event.unregister("numba:compile", inherited)
    _OPEN.clear()
    if not announce:
        return
    listener = _listener(_stderr, package, shared)
    event.register("numba:compile", listener)
    _OPEN.append(listener)
