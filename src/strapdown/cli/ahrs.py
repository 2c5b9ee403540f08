"""``strapdown ahrs``: attitude and heading from gyro, accelerometer and magnetometer."""

from __future__ import annotations

import argparse

from strapdown.cli._common import columns, say

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``ahrs`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "ahrs", arguments=_arguments,
        help="attitude and heading from gyro, accelerometer and magnetometer (error-state EKF)",
        description="Run the AHRS filter over a recording (BROAD .mat or CSV with "
        "t,gx,gy,gz,ax,ay,az[,mx,my,mz]) and write t,qw,qx,qy,qz (q_n_b) and the gyro bias, "
        "plus OUT.meta.json. Without magnetometer columns heading is not observed (said on "
        "stderr and in the metadata).")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.apps.ahrs_log import DEFAULT_COLUMNS
    from strapdown.io.readers import RATE_UNITS

    p.add_argument("--imu", required=True, help="recording (.mat BROAD, .csv)")
    p.add_argument("--out", required=True, help="output .csv or .npz")
    p.add_argument("--algorithm", default="rate-single",
                   help="attitude propagation, an algorithm spec: rate-single, rate-three, "
                   "rate-three:structure=sliding, rk4, rotvec:N=3, ...")
    p.add_argument("--frame", choices=["ENU", "NED"], default="ENU",
                   help="reference frame n of q_n_b")
    p.add_argument("--gyro-units", choices=RATE_UNITS, default="rad/s", help="gyro units")
    p.add_argument("--acc-units", choices=["m/s2", "g"], default="m/s2",
                   help="accelerometer units")
    p.add_argument("--columns", default=",".join(DEFAULT_COLUMNS),
                   help="CSV columns: time, gyro xyz, accelerometer xyz[, magnetometer xyz]")
    p.add_argument("--no-mag", action="store_true", help="ignore the magnetometer")
    p.add_argument("--no-gating", action="store_true",
                   help="accept every measurement (no innovation gating or disturbance checks)")
    p.add_argument("--declination-deg", type=float, default=0.0,
                   help="magnetic declination (deg, east positive); 0 gives a magnetic-north "
                   "heading")


def run(args: argparse.Namespace) -> int:
    """Filter the recording, write attitude and metadata, report what was used."""
    import warnings

    from strapdown.ahrs import AhrsConfig
    from strapdown.apps.ahrs_log import run_ahrs

    cfg = AhrsConfig(gating=not args.no_gating, declination_deg=args.declination_deg)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res, meta = run_ahrs(args.imu, args.out, algorithm=args.algorithm, frame=args.frame,
                             config=cfg, gyro_units=args.gyro_units, acc_units=args.acc_units,
                             columns=columns(args.columns), use_magnetometer=not args.no_mag)
    for w in caught:
        say(f"warning: {w.message}")
    if not res.heading_observed:
        say("warning: no magnetometer: heading is not observed (gyro integral from yaw 0)")
    print(f"wrote {args.out} ({meta['outputs']} attitudes, q_n_b with n = {args.frame}; "
          f"accelerometer used {meta['accelerometer_used']:.0%}, magnetometer "
          f"{meta['magnetometer_used']:.0%}) and {args.out}.meta.json")
    return 0
