"""Finite-amplitude coefficient sets (triple cross products): tables, kernels, arbitrary
precision against the exact double series, and the places that refuse them."""

from __future__ import annotations

import math
from dataclasses import replace
from fractions import Fraction as F

import numpy as np
import pytest

from strapdown._core.backend import NUMPY
from strapdown.algorithms import _reference
from strapdown.algorithms.coning import coefficient_set, rotation_vectors
from strapdown.algorithms.finite_amplitude import (
    A6_DESIGN,
    AMPLITUDE_LAW,
    TRIPLE,
    triple_terms,
)
from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.algorithms.streaming import RotvecStream
from strapdown.algorithms.structures import (
    conventional,
    single_chain,
    single_chain_coefficients,
    single_chain_table,
)
from strapdown.analysis.coning_drift import CONE_RATE, drift_mp
from strapdown.design import designer as D
from strapdown.design import finite_amplitude as FA

MAKE = {"conventional": D.interval_structure, "single-chain": D.single_chain_structure}


def _design(structure, n):
    """The structure and design the table's entry comes from (A6_DESIGN: the a⁶ designs)."""
    if structure == "conventional" and n in A6_DESIGN:
        st = FA.with_a6_triples(D.interval_structure(n), through_law=A6_DESIGN[n])
        return st, FA.derive_triple_a6(st)
    st = FA.with_last_triples(MAKE[structure](n))
    return st, FA.derive_triple(st)


@pytest.mark.parametrize("structure", list(MAKE))
def test_tables_are_the_designers(structure):
    for n in range(2, 7):
        st, d = _design(structure, n)
        assert TRIPLE[structure][n] == tuple((m, i, j, t) for (m, i, j), t
                                             in zip(st.triples, d.triple_coefficients,
                                                    strict=True))
        law = AMPLITUDE_LAW[structure][n]
        assert law[:len(d.amplitude_law)] == d.amplitude_law
        assert len(law) == len(d.amplitude_law) + (structure == "conventional" and n == 6)


@pytest.mark.parametrize("n", sorted(A6_DESIGN))
def test_a6_tables_meet_their_conditions(n):
    """The tabulated a⁶ sets themselves: a² drift that of the pair set, a⁴ zero through
    (Ωh)^{2N+2} exactly, the cancelled a⁶ terms below 1e-20 (N = 6: and its a⁸ law term)."""
    st, _ = _design("conventional", n)
    pairs = D.derive(replace(st, triples=()))
    tau = [t for *_, t in TRIPLE["conventional"][n]]
    ser = FA.drift_series(st, pairs.coefficients, tau, x_order=2 * n + 2,
                          a_order=8 if n == 6 else 6)
    assert ser[2] == FA.drift_series(st, pairs.coefficients, [F(0)] * len(tau),
                                     x_order=2 * n + 2, a_order=2)[2]
    assert not any(ser[4])
    cancelled = range(6, 2 * n + 1 if A6_DESIGN[n] else 2 * n - 1, 2)  # x⁶ … (N−3 or N−2)
    assert all(abs(ser[6][q]) < 1e-20 for q in cancelled)
    assert max(abs(t) for t in tau) < 35  # 4.27, 16.4, 34.5 for N = 4, 5, 6
    if n == 6:
        assert (8, 8, -ser[8][8]) == AMPLITUDE_LAW["conventional"][6][-1]
        assert float(ser[8][8]) == pytest.approx(0.3737, abs=1e-4)


def _theta(n, seed):
    return np.random.default_rng(seed).normal(size=(n, 3)) * 0.05


@pytest.mark.parametrize("n", [2, 4, 6])
def test_conventional_kernel_matches_reference(n):
    cs = coefficient_set("finite-amplitude", n)
    theta = _theta(n * 50, n)
    sol = conventional(theta, cs, h=1e-3)
    th = [tuple(map(float, r)) for r in theta]
    tri = [(m, i, j, float(c)) for m, i, j, c in cs.triples]
    ref = np.array(_reference.conventional_triple(th, cs.matrix.tolist(), tri, (1.0, 0, 0, 0),
                                                  NUMPY), dtype=float)
    assert np.max(np.abs(sol.q - ref)) <= 2e-14
    # and the triple terms are there: the vectorised rotation vectors of the same set
    phi = rotation_vectors(theta, cs)
    plain = rotation_vectors(theta, coefficient_set("table3", n))
    assert np.max(np.abs(phi - plain)) > 1e-6


@pytest.mark.parametrize("n", [2, 3, 5])
def test_single_chain_kernel_matches_reference(n):
    theta = _theta(200, 10 + n)
    sol = single_chain(theta, n, h=1e-3, triple=True)
    th = [tuple(map(float, r)) for r in theta]
    s = n - 1
    # start-up: the plain single chain; then the steady reference with triple terms
    head = single_chain(theta[:s], n, h=1e-3).q if s else np.array([[1.0, 0, 0, 0]])
    c = [float(v) for v in single_chain_coefficients(n)]
    tri = [(m, i, j, float(t)) for m, i, j, t in triple_terms("single-chain", n)]
    ref = np.array(_reference.single_chain_triple(th, c, tri, s, tuple(head[-1]), NUMPY))
    assert np.array_equal(sol.q[:s + 1], head)
    assert np.max(np.abs(sol.q[s:] - ref)) <= 2e-14
    assert np.max(np.abs(sol.q - single_chain(theta, n, h=1e-3).q)) > 1e-9
    assert single_chain_table(n).shape == (n, max(n - 1, 1))


def _series_drift(structure, n, a, spp):
    st, d = _design(structure, n)
    ser = FA.drift_series(st, d.coefficients, d.triple_coefficients, x_order=2 * n + 12)
    x = 2 * math.pi / spp
    return CONE_RATE * sum(float(v) * a**p * x**q for p, row in ser.items()
                           for q, v in enumerate(row))


@pytest.mark.parametrize("structure", list(MAKE))
def test_arbitrary_precision_drift_is_the_series_and_beats_the_plain_set(structure):
    a, spp, n = math.radians(2.0), 60, 4
    got = drift_mp(a, spp, n, structure, "finite-amplitude", digits=40)
    assert got == pytest.approx(_series_drift(structure, n, a, spp), rel=1e-4)
    plain = drift_mp(a, spp, n, structure, "table3", digits=40)
    assert abs(plain) > 7 * abs(got)
    law = AlgorithmSpec(subsamples=n, coefficients="finite-amplitude",
                        structure=structure).drift_law()
    assert law is not None and law.constant == F(1, 1260)
    # a² law: −c a²Ω(Ωh)^8 within 5 % (a⁴ cancelled through x^8; a⁶x⁶ gives 1.4 %)
    assert got / law.predict(a, CONE_RATE, 1 / spp) == pytest.approx(1, abs=0.05)


def test_where_triple_terms_are_refused():
    with pytest.raises(ValueError, match="not realtime"):
        AlgorithmSpec.parse("rotvec:N=3:coefficients=finite-amplitude:structure=realtime")
    cs = coefficient_set("finite-amplitude", 3)
    with pytest.raises(ValueError, match="triple"):
        RotvecStream("realtime", cs, h=1e-3)
    spec = AlgorithmSpec.parse("rotvec:N=3:coefficients=finite-amplitude")
    with pytest.raises(ValueError, match="pair-only"):
        spec.propagation()
    from strapdown.codegen.export_c import generate

    with pytest.raises(ValueError, match="not realtime"):  # exported conventional/single chain
        generate("rotvec", structure="realtime", subsamples=3, coefficients="finite-amplitude")


@pytest.mark.parametrize("structure", list(MAKE))
@pytest.mark.parametrize("n", [1, 3, 5])
def test_streaming_is_the_one_shot_run_bit_for_bit(structure, n):
    from strapdown.algorithms.structures import run_structure

    cs = coefficient_set("finite-amplitude", n)
    theta = _theta(n * 41, 30 + n)
    whole = run_structure(structure, theta, cs, h=1e-3)
    s = RotvecStream(structure, cs, h=1e-3)
    rng = np.random.default_rng(n)
    cuts = np.sort(rng.choice(np.arange(1, theta.shape[0]), size=9, replace=False))
    parts = [s.feed(c).q for c in np.split(theta, cuts)]
    assert np.array_equal(np.concatenate(parts), whole.q)
