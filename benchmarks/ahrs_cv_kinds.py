"""Choose the AHRS defaults by cross-validation across kinds of data, and report held-out
figures per left-out kind (issue 25).

Usage: ``python benchmarks/ahrs_cv_kinds.py BROAD_DIR [--seed 0] [--out
reports/ahrs_cv_kinds.json] [--jobs 2]``.

The kinds: BROAD's trial groups (``benchmarks/ahrs_cv.py``'s :func:`groups`: undisturbed
trials by motion, disturbed ones by disturbance — five on the fifteen shared trials) and
the simulated scenario kinds of the generalisation suite (``strapdown.truth.scenarios``:
pendulum, vehicle, loiter, spin-coning, hand-held, steel-frame, rests), recorded with the
sensor errors of ``--seed``. A fold leaves one kind out: the tuning parameters are chosen
on the other kinds by coordinate search (each parameter in turn over a few multiples of
its value, ``ROUNDS`` rounds) from ``PRIOR`` — the defaults before this study — and the
left-out kind is filtered with them. The defaults are the same search on every kind.

The objective weighs kinds, not recordings: for each kind the mean over its recordings of
``log(ours / VQF)`` (total RMSE of the causal filters, BROAD's metric, VQF 2.x causal with
its defaults as the yardstick), then the mean over kinds plus the mean of their positive
parts — a kind where we lose to VQF costs twice. A kind with many recordings (BROAD's)
does not outvote a kind with one (a pendulum's), and no kind's loss is bought by
another's larger win.

The OpenAXES recordings are not used: they stay held out for the defaults this chooses
(``strapdown benchmark-ahrs --suite openaxes``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ahrs_cv import groups  # the BROAD grouping, one definition

#: The starting point of every search: the defaults before this study.
PRIOR = {"gyro_noise": 1.4e-3, "tilt_rate_noise": 4.2e-3, "heading_noise": 0.0126,
         "acc_lowpass_s": 2.1, "acc_lowpass_noise": 0.0252, "acc_motion_leak": 0.0,
         "mag_dip_tol": 0.12215, "rest_gyro": 0.04, "rest_acc": 0.28}
#: Each parameter's candidates: multiples of its current value, or these values.
_STEPS = (0.5, 0.7, 1.4, 2.0)
_CHOICES = {"acc_motion_leak": (0.0, 0.1, 0.25, 0.5, 1.0)}
ROUNDS = 2


class Data:
    """Every recording of the study, its kind and VQF's causal and offline errors."""

    def __init__(self, broad_dir: Path, seed: int):
        from strapdown.apps.ahrs_generalisation import trial
        from strapdown.io.broad import read_broad
        from strapdown.truth.scenarios import record, suite

        group_of = groups(broad_dir)
        self.trials = [read_broad(p) for p in sorted(broad_dir.glob("*.mat"))]
        self.kind = {tr.name: "broad:" + group_of[tr.name] for tr in self.trials}
        for k, sc in enumerate(suite(seed)):
            tr = trial(record(sc, np.random.SeedSequence([seed, k])))
            self.trials.append(tr)
            self.kind[tr.name] = "sim:" + sc.name.split("-")[0]
        self.kinds = sorted(set(self.kind.values()))
        self.vqf = {tr.name: _vqf(tr) for tr in self.trials}


def _vqf(tr) -> tuple[float, float]:
    from strapdown.analysis.broad import broad_errors
    from strapdown.apps.ahrs_benchmark import run_filter

    return tuple(broad_errors(run_filter(f, tr), tr.q_ref, tr.movement)["total_deg"]
                 for f in ("VQF", "offlineVQF"))


def errors(data: Data, config: dict, kinds, offline: bool = False) -> dict[str, float]:
    """Total RMSE (°, BROAD's metric) of our filter per recording of ``kinds``."""
    from strapdown.ahrs import AhrsConfig, ekf, offline_ekf
    from strapdown.analysis.broad import broad_errors

    run = offline_ekf if offline else ekf
    out = {}
    for tr in data.trials:
        if data.kind[tr.name] in kinds:
            r = run(tr.t, tr.gyro, tr.acc, tr.mag, config=AhrsConfig(**config))
            out[tr.name] = broad_errors(r.q, tr.q_ref, tr.movement)["total_deg"]
    return out


def kind_ratios(data: Data, err: dict[str, float], offline: bool = False) -> dict[str, float]:
    """Per kind, the geometric mean over its recordings of ours / VQF of the same kind."""
    j = 1 if offline else 0
    logs: dict[str, list[float]] = {}
    for n, e in err.items():
        logs.setdefault(data.kind[n], []).append(math.log(e / data.vqf[n][j]))
    return {k: math.exp(float(np.mean(v))) for k, v in logs.items()}


def cost(data: Data, config: dict, kinds) -> float:
    """The objective (module docstring) on ``kinds``."""
    lr = [math.log(r) for r in kind_ratios(data, errors(data, config, kinds)).values()]
    return float(np.mean(lr) + np.mean(np.maximum(lr, 0.0)))


def tune(data: Data, kinds) -> tuple[dict, float]:
    """Coordinate search from :data:`PRIOR` on ``kinds``."""
    cur = dict(PRIOR)
    best = cost(data, cur, kinds)
    for _ in range(ROUNDS):
        improved = False
        for k in PRIOR:
            cands = _CHOICES.get(k) or tuple(cur[k] * f for f in _STEPS)
            for v in cands:
                if v == cur[k]:
                    continue
                c = cost(data, {**cur, k: v}, kinds)
                if c < best - 1e-4:
                    best, cur, improved = c, {**cur, k: v}, True
        if not improved:
            break
    return cur, best


_DATA: Data | None = None


def _init(broad_dir: str, seed: int) -> None:
    global _DATA
    _DATA = Data(Path(broad_dir), seed)


def _fold(held: str | None):
    assert _DATA is not None
    train = [k for k in _DATA.kinds if k != held]
    config, c = tune(_DATA, train)
    test = [held] if held else _DATA.kinds
    causal = kind_ratios(_DATA, errors(_DATA, config, test))
    offline = kind_ratios(_DATA, errors(_DATA, config, test, True), True)
    return held, config, c, causal, offline


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    p.add_argument("dir", type=Path)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", type=Path, default=Path("reports/ahrs_cv_kinds.json"))
    p.add_argument("--jobs", type=int, default=2)
    a = p.parse_args(argv)
    _init(str(a.dir), a.seed)
    assert _DATA is not None
    kinds = _DATA.kinds
    with ProcessPoolExecutor(a.jobs, initializer=_init, initargs=(str(a.dir), a.seed)) as ex:
        folds = list(ex.map(_fold, [*kinds, None]))
    prior_c = kind_ratios(_DATA, errors(_DATA, PRIOR, kinds))
    prior_o = kind_ratios(_DATA, errors(_DATA, PRIOR, kinds, True), True)
    _, defaults, _, fit_c, fit_o = folds[-1]
    report = {"seed": a.seed, "prior": PRIOR, "defaults": defaults,
              "folds": {f[0]: f[1] for f in folds[:-1]},
              "kinds": {k: {"prior": prior_c[k], "fitted": fit_c[k],
                            "held_out": folds[i][3][k], "prior_offline": prior_o[k],
                            "fitted_offline": fit_o[k], "held_out_offline": folds[i][4][k]}
                        for i, k in enumerate(kinds)}}
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(report, indent=2))
    print("ours / VQF of the same kind (geometric mean over the kind's recordings), causal | "
          "offline: prior, fitted, held out")
    for k, r in report["kinds"].items():
        print(f"{k:28s} {r['prior']:5.2f} {r['fitted']:5.2f} {r['held_out']:5.2f} | "
              f"{r['prior_offline']:5.2f} {r['fitted_offline']:5.2f} "
              f"{r['held_out_offline']:5.2f}")
    print("defaults:", json.dumps(defaults))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
