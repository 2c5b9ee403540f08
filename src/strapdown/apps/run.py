"""``strapdown run``: attitude from a user's gyro log, streamed, written atomically.

Increment logs run through :class:`strapdown.algorithms.streaming.RotvecStream` in chunks
(``.npy`` logs are memory-mapped, so files larger than memory stream with O(1)
memory); rate logs run through :func:`strapdown.algorithms.rate.rate_attitude`. Output:
``t, qw, qx, qy, qz`` plus yaw/pitch/roll (deg, z-y-x) or cone angles (deg),
as CSV or ``.npz``. Nothing is written when the input fails validation, and
the input file is never overwritten.
"""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray
from tqdm import tqdm

from strapdown._core.kinds import InputKind
from strapdown._core.validation import first_bad_step
from strapdown.algorithms.coning import CoefficientSet
from strapdown.algorithms.family import AlgorithmName, IncrementStructure, StructureName
from strapdown.algorithms.rotvec import Rotvec
from strapdown.algorithms.spec import AlgorithmSpec, CoefficientName, algorithms_taking
from strapdown.algorithms.streaming import RotvecStream
from strapdown.algorithms.structures import increment_structure
from strapdown.io import read_imu
from strapdown.io.files import atomic_path
from strapdown.io.readers import GapPolicy, GyroUnit
from strapdown.rotation.cone_angles import cone_angles_from_quat
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.euler import euler_zyx_from_dcm

__all__ = ["ANGLES", "RUN_GAP_POLICIES", "AngleOutput", "RunGapPolicy", "run_log"]

CHUNK = 1 << 16

#: Angles written beside the quaternion: yaw/pitch/roll (z-y-x), cone angles, or none.
AngleOutput = Literal["ypr", "cone", "none"]
ANGLES: tuple[AngleOutput, ...] = get_args(AngleOutput)
#: What ``run`` does at a gap: the reader's policies, or ``split`` (each gap-free segment
#: runs on its own).
RunGapPolicy = Literal[GapPolicy, "split"]
RUN_GAP_POLICIES: tuple[RunGapPolicy, ...] = get_args(RunGapPolicy)


def _angles(q: NDArray[np.float64], kind: AngleOutput) -> dict[str, NDArray[np.float64]]:
    if kind == "ypr":
        y, p, r = euler_zyx_from_dcm(dcm_from_quat(q))
        return {"yaw_deg": np.degrees(y), "pitch_deg": np.degrees(p), "roll_deg": np.degrees(r)}
    if kind == "cone":
        d1, d2, d3 = cone_angles_from_quat(q)
        return {"delta1_deg": np.degrees(d1), "delta2_deg": np.degrees(d2),
                "delta3_deg": np.degrees(d3)}
    return {}


def _rows(t: NDArray[np.float64], q: NDArray[np.float64],
          angles: AngleOutput) -> NDArray[np.float64]:
    cols = [t, q[:, 0], q[:, 1], q[:, 2], q[:, 3], *_angles(q, angles).values()]
    return np.column_stack(cols)


def _header(angles: AngleOutput) -> str:
    names = ["t", "qw", "qx", "qy", "qz", *_angles(np.array([[1.0, 0, 0, 0]]), angles)]
    return ",".join(names)


def _npy_chunks(path: Path, units: GyroUnit, read: dict[str, Any], gaps: list[int],
                saturated: list[int]
                ) -> Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Validated (t, increments) chunks of an (n, 4) .npy log, memory-mapped.

    Gaps (intervals over ``gap_tolerance`` times the first interval — a
    streamed log has no median) and saturated rows are appended to ``gaps``
    and ``saturated`` as the chunks go by; ``on_gap="error"`` raises at the first gap.
    """
    arr = np.load(path, mmap_mode="r")
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise ValueError(f"{path}: .npy logs must be (n, 4) [t, gx, gy, gz], got {arr.shape}")
    scale = np.pi / 180.0 if units == "deg" else 1.0
    last = None
    h = None
    for s in range(0, arr.shape[0], CHUNK):
        c = np.array(arr[s:s + CHUNK], dtype=np.float64)
        bad = ~np.all(np.isfinite(c), axis=1)
        if np.any(bad):
            raise ValueError(f"{path}: NaN or infinity in data row {s + int(np.argmax(bad)) + 1}")
        t = c[:, 0] if last is None else np.concatenate([[last], c[:, 0]])
        d = np.diff(t)
        first = 1 if last is None else 0  # data row (1-based) of t[0] is s + first
        fault = first_bad_step(d)
        if fault is not None:
            k, what = fault
            raise ValueError(f"{path}: {what} time stamp in data row {s + k + first + 1}")
        if h is None and d.size:
            h = float(d[0])
        if h is not None:
            for i in np.flatnonzero(d > read["gap_tolerance"] * h):
                row = s + int(i) + first + 1
                if read["on_gap"] == "error":
                    raise ValueError(f"{path}: gap of {d[i]:.6g} s ({d[i] / h:.1f} sample "
                                     f"intervals) before data row {row}")
                gaps.append(row)
        if read["saturation"] is not None:
            hit = np.flatnonzero(np.any(np.abs(c[:, 1:]) >= read["saturation"], axis=1))
            saturated.extend(int(s + i + 1) for i in hit)
        last = c[-1, 0]
        yield c[:, 0], c[:, 1:] * scale


def run_log(imu: str | os.PathLike[str], out: str | os.PathLike[str], *, kind: InputKind,
            units: GyroUnit | None, algorithm: AlgorithmName = "rotvec",
            structure: StructureName = "conventional", subsamples: int = 3,
            coefficients: CoefficientName | None = None,
            columns: Sequence[str] = ("t", "gx", "gy", "gz"),
            sample_rate_hz: float | None = None, angles: AngleOutput = "ypr",
            q0: ArrayLike | None = None, on_gap: RunGapPolicy = "report",
            gap_tolerance: float = 1.5, saturation: float | None = None,
            progress: bool = False) -> dict[str, Any]:
    """Process a log; returns a summary (samples, outputs, gaps, saturated rows, warnings).

    Parameters
    ----------
    on_gap : {"report", "error", "split"}
        ``split`` runs each gap-free segment separately (each starting from the
        previous segment's last attitude, no increment or rate spanning the gap)
        and adds a ``segment`` column.
    saturation : float, optional
        Sensor range in the declared unit; saturated rows are reported.
    progress : bool
        Show a progress bar (tqdm, on stderr).
    """
    imu_path, out_path = Path(imu), Path(out)
    if out_path.resolve() == imu_path.resolve():
        raise ValueError("--out must not be the input file")
    if out_path.suffix.lower() not in (".csv", ".npz"):
        raise ValueError(f"{out_path}: output must be .csv or .npz")
    if angles not in ANGLES:
        raise ValueError(f"angles must be ypr, cone or none, got {angles!r}")
    if on_gap not in RUN_GAP_POLICIES:
        raise ValueError(f"on_gap must be report, error or split, got {on_gap!r}")
    spec = AlgorithmSpec(algorithm, subsamples=subsamples, coefficients=coefficients,
                         structure=structure)
    if spec.family.stepped:
        raise ValueError(f"{algorithm} runs on reference motions only (its input is the Krylov "
                         "model's increments at thirds or halves of a step)")
    if spec.input_kind == "increment" and kind != "increment":
        raise ValueError(f"{algorithm} takes increments (--increments); for rate logs use "
                         f"{', '.join(algorithms_taking('rate'))}")
    if spec.input_kind == "rate" and kind != "rate":
        raise ValueError(f"{algorithm} takes rate samples (--rates)")
    read = {"kind": kind, "units": units, "columns": columns, "sample_rate_hz": sample_rate_hz,
            "gap_tolerance": gap_tolerance, "on_gap": "error" if on_gap == "error" else "report",
            "saturation": saturation}
    fam = spec.family
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if spec.input_kind == "rate":
            res = _run_rates(imu_path, out_path, read, spec, angles, q0, on_gap == "split")
        elif isinstance(fam, Rotvec):  # the one increment family that runs on a log
            res = _run_increments(imu_path, out_path, read, increment_structure(structure),
                                  fam.coefficient_set(spec), angles, q0, on_gap == "split",
                                  progress)
        else:
            raise ValueError(f"{algorithm} does not run on a log; use rotvec or "
                             f"{', '.join(algorithms_taking('rate'))}")
    res["warnings"] = [str(w.message) for w in caught]
    return res


def _run_increments(imu: Path, out: Path, read: dict[str, Any], structure: IncrementStructure,
                    cs: CoefficientSet, angles: AngleOutput, q0: ArrayLike | None, split: bool,
                    progress: bool) -> dict[str, Any]:
    if imu.suffix.lower() == ".npy" and not split:
        if read["units"] is None:
            raise ValueError(f"{imu}: .npy logs carry no units; pass --units")
        total = np.load(imu, mmap_mode="r").shape[0]
        gaps: list[int] = []
        saturated: list[int] = []
        segments: list[Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]] = [
            _npy_chunks(imu, read["units"], read, gaps, saturated)]
        h_log = 1.0
    else:
        log = read_imu(imu, **read)
        total, gaps, saturated, h_log = log.t.size, log.gaps, log.saturated, log.h
        cuts = log.segments() if split else [slice(0, log.t.size)]
        segments = [((log.t[c][s:s + CHUNK], log.data[c][s:s + CHUNK])
                     for s in range(0, c.stop - c.start, CHUNK)) for c in cuts]
    csv_out = out.suffix.lower() == ".csv"
    names = _header(angles).split(",") + (["segment"] if split else [])
    n_in = n_out = 0
    q_last = q0
    with atomic_path(out) as tmp, tqdm(total=total, disable=not progress, unit="sample",
                                       unit_scale=True, file=sys.stderr) as bar:
        parts = []
        with open(tmp, "w", encoding="utf-8") as f:
            if csv_out:
                f.write(",".join(names) + "\n")
            for k, chunks in enumerate(segments):
                stream = None
                for t, th in chunks:
                    if stream is None:
                        h = float(t[1] - t[0]) if t.size > 1 else h_log
                        stream = RotvecStream(structure, cs, h=h, t0=float(t[0]) - h, q0=q_last)
                    res = stream.feed(th)
                    n_in += th.shape[0]
                    bar.update(th.shape[0])
                    if res.q.shape[0]:
                        rows = _rows(res.t, res.q, angles)
                        if split:
                            rows = np.column_stack([rows, np.full(rows.shape[0], float(k))])
                        n_out += rows.shape[0]
                        if csv_out:
                            np.savetxt(f, rows, delimiter=",", fmt="%.17g")
                        else:
                            parts.append(rows)
                        q_last = res.q[-1]
        if n_in == 0:
            raise ValueError(f"{imu}: no samples")
        if not csv_out:
            table = np.concatenate(parts) if parts else np.empty((0, len(names)))
            # Any: np.savez's column keywords share its signature with allow_pickle: bool
            columns: dict[str, Any] = {k: table[:, i] for i, k in enumerate(names)}
            with open(tmp, "wb") as f:
                np.savez(f, **columns)
    return {"samples": n_in, "outputs": n_out, "gaps": gaps, "saturated": saturated}


def _run_rates(imu: Path, out: Path, read: dict[str, Any], spec: AlgorithmSpec,
               angles: AngleOutput, q0: ArrayLike | None, split: bool) -> dict[str, Any]:
    from strapdown.io import write_attitude

    log = read_imu(imu, **read)
    cuts = log.segments() if split else [slice(0, log.t.size)]
    ts, qs, segs = [], [], []
    q_last = q0
    for k, c in enumerate(cuts):
        sol = spec.run_rates(log.t[c], log.data[c], q0=q_last)
        ts.append(sol.t)
        qs.append(sol.q)
        segs.append(np.full(sol.t.size, float(k)))
        q_last = sol.q[-1]
    t, q = np.concatenate(ts), np.concatenate(qs)
    extra = _angles(q, angles)
    if split:
        extra["segment"] = np.concatenate(segs)
    write_attitude(out, t, q, extra=extra)
    return {"samples": int(log.t.size), "outputs": int(t.size), "gaps": log.gaps,
            "saturated": log.saturated}
