"""Choose the AHRS defaults by cross-validation across kinds of data, and report held-out
figures per left-out kind (issue 25).

Usage: ``python benchmarks/ahrs_cv_kinds.py BROAD_DIR [--seed 0] [--out
reports/ahrs_cv_kinds.json] [--jobs 2] [--gyro-scale SD] [--gyro-misalignment SD]``.

The kinds: BROAD's trial groups (``benchmarks/ahrs_cv.py``'s :func:`groups`: undisturbed
trials by motion, disturbed ones by disturbance — five on the fifteen shared trials) and
the simulated scenario kinds of the generalisation suite (``strapdown.truth.scenarios``:
pendulum, vehicle, loiter, spin-coning, hand-held, steel-frame, rests), recorded with the
sensor errors of ``--seed`` (and, with ``--gyro-scale`` / ``--gyro-misalignment``, a gyro
scale-factor and cross-axis error of that standard deviation, ``Sensors.gyro_scale_sd``:
the study on consumer gyros that are not calibrated). Every candidate of :data:`GRID` runs
once, causally, on every recording. A fold leaves one kind out and picks the candidate best
on the other kinds; the left-out kind is then scored with it, causally and offline. The
defaults are the candidate best on every kind.

The pendulum, vehicle, spin-coning and hand-held recordings also run without their
magnetometer, as kinds of a third dataset (6-axis: VQF's 6D estimate the yardstick; the
errors after removing each estimate's constant heading offset, its start yaw being a
convention).

The objective weighs datasets and kinds, not recordings: for each kind the mean over its
recordings of ``log r``, r = ours / VQF of the same kind (total RMSE, BROAD's metric, VQF
2.x with its defaults), counted twice where positive (a kind where we lose costs double);
the mean over a dataset's kinds; the mean over the datasets (BROAD, simulated, simulated
6-axis). A kind with many recordings does not outvote a kind with one, nor a dataset with
many kinds one with few.

The OpenAXES recordings are not used: they stay held out for the defaults this chooses
(``strapdown benchmark-ahrs --suite openaxes``).
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import sys
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ahrs_cv import groups  # the BROAD grouping, one definition

#: The candidates: every combination of these values (the defaults before this study are
#: among them but for ``tilt_rate_noise``'s 4.2e-3, also on the grid). Each is run once on
#: every recording; a fold picks the combination best on its training kinds — a search over
#: a finite grid shared by the folds, so the study costs one filter run per candidate and
#: recording.
GRID = {"gyro_noise": (1.4e-3, 2.8e-3, 5.6e-3), "heading_noise": (0.0063, 0.0126, 0.025),
        "tilt_rate_noise": (0.0, 0.0021, 0.0042), "gyro_bias_sigma0": (0.01, 0.003),
        "acc_motion_leak": (0.0, 0.25, 0.5)}
#: Scenario kinds also run without their magnetometer (a 6-axis filter: heading from the
#: gyro alone), a kind of their own.
SIX_AXIS = ("pendulum", "vehicle", "spin", "hand")
#: The defaults before this study.
PRIOR = {"gyro_noise": 1.4e-3, "heading_noise": 0.0126, "tilt_rate_noise": 4.2e-3,
         "gyro_bias_sigma0": 0.01, "acc_motion_leak": 0.0}


class Data:
    """Every recording of the study, its kind and VQF's causal and offline errors."""

    def __init__(self, broad_dir: Path, seed: int, gyro_scale: float = 0.0,
                 gyro_misalignment: float = 0.0):
        from strapdown.apps.ahrs_generalisation import trial
        from strapdown.io.broad import read_broad
        from strapdown.truth.scenarios import record, suite

        group_of = groups(broad_dir)
        self.trials = [read_broad(p) for p in sorted(broad_dir.glob("*.mat"))]
        self.kind = {tr.name: "broad:" + group_of[tr.name] for tr in self.trials}
        self.six_axis: set[str] = set()
        for k, sc in enumerate(suite(seed)):
            sc = replace(sc, sensors=replace(sc.sensors, gyro_scale_sd=gyro_scale,
                                             gyro_misalignment_sd=gyro_misalignment))
            tr = trial(record(sc, np.random.SeedSequence([seed, k])))
            self.trials.append(tr)
            self.kind[tr.name] = "sim:" + sc.name.split("-")[0]
            if sc.name.split("-")[0] in SIX_AXIS:  # the same recording without its field
                six = replace(tr, name=tr.name + " (6-axis)")
                self.trials.append(six)
                self.kind[six.name] = "sim6:" + sc.name.split("-")[0]
                self.six_axis.add(six.name)
        self.kinds = sorted(set(self.kind.values()))
        self.vqf = {tr.name: _vqf(tr, tr.name in self.six_axis) for tr in self.trials}

    def mag(self, tr):
        """The recording's field, or None for its 6-axis version."""
        return None if tr.name in self.six_axis else tr.mag


def _vqf(tr, six_axis: bool) -> tuple[float, float]:
    from strapdown.apps.ahrs_benchmark import vqf_attitude

    m = None if six_axis else tr.mag
    return tuple(total(vqf_attitude(tr.gyro, tr.acc, m, tr.h, offline=off), tr, six_axis)
                 for off in (False, True))


def total(q, tr, six_axis: bool) -> float:
    """Total RMSE (°): BROAD's metric; for a 6-axis estimate after removing the constant
    heading offset (its heading starts from an arbitrary yaw, each filter's own)."""
    from strapdown.analysis.broad import broad_errors

    e = broad_errors(q, tr.q_ref, tr.movement, remove_heading_offset=six_axis)
    return e["total_offset_removed_deg" if six_axis else "total_deg"]


def errors(data: Data, config: dict, kinds, offline: bool = False) -> dict[str, float]:
    """Total RMSE (°, BROAD's metric) of our filter per recording of ``kinds``."""
    from strapdown.ahrs import AhrsConfig, ekf, offline_ekf

    run = offline_ekf if offline else ekf
    out = {}
    for tr in data.trials:
        if data.kind[tr.name] in kinds:
            r = run(tr.t, tr.gyro, tr.acc, data.mag(tr), config=AhrsConfig(**config))
            out[tr.name] = total(r.q, tr, tr.name in data.six_axis)
    return out


def kind_ratios(data: Data, err: dict[str, float], offline: bool = False) -> dict[str, float]:
    """Per kind, the geometric mean over its recordings of ours / VQF of the same kind."""
    j = 1 if offline else 0
    logs: dict[str, list[float]] = {}
    for n, e in err.items():
        logs.setdefault(data.kind[n], []).append(math.log(e / data.vqf[n][j]))
    return {k: math.exp(float(np.mean(v))) for k, v in logs.items()}


def objective(ratios: dict[str, float], kinds) -> float:
    """The objective (module docstring) of per-kind ratios over ``kinds``: per dataset (the
    prefix of a kind: BROAD, simulated, simulated 6-axis) the mean over its kinds of
    ``log r + max(log r, 0)``, then the mean over datasets."""
    per: dict[str, list[float]] = {}
    for k in kinds:
        lr = math.log(ratios[k])
        per.setdefault(k.split(":")[0], []).append(lr + max(lr, 0.0))
    return float(np.mean([np.mean(v) for v in per.values()]))


_DATA: Data | None = None


def _init(broad_dir: str, seed: int, gyro_scale: float = 0.0,
          gyro_misalignment: float = 0.0) -> None:
    global _DATA
    _DATA = Data(Path(broad_dir), seed, gyro_scale, gyro_misalignment)


def _candidate(config: dict) -> tuple[dict, dict[str, float]]:
    assert _DATA is not None
    return config, kind_ratios(_DATA, errors(_DATA, config, _DATA.kinds))


def _scores(data: Data, config: dict, kinds) -> tuple[dict, dict]:
    """Causal and offline per-kind ratios of ``config`` on ``kinds``."""
    return (kind_ratios(data, errors(data, config, kinds)),
            kind_ratios(data, errors(data, config, kinds, True), True))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    p.add_argument("dir", type=Path)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", type=Path, default=Path("reports/ahrs_cv_kinds.json"))
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--gyro-scale", type=float, default=0.0,
                   help="the simulated gyros' scale-factor error, standard deviation")
    p.add_argument("--gyro-misalignment", type=float, default=0.0,
                   help="their cross-axis sensitivity, standard deviation")
    a = p.parse_args(argv)
    init = (str(a.dir), a.seed, a.gyro_scale, a.gyro_misalignment)
    _init(*init)
    assert _DATA is not None
    kinds = _DATA.kinds
    cands = [dict(zip(GRID, v, strict=True)) for v in itertools.product(*GRID.values())]
    with ProcessPoolExecutor(a.jobs, initializer=_init, initargs=init) as ex:
        table = list(ex.map(_candidate, cands))
    folds = {}
    for held in kinds:
        train = [k for k in kinds if k != held]
        folds[held] = min(table, key=lambda c: objective(c[1], train))[0]
    defaults = min(table, key=lambda c: objective(c[1], kinds))[0]
    prior_c, prior_o = _scores(_DATA, PRIOR, kinds)
    fit_c, fit_o = _scores(_DATA, defaults, kinds)
    held_c, held_o = {}, {}
    for k, cfg in folds.items():
        c, o = _scores(_DATA, cfg, [k])
        held_c[k], held_o[k] = c[k], o[k]
    report = {"seed": a.seed, "gyro_scale": a.gyro_scale,
              "gyro_misalignment": a.gyro_misalignment, "grid": GRID, "prior": PRIOR,
              "defaults": defaults,
              "folds": folds, "table": table,
              "kinds": {k: {"prior": prior_c[k], "fitted": fit_c[k], "held_out": held_c[k],
                            "prior_offline": prior_o[k], "fitted_offline": fit_o[k],
                            "held_out_offline": held_o[k]} for k in kinds}}
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(report, indent=2))
    print("| kind | prior | fitted | held out | prior offline | fitted offline | "
          "held out offline |\n|---|---|---|---|---|---|---|")
    for k, r in report["kinds"].items():
        print(f"| {k} | {r['prior']:.2f} | {r['fitted']:.2f} | {r['held_out']:.2f} | "
              f"{r['prior_offline']:.2f} | {r['fitted_offline']:.2f} | "
              f"{r['held_out_offline']:.2f} |")
    print("defaults:", json.dumps(defaults))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
