"""Every tabulated coefficient equals what the designer derives (exact rationals)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from strapdown.algorithms import rate, tables
from strapdown.design import (
    classical_coning_drift,
    derive,
    rate_structure,
    rk4_classical_coning_drift,
    single_chain_structure,
    three_period_structure,
)


@pytest.mark.parametrize("n", sorted(tables.SINGLE_CHAIN))
def test_single_chain_table_is_the_designers(n):
    assert derive(single_chain_structure(n)).coefficients == tables.SINGLE_CHAIN[n]


def test_rate_single_table_is_the_designers():
    c = derive(rate_structure(1)).coefficients[0]
    assert tables.RATE_SINGLE["derived"] == c
    for name, law in tables.RATE_SINGLE_DRIFT.items():
        assert classical_coning_drift(rate_structure(1), [tables.RATE_SINGLE[name]]) == law


@pytest.mark.parametrize(("name", "quadrature"), [("derived", True), ("paper", False)])
def test_rate_three_table_is_the_designers(name, quadrature):
    alg = derive(three_period_structure(), quadrature=quadrature).algorithm()
    assert alg.offsets == (0, 1, 2, 3)
    assert alg.weights == tables.RATE_THREE_WEIGHTS
    assert alg.pairs == tables.RATE_THREE_PAIRS
    assert alg.pair_coefficients == tables.RATE_THREE[name]
    assert classical_coning_drift(three_period_structure(), alg.pair_coefficients) == (
        tables.RATE_THREE_DRIFT[name])
    assert rate.three_period_algorithm(name).pair_coefficients == tables.RATE_THREE[name]


@pytest.mark.parametrize("step", sorted(tables.RK4_DRIFT))
def test_rk4_drift_table_is_the_derivation(step):
    assert rk4_classical_coning_drift(step) == tables.RK4_DRIFT[step]


_NO_SYMPY = """
import sys
import numpy as np
import strapdown
from strapdown.analysis.evaluate import EvaluationConfig, evaluate
for alg, st in [("rotvec", "single-chain"), ("rate-single", "conventional"),
                ("rate-three", "sliding"), ("rk4", "conventional"), ("rotvec", "realtime")]:
    evaluate(EvaluationConfig.of(algorithm=alg, structure=st, sample_rate_hz=600, duration=0.1))
from strapdown.ahrs import ekf
t = np.arange(200) / 100.0
ekf(t, np.zeros((200, 3)), np.tile([0.0, 0.0, 9.80665], (200, 1)),
    np.tile([0.0, 20.0, -40.0], (200, 1)))
loaded = sorted(m for m in ("sympy", "matplotlib") if m in sys.modules)
print(",".join(loaded) or "none")
"""


def test_run_evaluate_and_ahrs_paths_never_import_sympy_or_matplotlib():
    out = subprocess.run([sys.executable, "-c", _NO_SYMPY], capture_output=True, text=True,
                         check=True).stdout.strip().splitlines()[-1]
    assert out == "none"


@pytest.mark.parametrize("n", sorted(tables.SCULLING_CONVENTIONAL))
def test_sculling_tables_are_the_designers(n):
    from strapdown.design import interval_structure

    conv = derive(interval_structure(n), target="sculling")
    chain = derive(single_chain_structure(n), target="sculling")
    assert conv.coefficients == tables.SCULLING_CONVENTIONAL[n]
    assert chain.coefficients == tables.SCULLING_SINGLE_CHAIN[n]
    assert (conv.order, conv.drift_constant) == tables.SCULLING_DRIFT[n]
    assert (chain.order, chain.drift_constant) == tables.SCULLING_DRIFT[n]
