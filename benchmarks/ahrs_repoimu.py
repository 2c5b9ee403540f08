"""Real swinging bodies: RepoIMU's three-segment pendulum, our filter against VQF.

Usage: ``python benchmarks/ahrs_repoimu.py DIR [--timing uniform|resample] [--glob PATTERN]
[--set FIELD=VALUE ...] [--jobs 2] [--out FILE]``

DIR holds the pendulum recordings of RepoIMU (Szczęsna et al. (2016), the public repository
``agnieszkaszczesna/RepoIMU``, folder ``Pendulum``: ``Pendulum_TestNN_TrialM_Segment_S.csv``,
one IMU per segment of a three-segment pendulum, optical reference). Not shipped with the
project; the default glob takes the swinging trials (tests 02–08, every segment: 63
recordings) and leaves out the static ones (test 01).

Each file has two header rows and one row per optical frame (100–165 Hz); the IMU's samples
(about 51 Hz; acceleration m/s², gyro rad/s, magnetometer in arbitrary units, uncalibrated)
are repeated over the frames until the next one arrives, and a few are lost. Every filter is
given the same clean, uniform record (:func:`load`): held rows collapsed to their first
frame, then with ``--timing uniform`` (default) the samples taken as they are on a uniform
grid of the mean period, or with ``--timing resample`` interpolated onto that grid from the
frames' stamps. The reference is the optical quaternion at each kept sample. The error is
taken after fitting a constant world and body rotation to each estimate
(:func:`strapdown.analysis.alignment.aligned_errors`), over the whole record.

The same repository's ``TStick`` folder (a T-shaped stick moved by hand, IMU and optical
reference both at 100 Hz, so no held rows; 28 trials, tests 02–11) reads the same way: ``DIR``
that folder and ``--glob 'TStick_Test*_Trial*.csv'``.

Filters: ``ekf`` and ``offline_ekf`` (defaults, or ``--set``), VQF's ``VQF.updateBatch`` and
``offlineVQF`` (defaults, 9D). Prints, per recording, total RMSE of each and ours / VQF of
the same kind; then the means, the ratio of the means, the worst ratio and how many
recordings are above 1.5× — over all recordings, then over those our causal filter found
starting still and those starting in motion. Needs ``vqf`` (``pip install
'strapdown[bench]'``). Half a minute on two cores. What it shows is in
docs/reproductions.md ("RepoIMU's pendulum").
"""

from __future__ import annotations

import argparse
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from strapdown.cli._common import ahrs_config_fields

DEFAULT_GLOB = "Pendulum_Test0[2-8]*_Segment_*.csv"
FILTERS = ("strapdown EKF", "VQF", "strapdown EKF offline", "offlineVQF")


def load(path: Path, timing: str = "uniform") -> dict[str, np.ndarray | float]:
    """One RepoIMU CSV as a clean uniform record: ``t``, ``gyro``, ``acc``, ``mag``,
    ``q_ref`` (scalar first) and the period ``h``; see the module docstring."""
    a = np.genfromtxt(path, delimiter=";", skip_header=2, usecols=range(14))
    a = a[np.all(np.isfinite(a), axis=1)]
    imu = a[:, 5:14]
    new = np.ones(len(a), bool)
    new[1:] = np.any(imu[1:] != imu[:-1], axis=1)  # a held row repeats the previous sample
    a = a[new]
    stamps = a[:, 0] - a[0, 0]
    h = float(stamps[-1] / (stamps.size - 1))
    t = h * np.arange(stamps.size)
    cols = {"acc": a[:, 5:8], "gyro": a[:, 8:11], "mag": a[:, 11:14], "q_ref": a[:, 1:5]}
    if timing == "resample":
        cols = {k: np.column_stack([np.interp(t, stamps, v[:, i]) for i in range(v.shape[1])])
                for k, v in cols.items()}
    elif timing != "uniform":
        raise ValueError(f"timing must be 'uniform' or 'resample', got {timing!r}")
    q = cols["q_ref"]
    out = {k: np.ascontiguousarray(v) for k, v in cols.items()}
    out["q_ref"] = q / np.linalg.norm(q, axis=1, keepdims=True)
    out["t"], out["h"] = t, h
    return out


def evaluate(path: Path, timing: str, config: dict) -> tuple[str, dict[str, float]]:
    """Total RMSE (degrees, aligned) of every filter on one recording, and ``start_still``
    (1.0 when our causal filter found the start still, 0.0 for a start in motion)."""
    import warnings

    from strapdown.ahrs import AhrsConfig, ekf, offline_ekf
    from strapdown.analysis.alignment import aligned_errors
    from strapdown.apps.ahrs_benchmark import vqf_attitude

    r = load(path, timing)
    cfg = AhrsConfig(**config)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an unused accelerometer is reported by the table
        causal = ekf(r["t"], r["gyro"], r["acc"], r["mag"], config=cfg)
        qs = {"strapdown EKF": causal.q,
              "strapdown EKF offline": offline_ekf(r["t"], r["gyro"], r["acc"], r["mag"],
                                                   config=cfg).q,
              "VQF": vqf_attitude(r["gyro"], r["acc"], r["mag"], r["h"]),
              "offlineVQF": vqf_attitude(r["gyro"], r["acc"], r["mag"], r["h"], offline=True)}
    errors = {f: aligned_errors(qs[f], r["q_ref"])["total_deg"] for f in FILTERS}
    return path.stem, {**errors, "start_still": float(causal.start_still)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("dir", type=Path, help="RepoIMU's Pendulum folder")
    ap.add_argument("--timing", choices=["uniform", "resample"], default="uniform")
    ap.add_argument("--glob", default=DEFAULT_GLOB)
    ap.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE",
                    help="an AhrsConfig field for our filter (repeatable; default: none)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None, help="write every figure as JSON here")
    args = ap.parse_args(argv)
    files = sorted(args.dir.glob(args.glob))
    if not files:
        ap.error(f"no {args.glob} in {args.dir}")
    try:
        config = ahrs_config_fields(args.set)
    except ValueError as e:
        ap.error(str(e))
    with ProcessPoolExecutor(args.jobs) as ex:
        rows = list(ex.map(evaluate, files, [args.timing] * len(files),
                           [config] * len(files)))
    print(f"{'recording':38s} " + " ".join(f"{f:>21s}" for f in FILTERS)
          + "   ours/VQF causal, offline")
    for name, e in rows:
        print(f"{name:38s} " + " ".join(f"{e[f]:21.2f}" for f in FILTERS)
              + f"   {e[FILTERS[0]] / e[FILTERS[1]]:5.2f} {e[FILTERS[2]] / e[FILTERS[3]]:5.2f}")
    means = {f: float(np.mean([e[f] for _, e in rows])) for f in FILTERS}
    print(f"{'mean':38s} " + " ".join(f"{means[f]:21.2f}" for f in FILTERS))
    summary = {}
    groups = {"": rows, " (start still)": [x for x in rows if x[1]["start_still"]],
              " (start in motion)": [x for x in rows if not x[1]["start_still"]]}
    for group, sel in groups.items():
        for kind, (ours, peer) in {"causal": FILTERS[:2], "offline": FILTERS[2:]}.items():
            if not sel:
                continue
            r = np.array([e[ours] / e[peer] for _, e in sel])
            mo, mp = (float(np.mean([e[f] for _, e in sel])) for f in (ours, peer))
            summary[kind + group] = {"ours": mo, "vqf": mp, "ratio_of_means": mo / mp,
                                     "worst": float(r.max()), "above_1.5": int((r > 1.5).sum()),
                                     "recordings": len(sel)}
            print(f"{kind}{group}: ours {mo:.2f}° / VQF {mp:.2f}° = {mo / mp:.3f}, worst "
                  f"{r.max():.2f}, {int((r > 1.5).sum())} of {len(sel)} above 1.5×")
    if args.out:
        from strapdown.io.files import write_text

        write_text(args.out, json.dumps({"timing": args.timing, "config": config,
                                                "recordings": dict(rows), "means": means,
                                                "summary": summary}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
