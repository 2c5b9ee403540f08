"""BROAD recordings (Laidig, Caruso, Cereatti & Seel, Data 6(7), 2021; CC BY 4.0).

A BROAD trial (``.mat``) holds ``imu_gyr`` (rad/s), ``imu_acc`` (m/s²),
``imu_mag`` (µT), ``opt_quat`` (optical reference q_ENU_b, scalar first; NaN
where the markers were lost), ``movement`` (1 during motion phases) and
``sampling_rate``.

The error metrics are in :mod:`strapdown.analysis.broad`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

__all__ = ["BroadTrial", "read_broad"]


@dataclass(frozen=True)
class BroadTrial:
    """One BROAD recording (SI units; ``mag`` in µT)."""

    name: str
    t: NDArray[np.float64]
    gyro: NDArray[np.float64]
    acc: NDArray[np.float64]
    mag: NDArray[np.float64]
    q_ref: NDArray[np.float64]
    movement: NDArray[np.bool_]

    @property
    def h(self) -> float:
        return float(self.t[1] - self.t[0])


def read_broad(path: str | os.PathLike[str]) -> BroadTrial:
    """Load a BROAD ``.mat`` trial; errors name what is missing."""
    from scipy.io import loadmat

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    m = loadmat(path)
    need = ("imu_gyr", "imu_acc", "imu_mag", "opt_quat", "movement", "sampling_rate")
    missing = [k for k in need if k not in m]
    if missing:
        raise ValueError(f"{path}: not a BROAD trial (missing {missing})")
    fs = float(np.squeeze(m["sampling_rate"]))
    g = np.asarray(m["imu_gyr"], float)
    n = g.shape[0]
    return BroadTrial(path.stem, np.arange(n) / fs, g, np.asarray(m["imu_acc"], float),
                      np.asarray(m["imu_mag"], float), np.asarray(m["opt_quat"], float),
                      np.asarray(m["movement"], float).reshape(-1) > 0)
