"""``strapdown run``: attitude from a user's gyro log, streamed, written atomically with its
metadata.

Increment logs run through :class:`strapdown.algorithms.streaming.RotvecStream` in chunks
(``.npy`` logs are memory-mapped, so files larger than memory stream with O(1)
memory); rate logs run on a uniform grid (jittered stamps: the nominal period, or
resampled; :func:`strapdown.algorithms.rate.check_rate_record`). Output: ``t, qw, qx, qy,
qz`` (q_n_b) plus yaw/pitch/roll (deg, z-y-x) or cone angles (deg), one row per attitude
update (rate-three: every 3 samples, rk4: every 2), as CSV or ``.npz``, and
``OUT.meta.json`` beside it: input, algorithm, samples, outputs, update and sample period,
jitter, gaps, saturation, warnings, version — written so that a failure never leaves one
without the other (:mod:`strapdown.apps._logs`). Nothing is written when the input fails
validation, when magnitudes suggest another unit than declared (unless accepted) or when
the result is not finite, and the input file is never overwritten.
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

from strapdown._core.errors import InputError, shown
from strapdown._core.kinds import InputKind
from strapdown.algorithms.family import StructureName
from strapdown.algorithms.rotvec import Rotvec
from strapdown.algorithms.spec import (
    AlgorithmName,
    AlgorithmSpec,
    CoefficientName,
    algorithms_taking,
)
from strapdown.algorithms.streaming import RotvecStream
from strapdown.algorithms.structures import increment_structure
from strapdown.apps._logs import check_finite, output_with_sidecar, rate_records, unit_action
from strapdown.io import read_imu
from strapdown.io.readers import (
    GapPolicy,
    GyroUnit,
    check_motion,
    check_read_options,
    check_steps,
    input_file,
    npy_log,
    warn_implausible_rate,
)
from strapdown.rotation.cone_angles import cone_angles_from_quat
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.euler import euler_zyx_from_dcm

__all__ = ["ANGLES", "DEFAULT_ALGORITHM", "RUN_GAP_POLICIES", "AngleOutput", "RunGapPolicy",
           "run_log"]

CHUNK = 1 << 16

#: Angles written beside the quaternion: yaw/pitch/roll (z-y-x), cone angles, or none.
AngleOutput = Literal["ypr", "cone", "none"]
ANGLES: tuple[AngleOutput, ...] = get_args(AngleOutput)
#: What ``run`` does at a gap: the reader's policies, or ``split`` (each gap-free segment
#: runs on its own).
RunGapPolicy = Literal[GapPolicy, "split"]
RUN_GAP_POLICIES: tuple[RunGapPolicy, ...] = get_args(RunGapPolicy)
#: The algorithm a log runs without --algorithm, by what it holds.
DEFAULT_ALGORITHM: dict[InputKind, AlgorithmName] = {"rate": "rate-three", "increment": "rotvec"}


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


def _npy_chunks(path: Path, arr: NDArray[Any], units: GyroUnit, read: dict[str, Any],
                gaps: list[int], saturated: list[int]
                ) -> Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Validated (t, increments) chunks of an (n, 4) .npy log, memory-mapped.

    The checks of :func:`strapdown.io.read_imu`, chunk by chunk: finite rows, time steps
    (:func:`~strapdown.io.readers.check_steps`), no sample over π
    (:func:`~strapdown.io.readers.check_motion`). Gaps (intervals over ``gap_tolerance``
    times the nominal period, or the first interval — a streamed log has no median) and
    saturated rows are appended to ``gaps`` and ``saturated`` as the chunks go by;
    ``on_gap="error"`` raises at the first gap. The unit plausibility check
    (``read["unit_check"]``) judges the first chunk.
    """
    scale = np.pi / 180.0 if units == "deg" else 1.0
    last = None
    h = None if read["sample_rate_hz"] is None else 1.0 / read["sample_rate_hz"]
    for s in range(0, arr.shape[0], CHUNK):
        c = np.array(arr[s:s + CHUNK], dtype=np.float64)
        bad = ~np.all(np.isfinite(c), axis=1)
        if np.any(bad):
            raise InputError(f"{path}: NaN or infinity in data row {s + int(np.argmax(bad)) + 1}")
        t = c[:, 0] if last is None else np.concatenate([[last], c[:, 0]])
        with np.errstate(over="ignore", invalid="ignore"):  # an overflowing step is reported
            d = np.diff(t)
        first = 1 if last is None else 0  # data row (1-based) of t[0] is s + first
        check_steps(path, d, t, s + first)
        if h is None and d.size:
            h = float(d[0])
        if h is not None:
            if last is None:
                with np.errstate(over="ignore"):  # refused by check_motion below
                    rate = c[:, 1:] * (scale / h)
                warn_implausible_rate(path, rate, units, action=read["unit_check"])
            check_motion(path, c[:, 1:] * scale, "increment", h, s + 1)
            for i in np.flatnonzero(d > read["gap_tolerance"] * h):
                row = s + int(i) + first + 1
                if read["on_gap"] == "error":
                    raise InputError(f"{path}: gap of {d[i]:.6g} s ({d[i] / h:.1f} sample "
                                     f"intervals) before data row {row}")
                gaps.append(row)
        if read["saturation"] is not None:
            hit = np.flatnonzero(np.any(np.abs(c[:, 1:]) >= read["saturation"], axis=1))
            saturated.extend(int(s + i + 1) for i in hit)
        last = c[-1, 0]
        yield c[:, 0], c[:, 1:] * scale


def _spec(kind: InputKind, algorithm: AlgorithmName | None, structure: StructureName,
          subsamples: int | None, coefficients: CoefficientName | None) -> AlgorithmSpec:
    """The algorithm a log runs: by default rate-three for rates, rotvec for increments;
    options that do not apply to it are errors."""
    if kind not in ("rate", "increment"):
        raise InputError(f"kind must be 'rate' or 'increment', got {kind!r}")
    name: AlgorithmName = algorithm or DEFAULT_ALGORITHM[kind]
    spec = AlgorithmSpec(name, subsamples=3 if subsamples is None else subsamples,
                         coefficients=coefficients, structure=structure)
    if subsamples is not None and "subsamples" not in spec.family.options:
        raise InputError(f"--subsamples does not apply to {name} (only rotvec has subsamples "
                         "per update)")
    if spec.family.stepped:
        raise InputError(f"{name} runs on reference motions only (its input is the Krylov "
                         "model's increments at thirds or halves of a step)")
    if spec.input_kind == "increment" and kind != "increment":
        raise InputError(f"{name} takes increments (--increments); for rate logs use "
                         f"{', '.join(algorithms_taking('rate'))}")
    if spec.input_kind == "rate" and kind != "rate":
        raise InputError(f"{name} takes rate samples (--rates)")
    if not isinstance(spec.family, Rotvec) and spec.input_kind == "increment":
        raise InputError(f"{name} does not run on a log; use rotvec or "
                         f"{', '.join(algorithms_taking('rate'))}")
    return spec


def run_log(imu: str | os.PathLike[str], out: str | os.PathLike[str], *, kind: InputKind,
            units: GyroUnit | None, algorithm: AlgorithmName | None = None,
            structure: StructureName = "conventional", subsamples: int | None = None,
            coefficients: CoefficientName | None = None, columns: Sequence[str] | None = None,
            sample_rate_hz: float | None = None, angles: AngleOutput = "ypr",
            q0: ArrayLike | None = None, on_gap: RunGapPolicy = "report",
            gap_tolerance: float = 1.5, saturation: float | None = None,
            progress: bool = False, resample: bool = False,
            accept_unit_warning: bool = False, delimiter: str | None = None) -> dict[str, Any]:
    """Process a log and write ``out`` with its metadata sidecar ``OUT.meta.json``.

    Returns the metadata (input, algorithm, samples, outputs, update and sample period,
    jitter, gaps, saturated rows, warnings, version).

    Parameters
    ----------
    algorithm : str, optional
        Default: ``rate-three`` for rates, ``rotvec`` for increments.
    subsamples : int, optional
        N of ``rotvec`` (default 3); an error for algorithms without subsamples.
    columns : four CSV column names, optional
        Default: found in the header (:func:`strapdown.io.read_imu`).
    sample_rate_hz : float, optional
        The sensor's rate: the nominal period of a rate log's (jittered) stamps, the
        increment interval of an increment log, the time base of a log without stamps.
    on_gap : {"report", "error", "split"}
        ``split`` runs each gap-free segment separately (each starting from the
        previous segment's last attitude, no increment or rate spanning the gap)
        and adds a ``segment`` column. A rate log with a gap needs ``split``.
    saturation : float, optional
        Sensor range in the declared unit; saturated rows are reported.
    progress : bool
        Show a progress bar (tqdm, on stderr).
    resample : bool
        Rate logs: interpolate jittered rates onto the uniform grid
        (:func:`strapdown.algorithms.rate.check_rate_record`) instead of taking them to lie
        on it.
    accept_unit_warning : bool
        Run although magnitudes suggest another unit than declared (else an error).
    delimiter : str, optional
        A CSV's delimiter (default: detected from its header row).

    Raises
    ------
    InputError
        Anything wrong with the log or the options (every route, the streamed ``.npy``
        too, by :func:`strapdown.io.read_imu`'s rules), or a non-finite or empty result.
    """
    imu_path, out_path = Path(imu), Path(out)
    if out_path.resolve() == imu_path.resolve():
        raise InputError("--out must not be the input file")
    if out_path.suffix.lower() not in (".csv", ".npz"):
        raise InputError(f"{out_path}: output must be .csv or .npz")
    if angles not in ANGLES:
        raise InputError(f"angles must be ypr, cone or none, got {shown(angles, 20)}")
    if on_gap not in RUN_GAP_POLICIES:
        raise InputError(f"on_gap must be report, error or split, got {shown(on_gap, 20)}")
    spec = _spec(kind, algorithm, structure, subsamples, coefficients)
    check_read_options(kind=kind, units=units, gap_tolerance=gap_tolerance, on_gap="report",
                       saturation=saturation, sample_rate_hz=sample_rate_hz, columns=columns)
    input_file(imu_path, "log file")
    if resample and kind != "rate":
        raise InputError("--resample applies to rate logs (--rates) only")
    read = {"kind": kind, "units": units, "columns": columns, "sample_rate_hz": sample_rate_hz,
            "gap_tolerance": gap_tolerance, "on_gap": "error" if on_gap == "error" else "report",
            "saturation": saturation, "unit_check": unit_action(accept_unit_warning),
            "delimiter": delimiter}
    split = on_gap == "split"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with output_with_sidecar(out_path) as paired:
            if spec.input_kind == "rate":
                res = _run_rates(imu_path, paired.path, read, spec, angles, q0, split, resample,
                                 progress)
            else:
                res = _run_increments(imu_path, paired.path, read, spec, angles, q0, split,
                                      progress)
            paired.meta = _metadata(imu_path, spec, res, on_gap, saturation,
                                    [str(w.message) for w in caught])
    return paired.meta


def _metadata(imu: Path, spec: AlgorithmSpec, res: dict[str, Any], on_gap: str,
              saturation: float | None, caught: list[str]) -> dict[str, Any]:
    """The sidecar's record of a run (also what :func:`run_log` returns)."""
    from strapdown import __version__

    def rows(found: list[int]) -> dict[str, Any]:
        return {"count": len(found), "first_rows": found[:100]}

    h = res["sample_period_s"]
    return {
        "input": str(imu), "kind": spec.input_kind, "units": res["units"],
        "algorithm": str(spec), "quaternion": "q_n_b, Hamilton, scalar first",
        "columns": res["columns"], "samples": res["samples"], "outputs": res["outputs"],
        "update_period_s": spec.update_period(h) if h else None, "sample_period_s": h,
        "jitter_periods": res.get("jitter_periods"), "resampled": res.get("resampled", False),
        "time_base": res.get("time_base"), "on_gap": on_gap, "gaps": rows(res["gaps"]),
        "segments": res["segments"], "saturation": saturation,
        "saturated": rows(res["saturated"]), "warnings": caught,
        "version": __version__,
    }


def _increment_segments(imu: Path, read: dict[str, Any], split: bool):
    """``(total, gaps, saturated, units, h, segments)``: the log's chunks per segment."""
    if imu.suffix.lower() == ".npy" and not split:
        if read["units"] is None:
            raise InputError(f"{imu}: .npy logs carry no units; pass --units")
        arr = npy_log(imu)
        total = arr.shape[0]
        if total < 2:
            raise InputError(f"{imu}: {total} samples; at least 2 are needed")
        gaps: list[int] = []
        saturated: list[int] = []
        segments: list[Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]] = [
            _npy_chunks(imu, arr, read["units"], read, gaps, saturated)]
        h_given = None if read["sample_rate_hz"] is None else 1.0 / read["sample_rate_hz"]
        return total, gaps, saturated, read["units"], h_given, segments
    log = read_imu(imu, **read)
    cuts = log.segments() if split else [slice(0, log.t.size)]
    segments = [((log.t[c][s:s + CHUNK], log.data[c][s:s + CHUNK])
                 for s in range(0, c.stop - c.start, CHUNK)) for c in cuts]
    return log.t.size, log.gaps, log.saturated, log.units, log.nominal_period, segments


def _run_increments(imu: Path, tmp: Path, read: dict[str, Any], spec: AlgorithmSpec,
                    angles: AngleOutput, q0: ArrayLike | None, split: bool,
                    progress: bool) -> dict[str, Any]:
    """Stream the increments through :class:`RotvecStream` into ``tmp`` (see run_log)."""
    assert isinstance(spec.family, Rotvec)
    structure = increment_structure(spec.structure)
    cs = spec.family.coefficient_set(spec)
    total, gaps, saturated, units, h_given, segments = _increment_segments(imu, read, split)
    csv_out = tmp.suffix.lower() == ".csv"
    names = _header(angles).split(",") + (["segment"] if split else [])
    n_in = n_out = 0
    q_last = q0
    h = h_given
    with tqdm(total=total, disable=not progress, unit="sample", unit_scale=True,
              file=sys.stderr) as bar:
        parts = []
        with open(tmp, "w", encoding="utf-8") as f:
            if csv_out:
                f.write(",".join(names) + "\n")
            for k, chunks in enumerate(segments):
                stream = None
                for t, th in chunks:
                    if stream is None:
                        h = h_given or (float(t[1] - t[0]) if t.size > 1 else h or 1.0)
                        stream = RotvecStream(structure, cs, h=h, t0=float(t[0]) - h, q0=q_last)
                    res = stream.feed(th)
                    n_in += th.shape[0]
                    bar.update(th.shape[0])
                    if res.q.shape[0]:
                        check_finite(f"{imu}: the {spec} attitude", res.t, res.q)
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
        raise InputError(f"{imu}: no samples")
    if n_out == 0:
        raise InputError(f"{imu}: {n_in} samples give no attitude update with {spec} (it "
                         f"needs at least {spec.min_samples}); nothing written")
    if not csv_out:
        table = np.concatenate(parts) if parts else np.empty((0, len(names)))
        # Any: np.savez's column keywords share its signature with allow_pickle: bool
        columns: dict[str, Any] = {k: table[:, i] for i, k in enumerate(names)}
        with open(tmp, "wb") as f:
            np.savez(f, **columns)
    return {"samples": n_in, "outputs": n_out, "gaps": gaps, "saturated": saturated,
            "units": units, "columns": names, "sample_period_s": h,
            "segments": len(segments)}


def _run_rates(imu: Path, tmp: Path, read: dict[str, Any], spec: AlgorithmSpec,
               angles: AngleOutput, q0: ArrayLike | None, split: bool,
               resample: bool, progress: bool = False) -> dict[str, Any]:
    """Run the rate algorithm over each gap-free record and write ``tmp`` (see run_log).

    The progress bar advances by each record's samples as its run completes (a rate
    algorithm runs a whole record in one compiled call)."""
    from strapdown.io import write_attitude

    log = read_imu(imu, **read)
    recs, base = rate_records(imu, log, split=split, min_samples=spec.min_samples,
                              resample=resample)
    ts, qs, segs = [], [], []
    q_last = q0
    with tqdm(total=int(log.t.size), disable=not progress, unit="sample", unit_scale=True,
              file=sys.stderr) as bar:
        for k, rec in enumerate(recs):
            sol = spec.run_rates(rec.t, rec.omega, q0=q_last)
            ts.append(sol.t)
            qs.append(sol.q)
            segs.append(np.full(sol.t.size, float(k)))
            q_last = sol.q[-1]
            bar.update(int(rec.t.size))
    t, q = np.concatenate(ts), np.concatenate(qs)
    check_finite(f"{imu}: the {spec} attitude", t, q)
    extra = _angles(q, angles)
    if split:
        extra["segment"] = np.concatenate(segs)
    write_attitude(tmp, t, q, extra=extra)
    return {"samples": int(log.t.size), "outputs": int(t.size), "gaps": log.gaps,
            "saturated": log.saturated, "units": log.units,
            "columns": ["t", "qw", "qx", "qy", "qz", *extra], **base.to_dict(),
            "time_base": base.describe()}
