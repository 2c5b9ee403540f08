"""Limits checked before anything is allocated: the memory budget and the inflation ratio.

Every reader compares what a file *declares* (an array's shape, a zip member's or a
compressed MATLAB variable's inflated size, an HDF5 dataset's extent) against

* the file itself — data a header declares must fit in the bytes that follow it;
* the **memory budget**: the bytes the arrays one input decodes to may take, by default
  :data:`DEFAULT_MAX_BYTES` (2 GiB), overridden by the environment variable
  ``STRAPDOWN_MAX_BYTES`` or the command line's ``--max-memory`` (sizes such as
  ``512M``, ``4G`` or a number of bytes; :func:`parse_size`), or in code by
  :func:`memory_budget`. A run needs a few times its input's size on top (the attitude,
  the angles, the output table);
* the **inflation ratio**: a compressed member may expand at most :data:`DEFAULT_MAX_RATIO`
  (100) times its stored size (environment ``STRAPDOWN_MAX_RATIO``); measured IMU data
  compresses 1.5–10 times, a zip bomb a thousand. Compressed data is inflated in chunks, and
  never beyond the size declared and checked.

A file over a limit is an :class:`~strapdown._core.errors.InputError` saying which limit
and how to raise it.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import os
import re
from collections.abc import Iterator

from strapdown._core.errors import InputError

__all__ = ["BUDGET_ENV", "DEFAULT_MAX_BYTES", "DEFAULT_MAX_RATIO", "RATIO_ENV", "check_bytes",
           "check_ratio", "max_bytes", "max_ratio", "memory_budget", "parse_size"]

#: Default memory budget for the arrays one input decodes to (bytes).
DEFAULT_MAX_BYTES = 2 * 1024**3
#: Default largest inflation ratio of a compressed member.
DEFAULT_MAX_RATIO = 100.0
BUDGET_ENV = "STRAPDOWN_MAX_BYTES"
RATIO_ENV = "STRAPDOWN_MAX_RATIO"
_UNITS = {"": 1, "b": 1, "k": 1024, "kb": 1024, "kib": 1024, "m": 1024**2, "mb": 1024**2,
          "mib": 1024**2, "g": 1024**3, "gb": 1024**3, "gib": 1024**3, "t": 1024**4,
          "tb": 1024**4, "tib": 1024**4}
_SIZE = re.compile(r"^\s*([0-9]+(?:\.[0-9]*)?(?:e[0-9]+)?)\s*([a-z]*)\s*$", re.IGNORECASE)
_budget: contextvars.ContextVar[int | None] = contextvars.ContextVar("strapdown_budget",
                                                                      default=None)


def parse_size(text: str, what: str = "--max-memory") -> int:
    """Bytes of a size written ``2G``, ``512M``, ``100k``, ``1e9`` (binary units: 1k = 1024);
    an unreadable or non-positive size is an :class:`InputError` naming ``what``."""
    m = _SIZE.match(str(text))
    unit = m.group(2).lower() if m else ""
    if m is None or unit not in _UNITS:
        raise InputError(f"{what}: {str(text)[:40]!r} is not a size (e.g. 512M, 4G or bytes)")
    value = float(m.group(1)) * _UNITS[unit]
    if not (math.isfinite(value) and 1 <= value < 2**63):
        raise InputError(f"{what}: {str(text)[:40]!r} must be at least one byte and finite")
    return int(value)


def max_bytes() -> int:
    """The memory budget in force: :func:`memory_budget`'s, else ``STRAPDOWN_MAX_BYTES``'s,
    else :data:`DEFAULT_MAX_BYTES`."""
    given = _budget.get()
    if given is not None:
        return given
    env = os.environ.get(BUDGET_ENV)
    return DEFAULT_MAX_BYTES if not env else parse_size(env, BUDGET_ENV)


def max_ratio() -> float:
    """The inflation-ratio limit: ``STRAPDOWN_MAX_RATIO``, else :data:`DEFAULT_MAX_RATIO`."""
    env = os.environ.get(RATIO_ENV)
    if not env:
        return DEFAULT_MAX_RATIO
    try:
        r = float(env)
    except ValueError:
        r = math.nan
    if not (math.isfinite(r) and r >= 1):
        raise InputError(f"{RATIO_ENV}: {env[:40]!r} must be a number of at least 1")
    return r


@contextlib.contextmanager
def memory_budget(nbytes: int | None) -> Iterator[None]:
    """Use ``nbytes`` as the budget inside the block (None: leave it as it is)."""
    if nbytes is None:
        yield
        return
    if isinstance(nbytes, bool) or not isinstance(nbytes, int) or nbytes < 1:
        raise InputError(f"the memory budget must be a positive number of bytes, got {nbytes!r}")
    token = _budget.set(nbytes)
    try:
        yield
    finally:
        _budget.reset(token)


def _size(n: float) -> str:
    for unit, f in (("GiB", 1024**3), ("MiB", 1024**2), ("kiB", 1024)):
        if n >= f:
            return f"{n / f:.3g} {unit}"
    return f"{int(n)} bytes"


def check_bytes(where: object, nbytes: int, what: str) -> None:
    """Raise unless ``nbytes`` (what ``what`` would take) fits the memory budget."""
    limit = max_bytes()
    if nbytes > limit:
        raise InputError(f"{where}: {what} would take {_size(nbytes)}, over the memory budget "
                         f"of {_size(limit)}; raise it with --max-memory or {BUDGET_ENV} if "
                         "the file is right")


def check_ratio(where: object, inflated: int, stored: int, what: str) -> None:
    """Raise when ``inflated`` bytes from ``stored`` exceed the inflation-ratio limit (a
    member under 1 MiB is always accepted: small arrays of constants compress well)."""
    limit = max_ratio()
    if inflated > 1024**2 and inflated > limit * max(stored, 1):
        raise InputError(f"{where}: {what} would inflate {_size(stored)} to {_size(inflated)} "
                         f"(over {limit:g} times; a compression bomb?); raise {RATIO_ENV} if "
                         "the file is right")
