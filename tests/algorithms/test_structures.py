"""Update structures: compiled kernels against the plain-Python reference; start-up; errors."""

from __future__ import annotations

import numpy as np
import pytest

from strapdown._core.backend import NUMPY
from strapdown.algorithms import _reference
from strapdown.algorithms.coning import coefficient_set, user_coefficients
from strapdown.algorithms.structures import conventional, realtime, startup_sets

NAMES = [("table3", n) for n in range(1, 7)] + [("lag", 4), ("eq6-printed", 5), ("miller", 3),
                                                   ("none", 2)]


def _theta(n, seed=0, scale=0.05):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, 3)) * scale


def _ref(fn, theta, mats, q0):
    m = NUMPY
    th = [tuple(float(v) for v in r) for r in theta]
    return np.array(fn(th, mats, tuple(float(v) for v in q0), m), dtype=float)


@pytest.mark.parametrize(("name", "n"), NAMES)
def test_conventional_kernel_matches_reference(name, n):
    cs = coefficient_set(name, n)
    theta = _theta(n * 97, seed=n)
    q0 = np.array([0.5, 0.5, -0.5, 0.5])
    sol = conventional(theta, cs, h=1e-3, q0=q0)
    ref = _ref(_reference.conventional, theta, cs.matrix.tolist(), q0)
    assert sol.q.shape == (98, 4)
    assert np.max(np.abs(sol.q - ref)) <= 2e-14
    assert np.allclose(sol.t, np.arange(98) * n * 1e-3)


@pytest.mark.parametrize(("name", "n"), NAMES)
def test_realtime_kernel_matches_reference(name, n):
    cs = coefficient_set(name, n)
    theta = _theta(301, seed=10 + n)
    sol = realtime(theta, cs, h=2e-3)
    ref = _ref(_reference.realtime, theta, [s.matrix.tolist() for s in startup_sets(cs)],
               [1.0, 0, 0, 0])
    assert np.max(np.abs(sol.q - ref)) <= 2e-14
    assert np.array_equal(sol.chain, np.arange(302) % n)
    assert sol.update_period == 2e-3


@pytest.mark.parametrize("n", [2, 3, 5])
def test_realtime_chain0_is_the_conventional_solution(n):
    cs = coefficient_set("table3", n)
    theta = _theta(n * 40, seed=3)
    rt = realtime(theta, cs, h=1e-3)
    cv = conventional(theta, cs, h=1e-3)
    assert np.array_equal(rt.q[::n], cv.q)  # same operations, bit for bit


def test_realtime_startup_uses_k_subsample_sets():
    cs = coefficient_set("table3", 3)
    theta = _theta(3, seed=4)
    rt = realtime(theta, cs, h=1e-3)
    two = conventional(theta[:2], coefficient_set("table3", 2), h=1e-3)
    one = conventional(theta[:1], coefficient_set("table3", 1), h=1e-3)
    assert np.array_equal(rt.q[1], one.q[1])
    assert np.array_equal(rt.q[2], two.q[1])
    # a family without a k-subsample member starts with Table 3
    assert [s.name for s in startup_sets(coefficient_set("miller", 3))] == [
        "table3", "table3", "miller"]


def test_user_matrix_runs():
    k = np.zeros((3, 3))
    k[0, 2] = 0.5
    sol = conventional(_theta(9), user_coefficients(k), h=1e-3)
    assert np.allclose(np.linalg.norm(sol.q, axis=1), 1.0, atol=1e-15)


def test_tail_handling():
    cs = coefficient_set("table3", 3)
    with pytest.raises(ValueError, match="do not fill whole updates"):
        conventional(_theta(10), cs, h=1e-3)
    assert conventional(_theta(10), cs, h=1e-3, tail="drop").q.shape == (4, 4)
    with pytest.raises(ValueError, match="tail must be"):
        conventional(_theta(10), cs, h=1e-3, tail="pad")


@pytest.mark.parametrize(
    ("kwargs", "msg"),
    [
        ({"increments": np.zeros((2, 3))}, "need at least 3 increments"),
        ({"increments": np.zeros((6, 2))}, r"shape \(\.\.\., 3\)"),
        ({"increments": np.zeros((2, 3, 3))}, r"shape \(n, 3\)"),
        ({"increments": np.full((6, 3), np.nan)}, "NaN"),
        ({"h": 0.0}, "positive"),
        ({"h": -1e-3}, "positive"),
        ({"q0": [0, 0, 0, 0]}, "zero quaternion"),
        ({"q0": np.eye(4)}, r"shape \(4,\)"),
        ({"coefficients": "table3"}, "CoefficientSet"),
    ],
)
@pytest.mark.parametrize("fn", [conventional, realtime])
def test_bad_input(fn, kwargs, msg):
    args = {"increments": np.zeros((6, 3)), "coefficients": coefficient_set("table3", 3),
            "h": 1e-3} | kwargs
    with pytest.raises(ValueError, match=msg):
        fn(args.pop("increments"), args.pop("coefficients"), **args)
