"""Single-chain structure: accuracy of N subsamples at update period h, from one chain."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown._core.backend import NUMPY
from strapdown.algorithms import _reference
from strapdown.algorithms.coning import coefficient_set
from strapdown.algorithms.structures import single_chain, single_chain_coefficients
from strapdown.analysis.coning_drift import drift_mp
from strapdown.analysis.evaluate import EvaluationConfig, evaluate


def test_matches_plain_reference_with_startup():
    rng = np.random.default_rng(5)
    theta = rng.normal(size=(200, 3)) * 0.03
    n = 4
    sol = single_chain(theta, n, h=1e-3)
    sets = {m: [float(c) for c in single_chain_coefficients(m)] for m in range(1, n + 1)}
    phis = []
    for k in range(theta.shape[0]):
        cs = sets[min(k + 1, n)]
        window = [tuple(theta[k - m]) for m in range(len(cs), -1, -1)]
        last = len(window) - 1
        pairs = [(last - m, last, c) for m, c in enumerate(cs, start=1)]
        phis.append(_reference.windowed_rotvec(window, [0.0] * last + [1.0], pairs, 0.0))
    ref = np.array(_reference.chain(phis, [(1.0, 0.0, 0.0, 0.0)], 1, NUMPY))
    assert np.max(np.abs(sol.q - ref)) <= 1e-14
    assert sol.startup == n - 1 and sol.update_period == 1e-3


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_single_chain_reaches_conventional_drift(n):
    # same h, small cone angle, arbitrary precision; single chain updates every h
    cfg = dict(motion="coning", half_angle_deg=math.degrees(1e-9), cone_rate_hz=1.0,
               sample_rate_hz=60.0, duration=2.0, subsamples=n, precision=60)
    sc = evaluate(EvaluationConfig.of(structure="single-chain", **cfg))
    conv = drift_mp(1e-9, 60, n, "conventional", digits=60)
    assert sc.update_period == pytest.approx(1 / 60)
    assert abs(sc.cone_axis_drift / conv - 1) <= 0.02


def test_float64_single_chain_at_one_degree():
    cfg = EvaluationConfig.of(structure="single-chain", subsamples=2, sample_rate_hz=240.0,
                              duration=20.0)
    r = evaluate(cfg)
    assert abs(r.cone_axis_drift / r.predicted - 1) <= 0.01


def test_single_chain_rejects_other_sets():
    with pytest.raises(ValueError, match="designer"):
        from strapdown.algorithms.structures import run_structure

        run_structure("single-chain", np.zeros((5, 3)), coefficient_set("miller", 3), h=1e-3)


def test_bad_input():
    with pytest.raises(ValueError, match="positive integer"):
        single_chain(np.zeros((4, 3)), 0, h=1e-3)
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        single_chain(np.zeros((0, 3)), 2, h=1e-3)
