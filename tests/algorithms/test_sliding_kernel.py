"""The fused four-sample window kernel (three-period rate algorithm, conventional and sliding).

Peers: the general ``windowed_kernel`` (same floating-point operations in the same order, so
compared bit for bit) and the plain-Python twin ``_reference.windowed`` (exact exponential map
instead of the small-angle series, so compared to 1e-14).
"""

from __future__ import annotations

from fractions import Fraction as F

import numpy as np
import pytest

from strapdown._core.backend import NUMPY
from strapdown.algorithms import _kernels, _reference, rate, structures
from strapdown.algorithms.coning import WindowedAlgorithm

PAIRS = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))
WEIGHTS = np.array([0.375, 1.125, -0.5, 0.0])
COEFFS = np.array([719 / 1680, 103 / 560, 0.0, -43 / 560, 1 / 3, 719 / 1680])
# (step, stride): sliding three-period, conventional three-period, other slides
CASES = [(1, 3), (3, 1), (2, 1), (1, 1), (4, 2)]


def _bits(a):
    return np.ascontiguousarray(a).view(np.uint64)


def _start(stride, seed):
    """Unit attitudes for the first ``stride`` rows."""
    q = np.random.default_rng(seed).normal(size=(stride, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _general(x, step, stride, count, sa, sb, q0):
    """The general kernel on the same windows (what ``_run_windowed`` used before)."""
    q = np.empty((count + stride, 4))
    q[:stride] = q0
    ij = np.array(PAIRS, dtype=np.int64)
    _kernels.windowed_kernel(x, np.arange(4, dtype=np.int64), WEIGHTS,
                             np.ascontiguousarray(ij[:, 0]), np.ascontiguousarray(ij[:, 1]),
                             COEFFS, sa, sb, np.arange(count, dtype=np.int64) * step + 1,
                             stride, q)
    return q


def _fused(x, step, stride, count, sa, sb, q0):
    q = np.empty((count + stride, 4))
    q[:stride] = q0
    _kernels.window4_kernel(x, WEIGHTS, COEFFS, sa, sb, 1, step, stride, q)
    return q


@pytest.mark.parametrize(("step", "stride"), CASES)
@pytest.mark.parametrize("scale", [0.0, 1e-3, 2.0])  # zero, small-angle series, sin/cos
@pytest.mark.parametrize(("sa", "sb"), [(1.0, 1.0), (1e-2, 1e-4)])
def test_window4_is_bitwise_the_general_kernel(step, stride, scale, sa, sb):
    count = 37
    x = np.random.default_rng(3).normal(size=(1 + (count - 1) * step + 4 + 2, 3)) * scale
    q0 = _start(stride, 4)
    ref = _general(x, step, stride, count, sa, sb, q0)
    new = _fused(x, step, stride, count, sa, sb, q0)
    assert np.array_equal(_bits(new), _bits(ref))


@pytest.mark.parametrize(("step", "stride"), CASES)
@pytest.mark.parametrize("scale", [1e-3, 2.0])
def test_window4_matches_plain_python_twin(step, stride, scale):
    count = 25
    x = np.random.default_rng(5).normal(size=(1 + (count - 1) * step + 4, 3)) * scale
    q0 = _start(stride, 6)
    new = _fused(x, step, stride, count, 1e-2, 1e-4, q0)
    ref = _reference.windowed([tuple(r) for r in x], range(4), WEIGHTS.tolist(), PAIRS,
                              COEFFS.tolist(), 1e-2, 1e-4, [1 + r * step for r in range(count)],
                              [tuple(q) for q in q0], stride, NUMPY)
    assert np.max(np.abs(new - np.array(ref))) <= 1e-14


def _old_windowed(x, alg, h, t0, q0, sliding, startup):
    """``structures._windowed`` as it was before the fused kernel: index arrays, the general
    kernel, times and chains from integer aranges."""
    def run(a, starts, stride, q):
        sa, sb = (1.0, 1.0) if a.input == "increment" else (h, h * h)
        ij = np.array(a.pairs, dtype=np.int64).reshape(-1, 2)
        _kernels.windowed_kernel(x, np.array(a.offsets, dtype=np.int64),
                                 np.array([float(w) for w in a.weights]),
                                 np.ascontiguousarray(ij[:, 0]), np.ascontiguousarray(ij[:, 1]),
                                 np.array([float(c) for c in a.pair_coefficients]), sa, sb,
                                 np.asarray(starts, dtype=np.int64), stride, q)

    b0, u = alg.history, alg.update
    last = x.shape[0] - 1 - alg.span
    if not sliding:
        starts = np.arange(b0, last + 1, u)
        q = np.empty((starts.size + 1, 4))
        q[0] = q0
        run(alg, starts, 1, q)
        return t0 + (b0 + np.arange(q.shape[0]) * u) * h, q, np.zeros(q.shape[0], int)
    starts = np.arange(b0, last + 1)
    q = np.empty((starts.size + u, 4))
    q[0] = q0
    if u > 1:
        run(startup, np.arange(b0, b0 + u - 1), 1, q[:u])
    run(alg, starts, u, q)
    k = np.arange(q.shape[0])
    return t0 + (b0 + k) * h, q, k % u


@pytest.mark.parametrize("structure", ["sliding", "conventional"])
@pytest.mark.parametrize("coefficients", ["derived", "paper"])
@pytest.mark.parametrize("n", [4, 5, 6, 7, 50])
def test_rate_three_is_bitwise_the_old_path(structure, coefficients, n, monkeypatch):
    calls = []
    fused = _kernels.window4_kernel
    monkeypatch.setattr(_kernels, "window4_kernel",
                        lambda *a: (calls.append(a[5:8]), fused(*a))[1])
    rng = np.random.default_rng(n)
    w = rng.normal(size=(n, 3)) * 3.0
    t = 0.3 + np.arange(n) * 7e-3
    q0 = _start(1, n)[0]
    sol = rate.rate_attitude(t, w, algorithm="rate-three", structure=structure,
                             coefficients=coefficients, q0=q0)
    sliding = structure == "sliding"
    # the old path from the attitude rate_attitude normalised q0 to, at the td it derived
    tt, q, chain = _old_windowed(w, rate.three_period_algorithm(coefficients), sol.h, 0.3,
                                 sol.q[0].copy(), sliding,
                                 rate.single_period_algorithm(coefficients))
    assert calls == [(0, 1, 3) if sliding else (0, 3, 1)]  # (b0, step, stride)
    assert np.array_equal(_bits(sol.q), _bits(q))
    assert np.array_equal(_bits(sol.t), _bits(tt))
    assert sol.chain.dtype == chain.dtype and np.array_equal(sol.chain, chain)


START = WindowedAlgorithm("increment", 1, (0, 1), (F(1, 2), F(1, 2)), ((0, 1),), (F(1, 6),))
OTHER = {  # shapes the fused kernel must leave to the general one
    "history": WindowedAlgorithm("increment", 2, (-1, 0, 1, 2), (0, 1, 1, 0), PAIRS, (0.1,) * 6),
    "pair order": WindowedAlgorithm("increment", 3, (0, 1, 2, 3), (1, 1, 1, 1), PAIRS[::-1],
                                    (0.1, 0.2, 0.3, 0.4, 0.5, 0.6)),
    "three nodes": WindowedAlgorithm("increment", 2, (0, 1, 2), (1, 1, 1), ((0, 1), (1, 2)),
                                     (F(1, 2), F(1, 3))),
}


@pytest.mark.parametrize("name", list(OTHER))
@pytest.mark.parametrize("sliding", [False, True])
def test_other_shapes_keep_the_general_kernel(name, sliding, monkeypatch):
    monkeypatch.setattr(_kernels, "window4_kernel", None)  # any call would fail
    alg = OTHER[name]
    x = np.random.default_rng(7).normal(size=(41, 3)) * 0.1
    sol = structures.windowed(x, alg, h=1e-3, t0=-0.2, sliding=sliding, startup=START)
    tt, q, chain = _old_windowed(x, alg, 1e-3, -0.2, np.array([1.0, 0, 0, 0]), sliding, START)
    assert np.array_equal(_bits(sol.q), _bits(q))
    assert np.array_equal(_bits(sol.t), _bits(tt))
    assert np.array_equal(sol.chain, chain)
