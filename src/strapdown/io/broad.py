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

import numpy as np
from numpy.typing import NDArray

from strapdown._core.errors import InputError
from strapdown.io.containers import read_mat

__all__ = ["ENV", "BroadTrial", "broad_hint", "read_broad"]

#: The environment variable naming the folder of BROAD trials (README, the test suite).
ENV = "STRAPDOWN_BROAD"


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


def broad_hint() -> str:
    """What to say after a BROAD path that is not there: where the trials are looked for
    (:data:`ENV`) and what it holds in this environment."""
    value = os.environ.get(ENV)
    now = ("it is not set here" if value is None else "it is empty here" if not value
           else f"it is {value!r} here")
    return (f"the BROAD trials (NN_*.mat) are the folder ${ENV} names: export {ENV}="
            f"/path/to/broad ({now})")


def read_broad(path: str | os.PathLike[str]) -> BroadTrial:
    """Load a BROAD ``.mat`` trial (read by :func:`strapdown.io.containers.read_mat`, which
    validates the file's structure first); errors name the file and what is missing."""
    from strapdown.io.readers import file_rate, input_file

    path = input_file(path, "BROAD trial (.mat)")
    need = ("imu_gyr", "imu_acc", "imu_mag", "opt_quat", "movement", "sampling_rate")
    c = read_mat(path, need)
    m = c.arrays
    missing = [k for k in need if k not in m]
    if missing:
        raise InputError(f"{path}: not a BROAD trial (missing {missing}; found {c.found()})")
    fs = file_rate(path, m["sampling_rate"])
    assert fs is not None
    g = m["imu_gyr"]
    n = g.shape[0]
    for k in ("imu_gyr", "imu_acc", "imu_mag", "opt_quat"):
        want = 4 if k == "opt_quat" else 3
        if m[k].ndim != 2 or m[k].shape != (n, want):
            raise InputError(f"{path}: {k} must have shape ({n}, {want}), got {m[k].shape}")
    if m["movement"].size != n:
        raise InputError(f"{path}: movement must have {n} values, got {m['movement'].size}")
    return BroadTrial(path.stem, np.arange(n) / fs, g, m["imu_acc"], m["imu_mag"],
                      m["opt_quat"], m["movement"].reshape(-1) > 0)
