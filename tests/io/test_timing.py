"""The sensor clock from stamps (strapdown.io.timing): one test per case the issue names —
stamp noise, quantised stamps, irregular sampling, gaps, held samples, duplicated stamps,
a drifting clock — each against the clock the stamps were made from."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from strapdown import InputError
from strapdown.io.timing import (
    clean_rows,
    fit_clock,
    format_times,
    reconstruct,
    relative_times,
)

N = 4000


def _fit(raw, scale=1.0, **kw):
    base = relative_times(np.asarray(raw, float), scale)
    return fit_clock(base.t, tick=base.tick, **kw), base


def test_exact_stamps_are_uniform_and_kept():
    clock, _ = _fit(np.arange(N) * 0.01)
    assert clock.kind == "uniform" and clock.missing == 0
    assert clock.period == pytest.approx(0.01, rel=1e-12)
    assert np.array_equal(clock.ticks, np.arange(N))


def test_stamp_noise_around_a_uniform_clock():
    """±1 ms on 5 ms (0.2 period): every sample gets its tick, the period to 1e-6."""
    rng = np.random.default_rng(1)
    k = np.arange(N)
    clock, _ = _fit(k * 0.005 + rng.uniform(-1e-3, 1e-3, N))
    assert clock.kind == "noise"
    assert np.array_equal(clock.ticks, k)
    assert clock.period == pytest.approx(0.005, rel=1e-6)
    assert 0.19 < clock.residual_max / clock.period < 0.21


def test_stamps_rounded_to_whole_ms_are_quantised():
    """400 Hz rounded to 1 ms (0, 2, 5, 8, 10 …): the tick is found, the residuals are the
    rounding (≤ half a tick)."""
    k = np.arange(N)
    raw = np.rint(k * 2.5) / 1000.0
    clock, base = _fit(raw)
    assert base.tick == pytest.approx(1e-3)
    assert clock.kind == "quantised"
    assert np.array_equal(clock.ticks, k)
    assert clock.period == pytest.approx(0.0025, rel=1e-6)  # rounding: 7.5e-8 seen
    assert clock.residual_max <= 0.501e-3  # the rounding, and the fitted line's 4e-7 s


def test_missing_samples_are_a_gap_of_whole_periods():
    """A dropped burst of 10 samples is 10 missing ticks, not a late stamp."""
    rng = np.random.default_rng(2)
    k = np.delete(np.arange(N), np.arange(1500, 1510))
    clock, _ = _fit(np.rint(1733119200123 + k * 5.0 + rng.uniform(-1, 1, k.size)), 1e-3)
    assert clock.kind in ("noise", "quantised")
    assert clock.missing == 10
    assert clock.gap_rows().tolist() == [1500] and clock.gap_lengths().tolist() == [10]
    assert np.array_equal(clock.ticks, k)


def test_drifting_clock_is_fitted_with_its_drift():
    """The period changes by 0.1 % over the record: a line alone would leave residuals of
    more than a period; the drift term brings them back to the stamp noise."""
    rng = np.random.default_rng(3)
    k = np.arange(N)
    periods = 0.01 * (1 + 1e-3 * k / N)
    t = np.concatenate([[0.0], np.cumsum(periods[:-1])]) + rng.normal(0, 2e-4, N)
    clock, _ = _fit(t)
    assert clock.kind == "drifting" and clock.drift
    assert np.array_equal(clock.ticks, k)
    assert clock.residual_p99 < 0.1 * clock.period


@pytest.mark.parametrize("draw", ["poisson", "uniform-intervals"])
def test_irregular_sampling_is_not_forced_onto_a_clock(draw):
    rng = np.random.default_rng(4)
    t = (np.sort(rng.uniform(0, 40, N)) if draw == "poisson"
         else np.cumsum(rng.uniform(0.005, 0.015, N)))
    clock, _ = _fit(t)
    assert clock.kind == "irregular"
    assert "irregular sampling" in clock.describe()


def _lab(seed=5, imu_hz=51.0, logger_hz=91.0, seconds=40.0):
    """A logger at 91 Hz holding a 51 Hz IMU's last sample: (stamps, values, IMU index)."""
    rng = np.random.default_rng(seed)
    tl = np.rint(np.arange(0, seconds, 1 / logger_hz) * 1000) / 1000
    ti = np.arange(0, seconds, 1 / imu_hz) + 0.003
    idx = np.searchsorted(ti, tl, side="right") - 1
    tl, idx = tl[idx >= 0], idx[idx >= 0]
    values = rng.normal(size=(ti.size, 6))[idx]
    return tl, values, idx


def test_held_samples_are_collapsed_to_their_first_stamp():
    t, v, idx = _lab()
    held = np.r_[False, idx[1:] == idx[:-1]]
    assert 0.4 < held.mean() < 0.47  # as in the lab file of the issue: 43 %
    rc = clean_rows("lab", t, v)
    assert rc.held == held.sum() and rc.held_candidates == held.sum()
    assert np.array_equal(idx[rc.keep], np.unique(idx))
    clock = fit_clock(t[rc.keep], tick=1e-3)
    assert clock.kind == "noise" and 1 / clock.period == pytest.approx(51.0, rel=1e-4)
    assert np.array_equal(clock.ticks, idx[rc.keep] - idx[0])


def test_a_quiet_sensors_repeats_are_real_samples():
    """A sensor at rest whose quantised output repeats: collapsing would leave a missing
    tick for every repeat, so the clock does not confirm them as held."""
    rng = np.random.default_rng(6)
    v = np.rint(rng.normal(0, 0.4, (N, 3)))
    rc = clean_rows("quiet", np.arange(N) * 0.01, v)
    assert rc.held_candidates > 0.05 * N and rc.held == 0 and rc.keep.size == N
    # and a constant signal (every row the same) is never held
    rc = clean_rows("spin", np.arange(N) * 0.01, np.ones((N, 3)))
    assert rc.held == 0
    # unless asked
    assert clean_rows("spin", np.arange(N) * 0.01, np.ones((N, 3)), held="collapse").held \
        == N - 1


def test_duplicated_stamps():
    t = np.arange(10) * 0.01
    t[6] = t[5]
    v = np.arange(30.0).reshape(10, 3)
    v[6] = v[5]
    rc = clean_rows("dup", t, v)  # identical rows: dropped
    assert rc.duplicates == 1 and 6 not in rc.keep
    v[6, 0] += 1.0  # different rows: an error naming both rows and the option
    with pytest.raises(InputError, match=r"data rows 6 and 7 .*--duplicate-stamps first"):
        clean_rows("dup", t, v)
    assert 5 not in clean_rows("dup", t, v, duplicates="last").keep
    assert 6 not in clean_rows("dup", t, v, duplicates="first").keep


def test_reconstruct_refuses_a_decreasing_stamp_by_row():
    base = relative_times(np.array([0.0, 0.01, 0.005, 0.02]), 1.0)
    with pytest.raises(InputError, match="non-monotonic time stamp in data row 3"):
        reconstruct("log", base, np.zeros((4, 3)))


def test_given_period_that_contradicts_the_stamps_is_refused():
    with pytest.raises(InputError, match="not at the given sample period"):
        fit_clock(np.arange(N) * 0.001, period=1 / 1010)


def test_epoch_stamps_keep_every_digit():
    raw = 1733119200123 + np.arange(5) * 5.0
    base = relative_times(raw, 1e-3)
    assert base.origin_text == "1733119200.123"
    assert base.t.tolist() == [0.0, 0.005, 0.01, 0.015, 0.02]
    assert base.tick == pytest.approx(5e-3)
    assert format_times(base.origin_text, base.t, 6) == [
        "1733119200.123", "1733119200.128", "1733119200.133", "1733119200.138",
        "1733119200.143"]


@given(st.integers(1, 10**13), st.integers(0, 9), st.integers(1, 1000))
def test_integer_stamps_are_made_relative_exactly(first, decimals, step):
    raw = (first + np.arange(50, dtype=np.int64) * step).astype(np.float64)
    base = relative_times(raw / 10.0**decimals, 1.0)
    assert np.allclose(base.t * 10.0**decimals, np.arange(50) * step, rtol=1e-12, atol=0)


def test_a_block_of_identical_rows_at_the_end_is_kept():
    """A log whose sensor stopped and whose last value was repeated for its last rows (as in
    a re-packaged recording): each repeat has a tick of its own, so none is a held sample
    (dropping them would silently cut the log)."""
    rng = np.random.default_rng(8)
    v = rng.normal(size=(N, 6))
    v[-200:] = v[-201]
    rc = clean_rows("tail", np.arange(N) * 0.008, v)
    assert rc.held_candidates == 200 and rc.held == 0 and rc.keep.size == N
