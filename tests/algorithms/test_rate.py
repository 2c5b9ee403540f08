"""Rate-input algorithms: kernels vs reference, drift orders, sliding scheme, validation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown._core.backend import NUMPY
from strapdown.algorithms import _reference, rate
from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.analysis.evaluate import EvaluationConfig, evaluate
from strapdown.design import rk4_classical_coning_drift
from strapdown.truth.motions import SpinConing

A_SMALL_DEG = math.degrees(1e-9)


def _mp_drift(algorithm, structure="conventional", coefficients=None, spp=60, rk4_step="2td"):
    cfg = EvaluationConfig.of(algorithm=algorithm, structure=structure, coefficients=coefficients,
                              half_angle_deg=A_SMALL_DEG, cone_rate_hz=1.0, sample_rate_hz=spp,
                              duration=2.0, precision=80, rk4_step=rk4_step)
    r = evaluate(cfg)
    return r.cone_axis_drift, r.predicted


CASES = [
    ("rate-single", "conventional", "paper", "2td", 2),
    ("rate-single", "conventional", None, "2td", 4),
    ("rate-three", "conventional", "paper", "2td", 4),
    ("rate-three", "conventional", None, "2td", 8),
    ("rate-three", "sliding", None, "2td", 8),
    ("rk4", "conventional", None, "2td", 4),
    ("rk4", "conventional", None, "td-interp", 2),
]


@pytest.mark.parametrize(("alg", "structure", "coeffs", "step", "order"), CASES)
def test_measured_order_matches_derived_order(alg, structure, coeffs, step, order):
    law_order = AlgorithmSpec(alg, coefficients=coeffs, rk4_step=step).drift_law().order
    assert law_order == order
    xs, ds, ratios = [], [], []
    for spp in (600, 240, 120, 60):  # Ωtd from 0.0105 to 0.105: a decade
        d, pred = _mp_drift(alg, structure, coeffs, spp, step)
        xs.append(2 * math.pi / spp)
        ds.append(abs(d))
        ratios.append(d / pred)
    slope = np.polyfit(np.log(xs), np.log(ds), 1)[0]
    assert abs(slope - order) <= 0.2
    assert all(abs(r - 1) <= 0.02 for r in ratios), ratios


def test_rk4_orders_derived_symbolically():
    assert rk4_classical_coning_drift("2td") == rate.RK4_DRIFT["2td"]
    assert rk4_classical_coning_drift("td-interp") == rate.RK4_DRIFT["td-interp"]


@pytest.mark.parametrize("precision", [None, 60])
def test_sliding_drift_equals_three_period(precision):
    base = dict(algorithm="rate-three", half_angle_deg=1.0, cone_rate_hz=1.0,
                sample_rate_hz=120.0, duration=6.0 if precision is None else 2.0,
                precision=precision)
    conv = evaluate(EvaluationConfig.of(structure="conventional", **base)).cone_axis_drift
    sl = evaluate(EvaluationConfig.of(structure="sliding", **base))
    assert sl.update_period == pytest.approx(1 / 120)
    assert sl.chain.max() == 2
    assert abs(sl.cone_axis_drift / conv - 1) <= 1e-6


def _omega(n=40, seed=0):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, 3)) * 2.0


@pytest.mark.parametrize("mode", [0, 1])
def test_rk4_kernel_matches_reference(mode):
    w = _omega(41)
    t = np.arange(41) * 1e-2
    sol = rate.rate_attitude(t, w, algorithm="rk4", rk4_step="2td" if mode == 0 else "td-interp")
    ref = np.array(_reference.rk4([tuple(r) for r in w], 1e-2, (1.0, 0.0, 0.0, 0.0), mode,
                                  NUMPY))
    assert sol.q.shape == ref.shape
    assert np.max(np.abs(sol.q - ref)) <= 1e-14


def test_sliding_matches_plain_reference():
    w = _omega(30, seed=2)
    t = np.arange(30) * 1e-2
    sol = rate.rate_attitude(t, w, algorithm="rate-three", structure="sliding")
    three = rate.three_period_algorithm()
    single = rate.single_period_algorithm()

    def phi(alg, b):
        ws = [1e-2 * float(x) for x in alg.weights]
        pairs = [(i, j, 1e-4 * float(c)) for (i, j), c in
                 zip(alg.pairs, alg.pair_coefficients, strict=True)]
        return _reference.windowed_rotvec([tuple(w[b + o]) for o in alg.offsets], ws, pairs, 0.0)

    first = _reference.chain([phi(single, 0), phi(single, 1)], [(1.0, 0.0, 0.0, 0.0)], 1, NUMPY)
    q = _reference.chain([phi(three, b) for b in range(27)], first, 3, NUMPY)
    assert np.max(np.abs(sol.q - np.array(q))) <= 1e-14


def test_spin_coning_rates_run_every_algorithm():
    m = SpinConing(0.02, 2 * math.pi, 20.0)
    t = np.arange(601) / 600
    w = m.rate(t)
    for alg, st in (("rate-single", "conventional"), ("rate-three", "sliding"),
                    ("rk4", "conventional")):
        sol = rate.rate_attitude(t, w, algorithm=alg, structure=st, q0=m.attitude(0.0))
        from strapdown.analysis import attitude_errors

        _, ang = attitude_errors(sol.t, sol.q, m)
        assert ang.max() < 1e-5


Z4 = np.zeros((4, 3))


@pytest.mark.parametrize(
    ("t", "w", "kw", "msg"),
    [
        (np.array([0.0, 0.1, 0.1, 0.3]), Z4, {}, "duplicated time stamp at row 2"),
        (np.array([0.0, 0.1, 0.05, 0.3]), Z4, {}, "non-monotonic time stamp at row 2"),
        (np.array([0.0, 0.1, 0.2, 0.35, 0.45]), np.zeros((5, 3)), {},
         "non-uniform sampling between samples 3 and 4"),
        (np.arange(4) * 0.1, np.array([[0, 0, 0], [0, np.nan, 0], [0, 0, 0], [0, 0, 0]]), {},
         "NaN or infinity at row 1"),
        (np.arange(3) * 0.1, np.zeros((3, 3)), {}, "needs at least 4"),
        (np.arange(4) * 0.1, np.zeros((4, 2)), {}, r"shape \(4, 3\)"),
        (np.arange(4) * 0.1, Z4, {"structure": "realtime"}, "supports the structures"),
        (np.arange(4) * 0.1, Z4, {"coefficients": "table3"}, "derived or paper"),
    ],
)
def test_rate_record_validation(t, w, kw, msg):
    with pytest.raises(ValueError, match=msg):
        rate.rate_attitude(t, w, algorithm="rate-three", **kw)


def test_evaluate_rate_validation():
    with pytest.raises(ValueError, match="rk4 has no coefficients"):
        evaluate(EvaluationConfig.of(algorithm="rk4", coefficients="paper"))
    with pytest.raises(ValueError, match="supports the structures"):
        evaluate(EvaluationConfig.of(algorithm="rate-single", structure="sliding"))
    with pytest.raises(ValueError, match="takes coefficients"):
        evaluate(EvaluationConfig.of(algorithm="rate-three", coefficients="table3"))
