"""Finite-amplitude coning sets: pair terms plus triple cross products, tabulated exactly.

``φ = Σθ + Σ_m ς_m θ_{N−m} × θ_N + Σ_m τ_m θ_N × (θ_{N−m} × θ_N)`` (conventional: the
pairs are Li & Zhang (2017) Table 3 read as cross-with-last) and
``φ_k = θ_k + Σ_m c_m θ_{k−m} × θ_k + Σ_m τ_m θ_k × (θ_{k−m} × θ_k)`` (single chain: the
pairs are :data:`strapdown.algorithms.tables.SINGLE_CHAIN`), m = 1 … N−1. The τ_m come
from :func:`strapdown.design.finite_amplitude.derive_triple` (exact rational arithmetic;
re-derived by the test suite): they cancel the ``a⁴`` classical-coning drift through the
order of the ``a²`` law, so the drift is ``−c₂ a²Ω(Ωh)^{2N} − c₄ a⁴Ω(Ωh)^{2N+2} −
c₆ a⁶Ω(Ωh)^6 − …`` with the constants of :data:`AMPLITUDE_LAW`. Selected as
``--coefficients finite-amplitude`` (``rotvec``, structures conventional and single-chain).
"""

from __future__ import annotations

from fractions import Fraction as F
from typing import Literal

__all__ = ["AMPLITUDE_LAW", "TRIPLE", "TripleStructure", "triple_terms"]

#: The structures the finite-amplitude sets are designed for.
TripleStructure = Literal["conventional", "single-chain"]

#: τ_1 … τ_{N−1}, multiplying θ_L × (θ_{L−m} × θ_L) (θ_L = θ_N, or θ_k in the single chain).
TRIPLE: dict[TripleStructure, dict[int, tuple[F, ...]]] = {
    "conventional": {
        1: (),
        2: (F(-2, 15),),
        3: (F(1143, 2440), F(-903, 2440)),
        4: (F(2834959, 483840), F(-546271, 120960), F(238619, 290304)),
        5: (F(59762259161075, 1975232660016), F(-81649385897725, 2962848990024),
            F(58101159894025, 5925697980048), F(-872965312325, 564352188576)),
        6: (F(68613375609779743, 837531010516200), F(-367170473326178141, 4815803310468150),
            F(388115605941166401, 12842142161248400), F(-29819243430728201, 4815803310468150),
            F(62420142887648291, 192632132418726000)),
    },
    "single-chain": {
        1: (),
        2: (F(1, 40),),
        3: (F(19, 1080), F(-1, 270)),
        4: (F(29, 2520), F(-13, 3150), F(7, 8100)),
        5: (F(5287, 748440), F(-1867, 534600), F(673, 467775), F(-611, 2993760)),
        6: (F(81251, 21621600), F(-436759, 170270100), F(4610269, 2724321600),
            F(-914327, 2043241200), F(1977439, 40864824000)),
    },
}

#: Leading term of each power of a: (p, q, c) with drift ``= −Σ c a^p Ω (Ωh)^q`` about the
#: cone axis (classical coning, h the sample interval), for N = 2 … 6.
AMPLITUDE_LAW: dict[TripleStructure, dict[int, tuple[tuple[int, int, F], ...]]] = {
    "conventional": {
        2: ((2, 4, F(1, 60)), (4, 6, F(1, 360)), (6, 4, F(-17, 10800))),
        3: ((2, 6, F(1, 280)), (4, 8, F(143969, 1317600)), (6, 6, F(-12059851, 600122880))),
        4: ((2, 8, F(1, 1260)), (4, 10, F(5940218243, 10729635840)),
            (6, 6, F(-16877674969, 208089907200))),
        5: ((2, 10, F(1, 5544)), (4, 12, F(27937763340724483, 25883448776849664)),
            (6, 6, F(-1637344919771441106614945, 8778474137686236851520576))),
        6: ((2, 12, F(1, 24024)), (4, 14, F(-941606500467706840727, 355984180709805648000)),
            (6, 6, F(-312119645979433669057843111, 784174523249906770562034300))),
    },
    "single-chain": {
        2: ((2, 4, F(1, 60)), (4, 6, F(1, 1440)), (6, 4, F(-17, 10800))),
        3: ((2, 6, F(1, 280)), (4, 8, F(17, 129600)), (6, 6, F(-42079, 65318400))),
        4: ((2, 8, F(1, 1260)), (4, 10, F(313, 11975040)), (6, 6, F(-266813, 1428840000))),
        5: ((2, 10, F(1, 5544)), (4, 12, F(889061, 163459296000)),
            (6, 6, F(-563065873, 4001160240000))),
        6: ((2, 12, F(1, 24024)), (4, 14, F(1145611, 980755776000)),
            (6, 6, F(-79875249873409, 681605649204480000))),
    },
}


def triple_terms(structure: TripleStructure, n: int) -> tuple[tuple[int, int, int, F], ...]:
    """``(m, i, j, τ)`` per triple term ``x_m × (x_i × x_j)`` over the window of N increments
    (index N−1 the last: θ_N, or θ_k in the single chain)."""
    if structure not in TRIPLE:
        raise ValueError(f"finite-amplitude sets exist for the structures "
                         f"{', '.join(TRIPLE)}, not {structure!r}")
    if n not in TRIPLE[structure]:
        raise ValueError(f"finite-amplitude sets are tabulated for N = 1 … 6, got N = {n}")
    last = n - 1
    return tuple((last, last - m, last, t) for m, t in enumerate(TRIPLE[structure][n], start=1))
