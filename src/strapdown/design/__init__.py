"""Coefficient design: exact rational coning coefficients and drift laws for any update
structure (:mod:`strapdown.design.designer`, uses sympy) and numerical optimisation against
any motion (:mod:`strapdown.design.optimize`).

The designer is re-exported here (``strapdown.design.derive``).
"""

from strapdown.design.designer import (
    FORMS,
    RULES,
    TARGETS,
    Design,
    Structure,
    classical_coning_drift,
    derive,
    interval_structure,
    newton_cotes_weights,
    rate_structure,
    rk4_classical_coning_drift,
    single_chain_structure,
    structure_by_name,
    three_period_structure,
    uncompressed_structure,
)

__all__ = [
    "FORMS",
    "RULES",
    "TARGETS",
    "Design",
    "Structure",
    "classical_coning_drift",
    "derive",
    "interval_structure",
    "newton_cotes_weights",
    "rate_structure",
    "rk4_classical_coning_drift",
    "single_chain_structure",
    "structure_by_name",
    "three_period_structure",
    "uncompressed_structure",
]
