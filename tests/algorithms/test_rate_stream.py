"""RateStream: every rate algorithm ``strapdown run`` offers, streamed in chunks of any size,
equals the one-shot :meth:`AlgorithmSpec.run_rates` to the last bit (attitude, times,
chains), across every chunk boundary."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.algorithms.streaming import RateStream

SPECS = [AlgorithmSpec("rate-single"), AlgorithmSpec("rate-single", coefficients="paper"),
         AlgorithmSpec("rate-three"), AlgorithmSpec("rate-three", structure="sliding"),
         AlgorithmSpec("rate-three", coefficients="paper", structure="sliding"),
         AlgorithmSpec("rate-two"), AlgorithmSpec("rk4"),
         AlgorithmSpec("rk4", rk4_step="td-interp")]
Q0 = np.array([0.5, 0.5, 0.5, 0.5])
TD, T0 = 1e-3, 12.25


def _record(n, seed):
    rng = np.random.default_rng(seed)
    t = T0 + np.arange(n) * TD
    w = np.column_stack([3 * np.sin(40 * t), 2 * np.cos(31 * t), np.full(n, 1.5)])
    return t, w + rng.normal(size=(n, 3)) * 0.1


def _streamed(spec, t, w, sizes):
    # the one-shot run's period for uniform stamps
    td = float((t[-1] - t[0]) / (t.size - 1)) if t.size > 1 else TD
    s = RateStream(spec, td=td, t0=float(t[0]), q0=Q0)
    parts, i, k = [], 0, 0
    while i < w.shape[0]:
        m = sizes[k % len(sizes)]
        parts.append(s.feed(w[i:i + m]))
        i, k = i + m, k + 1
    assert s.samples == w.shape[0]
    return (np.concatenate([p.t for p in parts]), np.concatenate([p.q for p in parts]),
            np.concatenate([p.chain for p in parts]), parts)


@pytest.mark.parametrize("spec", SPECS, ids=str)
@settings(max_examples=25, deadline=None)
@given(n=st.integers(4, 400),
       sizes=st.lists(st.integers(0, 70), min_size=1, max_size=8).filter(any))
def test_streamed_equals_one_shot_whatever_the_chunks(spec, n, sizes):
    t, w = _record(n, n)
    one = spec.run_rates(t, w, q0=Q0)
    ts, qs, chain, parts = _streamed(spec, t, w, sizes)
    assert np.array_equal(qs, one.q) and np.array_equal(ts, one.t)
    assert np.array_equal(chain, one.chain)
    done = next(p for p in parts if p.q.shape[0])
    assert (done.structure, done.update_period) == (one.structure, one.update_period)


@pytest.mark.parametrize("spec", SPECS, ids=str)
def test_long_record_in_uneven_chunks(spec):
    t, w = _record(20_011, 3)
    one = spec.run_rates(t, w, q0=Q0)
    ts, qs, _, _ = _streamed(spec, t, w, [4099, 1, 2, 3, 7777])
    assert np.array_equal(qs, one.q) and np.array_equal(ts, one.t)


@pytest.mark.parametrize("spec", SPECS, ids=str)
def test_too_few_samples_give_no_output(spec):
    t, w = _record(spec.min_samples - 1, 0)
    _, qs, _, _ = _streamed(spec, t, w, [1])
    assert qs.shape == (0, 4)


def test_errors():
    with pytest.raises(ValueError, match="rate-input algorithms"):
        RateStream(AlgorithmSpec("rotvec"), td=1e-3)
    with pytest.raises(ValueError, match="td"):
        RateStream(AlgorithmSpec("rk4"), td=0.0)
    with pytest.raises(ValueError, match="q0"):
        RateStream(AlgorithmSpec("rk4"), td=1e-3, q0=[1.0, 0.0])
    with pytest.raises(ValueError, match="shape"):
        RateStream(AlgorithmSpec("rk4"), td=1e-3).feed(np.zeros(3))
