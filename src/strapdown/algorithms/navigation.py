"""Deprecated: Earth navigation moved to :mod:`strapdown.navigation` (issue 26).

This alias keeps code written against the old path working for one release: importing it
warns (``DeprecationWarning``) and gives the same objects as :mod:`strapdown.navigation`
(each name of :mod:`strapdown.navigation.earth`, looked up there). Import
:func:`strapdown.navigate` (or :mod:`strapdown.navigation`) instead. It is the one module
of ``strapdown.algorithms`` allowed to import the navigation layer above it (an
``ignore_imports`` entry of the import contract in ``pyproject.toml``), and it goes with the
next release.
"""

from __future__ import annotations

import warnings

from strapdown.navigation import earth as _earth

__all__ = list(_earth.__all__)


def __getattr__(name: str) -> object:
    if name in _earth.__all__:
        return getattr(_earth, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


warnings.warn("strapdown.algorithms.navigation moved to strapdown.navigation (issue 26); "
              "this alias goes with the next release", DeprecationWarning, stacklevel=2)
