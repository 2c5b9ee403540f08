"""Streaming: identical to the one-shot run to the last bit, whatever the chunking."""

from __future__ import annotations

import numpy as np
import pytest

from strapdown.algorithms.coning import coefficient_set
from strapdown.algorithms.streaming import RotvecStream
from strapdown.algorithms.structures import conventional, realtime, single_chain


def _chunks(theta, rng):
    i = 0
    while i < theta.shape[0]:
        k = int(rng.choice([0, 1, 2, 3, 5, 17, 64, 257]))
        yield theta[i:i + k]
        i += k


def _stream(structure, cs, theta, seed):
    s = RotvecStream(structure, cs, h=1e-3, t0=0.5, q0=[0.5, 0.5, 0.5, 0.5])
    parts = [s.feed(c) for c in _chunks(theta, np.random.default_rng(seed))]
    t = np.concatenate([p.t for p in parts])
    q = np.concatenate([p.q for p in parts])
    chain = np.concatenate([p.chain for p in parts])
    return t, q, chain


@pytest.mark.parametrize("n", [1, 2, 3, 5])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_conventional(n, seed):
    theta = np.random.default_rng(10 + n).normal(size=(n * 301, 3)) * 0.02
    cs = coefficient_set("table3", n)
    one = conventional(theta, cs, h=1e-3, t0=0.5, q0=[0.5, 0.5, 0.5, 0.5])
    t, q, _ = _stream("conventional", cs, theta, seed)
    assert np.array_equal(q, one.q) and np.array_equal(t, one.t)


@pytest.mark.parametrize("n", [1, 2, 3, 5])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_realtime(n, seed):
    theta = np.random.default_rng(20 + n).normal(size=(1000, 3)) * 0.02
    cs = coefficient_set("table3", n)
    one = realtime(theta, cs, h=1e-3, t0=0.5, q0=[0.5, 0.5, 0.5, 0.5])
    t, q, chain = _stream("realtime", cs, theta, seed)
    assert np.array_equal(q, one.q) and np.allclose(t, one.t, rtol=0, atol=1e-15)
    assert np.array_equal(chain, one.chain)


@pytest.mark.parametrize("n", [1, 2, 3, 6])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_single_chain(n, seed):
    theta = np.random.default_rng(30 + n).normal(size=(1000, 3)) * 0.02
    one = single_chain(theta, n, h=1e-3, t0=0.5, q0=[0.5, 0.5, 0.5, 0.5])
    t, q, _ = _stream("single-chain", coefficient_set("table3", n), theta, seed)
    assert np.array_equal(q, one.q) and np.allclose(t, one.t, rtol=0, atol=1e-15)


def test_errors():
    with pytest.raises(ValueError, match="unknown structure"):
        RotvecStream("sliding", coefficient_set("table3", 3), h=1e-3)
    s = RotvecStream("conventional", coefficient_set("table3", 3), h=1e-3)
    with pytest.raises(ValueError, match="NaN"):
        s.feed(np.full((3, 3), np.nan))
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3\)"):
        s.feed(np.zeros((3, 2)))
