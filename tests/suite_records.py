"""Recordings of the generalisation suite cut for a test, shared by the library's and the C
export's tests (one definition, so that both check the same record)."""

from __future__ import annotations

import numpy as np

__all__ = ["clipped_pendulum", "released_pendulum"]


def released_pendulum(still_s: float = 0.35):
    """The suite's 0.8 m pendulum (seed 0, its first 8 s), cut ``still_s`` before its
    release: a record that starts still and swings from within its initial window. Returns
    t, gyro, acc, mag and the truth."""
    from strapdown.truth.scenarios import record, suite

    k, sc = next((k, s) for k, s in enumerate(suite(0)) if s.name == "pendulum-0.8m-45deg")
    rec = record(sc, np.random.SeedSequence([0, k]), duration_s=8.0)
    moving = np.linalg.norm(rec.gyro - rec.gyro[:50].mean(axis=0), axis=1) > 0.05
    i0 = int(np.searchsorted(rec.t, rec.t[np.argmax(moving)] - still_s))
    g, a, m = (np.ascontiguousarray(x[i0:]) for x in (rec.gyro, rec.acc, rec.mag))
    return rec.t[i0:] - rec.t[i0], g, a, m, rec.q_n_b[i0:]


def clipped_pendulum(seed: int = 0, fraction: float = 0.6, duration_s: float | None = None):
    """The suite's 0.3 m pendulum swung 70° (100 Hz), read by a gyro clipped at ``fraction``
    of its peak rate (0.6: 3.3 rad/s, every swing clipped). Returns t, gyro, acc, mag, the
    truth and the clip level (rad/s)."""
    from strapdown.truth.scenarios import record, suite

    k, sc = next((k, s) for k, s in enumerate(suite(seed)) if s.name == "pendulum-0.3m-70deg")
    rec = record(sc, np.random.SeedSequence([seed, k]), duration_s=duration_s)
    level = fraction * float(np.abs(rec.gyro).max())
    return rec.t, np.clip(rec.gyro, -level, level), rec.acc, rec.mag, rec.q_n_b, level
