"""Velocity/position updates: kernels against the plain-Python twin, the classical-sculling
law in arbitrary precision (N = 1–6, both structures) and in float64, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown._core.backend import NUMPY
from strapdown.algorithms import _velocity_reference as vref
from strapdown.algorithms.coning import coefficient_set
from strapdown.algorithms.structures import single_chain_table
from strapdown.algorithms.velocity import (
    sculling_law,
    sculling_matrix,
    sculling_single_chain_table,
)
from strapdown.navigation import _reference as ref
from strapdown.navigation import integrate_inertial, integrate_inertial_mp
from strapdown.truth.sculling import classical_sculling


def _twin(g, a, n, h, structure, velocity_set="coning-force"):
    gl, al = [tuple(r) for r in g], [tuple(r) for r in a]
    if structure == "conventional":
        body = vref.conventional_body(gl, al, coefficient_set("table3", n).matrix.tolist(),
                                      sculling_matrix(n, velocity_set=velocity_set).tolist(),
                                      h, 0.0)
        period = n * h
    else:
        body = vref.single_chain_body(gl, al, single_chain_table(n).tolist(),
                                      sculling_single_chain_table(n).tolist(), h)
        period = h
    q, v, p = ref.inertial(body, period, (1.0, 0.0, 0.0, 0.0), (0.0,) * 3, (0.0,) * 3, NUMPY)
    return np.array(q), np.array(v), np.array(p)


@pytest.mark.parametrize("velocity_set", ["coning-force", "classical"])
@pytest.mark.parametrize("structure", ["conventional", "single-chain"])
@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_kernels_match_the_plain_python_twin(n, structure, velocity_set):
    rng = np.random.default_rng(10 * n + len(structure))
    g = rng.normal(size=(60, 3)) * 0.03
    a = rng.normal(size=(60, 3)) * 0.2
    sol = integrate_inertial(g, a, n, h=0.01, structure=structure, velocity_set=velocity_set)
    q, v, p = _twin(g, a, n, 0.01, structure, velocity_set)
    assert q.shape == sol.q.shape
    assert np.max(np.abs(q - sol.q)) <= 1e-15  # the exponential map's series vs sin (≤ 1 ulp)
    assert np.max(np.abs(v - sol.v)) <= 1e-15 and np.max(np.abs(p - sol.p)) <= 1e-15


@pytest.mark.parametrize("structure", ["conventional", "single-chain"])
@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_sculling_law_in_arbitrary_precision(n, structure):
    # θ0 = 1e-20 rad (third-order terms far below the law), 120 samples per period,
    # rate measured between whole periods 1 and 3 (after the single chain's start-up)
    th, om, acc, psi, spp = 1e-20, 2 * math.pi, 1.0, 0.3, 120
    sol = integrate_inertial_mp(classical_sculling(th, om, acc, psi), n, h=1 / spp,
                                samples=3 * spp, digits=90, structure=structure)
    i0, i1 = np.searchsorted(sol.t, 1.0 - 1e-9), len(sol.t) - 1
    assert sol.t[i0] == pytest.approx(1.0) and sol.t[i1] == pytest.approx(3.0)
    rate = (sol.dv[i1] - sol.dv[i0]) / (sol.t[i1] - sol.t[i0])
    law = sculling_law(n).predict(th, acc, psi, om, 1 / spp)
    assert abs(rate[2] / law - 1) <= 0.01
    assert abs(rate[1]) <= 1e-6 * abs(law) and rate[0] == 0.0
    # the position error is the integral of the velocity error (no secular term of its own)
    assert sol.dp[i1, 2] == pytest.approx(0.5 * rate[2] * sol.t[i1] ** 2, rel=0.1)


def _float64_rate(n, sculling=True):
    f, spp, th, acc, psi = 10.0, 120, math.radians(1.0), 10.0, 0.0
    om, h = 2 * math.pi * f, 1 / (f * spp)
    mo = classical_sculling(th, om, acc, psi)
    edges = np.arange(round(3.0 / h) + 1) * h
    sol = integrate_inertial(mo.increments(edges), mo.velocity_increments(edges), n, h=h,
                             q0=mo.attitude(0.0), sculling=sculling)
    dv = sol.v - mo.velocity(sol.t)
    i0 = np.searchsorted(sol.t, 1.0 - 1e-9)
    return (dv[-1] - dv[i0]) / (sol.t[-1] - sol.t[i0]), sculling_law(n).predict(th, acc, psi,
                                                                                om, h)


@pytest.mark.parametrize("n", [1, 2])
def test_sculling_law_in_float64_at_one_degree(n):
    rate, law = _float64_rate(n)
    assert abs(rate[2] / law - 1) <= 0.01


def test_sculling_terms_matter():
    with_terms, _law = _float64_rate(2)
    without, _ = _float64_rate(2, sculling=False)
    assert abs(without[2]) > 1000 * abs(with_terms[2])
    assert abs(without[2] / sculling_law(1).predict(math.radians(1.0), 10.0, 0.0,
                                                   2 * math.pi * 10, 1 / 600) - 1) < 0.01


def test_constant_force_without_rotation_is_exact():
    a = np.tile([0.3, -0.2, 0.1], (40, 1)) * 0.01
    for structure in ("conventional", "single-chain"):
        sol = integrate_inertial(np.zeros((40, 3)), a, 4, h=0.01, structure=structure)
        assert np.allclose(sol.v, sol.t[:, None] * [0.3, -0.2, 0.1], rtol=0, atol=1e-15)
        assert np.allclose(sol.p, 0.5 * sol.t[:, None] ** 2 * [0.3, -0.2, 0.1], rtol=0,
                           atol=1e-15)


def test_bad_input():
    z = np.zeros((6, 3))
    with pytest.raises(ValueError, match="shape"):
        integrate_inertial(z, np.zeros((5, 3)), 2, h=0.01)
    with pytest.raises(ValueError, match="at most 6"):
        integrate_inertial(z, z, 7, h=0.01)
    with pytest.raises(ValueError, match="unknown velocity structure"):
        integrate_inertial(z, z, 2, h=0.01, structure="realtime")
    with pytest.raises(ValueError, match="NaN"):
        integrate_inertial(z + np.nan, z, 2, h=0.01)
    with pytest.raises(ValueError, match="at least 3"):
        integrate_inertial(z[:2], z[:2], 3, h=0.01)
