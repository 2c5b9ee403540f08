"""OpenAXES robot recordings (Webering, Fahnemann & Stanislawski (2023), as re-packaged
with the supplementary material of Bachhuber et al. (2024), RING, synchronised to the
reference).

An industrial robot moves two 6-axis IMUs, on its "carpus" and "radius" links, along
circles and triangles at four speed settings. A directory of the data set holds one folder
per motion (``circle-100``, ``triangle-250`` …), each with, per link:

- ``imu_<link>_adx.csv``: a row index (unnamed first column), ``acc_x, acc_y, acc_z``
  (m/s²) and ``gyr_x, gyr_y, gyr_z`` (rad/s), one row per reference row, no time column;
- ``truth_<link>.csv``: ``TIME`` (µs; 8000 µs steps, 125 Hz) and ``QUATERNION_0..3``, the
  link's attitude in the robot's base frame, scalar first.

The IMU's axes are not the link's and the base frame is not ENU: an estimate is compared
with the reference after fitting both constant rotations
(:mod:`strapdown.analysis.alignment`). No magnetometer. Two recordings are suspect
(:data:`SUSPECT`: 35–55° for every filter, a synchronisation fault) and are reported apart.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from strapdown._core.errors import InputError, shown
from strapdown.io.readers import check_finite_rows, csv_columns, csv_header, input_file
from strapdown.rotation.quaternion import quat_conjugate, quat_multiply, rotvec_from_quat

__all__ = ["ACC_COLUMNS", "ENV", "GYRO_COLUMNS", "LINKS", "QUAT_COLUMNS", "SUSPECT",
           "OpenAxesRecording", "list_openaxes", "openaxes_hint", "rate_agreement",
           "read_openaxes"]

#: The environment variable naming the OpenAXES directory (the test suite, the command).
ENV = "STRAPDOWN_OPENAXES"
#: The robot links that carry an IMU.
LINKS = ("carpus", "radius")
ACC_COLUMNS = ("acc_x", "acc_y", "acc_z")
GYRO_COLUMNS = ("gyr_x", "gyr_y", "gyr_z")
QUAT_COLUMNS = ("QUATERNION_0", "QUATERNION_1", "QUATERNION_2", "QUATERNION_3")
#: The recordings the data set's notes call suspect (every filter 35–55° off, a
#: synchronisation fault); :func:`rate_agreement` finds a third (triangle-100-carpus).
SUSPECT = frozenset({"circle-200-radius", "triangle-100-radius"})
_US = 1e-6


@dataclass(frozen=True)
class OpenAxesRecording:
    """One link's recording of one motion (SI units; no magnetometer).

    Attributes
    ----------
    name : str
        ``<motion>-<link>``, e.g. ``circle-200-radius``.
    motion, link : str
    t : ndarray (n,)
        Seconds from the first reference sample (the reference's ``TIME``).
    gyro : ndarray (n, 3)
        Body rates, rad/s.
    acc : ndarray (n, 3)
        Specific force, m/s².
    q_ref : ndarray (n, 4)
        The link's attitude in the robot's base frame, scalar first, unit norm.
    """

    name: str
    motion: str
    link: str
    t: NDArray[np.float64]
    gyro: NDArray[np.float64]
    acc: NDArray[np.float64]
    q_ref: NDArray[np.float64]

    @property
    def h(self) -> float:
        """The median sample period (s)."""
        return float(np.median(np.diff(self.t)))

    @property
    def suspect(self) -> bool:
        """Whether the recording is one of :data:`SUSPECT` (the data set's notes)."""
        return self.name in SUSPECT


def rate_agreement(rec: OpenAxesRecording) -> float:
    """Whether the gyro saw the reference's motion: the correlation coefficient, sample by
    sample, of the gyro's rate magnitude ``|ω|`` with the reference's (its rotation angle
    from each sample to the next over the step; both rates frame-free). About 1 on a
    synchronised recording (≥ 0.99 on 13 of the 16 shared ones); far below where the IMU
    and the reference do not show the same motion at the same time."""
    dq = quat_multiply(quat_conjugate(rec.q_ref[:-1]), rec.q_ref[1:])
    ref = np.linalg.norm(rotvec_from_quat(dq), axis=1) / np.diff(rec.t)
    gyro = np.linalg.norm(rec.gyro[1:], axis=1)
    if ref.size < 2 or np.std(ref) == 0 or np.std(gyro) == 0:
        return float("nan")
    return float(np.corrcoef(ref, gyro)[0, 1])


def openaxes_hint() -> str:
    """What to say after an OpenAXES path that is not there: where the recordings are looked
    for (:data:`ENV`) and what it holds in this environment."""
    value = os.environ.get(ENV)
    now = ("it is not set here" if value is None else "it is empty here" if not value
           else f"it is {value!r} here")
    return (f"the OpenAXES recordings (<motion>/imu_<link>_adx.csv, truth_<link>.csv) are "
            f"the folder ${ENV} names: export {ENV}=/path/to/openaxes ({now})")


def _paths(motion_dir: Path, link: str) -> tuple[Path, Path]:
    return motion_dir / f"imu_{link}_adx.csv", motion_dir / f"truth_{link}.csv"


def list_openaxes(directory: str | os.PathLike[str]) -> list[tuple[Path, str]]:
    """The recordings of an OpenAXES directory: ``(motion folder, link)`` for every motion
    folder holding an IMU or a reference file of a link, sorted by motion then link.

    Raises
    ------
    InputError
        When ``directory`` is not a directory or holds no recording (with where the data
        are looked for, :func:`openaxes_hint`).
    """
    if not str(directory):  # "$STRAPDOWN_OPENAXES" with the variable unset
        raise InputError(f"no OpenAXES directory given; {openaxes_hint()}")
    root = Path(directory)
    if not root.is_dir():
        raise InputError(f"{root}: not a directory; {openaxes_hint()}")
    found = [(d, link) for d in sorted(p for p in root.iterdir() if p.is_dir())
             for link in LINKS if any(f.is_file() for f in _paths(d, link))]
    if not found:
        raise InputError(f"{root}: no OpenAXES recordings (<motion>/imu_<link>_adx.csv with "
                         f"truth_<link>.csv, links {', '.join(LINKS)}); {openaxes_hint()}")
    return found


def _columns(path: Path, names: tuple[str, ...], what: str) -> NDArray[np.float64]:
    """``names`` of the CSV ``path`` (an error naming the file and the missing columns)."""
    header, _ = csv_header(path)
    missing = [c for c in names if c not in header]
    if missing:
        raise InputError(f"{path}: not an OpenAXES {what} file: columns "
                         f"{shown(missing, 100)} missing from the header {shown(header, 160)}")
    values, _, _ = csv_columns(path, names)
    return values


def _check_time(path: Path, us: NDArray[np.float64]) -> None:
    """TIME strictly increasing and uniform (within 1 % of the median step)."""
    d = np.diff(us)
    bad = ~(d > 0)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise InputError(f"{path}: TIME is not increasing at data row {i + 2} "
                         f"({float(us[i + 1])!r} µs after {float(us[i])!r} µs)")
    if d.size:
        step = float(np.median(d))
        off = np.abs(d - step) > 0.01 * step
        if np.any(off):
            i = int(np.argmax(off))
            raise InputError(f"{path}: TIME is not uniform: a step of {float(d[i])!r} µs "
                             f"before data row {i + 2} (the median step is {step!r} µs)")


def read_openaxes(motion_dir: str | os.PathLike[str], link: str) -> OpenAxesRecording:
    """Read one link's recording of one motion (see the module docstring).

    Parameters
    ----------
    motion_dir : path
        The motion's folder (its name is the motion, e.g. ``circle-100``).
    link : {"carpus", "radius"}

    Raises
    ------
    InputError
        Naming the file: a missing file or column, unreadable numbers, NaN or infinity, a
        row count that differs between the IMU and the reference file, a ``TIME`` that does
        not increase uniformly, a zero reference quaternion.
    """
    if link not in LINKS:
        raise InputError(f"unknown OpenAXES link {shown(link)}; the links are "
                         f"{', '.join(LINKS)}")
    motion_dir = Path(motion_dir)
    imu_path, truth_path = _paths(motion_dir, link)
    imu_path = input_file(imu_path, "OpenAXES IMU file (imu_<link>_adx.csv)")
    truth_path = input_file(truth_path, "OpenAXES reference file (truth_<link>.csv)")
    imu = _columns(imu_path, ACC_COLUMNS + GYRO_COLUMNS, "IMU")
    truth = _columns(truth_path, ("TIME", *QUAT_COLUMNS), "reference")
    if imu.shape[0] != truth.shape[0]:
        raise InputError(f"{imu_path}: {imu.shape[0]} data rows, but its reference "
                         f"{truth_path.name} has {truth.shape[0]}: the IMU file has one row "
                         "per reference row")
    check_finite_rows(imu_path, [(None, [imu])])
    check_finite_rows(truth_path, [(None, [truth])])
    _check_time(truth_path, truth[:, 0])
    q = truth[:, 1:5]
    norm = np.linalg.norm(q, axis=1)
    if np.any(norm == 0):
        raise InputError(f"{truth_path}: zero quaternion in data row "
                         f"{int(np.argmax(norm == 0)) + 1}")
    t = (truth[:, 0] - truth[0, 0]) * _US
    c = np.ascontiguousarray
    return OpenAxesRecording(f"{motion_dir.name}-{link}", motion_dir.name, link, t,
                             c(imu[:, 3:6]), c(imu[:, 0:3]), q / norm[:, None])
