"""``strapdown nav``: position, velocity and attitude on the WGS-84 Earth from a gyro and
accelerometer log, streamed, written atomically."""

from __future__ import annotations

import argparse

from strapdown.cli._common import (
    columns,
    input_args,
    progress,
    progress_args,
    say,
    timing_args,
    timing_options,
)

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``nav`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "nav", arguments=_arguments,
        help="navigate a gyro + accelerometer log on the WGS-84 Earth (NED)",
        description="Validate a gyro and accelerometer log, navigate it from the initial "
        "position, velocity and attitude (coning and sculling compensated, NED on WGS-84) and "
        "write t,lat_deg,lon_deg,height_m,vn,ve,vd,qw,qx,qy,qz,yaw_deg,pitch_deg,roll_deg "
        "atomically, with OUT.meta.json (the time base: the sensor's clock fitted to the "
        "stamps and its residuals). Frames: n = NED (north, east, down), q_n_b rotates body "
        "vectors into it (Hamilton, scalar first), yaw/pitch/roll its z-y-x Euler angles (deg). "
        "Each increment's stamp is the end of its interval. Row 0 is the initial state, at "
        "t0 = the first stamp - h for increments (the start of the first interval) or the "
        "first stamp for rates; then one row per update, t the end of the update. An "
        "increment log whose first two rows are identical (a duplicated first row) warns; "
        "fewer than N samples left after the last whole update are dropped and said so "
        "(--trailing error refuses them). Gravity: WGS-84 normal gravity with the second-order "
        "height correction, or its linear term (--gravity linear).")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.algorithms.velocity import NAV_STRUCTURES, rate_velocity_algorithms
    from strapdown.apps.nav import ACC_UNITS, TRAILING_POLICIES
    from strapdown.io.readers import INCREMENT_UNITS, RATE_UNITS
    from strapdown.truth.earth import GRAVITY_MODELS

    g = p.add_argument_group("log")
    g.add_argument("--imu", required=True,
                   help="input log: CSV with a header, .npz/HDF5 (t, gyro, accel) or .mat")
    kind = g.add_mutually_exclusive_group()
    kind.add_argument("--rates", dest="kind", action="store_const", const="rate",
                      default="rate", help="the log holds rates and specific force (default)")
    kind.add_argument("--increments", dest="kind", action="store_const", const="increment",
                      help="the log holds angular (rad) and velocity (m/s) increments, each "
                      "over the interval that ends at its stamp")
    g.add_argument("--units", default=None, choices=(*RATE_UNITS, *INCREMENT_UNITS),
                   help="gyro units (required unless the header declares them, e.g. "
                   "gx[deg/s])")
    g.add_argument("--acc-units", default=None, choices=ACC_UNITS,
                   help="accelerometer units: m/s2 or g for rates, m/s for increments "
                   "(required unless the header declares them, e.g. ax[m/s^2])")
    g.add_argument("--columns", default=None,
                   help="CSV columns for time, gyro x,y,z and accelerometer x,y,z, "
                   "comma-separated (default: found in the header, t,gx,gy,gz,ax,ay,az)")
    g.add_argument("--sample-rate-hz", type=float, default=None,
                   help="the sensor's sample rate (Hz), for files without time stamps")
    g.add_argument("--accept-unit-warning", action="store_true",
                   help="run although magnitudes suggest other units than declared")
    input_args(g, delimiter=False)
    tb = p.add_argument_group("gaps and time base")
    tb.add_argument("--on-gap", choices=("error", "report"), default="error",
                    help="a gap (samples missing on the sensor's fitted clock): fail (default), "
                    "or bridge it by linear interpolation of gyro and accelerometer when no "
                    "longer than 1 s (reported in the summary and OUT.meta.json)")
    timing_args(tb)
    s = p.add_argument_group("initial state")
    s.add_argument("--init-lat", type=float, required=True,
                   help="latitude (deg, within ±89.9: the north-pointing NED mechanisation is "
                   "singular at the poles; a flight reaching 89.9° is refused)")
    s.add_argument("--init-lon", type=float, required=True,
                   help="longitude (deg, within ±360: -180..180 or 0..360)")
    s.add_argument("--init-height", type=float, required=True,
                   help="height above the WGS-84 ellipsoid (m, -20000..1000000: the range of "
                   "the normal gravity model)")
    s.add_argument("--init-velocity", type=float, nargs=3, metavar=("VN", "VE", "VD"),
                   default=None, help="NED velocity (m/s; default at rest)")
    s.add_argument("--init-attitude", type=float, nargs=3, metavar=("YAW", "PITCH", "ROLL"),
                   default=None, help="z-y-x Euler angles of the body in NED (deg, each within "
                   "±360; default 0 0 0)")
    a = p.add_argument_group("algorithm")
    a.add_argument("--structure", choices=NAV_STRUCTURES, default="conventional",
                   help="conventional: an update every N samples; single-chain: every sample")
    a.add_argument("--subsamples", type=int, default=3,
                   help="N of the coning and sculling corrections (1-6; default 3, whose "
                   "velocity set also holds on a coning body in gravity)")
    a.add_argument("--algorithm", choices=rate_velocity_algorithms(), default=None,
                   help="rate logs only: navigate with this rate-input family's velocity "
                   "counterpart (the dual of its coning update: its window on the rate and "
                   "specific-force samples, an update every its period; --structure and "
                   "--subsamples are then not used). Default: the rates are integrated to "
                   "increments for the N-subsample update")
    a.add_argument("--no-sculling", dest="sculling", action="store_false",
                   help="drop the sculling correction (rotation compensation only)")
    a.add_argument("--gravity", choices=GRAVITY_MODELS, default="wgs84",
                   help="normal gravity: the WGS-84 formula (Somigliana with the second-order "
                   "height correction; default) or its linear height correction (linear)")
    a.add_argument("--trailing", choices=TRAILING_POLICIES, default="drop",
                   help="fewer than N samples left after the last whole conventional update: "
                   "drop them, said on stderr and counted in OUT.meta.json (default: a rate "
                   "log of n samples gives n - 1 increments, so half of all logs leave one), "
                   "or refuse the log (error)")
    o = p.add_argument_group("output")
    progress_args(o)
    o.add_argument("--out", required=True, help="output .csv or .npz")


def run(args: argparse.Namespace) -> int:
    """Navigate the log and write the solution; warnings go to stderr."""
    from strapdown.apps.nav import navigate_log

    res = navigate_log(args.imu, args.out, lat_deg=args.init_lat, lon_deg=args.init_lon,
                       height=args.init_height, velocity=args.init_velocity,
                       attitude_deg=args.init_attitude, kind=args.kind, units=args.units,
                       acc_units=args.acc_units,
                       columns=None if args.columns is None else columns(args.columns),
                       sample_rate_hz=args.sample_rate_hz, subsamples=args.subsamples,
                       structure=args.structure, sculling=args.sculling,
                       accept_unit_warning=args.accept_unit_warning, progress=progress(args),
                       on_gap=args.on_gap, trailing=args.trailing, gravity=args.gravity,
                       algorithm=args.algorithm, **timing_options(args))
    for w in res["warnings"]:
        say(f"warning: {w}")
    if res["trailing_samples_dropped"]:
        say(f"note: {res['trailing_samples_dropped']} trailing sample(s) short of a whole "
            "update not navigated (--trailing drop)")
    if res["bridged_samples"]:
        say(f"warning: {res['bridged_samples']} missing sample(s) bridged by interpolation")
    base = f"; {res['time_base']}" if res["time_base"] else ""
    print(f"wrote {args.out}: {res['outputs']} updates from {res['samples']} samples "
          f"(update every {res['update_period_s']:.6g} s{base}) and {args.out}.meta.json")
    return 0
