"""Designed coefficient sets the algorithms run with, tabulated as exact rationals.

Every entry was derived by :func:`strapdown.design.derive` (exact rational arithmetic,
sympy) and is re-derived by the test suite (``tests/algorithms/test_tables.py``), so the
algorithms need no computer algebra at run time.

Drift laws are for classical coning (half angle ``a``, cone rate ``Ω``, sample interval
``h``): ``drift = −c · a² Ω (Ω h)^order`` about the cone axis, leading order in ``a``.
"""

from __future__ import annotations

from fractions import Fraction as F

from strapdown.algorithms.coning import TABLE3
from strapdown.algorithms.family import RateCoefficients, Rk4Step

__all__ = [
    "CONING_FORCE_DRIFT",
    "RATE_SINGLE",
    "RATE_SINGLE_DRIFT",
    "RATE_THREE",
    "RATE_THREE_DRIFT",
    "RK4_DRIFT",
    "SCULLING_CONING_FORCE",
    "SCULLING_CONVENTIONAL",
    "SCULLING_DRIFT",
    "SCULLING_SINGLE_CHAIN",
    "SINGLE_CHAIN",
]

#: Single-chain coefficients c_1 … c_{N−1} (``single_chain_structure(N)``, classical-coning
#: optimum), for N = 1 … 6.
SINGLE_CHAIN: dict[int, tuple[F, ...]] = {
    1: (),
    2: (F(1, 12),),
    3: (F(7, 60), F(-1, 60)),
    4: (F(113, 840), F(-13, 420), F(1, 280)),
    5: (F(367, 2520), F(-53, 1260), F(1, 120), F(-1, 1260)),
    6: (F(4247, 27720), F(-703, 13860), F(61, 4620), F(-31, 13860), F(1, 5544)),
}

#: Single-period rate algorithm ΔΦ = td/2 (ω₀ + ω₁) + c td² ω₀ × ω₁: the cross-product
#: coefficient c. ``derived``: ``derive(rate_structure(1))`` (quadrature error included);
#: ``paper``: Wang, Wang & Wang's start-up form.
RATE_SINGLE: dict[RateCoefficients, F] = {"derived": F(1, 6), "paper": F(1, 12)}
RATE_SINGLE_DRIFT: dict[RateCoefficients, tuple[int, F]] = {"derived": (4, F(11, 1440)),
                                                             "paper": (2, F(1, 12))}

#: Three-period rate algorithm on ω at 0, td, 2td, 3td: pair coefficients k_ij (in units of
#: td²) for the pairs (0,1), (0,2), (0,3), (1,2), (1,3), (2,3); the quadrature weights are
#: Simpson's 3/8 rule, (3/8, 9/8, 9/8, 3/8) td. ``derived``: ``derive(three_period_structure())``
#: (quadrature error included); ``paper``: the lag sums fitted to the coning term alone
#: (``quadrature=False``), Wang, Wang & Wang's derivation as reconstructed.
RATE_THREE_PAIRS: tuple[tuple[int, int], ...] = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))
RATE_THREE_WEIGHTS: tuple[F, ...] = (F(3, 8), F(9, 8), F(9, 8), F(3, 8))
RATE_THREE: dict[RateCoefficients, tuple[F, ...]] = {
    "derived": (F(719, 1680), F(103, 560), F(43, 560), F(719, 1680), F(103, 560), F(719, 1680)),
    "paper": (F(873, 2240), F(27, 112), F(87, 2240), F(873, 2240), F(27, 112), F(873, 2240)),
}
RATE_THREE_DRIFT: dict[RateCoefficients, tuple[int, F]] = {"derived": (8, F(433, 806400)),
                                                            "paper": (4, F(-1, 80))}

#: Quaternion RK4 on q̇ = ½ q ⊗ ω: (order, c) per step variant, derived symbolically by
#: :func:`strapdown.design.rk4_classical_coning_drift`.
RK4_DRIFT: dict[Rk4Step, tuple[int, F]] = {"2td": (4, F(-1, 60)), "td-interp": (2, F(1, 12))}

#: Sculling compensation of the conventional structure, ``Σ_m ς_m (θ_{N−m} × v_N +
#: v_{N−m} × θ_N)``: ς_1 … ς_{N−1} (lag m = 1, 2, …) from
#: ``derive(interval_structure(N), target="sculling")``, for N = 1 … 6. They equal the
#: classical-coning optimum of the same structure, Li & Zhang (2017) Table 3 (Ignagni's
#: duality, Ignagni (1998)).
SCULLING_CONVENTIONAL: dict[int, tuple[F, ...]] = TABLE3  # the duality: the same numbers

#: Sculling compensation of the single chain, ``Σ_m c_m (θ_{k−m} × v_k + v_{k−m} × θ_k)``:
#: c_1 … c_{N−1} from ``derive(single_chain_structure(N), target="sculling")`` (equal to
#: :data:`SINGLE_CHAIN`).
SCULLING_SINGLE_CHAIN: dict[int, tuple[F, ...]] = SINGLE_CHAIN  # the duality

#: Classical-sculling law of both structures with these sets: (order, c) with the rectified
#: velocity error rate ``−c · θ0 A cos ψ (Ωh)^order`` along the axis normal to the angular
#: and linear vibration (leading order in θ0; ``h`` the sample interval). The coning
#: drift constants of Li & Zhang (2017) Table 1, ``N!(N+1)!/(2N+2)!``.
SCULLING_DRIFT: dict[int, tuple[int, F]] = {
    1: (2, F(1, 12)),
    2: (4, F(1, 60)),
    3: (6, F(1, 280)),
    4: (8, F(1, 1260)),
    5: (10, F(1, 5544)),
    6: (12, F(1, 24024)),
}


#: Velocity pairs of the conventional structure that hold on a coning body in a constant
#: specific force as well as under classical sculling: ``Σ_{i<j} k_ij (θ_i × v_j + v_i ×
#: θ_j)`` over *all* pairs of the N subsamples, in the order (0, 1), (0, 2), …, (0, N−1),
#: (1, 2), …, (N−2, N−1) (0-based), from ``derive(interval_structure(N, "all-pairs"),
#: target="coning-force", rule="min-norm")``. Their lag sums are the classical set's
#: (:data:`SCULLING_CONVENTIONAL`), so the classical-sculling law is unchanged; N = 1, 2 are the
#: classical sets.
SCULLING_CONING_FORCE: dict[int, tuple[F, ...]] = {
    1: (),
    2: (F(2, 3),),
    3: (F(31, 20), F(9, 20), F(-1, 5)),
    4: (F(236, 105), F(26, 21), F(18, 35), F(-6, 7), F(-38, 105), F(68, 105)),
    5: (F(165, 56), F(1405, 1008), F(205, 112), F(125, 252), F(-1265, 1008), F(-425, 504),
        F(-265, 336), F(715, 1008), F(745, 1008), F(55, 168)),
    6: (F(5589, 1540), F(29597, 18480), F(41159, 18480), F(449, 220), F(463, 924),
        F(-599, 336), F(-16789, 18480), F(-13697, 9240), F(-4871, 4620), F(3447, 3080),
        F(14671, 18480), F(15419, 18480), F(-9, 112), F(551, 2640), F(2467, 4620)),
}

#: Coning-in-constant-force law, (order, c) per N, with the rectified velocity error rate
#: along the cone axis ``−c · a² f (Ωh)^order`` (half angle ``a``, cone rate ``Ω``, force
#: ``f`` along the cone axis; leading order in ``a``), from
#: :func:`strapdown.design.velocity_error_laws`, per (structure, velocity set). The classical
#: sets stop at order 4 for every N ≥ 2: their pair coefficients are all fixed by the
#: sculling conditions.
CONING_FORCE_DRIFT: dict[tuple[str, str], dict[int, tuple[int, F]]] = {
    ("conventional", "coning-force"): {
        1: (2, F(1, 12)), 2: (4, F(-1, 20)), 3: (6, F(-29, 840)), 4: (8, F(-19, 1260)),
        5: (10, F(-31, 5544)), 6: (12, F(-137, 72072))},
    ("conventional", "classical"): {
        1: (2, F(1, 12)), 2: (4, F(-1, 20)), 3: (4, F(-31, 40)), 4: (4, F(-59, 20)),
        5: (4, F(-2665, 336)), 6: (4, F(-1049, 60))},
    ("single-chain", "classical"): {
        1: (2, F(1, 12)), 2: (4, F(1, 30)), 3: (4, F(1, 120)), 4: (4, F(11, 1680)),
        5: (4, F(29, 5040)), 6: (4, F(7, 1320))},
}
