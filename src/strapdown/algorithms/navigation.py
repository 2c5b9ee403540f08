"""Deprecated: Earth navigation moved to :mod:`strapdown.navigation` (issue 26).

This alias keeps code written against the old path working for one release: importing it
warns (``DeprecationWarning``) and gives the same objects as :mod:`strapdown.navigation`.
Import :func:`strapdown.navigate` (or :mod:`strapdown.navigation`) instead. It is the one
module of ``strapdown.algorithms`` allowed to import the navigation layer above it (an
``ignore_imports`` entry of the import contract in ``pyproject.toml``), and it goes with the
next release.
"""

from __future__ import annotations

import warnings

from strapdown.navigation.earth import (
    GRAVITY_MODELS,
    POLE_LIMIT_DEG,
    TRAILING_POLICIES,
    GravityModel,
    NavSolution,
    NavStream,
    TrailingPolicy,
    TrailingSamplesWarning,
    navigate,
    navigate_rates,
)

__all__ = ["GRAVITY_MODELS", "POLE_LIMIT_DEG", "TRAILING_POLICIES", "GravityModel",
           "NavSolution", "NavStream", "TrailingPolicy", "TrailingSamplesWarning", "navigate",
           "navigate_rates"]

warnings.warn("strapdown.algorithms.navigation moved to strapdown.navigation (issue 26); "
              "this alias goes with the next release", DeprecationWarning, stacklevel=2)
