"""Records that start in motion: the AHRS generalisation suite cropped to begin mid-motion.

Usage: ``python benchmarks/ahrs_motion_start.py [--start-s 15] [--seeds 0 1] [--out FILE]
[--hard-iron F --soft-iron F] [--acc-scale F] [--set FIELD=VALUE ...] [--broad DIR]``

Every simulated recording of :func:`strapdown.truth.scenarios.suite` starts at rest; a real
log often does not (a swing already under way, a robot already moving, a shell already
spinning). Each recording is cut at ``--start-s`` and the rest of it given to our filter
(``ekf``, ``offline_ekf``, defaults) and to VQF (``VQF``, ``offlineVQF``, defaults), 9-axis
and 6-axis (no magnetometer), scored against the truth with BROAD's metric
(:func:`strapdown.analysis.broad.broad_errors`, total RMSE from 5 s after the cut; 6-axis
after removing the constant heading offset, which no filter can know). Prints
ours / VQF of the same kind, the geometric mean over the seeds (worst seed). Needs the
``vqf`` package (``pip install 'strapdown[bench]'``). About five minutes on two cores.

``--hard-iron F --soft-iron F``: every recording's magnetometer uncalibrated, as
``benchmarks/ahrs_generalisation.py``'s options of the same names draw it (per seed and
recording, before the cut); the 9-axis errors are then also taken after removing the
constant heading offset (an uncalibrated field's north is off by a constant part too).

``--acc-scale F``: every recording's accelerometer with a scale error, its specific force
times ``1 + F`` (an untrimmed consumer accelerometer: ±1–2 %; RepoIMU's pendulum segments
read +0.15, +1.2 and +1.5 % at rest).

``--set FIELD=VALUE`` (repeatable) changes our filters' options (an ``AhrsConfig`` field,
typed by it); VQF's stay its defaults.

``--broad DIR``: instead, the BROAD trials of DIR (real recordings, optical truth), each cut
two seconds into its first movement phase after 10 s, 9-axis, BROAD's metric over the
movement samples from 5 s after the cut; one row per trial and the geometric mean.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from strapdown.ahrs.filter import AhrsConfig, ekf, offline_ekf
from strapdown.analysis.broad import broad_errors
from strapdown.apps.ahrs_benchmark import vqf_attitude
from strapdown.cli._common import ahrs_config_fields
from strapdown.truth.scenarios import record, suite

sys.path.insert(0, str(Path(__file__).parent))
from ahrs_generalisation import uncalibrated  # one definition of the drawn errors

SETTLE_S = 5.0


def _run(t, gyro, acc, mag, q_true, six_axis: bool, offset_removed: bool = False,
         config: AhrsConfig | None = None) -> dict[str, float]:
    h = float(t[1] - t[0])
    moving = t >= SETTLE_S
    m = None if six_axis else mag
    est = {"VQF": vqf_attitude(gyro, acc, m, h),
           "offlineVQF": vqf_attitude(gyro, acc, m, h, offline=True),
           "ours": ekf(t, gyro, acc, m, config=config).q,
           "ours offline": offline_ekf(t, gyro, acc, m, config=config).q}
    # without a magnetometer the heading's constant offset is arbitrary (each filter starts
    # at yaw 0 in its own way): taken out before the total, as the OpenAXES suite does
    key = "total_offset_removed_deg" if six_axis or offset_removed else "total_deg"
    return {k: broad_errors(q, q_true, moving, remove_heading_offset=True)[key]
            for k, q in est.items()}


def broad_cut(directory: str, config: AhrsConfig | None = None) -> int:
    """The ``--broad`` table (see the module docstring)."""
    from strapdown.io.broad import read_broad

    rows = []
    print("| BROAD trial, cut in motion | ours / VQF causal, deg | ratio | ours / offlineVQF "
          "offline, deg | ratio |")
    print("|---|---|---|---|---|")
    for path in sorted(Path(directory).glob("*.mat")):
        tr = read_broad(path)
        moving = np.flatnonzero(tr.movement & (tr.t > 10.0))
        if moving.size == 0:
            continue
        i0 = int(moving[0]) + round(2.0 / tr.h)
        t = tr.t[i0:] - tr.t[i0]
        g, a, m = (np.ascontiguousarray(x[i0:]) for x in (tr.gyro, tr.acc, tr.mag))
        mask = tr.movement[i0:] & (t >= SETTLE_S)
        e = {k: broad_errors(q, tr.q_ref[i0:], mask)["total_deg"] for k, q in (
            ("ours", ekf(t, g, a, m, config=config).q), ("VQF", vqf_attitude(g, a, m, tr.h)),
            ("ours offline", offline_ekf(t, g, a, m, config=config).q),
            ("offlineVQF", vqf_attitude(g, a, m, tr.h, offline=True)))}
        rows.append((e["ours"] / e["VQF"], e["ours offline"] / e["offlineVQF"]))
        print(f"| {tr.name} | {e['ours']:.2f} / {e['VQF']:.2f} | {rows[-1][0]:.2f} "
              f"| {e['ours offline']:.2f} / {e['offlineVQF']:.2f} | {rows[-1][1]:.2f} |")
    r = np.log(np.array(rows))
    print(f"| **geometric mean (worst)** | | {np.exp(r[:, 0].mean()):.2f} "
          f"({np.exp(r[:, 0].max()):.2f}) | | {np.exp(r[:, 1].mean()):.2f} "
          f"({np.exp(r[:, 1].max()):.2f}) |")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--start-s", type=float, default=15.0, help="where each record is cut, s")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    ap.add_argument("--out", default=None, help="write every figure as JSON here")
    ap.add_argument("--hard-iron", type=float, default=0.0, metavar="F",
                    help="an uncalibrated magnetometer's offset, times the field's norm "
                    "(default 0: calibrated)")
    ap.add_argument("--soft-iron", type=float, default=0.0, metavar="F",
                    help="its matrix's error, uniform in (-F, F) per entry (default 0)")
    ap.add_argument("--acc-scale", type=float, default=0.0, metavar="F",
                    help="an uncalibrated accelerometer: every specific force times 1 + F "
                    "(default 0)")
    ap.add_argument("--set", dest="config", action="append", default=[],
                    metavar="FIELD=VALUE",
                    help="an AhrsConfig field of our filters (repeatable; default: none)")
    ap.add_argument("--broad", default=None, metavar="DIR",
                    help="instead: BROAD's trials of DIR cut two seconds into a movement phase")
    args = ap.parse_args(argv)
    if not (args.hard_iron >= 0.0 and args.soft_iron >= 0.0):
        ap.error("--hard-iron and --soft-iron are sizes: expected numbers >= 0")
    if not -0.5 < args.acc_scale < 0.5:
        ap.error(f"--acc-scale is a relative error: expected a number in (-0.5, 0.5), got "
                 f"{args.acc_scale!r}")
    try:
        config = AhrsConfig(**ahrs_config_fields(args.config))
    except ValueError as e:
        ap.error(str(e))
    if args.config:
        print("our filters with " + ", ".join(args.config), file=sys.stderr)
    if args.broad:
        if args.hard_iron or args.soft_iron or args.acc_scale:
            ap.error("--hard-iron, --soft-iron and --acc-scale alter the simulated suite's "
                     "sensors, not --broad's recordings: give one or the other")
        return broad_cut(args.broad, config)
    res: dict[str, list[dict[str, float]]] = {}
    uncal = args.hard_iron > 0.0 or args.soft_iron > 0.0
    for seed in args.seeds:
        for k, sc in enumerate(suite(seed)):
            rec = record(sc, np.random.SeedSequence([seed, k]))
            if uncal:
                rec = uncalibrated(rec, args.hard_iron, args.soft_iron,
                                   np.random.default_rng([seed, k, 1]))
            i0 = int(np.searchsorted(rec.t, args.start_s))
            cut = [np.ascontiguousarray(a[i0:]) for a in
                   (rec.gyro, (1.0 + args.acc_scale) * rec.acc, rec.mag)]
            t = rec.t[i0:] - rec.t[i0]
            for six in (False, True):
                name = sc.name + (" (6-axis)" if six else "")
                res.setdefault(name, []).append(_run(t, *cut, rec.q_n_b[i0:], six, uncal,
                                                     config))
            print(f"seed {seed}: {sc.name}", file=sys.stderr)
    print(f"| scenario, cut at {args.start_s:g} s | ours/VQF causal (worst) "
          "| ours/offlineVQF offline (worst) |")
    print("|---|---|---|")
    for name, rows in res.items():
        cells = []
        for ours, peer in (("ours", "VQF"), ("ours offline", "offlineVQF")):
            r = [row[ours] / row[peer] for row in rows]
            cells.append(f"{np.exp(np.mean(np.log(r))):.2f} ({max(r):.2f})")
        print(f"| {name} | " + " | ".join(cells) + " |")
    if args.out:
        Path(args.out).write_text(json.dumps({"start_s": args.start_s, "seeds": args.seeds,
                                              "results": res}, indent=2), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
