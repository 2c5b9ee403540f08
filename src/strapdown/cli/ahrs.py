"""``strapdown ahrs``: attitude and heading from gyro, accelerometer and magnetometer."""

from __future__ import annotations

import argparse
import math
import time

from strapdown.cli._common import (
    columns,
    input_args,
    log_check_args,
    progress,
    progress_args,
    say,
    timing_options,
)

__all__ = ["MAX_DECLINATION_DEG", "add_parser", "run"]

#: Largest magnetic declination magnitude accepted (deg).
MAX_DECLINATION_DEG = 180.0


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``ahrs`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "ahrs", arguments=_arguments,
        help="attitude and heading from gyro, accelerometer and magnetometer (error-state EKF)",
        description="Run the AHRS filter over a recording (BROAD .mat or CSV with "
        "t,gx,gy,gz,ax,ay,az[,mx,my,mz]) and write t,qw,qx,qy,qz (q_n_b) and the gyro bias, "
        "one row per input sample (the first: the initial attitude at the first time stamp), "
        "plus yaw/pitch/roll (deg, z-y-x) and OUT.meta.json (with the time base: the "
        "sensor's clock fitted to the stamps, held and duplicated rows, gaps bridged). "
        "Frames: q_n_b rotates body vectors into n = ENU (x east, y north, z up; --frame NED: "
        "north, east, down), Hamilton product, scalar first; t is each sample's time on the "
        "fitted clock, in the file's time base. Without magnetometer columns heading is not "
        "observed (said on stderr and in the metadata).")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.apps.ahrs_log import ACC_UNITS, GYRO_UNITS

    p.add_argument("--imu", required=True, help="recording (.mat BROAD, .csv)")
    p.add_argument("--out", required=True, help="output .csv or .npz")
    p.add_argument("--algorithm", default="rate-single",
                   help="attitude propagation, an algorithm spec: rate-single, rate-three, "
                   "rate-three:structure=sliding, rk4, rotvec:N=3, ...")
    p.add_argument("--frame", choices=["ENU", "NED"], default="ENU",
                   help="reference frame n of q_n_b")
    p.add_argument("--gyro-units", choices=GYRO_UNITS, default=None,
                   help="gyro units; required unless the file declares them (a CSV header "
                   "gx[deg/s], BROAD: rad/s) or the magnetometer decides (its rotation against "
                   "the gyro's); one the file contradicts is an error")
    p.add_argument("--acc-units", choices=ACC_UNITS, default=None,
                   help="accelerometer units (default: the file's — a CSV header ax[g], BROAD "
                   "m/s2 — else inferred from the median norm: about 9.8 is m/s2, about 1 is "
                   "g). The magnetometer takes no unit: only its direction and constancy "
                   "matter")
    p.add_argument("--columns", default=None,
                   help="CSV columns: time, gyro xyz, accelerometer xyz[, magnetometer xyz], "
                   "by name or 0-based index (e.g. 0,8,9,10,5,6,7,11,12,13) (default: found "
                   "in the header — time t, time, timestamp, t[ms], timestamp_ms …; gx,gy,gz; "
                   "ax,ay,az; mx,my,mz when present). A second header row of units (s;rad/s…) "
                   "or of axis names under group names is read too")
    p.add_argument("--sample-rate-hz", type=float, default=None,
                   help="the sensor's sample rate (Hz): the nominal period of jittered time "
                   "stamps (default: from the stamps)")
    input_args(p)
    log_check_args(p, saturation=False)
    p.add_argument("--offline", action="store_true",
                   help="post-processing: run the filter forward and backward and combine the "
                   "two (acausal: every estimate uses the whole recording; not a real-time "
                   "filter)")
    p.add_argument("--gyro-sample", choices=["interval", "point"], default="interval",
                   help="what a gyro sample is: the mean rate over the period ending at its "
                   "stamp (interval: MEMS IMUs, VQF's convention; each output predicted half a "
                   "period ahead) or the rate at the stamp (point: exact simulations)")
    p.add_argument("--acc-sample", choices=["interval", "point"], default="interval",
                   help="what an accelerometer sample is, beside interval gyro samples: a "
                   "mean like the gyro's (interval: gyro and accelerometer through one "
                   "decimation filter; the default) or the specific force at its stamp "
                   "(point: exact simulations, VQF's convention; turned back half a period)")
    p.add_argument("--mag-sample", choices=["point", "interval"], default="point",
                   help="what a magnetometer sample is, beside interval gyro samples: the "
                   "field at its stamp (point: a magnetometer read at an instant; turned back "
                   "half a period to where the attitude refers; the default) or a mean like "
                   "the gyro's (interval)")
    p.add_argument("--no-mag", action="store_true", help="ignore the magnetometer")
    p.add_argument("--no-gating", action="store_true",
                   help="accept every measurement (no innovation gating or disturbance checks)")
    p.add_argument("--declination-deg", type=float, default=0.0,
                   help="magnetic declination (deg, east positive, within ±180); 0 gives a "
                   "magnetic-north heading")
    p.add_argument("--gyro-scale-sigma", type=float, default=0.0, metavar="SD",
                   help="for an uncalibrated gyro on a body that keeps turning one way (a "
                   "spinning projectile, a circling vehicle): the standard deviation of its "
                   "relative scale-factor error, e.g. 0.01; the gyro bias then follows the "
                   "scale error of the sustained rotation (AhrsConfig.gyro_scale_sigma). "
                   "Default 0: off, right for a calibrated gyro")
    p.add_argument("--gyro-range-deg-s", type=float, default=None, metavar="DEG_S",
                   help="the gyro's full scale, °/s (a datasheet's ±2000 °/s: 2000): a rate "
                   "at it is taken as clipped, and the rotation beyond it from the field's "
                   "turn (AhrsConfig.gyro_range, gyro_declip). Default: found from the record "
                   "(plateaus entered by a step, or a flat top the field turns faster than)")
    progress_args(p, "a line as the filter starts and ends")


def run(args: argparse.Namespace) -> int:
    """Filter the recording, write attitude and metadata, report what was used."""
    from strapdown._core.errors import InputError
    from strapdown.ahrs import AhrsConfig
    from strapdown.apps.ahrs_log import run_ahrs

    _missing_broad_trial(args.imu)
    if not abs(args.declination_deg) <= MAX_DECLINATION_DEG:
        raise InputError(f"--declination-deg must lie within ±{MAX_DECLINATION_DEG:g}° (east "
                         f"positive), got {args.declination_deg:g}")
    if not (0.0 <= args.gyro_scale_sigma < 1.0):
        raise InputError(f"--gyro-scale-sigma is a relative scale-factor error's standard "
                         f"deviation, within [0, 1) (e.g. 0.01), got {args.gyro_scale_sigma:g}")
    rng = args.gyro_range_deg_s
    if rng is not None and not 0.0 < rng < math.inf:
        raise InputError(f"--gyro-range-deg-s is the gyro's full scale in °/s, positive and "
                         f"finite (e.g. 2000), got {rng:g}")
    cfg = AhrsConfig(gating=not args.no_gating, declination_deg=args.declination_deg,
                     gyro_sample=args.gyro_sample, acc_sample=args.acc_sample,
                     mag_sample=args.mag_sample, gyro_scale_sigma=args.gyro_scale_sigma,
                     gyro_range=0.0 if rng is None else math.radians(rng))
    show = progress(args)
    if show:
        say(f"filtering {args.imu} ({args.algorithm}"
            f"{', forward and backward' if args.offline else ''})…")
        start = time.perf_counter()
    res, meta = run_ahrs(args.imu, args.out, algorithm=args.algorithm, frame=args.frame,
                         config=cfg, gyro_units=args.gyro_units, acc_units=args.acc_units,
                         columns=None if args.columns is None else columns(args.columns),
                         use_magnetometer=not args.no_mag, sample_rate_hz=args.sample_rate_hz,
                         on_gap=args.on_gap, gap_tolerance=args.gap_tolerance,
                         accept_unit_warning=args.accept_unit_warning,
                         delimiter=args.delimiter, offline=args.offline, **timing_options(args))
    if show:
        say(f"filtered {meta['outputs']} samples in {time.perf_counter() - start:.1f} s")
    for w in meta["warnings"]:
        say(f"warning: {w}")
    if meta["gaps"]["count"]:
        how = "split into segments" if args.on_gap == "split" else "bridged"
        say(f"warning: {meta['gaps']['count']} gap(s) ({how}), first at data row "
            f"{meta['gaps']['first_rows'][0]}")
    for what, unit in meta["units_inferred"].items():
        say(f"note: {what} units inferred from the data: {unit}")
    if not res.heading_observed:
        say("warning: no magnetometer: heading is not observed (gyro integral from yaw 0)")
    if res.mag_offset is not None:
        how = ("the offline filter subtracted" if res.smoothed else
               "the filter estimated it online and subtracted, at the end,")
        see = ("offline_hard_iron_min_explained" if res.smoothed else "hard_iron_s")
        say("note: the magnetometer carries a hard-iron offset (a field fixed in the body); "
            f"{how} {[round(float(x), 6) for x in res.mag_offset]} "
            f"(its unit; see AhrsConfig.{see})")
    if res.gyro_clipped:
        say(f"note: the gyro is at its range on {res.gyro_clipped} samples; the field's turn "
            f"gave the rate beyond it on {res.gyro_recovered} of them (AhrsConfig.gyro_declip"
            "; the others keep the clipped reading)")
    if not res.start_still:
        say("note: the recording starts in motion (its first "
            f"{cfg.init_window_s:g} s are not still): the first seconds converge from a "
            "rougher start")
    print(f"wrote {args.out} ({meta['outputs']} attitudes, {meta['mode'].split(' ')[0]}, "
          f"q_n_b with n = {args.frame}; "
          f"accelerometer used {meta['accelerometer_used']:.0%}, magnetometer "
          f"{meta['magnetometer_used']:.0%}; {meta['time_base']}) and {args.out}.meta.json")
    return 0


def _missing_broad_trial(imu: str) -> None:
    """A BROAD trial's name (``NN_*.mat``) that is not there: say where the trials are
    looked for ($STRAPDOWN_BROAD; the README's ``"$STRAPDOWN_BROAD/01_….mat"`` with the
    variable unset is ``/01_….mat``)."""
    import os
    import re

    from strapdown._core.errors import InputError

    if re.fullmatch(r"\d\d_\w+\.mat", os.path.basename(imu)) and not os.path.exists(imu):
        from strapdown.io.broad import broad_hint

        raise InputError(f"{imu}: no such recording; {broad_hint()}")
