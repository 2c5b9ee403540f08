"""Coefficient design: exact rational coning coefficients and drift laws for any update
structure (:mod:`strapdown.design.designer`, uses sympy) and numerical optimisation against
any motion (:mod:`strapdown.design.optimize`).

The designer is re-exported here (``strapdown.design.derive``).
"""

from strapdown.design import designer as _designer
from strapdown.design.designer import *  # noqa: F403  (the subpackage's public face)

__all__ = list(_designer.__all__)
