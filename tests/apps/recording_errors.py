"""Attitude errors of a command's output against a recording's truth or a file's own
reference, for the acceptance tests of issue 24 (recordings as devices write them)."""

from __future__ import annotations

import contextlib
import io
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Slerp

from strapdown._core.compile_notice import MESSAGE
from strapdown.cli import main
from strapdown.rotation.error import attitude_error_angle
from strapdown.rotation.interop import quat_from_scipy, scipy_from_quat


@dataclass(frozen=True)
class Run:
    """A command's exit status, what it wrote on stderr (without the one-off notice of a
    cold numba cache) and the output path it was given."""

    code: int | str | None
    err: str
    out: Path


def strapdown(out: os.PathLike[str] | str, *args: object) -> Run:
    """Run ``strapdown ARGS --out OUT`` in-process, stderr captured."""
    buf = io.StringIO()
    with contextlib.redirect_stderr(buf):
        try:
            code: int | str | None = main([*map(str, args), "--out", str(out)])
        except SystemExit as exc:
            code = exc.code
    err = "".join(ln for ln in buf.getvalue().splitlines(keepends=True)
                  if ln.rstrip("\n") != MESSAGE)
    return Run(code, err, Path(out))


def read_attitude(path: os.PathLike[str] | str
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """An attitude output's ``t`` (s) and ``qw, qx, qy, qz`` columns."""
    d = np.genfromtxt(path, delimiter=",", names=True)
    return (np.asarray(d["t"], float),
            np.column_stack([d["qw"], d["qx"], d["qy"], d["qz"]]).astype(float))


@dataclass(frozen=True)
class Errors:
    """RMS and largest error angle (deg) over ``n`` outputs."""

    rms: float
    max: float
    n: int

    def __str__(self) -> str:
        return f"RMS {self.rms:.3f}°, max {self.max:.3f}° over {self.n} outputs"


def errors(q_est: NDArray[np.float64], q_true: NDArray[np.float64]) -> Errors:
    """RMS and largest angle of ``q_est ⊗ q_true*``, deg."""
    e = np.degrees(attitude_error_angle(q_est, q_true))
    return Errors(float(np.sqrt(np.mean(e ** 2))), float(e.max()), int(e.size))


def truth_errors(out: os.PathLike[str] | str,
                 truth: Callable[[NDArray[np.float64]], NDArray[np.float64]], *,
                 after: float = -np.inf) -> Errors:
    """Errors of the output ``out`` against ``truth(t)`` (q_n_b at the output's times),
    over the outputs at ``t >= after``."""
    t, q = read_attitude(out)
    keep = t >= after
    return errors(q[keep], truth(t[keep]))


def read_lab_reference(path: os.PathLike[str] | str
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A lab file's time column and reference quaternion (columns 0 and W, X, Y, Z: 1–4),
    below its two header rows, each stamp once."""
    data = np.loadtxt(path, delimiter=";", skiprows=2, ndmin=2)
    t, first = np.unique(data[:, 0], return_index=True)
    return t, data[first, 1:5]


def reference_errors(out: os.PathLike[str] | str, t_ref: NDArray[np.float64],
                     q_ref: NDArray[np.float64], *, after: float = -np.inf,
                     max_span: float = 0.025) -> Errors:
    """Errors of the output ``out`` against a reference sampled at ``t_ref``, interpolated
    by slerp at the output's times; outputs after ``after`` whose neighbouring reference
    samples lie within ``max_span`` s of each other (not across the reference's own gaps)."""
    t, q = read_attitude(out)
    keep = (t >= max(after, t_ref[0])) & (t <= t_ref[-1])
    j = np.clip(np.searchsorted(t_ref, t, side="right"), 1, t_ref.size - 1)
    keep &= (t_ref[j] - t_ref[j - 1]) <= max_span
    q_at = quat_from_scipy(Slerp(t_ref, scipy_from_quat(q_ref))(t[keep]))
    return errors(q[keep], q_at)
