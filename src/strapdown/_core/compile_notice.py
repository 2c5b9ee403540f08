"""One line when numba is about to compile strapdown's kernels.

The compiled loops (:mod:`strapdown.algorithms._kernels`,
:mod:`strapdown.algorithms._velocity_kernels`, :mod:`strapdown.navigation._kernels`,
:mod:`strapdown.ahrs._kernel`) are ``cache=True``: the first call of each kernel in a fresh
environment compiles it (seconds; up to a minute for the AHRS), later calls load the machine
code from numba's cache. Each command and each algorithm uses its own kernels, so a new one
compiles on its own first use. The notices listen to numba's ``"numba:compile"`` event, which
numba broadcasts only when a dispatcher really compiles — after its cache lookup failed — so a
line appears on a cold cache (first use, a changed kernel source, a new numba) and never on a
warm run. Nothing is read from disk to decide.

- On the command line, :func:`notice` prints :data:`MESSAGE` on stderr, once per command.
- From Python, :func:`python_notice` (registered by the kernel modules when imported) logs
  :data:`API_MESSAGE` once per process on the ``strapdown.compile`` logger at WARNING level —
  shown on stderr when logging is not configured; ``logging.getLogger("strapdown.compile")
  .setLevel(logging.ERROR)`` silences it, and :func:`strapdown.warmup` compiles the common
  paths ahead of time.

:func:`worker_initializer` carries the notice into a process pool's workers (``strapdown
sweep``), said once for the whole pool.
"""

from __future__ import annotations

import logging
import signal
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["API_MESSAGE", "KERNELS", "LOGGER", "MESSAGE", "active", "notice", "python_notice",
           "worker_initializer"]

#: The line a command prints before it compiles a kernel not yet in numba's cache.
MESSAGE = ("compiling the numba kernels this run needs, on their first use (cached: later "
           "runs skip this)…")
#: The line logged when a Python call compiles kernels of one module (:func:`python_notice`).
API_MESSAGE = ("strapdown: compiling the numba kernels of {what} on their first use (cached: "
               "later runs skip this; strapdown.warmup() compiles the common paths ahead "
               "of time)…")
#: What :data:`API_MESSAGE` calls the kernels of each module.
KERNELS = {"strapdown.algorithms._kernels": "the attitude algorithms",
           "strapdown.algorithms._velocity_kernels": "the velocity updates",
           "strapdown.navigation._kernels": "the navigation algorithms",
           "strapdown.ahrs._kernel": "the AHRS filter"}
#: The logger of :data:`API_MESSAGE`.
LOGGER = "strapdown.compile"

_PACKAGE = __name__.split(".")[0]
#: The listeners of the :func:`notice` blocks now open in this process (innermost last).
_OPEN: list[Any] = []
#: The process-wide listener of Python calls (:func:`python_notice`), once registered.
_API: list[Any] = []


def _stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def _log(line: str) -> None:
    logging.getLogger(LOGGER).warning(line)


def _listener(say: Callable[[str], None], package: str, shared: Any = None, *,
              per_module: bool = False, quiet: Callable[[], bool] = lambda: False):
    """A numba listener saying :data:`MESSAGE` once, at the first compile of ``package``.

    ``shared`` (a ``multiprocessing.Value('b')``) makes the "once" hold across processes.
    ``per_module``: :data:`API_MESSAGE` once per kernel module instead (a Python session
    that first runs an algorithm and later the AHRS hears of both compiles). While
    ``quiet()`` is true (a :func:`notice` block speaks instead) it says nothing.
    """
    from numba.core import event

    class Listener(event.Listener):
        def __init__(self) -> None:
            self.said: set[str] = set()

        def on_start(self, ev) -> None:
            module = getattr(ev.data["dispatcher"].py_func, "__module__", "") or ""
            key = module if per_module else ""
            if key in self.said or module.split(".")[0] != package or quiet():
                return  # numba's own helpers compile too; only ours are announced
            self.said.add(key)
            if shared is not None:
                with shared.get_lock():
                    if shared.value:
                        return
                    shared.value = 1
            say(API_MESSAGE.format(what=KERNELS.get(module, module)) if per_module
                else MESSAGE)

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


def python_notice(package: str = _PACKAGE) -> None:
    """Log :data:`API_MESSAGE` (logger :data:`LOGGER`, WARNING) at the first compile of each
    kernel module of ``package`` in this process outside a :func:`notice` block — a Python
    call on a cold cache, which would otherwise compile for up to a minute in silence.
    Idempotent; the kernel modules call it when imported."""
    if _API:
        return
    from numba.core import event

    listener = _listener(_log, package, per_module=True, quiet=active)
    event.register("numba:compile", listener)
    _API.append(listener)


def worker_initializer(shared: Any, announce: bool, package: str = _PACKAGE) -> None:
    """Initialise a pool worker: ignore Ctrl-C and, if ``announce``, carry the notice.

    The parent handles SIGINT alone (it stops the pool and reports); workers would otherwise
    each print a traceback. Listeners inherited from a forked parent are dropped, and one
    listener sharing ``shared`` (``multiprocessing.Value('b', 0)``) is registered, so a cold
    cache is announced once for the whole pool.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if not (announce or _OPEN or _API):
        return
    from numba.core import event

    for inherited in (*_OPEN, *_API):
        event.unregister("numba:compile", inherited)
    _OPEN.clear()
    if announce:
        listener = _listener(_stderr, package, shared)
        event.register("numba:compile", listener)
        _OPEN.append(listener)
    elif _API:  # a Python call's pool: logged once for the pool, as the parent would
        _API[0] = _listener(_log, package, shared, per_module=True, quiet=active)
        event.register("numba:compile", _API[0])
