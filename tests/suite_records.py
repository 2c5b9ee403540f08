"""Recordings of the generalisation suite cut for a test, shared by the library's and the C
export's tests (one definition, so that both check the same record)."""

from __future__ import annotations

import numpy as np

__all__ = ["clipped_pendulum", "released_pendulum", "steep_soft_iron_pendulum", "suite_record"]


def suite_record(name: str, seed: int = 0, duration_s: float | None = None):
    """The recording of the suite's scenario ``name`` for ``seed``, as the benchmarks draw it
    (``SeedSequence([seed, k])``, k its place in the suite), the first ``duration_s``
    seconds of it (all by default)."""
    from strapdown.truth.scenarios import record, suite

    k, sc = next((k, s) for k, s in enumerate(suite(seed)) if s.name == name)
    return record(sc, np.random.SeedSequence([seed, k]), duration_s=duration_s)


def released_pendulum(still_s: float = 0.35):
    """The suite's 0.8 m pendulum (seed 0, its first 8 s), cut ``still_s`` before its
    release: a record that starts still and swings from within its initial window. Returns
    t, gyro, acc, mag and the truth."""
    rec = suite_record("pendulum-0.8m-45deg", duration_s=8.0)
    moving = np.linalg.norm(rec.gyro - rec.gyro[:50].mean(axis=0), axis=1) > 0.05
    i0 = int(np.searchsorted(rec.t, rec.t[np.argmax(moving)] - still_s))
    g, a, m = (np.ascontiguousarray(x[i0:]) for x in (rec.gyro, rec.acc, rec.mag))
    return rec.t[i0:] - rec.t[i0], g, a, m, rec.q_n_b[i0:]


def clipped_pendulum(seed: int = 0, fraction: float = 0.6, duration_s: float | None = None):
    """The suite's 0.3 m pendulum swung 70° (100 Hz), read by a gyro clipped at ``fraction``
    of its peak rate (0.6: 3.3 rad/s, every swing clipped). Returns t, gyro, acc, mag, the
    truth and the clip level (rad/s)."""
    rec = suite_record("pendulum-0.3m-70deg", seed, duration_s)
    level = fraction * float(np.abs(rec.gyro).max())
    return rec.t, np.clip(rec.gyro, -level, level), rec.acc, rec.mag, rec.q_n_b, level


def steep_soft_iron_pendulum(soft_iron: float = 0.08, duration_s: float = 20.0):
    """The suite's 0.3 m pendulum swung 70° (seed 0) in a uniform field of 72° dip
    (RepoIMU's pendulum lab), read by a magnetometer whose x and y axes are scaled by
    1 ± ``soft_iron``. Returns t, gyro, acc, mag and the truth."""
    import math
    from dataclasses import replace

    from strapdown.truth.scenarios import pendulum, record

    dip = math.radians(72.0)
    b = 50.0 * np.array([0.0, math.cos(dip), -math.sin(dip)])
    sc = pendulum(0.3, 70.0, duration_s=duration_s)
    sc = replace(sc, body=replace(sc.body,
                                  field=lambda r: np.broadcast_to(b, np.shape(r)).copy()))
    rec = record(sc, 0)
    mag = rec.mag @ np.diag([1.0 + soft_iron, 1.0 - soft_iron, 1.0])
    return rec.t, rec.gyro, rec.acc, mag, rec.q_n_b
