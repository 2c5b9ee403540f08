"""Numerical coefficient optimisation: closed-form optimum, reproducibility, transfer."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.design import interval_structure
from strapdown.design.optimize import (
    TransferCase,
    algorithm_from_groups,
    optimize,
    simulate_windowed,
    transfer,
    windowed_objective,
)
from strapdown.truth.motions import ClassicalConing

OMEGA = 2 * math.pi


def _k_exact(x):
    """Two-sample coefficient zeroing the leading-order-in-a drift at finite x = Ωh."""
    return (2 * x - math.sin(2 * x)) / (8 * math.sin(x / 2) ** 2 * math.sin(x))


def test_nelder_mead_finds_closed_form_optimum():
    m = ClassicalConing(1e-3, OMEGA)
    x = 2 * math.pi / 20
    f = windowed_objective(interval_structure(2), m, h=x / OMEGA, updates=20)
    r = optimize(f, [2 / 3])
    assert r.x[0] == pytest.approx(_k_exact(x), rel=1e-5)
    assert r.fun < 1e-3 * r.start_fun


def test_differential_evolution_is_reproducible():
    m = ClassicalConing(1e-3, OMEGA)
    x = 2 * math.pi / 20
    f = windowed_objective(interval_structure(2), m, h=x / OMEGA, updates=20)
    a = optimize(f, [0.5], method="differential-evolution", bounds=[(0, 1)], seed=3, maxiter=30)
    b = optimize(f, [0.5], method="differential-evolution", bounds=[(0, 1)], seed=3, maxiter=30)
    assert a.x.tobytes() == b.x.tobytes()
    assert a.x[0] == pytest.approx(_k_exact(x), rel=1e-4)
    with pytest.raises(ValueError, match="bounds and a seed"):
        optimize(f, [0.5], method="differential-evolution")


def test_transfer_shows_overfitting():
    m = ClassicalConing(1e-3, OMEGA)
    x = 2 * math.pi / 20
    st = interval_structure(2)
    tuned = [_k_exact(x)]
    rows = transfer(st, {"table3": [2 / 3], "tuned": tuned},
                    [TransferCase("tuned Ωh", m, x / OMEGA, 20),
                     TransferCase("Ωh/3", m, x / 3 / OMEGA, 60)])
    by = {(r["case"], r["set"]): r for r in rows}
    assert by["tuned Ωh", "tuned"]["ratio_to_first"] < 1e-3
    assert by["Ωh/3", "tuned"]["ratio_to_first"] > 2  # worse than Table 3 elsewhere


def test_simulate_windowed_float_agrees_with_mp():
    m = ClassicalConing(0.05, OMEGA)
    alg = algorithm_from_groups(interval_structure(3), [27 / 20, 9 / 20])
    t, e = simulate_windowed(m, alg, h=1 / 60, updates=40)
    t2, e2 = simulate_windowed(m, alg, h=1 / 60, updates=40, digits=40)
    assert np.allclose(t, t2)
    assert np.max(np.abs(e - e2)) < 1e-14


def test_bad_input():
    st = interval_structure(3)
    with pytest.raises(ValueError, match=r"shape \(2,\)"):
        algorithm_from_groups(st, [1.0])
    with pytest.raises(ValueError, match="unknown metric"):
        windowed_objective(st, ClassicalConing(0.1, 1.0), h=0.1, updates=3, metric="x")
    with pytest.raises(ValueError, match="unknown method"):
        optimize(lambda v: 0.0, [1.0], method="bfgs")
