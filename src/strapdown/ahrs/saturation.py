"""A gyro past its range: the rate it reads stops at its full scale while the body turns on.

No filter sees the rotation beyond the range: the attitude misses it, by degrees per
plateau, until the accelerometer and the magnetometer pull it back. RepoIMU's T-stick
(Szczęsna et al. (2016)) clips at 7.35 rad/s on its x axis on up to a fifth of a trial's
samples, and every filter is tens of degrees off there (docs/reproductions.md, "RepoIMU's
T-stick"). :func:`gyro_plateaus` finds the signature in a record and :func:`ekf
<strapdown.ahrs.ekf>` and :func:`offline_ekf <strapdown.ahrs.offline_ekf>` warn with it
(:class:`GyroSaturationWarning`), and near a clipped sample (:func:`clipped`, at the range
:func:`gyro_range` or ``AhrsConfig.gyro_range``) both distrust the attitude the gyro carried:
``ekf`` suspends its low-pass accelerometer's norm test, ``offline_ekf`` takes its tilt from
the accelerometer directly (``AhrsConfig.gyro_clip_s``).

The signature, per axis: plateaus near the axis's largest rate — at least :data:`MIN_RUN`
samples whose rate changes by no more than :data:`FLAT` of itself per sample — each entered
by a step of at least :data:`STEP` of the level, at least :data:`MIN_RUNS` of them, at a
level of at least :data:`MIN_LEVEL`. A smooth peak cannot be both: flat over three samples
needs a second difference below 0.2 % of the rate per sample², and a step of 2 % into it one
of 1.8 %. A steady turn or spin is flat but is not entered by a step (the suite's loiter,
0.06–0.17 rad/s, and its spin at 9.4 rad/s give none), and a robot's constant-rate legs
(OpenAXES, 0.2–0.45 rad/s, two to three plateaus) lie below :data:`MIN_LEVEL`. Measured
[m]: none on BROAD's fifteen trials, OpenAXES's sixteen recordings and the suite (seeds 0–4);
tests 05 and 10 of the T-stick (25–34 plateaus each, 112–1189 samples); RepoIMU's pendulum,
whose third segments clip at 10.3–10.5 rad/s on 2–26 samples, is not found (its plateaus
wander by more than :data:`FLAT`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from strapdown.ahrs import _kernel as K

__all__ = ["FLAT", "MIN_LEVEL", "MIN_RUN", "MIN_RUNS", "NEAR", "STEP", "GyroSaturationWarning",
           "Plateaus", "clipped", "gyro_plateaus", "gyro_range", "warn_if_saturated"]

#: Largest change per sample, relative to the rate, within a plateau.
FLAT = 0.002
#: Smallest step, relative to the level, that enters a plateau.
STEP = 0.02
#: Plateaus count within this fraction of the axis's largest |rate|.
NEAR = 0.9
#: Samples in a plateau, at least.
MIN_RUN = 3
#: Plateaus on an axis, at least.
MIN_RUNS = 2
#: Smallest level, rad/s: below every MEMS gyro's full scale (the smallest common one,
#: 125 °/s, is 2.18 rad/s).
MIN_LEVEL = 2.0

_AXES = "xyz"


class GyroSaturationWarning(UserWarning):
    """The gyro looks clipped at its range (:func:`gyro_plateaus`): the rotation beyond it
    is missing from every attitude there, ours and any other filter's."""


@dataclass(frozen=True)
class Plateaus:
    """An axis whose rate stops at a level: ``axis`` (0–2), the number of plateaus
    ``runs``, the mean of their levels ``level`` (|rate|, rad/s) and their ``samples`` in
    all."""

    axis: int
    runs: int
    level: float
    samples: int


def gyro_plateaus(omega: ArrayLike) -> list[Plateaus]:
    """The axes of a gyro record (rad/s, shape (n, 3)) that show a clipped gyro's
    signature (module docstring); empty when none does. One compiled pass over the record
    (:func:`strapdown.ahrs._kernel.gyro_plateau_runs`): it runs before every
    :func:`~strapdown.ahrs.ekf`."""
    w = np.ascontiguousarray(omega, dtype=np.float64)
    if w.ndim != 2 or w.shape[1] != 3:
        raise ValueError(f"omega must have shape (n, 3), got {w.shape}")
    runs, samples, level = np.zeros(3, np.int64), np.zeros(3, np.int64), np.zeros(3)
    K.gyro_plateau_runs(w, NEAR, FLAT, STEP, MIN_RUN, runs, samples, level)
    return [Plateaus(a, int(runs[a]), float(level[a]), int(samples[a])) for a in range(3)
            if runs[a] >= MIN_RUNS and level[a] >= MIN_LEVEL]


def gyro_range(found: list[Plateaus]) -> float:
    """The range a record's gyro clips at: the lowest level among the axes ``found``
    (:func:`gyro_plateaus`; one range for all three axes, as a MEMS gyro's full scale
    is), 0 when none is."""
    return min((p.level for p in found), default=0.0)


def clipped(omega: ArrayLike, level: float) -> np.ndarray:
    """The samples of ``omega`` (rad/s, shape (n, 3)) at a gyro range ``level`` (rad/s):
    an axis's rate at :data:`~strapdown.ahrs._kernel.CLIP_NEAR` (0.98) of it or beyond, as
    :func:`~strapdown.ahrs.ekf`'s kernel takes them. Boolean, shape (n,); all False when
    ``level`` is 0 or infinite (no range known)."""
    w = np.asarray(omega, dtype=np.float64)
    if not 0.0 < level < np.inf:
        return np.zeros(w.shape[0], dtype=bool)
    return np.any(np.abs(w) >= K.CLIP_NEAR * level, axis=1)


def warn_if_saturated(omega: ArrayLike, where: str) -> list[Plateaus]:
    """Warn (:class:`GyroSaturationWarning`) about every axis :func:`gyro_plateaus` finds,
    naming ``where`` (the function the record went to); returns them."""
    found = gyro_plateaus(omega)
    for p in found:
        warnings.warn(
            f"{where}: gyro axis {_AXES[p.axis]} stops at {p.level:.3g} rad/s "
            f"({np.degrees(p.level):.0f} °/s) on {p.samples} samples in {p.runs} plateaus, "
            f"each entered by a step: it looks clipped at its range, and the rotation beyond "
            f"it is missing from the attitude there (a gyro range above the motion's rate "
            f"avoids it)", GyroSaturationWarning, stacklevel=3)
    return found
