"""Coefficient designer: published sets, predicted vs simulated drift, rate-input order."""

from __future__ import annotations

import math
import time
from fractions import Fraction as F

import numpy as np
import pytest

from strapdown.algorithms.coning import TABLE3, coefficient_set
from strapdown.algorithms.precision import run_windowed_mp
from strapdown.analysis import drift_rate
from strapdown.design import designer as D
from strapdown.truth.motions import ClassicalConing

OMEGA = 2 * math.pi


def test_two_thirds_and_table3():
    assert D.derive(D.interval_structure(2)).coefficients == (F(2, 3),)
    for n, c in zip(range(2, 6), [F(1, 60), F(1, 280), F(1, 1260), F(1, 5544)], strict=True):
        d = D.derive(D.interval_structure(n, "cross-with-last"))
        assert d.coefficients == TABLE3[n]
        assert d.drift_constant == c and d.order == 2 * n


def test_miller_from_polynomial_target():
    d = D.derive(D.interval_structure(3, "all-pairs"), target="polynomial")
    assert dict(zip(d.terms, d.coefficients, strict=True)) == {
        "θ1×θ2": F(57, 80), "θ1×θ3": F(33, 80), "θ2×θ3": F(57, 80)}
    # and its classical-coning drift is +a²Ω(ΩT)⁴/6480 = +a²Ω(Ωh)⁴/80
    assert (d.order, d.drift_constant) == (4, F(-1, 80))


def test_polynomial_target_two_samples_is_two_thirds():
    assert D.derive(D.interval_structure(2, "all-pairs"), target="polynomial").coefficients == (
        F(2, 3),)


def test_lag_form_and_all_pairs_keep_the_lag_sums():
    for layout in ("lag", "all-pairs"):
        d = D.derive(D.interval_structure(4, layout))
        cs = d.coefficient_set()
        assert np.allclose(cs.lag_sums(), coefficient_set("table3", 4).lag_sums(), rtol=1e-15)
        assert d.drift_constant == F(1, 1260)


def test_rules_differ_only_beyond_the_leading_term():
    st = D.interval_structure(4, "all-pairs")
    a = D.derive(st, rule="polynomial")
    b = D.derive(st, rule="min-norm")
    assert a.coefficients != b.coefficients
    assert (a.order, a.drift_constant) == (b.order, b.drift_constant)


def test_single_chain_coefficients_relate_to_lag_sums():
    for n in range(2, 7):
        d = D.derive(D.single_chain_structure(n))
        k = TABLE3[n]
        assert d.coefficients == tuple((k[m - 1] - F(n - m, 2)) / n for m in range(1, n))
        assert d.drift_constant == D.derive(D.interval_structure(n)).drift_constant


def test_rate_three_period_true_order():
    st = D.three_period_structure()
    naive = D.derive(st, quadrature=False)
    assert naive.order == 8  # what a β-only fit claims
    assert D.classical_coning_drift(st, naive.coefficients) == (4, F(-1, 80))
    right = D.derive(st)
    assert right.order == 8


def _measure(design_or_alg, spp, a, digits=60, periods=2):
    m = ClassicalConing(a, OMEGA)
    h = m.period / spp
    alg = design_or_alg.algorithm()
    s = run_windowed_mp(m, alg, h=h, updates=periods * spp // alg.update, digits=digits)
    return drift_rate(s.t, s.err[:, 0], period=m.period).rate, h


CASES = (
    [(D.interval_structure(n), "coning") for n in (2, 3, 4, 5)]
    + [(D.interval_structure(3, "all-pairs"), "polynomial"), (D.interval_structure(4, "lag"),
                                                               "coning")]
    + [(D.single_chain_structure(n), "coning") for n in (2, 3, 4, 5)]
    + [(D.uncompressed_structure(2, 2), "coning"), (D.uncompressed_structure(3, 1), "coning")]
    + [(D.three_period_structure(), "coning"), (D.rate_structure(1), "coning"),
       (D.rate_structure(2), "coning")]
)


@pytest.mark.parametrize(("structure", "target"), CASES, ids=lambda c: getattr(c, "name", c))
def test_predicted_drift_matches_simulation(structure, target):
    d = D.derive(structure, target=target)
    for spp in (120, 60):
        meas, h = _measure(d, spp, 1e-9)
        pred = d.predicted_drift(1e-9, OMEGA, h)
        assert abs(meas / pred - 1) <= 0.02, (spp, meas / pred)


def test_ignoring_quadrature_order_confirmed_by_simulation():
    st = D.three_period_structure()
    naive = D.derive(st, quadrature=False)
    xs, ds = [], []
    for spp in (480, 240, 120, 60):
        meas, h = _measure(naive, spp, 1e-6)
        xs.append(OMEGA * h)
        ds.append(abs(meas))
    slope = np.polyfit(np.log(xs), np.log(ds), 1)[0]
    assert abs(slope - 4) <= 0.05


def test_derivation_is_fast_and_cached():
    D._derive.cache_clear()
    t0 = time.perf_counter()
    for n in range(1, 7):
        for st in (D.interval_structure(n, "all-pairs"), D.single_chain_structure(n),
                   D.uncompressed_structure(n, n), D.rate_structure(n)):
            D.derive(st)
    first = time.perf_counter() - t0
    assert first < 60.0
    info = D._derive.cache_info()
    D.derive(D.rate_structure(6))
    assert D._derive.cache_info().hits == info.hits + 1


def test_json_record():
    rec = D.derive(D.interval_structure(3)).to_dict()
    assert rec["coefficients"] == ["27/20", "9/20"]
    assert rec["terms"] == ["θ2×θ3", "θ1×θ3"]
    assert rec["drift_constant"] == "1/280" and rec["order"] == 6


def test_newton_cotes():
    assert D.newton_cotes_weights([0, 1, 2, 3], 3) == (F(3, 8), F(9, 8), F(9, 8), F(3, 8))


@pytest.mark.parametrize(
    ("call", "msg"),
    [
        (lambda: D.derive(D.interval_structure(2), target="x"), "unknown target"),
        (lambda: D.derive(D.interval_structure(2), rule="x"), "unknown rule"),
        (lambda: D.derive("table3"), "must be a Structure"),
        (lambda: D.interval_structure(0), "positive integer"),
        (lambda: D.interval_structure(3, "diagonal"), "unknown layout"),
        (lambda: D.uncompressed_structure(2, -1), "non-negative"),
        (lambda: D.structure_by_name("nope", 2), "unknown form"),
        (lambda: D.classical_coning_drift(D.interval_structure(3), [1]), "2 coefficients"),
        (lambda: D.derive(D.single_chain_structure(3)).coefficient_set(), "within-interval"),
    ],
)
def test_bad_input(call, msg):
    with pytest.raises(ValueError, match=msg):
        call()


def test_rate_input_at_arbitrary_nodes_matches_simulation():
    # non-uniform nodes need a motion sampled off the grid: check the series against the
    # general mp runner on the grid case built from the same nodes scaled to integers
    st = D.rate_structure(2, nodes=[0, 1, 2])
    d = D.derive(st)
    assert d.structure.weights == (F(1, 3), F(4, 3), F(1, 3))
    odd = D.derive(D.rate_structure(2, nodes=[0, F(1, 2), 2]))
    assert odd.order is not None and odd.structure.weights[1] != F(4, 3)
    prev = D.derive(D.rate_structure(1, nodes=[-1, 0, 1]))  # one sample of history
    meas, h = _measure(prev, 60, 1e-9)
    assert abs(meas / prev.predicted_drift(1e-9, OMEGA, h) - 1) <= 0.02
    with pytest.raises(ValueError, match="increasing"):
        D.rate_structure(2, nodes=[0, 2, 1])
