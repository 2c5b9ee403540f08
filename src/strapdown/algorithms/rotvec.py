"""The rotation-vector family: N-subsample coning correction in the conventional,
real-time and single-chain update structures.

``φ = Σ θ_i + Σ_{i<j} k_ij θ_i × θ_j`` over the N increments of an update (coefficient
sets in :mod:`.coning`), ``q ← q ⊗ q(φ)``; the structures are in :mod:`.structures`.

References
----------
Li, X. & Zhang, S. (2017), "A Real-Time Structure of Attitude Algorithm for High Dynamic
Bodies", J. Control Sci. Eng. 2017, 9542423: eq. 6 (pair form), eq. 9 (rotation vector),
eq. 10 (conventional structure), eq. 15 (real-time structure), Table 1 (drift law),
Table 3 (coefficients). Bortz (1971); Miller (1983). The single chain is strapdown's own
design (:func:`strapdown.design.single_chain_structure`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Literal

from strapdown.algorithms.coning import (
    MAX_SUBSAMPLES,
    CoefficientSet,
    ConingSetName,
    coefficient_set,
    coefficient_set_names,
    coning_set_name,
    table1_drift_constant,
)
from strapdown.algorithms.family import DriftLaw, Family, IncrementStructure
from strapdown.algorithms.structures import AttitudeSolution, increment_structure, structure

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from strapdown.algorithms.precision import MpSolution
    from strapdown.algorithms.spec import AlgorithmSpec
    from strapdown.truth.motions import Motion

__all__ = ["FAMILIES", "Rotvec", "RotvecName"]

#: The family defined here.
RotvecName = Literal["rotvec"]


class Rotvec(Family):
    """``rotvec``: the N-subsample rotation vector with a named coefficient set."""

    name = "rotvec"
    input_kind = "increment"
    structures: ClassVar[tuple[IncrementStructure, ...]] = ("conventional", "realtime",
                                                           "single-chain")
    options = frozenset({"subsamples"})
    default_coefficients = "table3"
    coning_sets = True
    reference = ("Li & Zhang 2017, J. Control Sci. Eng. 9542423: eq. 6 (pair form), eq. 9 "
                 "(rotation vector), eq. 10 (conventional), eq. 15 (real-time); single chain: "
                 "strapdown designer (c_m = (K_m - (N-m)/2)/N)")

    def coefficient_names(self) -> tuple[ConingSetName, ...]:
        return coefficient_set_names()

    def check(self, spec: AlgorithmSpec) -> None:
        super().check(spec)
        cs = self.coefficient_set(spec)  # unknown sets and impossible N fail here
        if cs.triples and spec.update_structure.pair_only:
            able = " and ".join(s for s in self.structures if not structure(s).pair_only)
            raise ValueError(f"coefficients {cs.name} run in the {able} structures, not "
                             f"{spec.structure}")

    def coefficient_set(self, spec: AlgorithmSpec) -> CoefficientSet:
        """The configured coefficient set (what the C exporter and the filter need)."""
        return coefficient_set(coning_set_name(spec.resolved_coefficients), spec.subsamples)

    def min_samples(self, spec: AlgorithmSpec) -> int:
        return spec.update_structure.min_increments(spec.subsamples)

    def update_period(self, spec: AlgorithmSpec, h: float) -> float:
        return spec.update_structure.update_period(spec.subsamples, h)

    def drift_law(self, spec: AlgorithmSpec) -> DriftLaw | None:
        cs = self.coefficient_set(spec)
        if not cs.classical_optimum:
            return None
        return DriftLaw(2 * cs.n, table1_drift_constant(cs.n))

    def run(self, spec: AlgorithmSpec, data: ArrayLike, *, h: float, t: ArrayLike | None = None,
            t0: float = 0.0, q0: ArrayLike | None = None) -> AttitudeSolution:
        return increment_structure(spec.structure).run(data, self.coefficient_set(spec), h=h,
                                                       t0=t0, q0=q0)

    def run_mp(self, spec: AlgorithmSpec, motion: Motion, *, h: float, samples: int,
               digits: int) -> MpSolution:
        from strapdown.algorithms.precision import run_mp

        return run_mp(motion, self.coefficient_set(spec),
                      structure=increment_structure(spec.structure), h=h, samples=samples,
                      digits=digits)

    def candidates(self) -> tuple[AlgorithmSpec, ...]:
        """Every N in every structure with the default set, then the finite-amplitude sets
        (N ≥ 2) in the structures that run triple terms."""
        from strapdown.algorithms.spec import AlgorithmSpec

        name: Any = self.name
        out = [AlgorithmSpec(name, subsamples=n, structure=s)
               for n in range(1, MAX_SUBSAMPLES + 1) for s in self.structures]
        triple = [s for s in self.structures if not structure(s).pair_only]
        out += [AlgorithmSpec(name, subsamples=n, structure=s,
                              coefficients="finite-amplitude")
                for n in range(2, MAX_SUBSAMPLES + 1) for s in triple]
        return tuple(out)

    def amplitude_cubed(self, spec: AlgorithmSpec) -> bool:
        """The default (Table 3) sets at N ≥ 4 outside the single chain (reproduce
        high-order)."""
        return (spec.subsamples >= 4 and spec.coefficients is None
                and not spec.update_structure.own_startup)

    def propagation(self, spec: AlgorithmSpec) -> dict[str, Any]:
        import numpy as np

        if not spec.update_structure.whole_updates:  # the filter steps once per whole update
            raise ValueError("the filter runs rotvec in the conventional structure")
        if self.coefficient_set(spec).triples:
            raise ValueError("the filter runs pair-only coefficient sets, not "
                             f"{spec.resolved_coefficients!r} (triple cross products)")
        n = spec.subsamples
        cs = self.coefficient_set(spec)
        ii, jj = np.nonzero(cs.matrix)
        return dict(is_rate=False, offsets=np.arange(n, dtype=np.int64), weights=np.ones(n),
                    pi=ii.astype(np.int64), pj=jj.astype(np.int64), pc=cs.matrix[ii, jj],
                    stride=n, span=n - 1, end_off=n, lag=1, start_c=0.0, rk4=False)


#: The families this module defines, in registry order.
FAMILIES: tuple[Family, ...] = (Rotvec(),)
