"""Parameter sweeps from a TOML scenario file: resumable, on a process pool or a Dask cluster.

A scenario names a motion and a sensor (any
:class:`~strapdown.analysis.evaluate.EvaluationConfig` field; gyro errors under
``[gyro]`` as :class:`~strapdown.truth.sensors.GyroErrors` fields), the algorithms
to run (specs as in :mod:`strapdown.apps.compare`), the metrics to keep (keys of
:meth:`~strapdown.analysis.evaluate.Evaluation.to_dict`) and a grid::

    algorithms = ["rotvec:N=2", "rotvec:N=3", "rate-three", "rk4"]
    metrics = ["max_error_rad", "cone_axis_drift_rad_s", "predicted_drift_rad_s"]
    seed = 7                      # noise seed (needed when [gyro] has random errors)

    [motion]
    motion = "coning"
    half_angle_deg = 1.0

    [sensor]
    sample_rate_hz = 2000.0
    duration = 4.0

    [gyro]
    white_noise = 1e-6

    [grid]                        # every combination, times every algorithm
    cone_rate_hz = [1.0, 2.0, 5.0]
    "gyro.white_noise" = [0.0, 1e-5]

A *case* is one grid point with one algorithm; it is identified by its grid point
(``case``, the grid parameters, ``algorithm``), and its result by its configuration.
Cases are numbered grid-point major, algorithm minor. Each finished result is written at
once, atomically, to ``OUT/cases/<key>.json`` where the key is a hash of the full
configuration (the metrics only, no labels); a rerun skips every configuration whose file
exists, so a crash or Ctrl-C loses no finished case, and a changed scenario never reuses a
stale result. Cases with the same configuration — a repeated grid value, or a grid field
the algorithm spec sets itself (``subsamples`` under ``rotvec:N=3``) — are computed once and
each labelled with its own grid point. When every case is done the tidy table — one row per
case: ``case``, the grid parameters, ``algorithm``, the metrics — is written as
``results.csv`` and, when pyarrow is installed (the ``parquet`` extra) or Parquet is asked
for, ``results.parquet`` (:func:`default_formats`), the Parquet table built before anything
is written.

Every value of a scenario is checked for what its field takes, and every configuration
before the first case runs (:func:`load_scenario`); anything wrong is an
:class:`~strapdown.InputError`.
A table with ``predicted_drift_rad_s`` also gets ``measured_over_law`` and
``law_status`` (resolved, below float64 floor, higher order in a dominates, gyro
errors included: :mod:`strapdown.analysis.law`), so no ratio goes out without its
meaning.

A scenario on the sculling motion (``motion = "sculling"`` with ``angle_amplitude_deg``,
``accel_amplitude``, ``frequency_hz``, ``phase_deg``; :mod:`strapdown.analysis.sculling`)
runs velocity algorithms (``rotvec:N=…`` in the conventional or single-chain structure)
and takes the velocity metrics (:data:`~strapdown.analysis.evaluate.SCULLING_METRICS`;
default: the rectified velocity-error rate, the law's and their ratio); an attitude
metric there, or a velocity metric on an attitude motion, is an InputError.

Noise is common to the algorithms of one grid point (common random numbers):
the case seed is drawn from ``SeedSequence([seed, grid_point])``. Results do
not depend on the scheduler, the number of workers or the order of
completion: tables from the local pool and from Dask are byte-identical.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import os
import sys
import tomllib
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, get_args

import numpy as np

from strapdown._core.errors import InputError, shown
from strapdown.algorithms.spec import parse_spec
from strapdown.analysis.evaluate import (
    CONFIG_FIELDS,
    METRICS,
    EvaluationConfig,
    MetricName,
    motion_kind,
    run_evaluation,
)
from strapdown.io.files import atomic_path, csv_table, write_text
from strapdown.truth.sensors import GyroErrors

__all__ = ["FORMATS", "Case", "Scenario", "SweepInterrupted", "SweepResult", "TableFormat",
           "case_metrics", "case_row", "cases", "default_formats", "load_scenario", "run_case",
           "sweep"]

# The metric names a scenario may ask for are the evaluation's (METRICS, MetricName: keys of
# Evaluation.to_dict), defined in strapdown.analysis.evaluate.
DEFAULT_METRICS: tuple[MetricName, ...] = ("max_error_rad", "rms_error_rad",
                                           "cone_axis_drift_rad_s", "predicted_drift_rad_s")
#: The default metrics of a scenario on the sculling motion.
SCULLING_DEFAULT_METRICS: tuple[MetricName, ...] = (
    "velocity_error_rate_m_s2", "predicted_velocity_error_rate_m_s2", "velocity_rate_over_law")
#: Added to a table that has the law's drift: the ratio and its meaning (analysis.law).
LAW_COLUMNS: tuple[MetricName, ...] = ("measured_over_law", "law_status")
#: The table formats a finished sweep can write.
TableFormat = Literal["csv", "parquet"]
FORMATS: tuple[TableFormat, ...] = get_args(TableFormat)


def default_formats() -> tuple[TableFormat, ...]:
    """The tables a sweep writes unless told: CSV always, Parquet too when pyarrow is
    installed (the ``parquet`` extra), so the core install runs a sweep as documented."""
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return ("csv",)
    return FORMATS
_CONFIG_FIELDS = set(CONFIG_FIELDS) - {"gyro", "seed"}
_GYRO_FIELDS = {f.name for f in dataclasses.fields(GyroErrors)}
_SECTIONS = ("motion", "sensor", "run")
_TOP = {"algorithms", "metrics", "seed", "grid", "gyro", *_SECTIONS}


@dataclass(frozen=True)
class Scenario:
    """A parsed scenario file (see the module docstring)."""

    base: dict
    gyro: dict
    algorithms: tuple[str, ...]
    metrics: tuple[str, ...]
    grid: dict
    seed: int | None = None


@dataclass(frozen=True)
class Case:
    """One grid point with one algorithm."""

    index: int
    point: int
    params: dict
    algorithm: str
    config: EvaluationConfig
    metrics: tuple[str, ...]

    @property
    def key(self) -> str:
        """Hash of everything that determines the result."""
        c = self.config.flat()  # the spec's fields flat beside the rest, as ever
        text = json.dumps({"config": c, "metrics": self.metrics}, sort_keys=True,
                          default=_jsonable)
        return hashlib.sha256(text.encode()).hexdigest()[:20]


def _jsonable(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"cannot serialise {type(x).__name__}")


def _check_keys(where: str, got, allowed) -> None:
    bad = sorted(set(got) - set(allowed))
    if bad:
        raise InputError(f"{where}: unknown key(s) {shown(bad, 120)}; allowed: "
                         f"{', '.join(sorted(allowed))}")


#: How often a local pool's parent looks for a deferred Ctrl-C while it waits (seconds).
POLL_S = 0.1
#: How long a local pool's workers have to end on SIGTERM before they are killed (seconds).
KILL_AFTER_S = 3.0
#: Largest scenario file read (bytes).
MAX_SCENARIO_BYTES = 1024**2
#: Most cases (grid points × algorithms) one scenario may have.
MAX_CASES = 100_000
#: What each value of a scenario must be: the EvaluationConfig and GyroErrors fields.
_KINDS = {"motion": "str", "half_angle_deg": "number", "cone_rate_hz": "number",
          "spin_rate_dps": "number", "sample_rate_hz": "number", "duration": "number",
          "subsamples": "int", "coefficients": "str", "structure": "str", "rk4_step": "str",
          "krylov_rates": "triple", "alpha": "number", "beta": "number", "step": "number",
          "exact_exp": "bool", "precision": "int", "angle_amplitude_deg": "number",
          "accel_amplitude": "number", "frequency_hz": "number", "phase_deg": "number",
          "gyro.white_noise": "number", "gyro.bias": "vector", "gyro.gm_sigma": "vector",
          "gyro.gm_tau": "number or inf", "gyro.scale_factor": "vector",
          "gyro.misalignment": "matrix", "gyro.quantization": "number",
          "gyro.saturation": "number or inf"}
#: Largest arbitrary-precision digits a scenario may ask for.
MAX_PRECISION = 10_000


def _is_number(v, inf: bool = False) -> bool:
    return (isinstance(v, (int, float)) and not isinstance(v, bool)
            and (math.isfinite(v) or (inf and v == math.inf)))


def _check_value(where: str, key: str, v) -> object:
    """``v`` if it is what ``key`` takes (:data:`_KINDS`), as the configuration wants it
    (lists of numbers as tuples for krylov_rates); else an InputError naming both."""
    kind = _KINDS.get(key)
    ok = {"str": lambda: isinstance(v, str),
          "int": lambda: isinstance(v, int) and not isinstance(v, bool),
          "bool": lambda: isinstance(v, bool),
          "number": lambda: _is_number(v),
          "number or inf": lambda: _is_number(v, inf=True),
          "triple": lambda: isinstance(v, list) and len(v) == 3 and all(map(_is_number, v)),
          "vector": lambda: _is_number(v) or (isinstance(v, list) and len(v) == 3
                                              and all(map(_is_number, v))),
          "matrix": lambda: isinstance(v, list) and len(v) == 3 and all(
              isinstance(r, list) and len(r) == 3 and all(map(_is_number, r)) for r in v),
          None: lambda: True}[kind]()
    if key == "precision" and ok and not 0 < v <= MAX_PRECISION:
        raise InputError(f"{where}: precision must be 1–{MAX_PRECISION} digits, got {v}")
    if not ok:
        what = {"number": "a finite number", "number or inf": "a number (inf allowed)",
                "triple": "a list of three finite numbers", "matrix": "a 3×3 list of lists",
                "vector": "a finite number or a list of three", "str": "a string",
                "int": "an integer", "bool": "true or false"}[str(kind)]
        raise InputError(f"{where}: {key} must be {what}, got {shown(v, 60)}")
    return tuple(v) if kind == "triple" else v


def _read_toml(path: Path) -> dict:
    """The scenario file's TOML document; anything unreadable is an InputError."""
    if path.is_dir():
        raise InputError(f"{path}: is a directory; expected a scenario file (.toml)")
    if not path.is_file():
        raise InputError(f"{path}: no such scenario file")
    size = path.stat().st_size
    if size > MAX_SCENARIO_BYTES:
        raise InputError(f"{path}: a scenario of {size} bytes (at most {MAX_SCENARIO_BYTES})")
    try:
        return tomllib.loads(path.read_bytes().decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not UTF-8 text (byte {exc.start}); expected a TOML "
                         "scenario") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML ({shown(str(exc), 160)})") from None
    except RecursionError:
        raise InputError(f"{path}: nested too deeply to be a scenario") from None


def _table(path: Path, doc: dict, key: str) -> dict:
    part = doc.get(key, {})
    if not isinstance(part, dict):
        raise InputError(f"{path}: [{key}] must be a table, got {shown(part, 40)}")
    return part


def _strings(path: Path, doc: dict, key: str, default: list[str] | None) -> list[str]:
    v = doc.get(key, default)
    if not isinstance(v, list) or not v or not all(isinstance(a, str) for a in v):
        raise InputError(f"{path}: '{key}' must be a non-empty list of strings, got "
                         f"{shown(v, 60)}")
    return list(v)


def _base(path: Path, doc: dict) -> tuple[dict, dict]:
    """The configuration fields of [motion], [sensor], [run] and the [gyro] table."""
    base: dict = {}
    for sec in _SECTIONS:
        part = _table(path, doc, sec)
        _check_keys(f"{path} [{sec}]", part, _CONFIG_FIELDS - {"algorithm"})
        dup = set(part) & set(base)
        if dup:
            raise InputError(f"{path}: {sorted(dup)} set in more than one section")
        base.update({k: _check_value(f"{path} [{sec}]", k, v) for k, v in part.items()})
    gyro = _table(path, doc, "gyro")
    _check_keys(f"{path} [gyro]", gyro, _GYRO_FIELDS)
    return base, {k: _check_value(f"{path} [gyro]", f"gyro.{k}", v) for k, v in gyro.items()}


def _grid(path: Path, doc: dict, n_algorithms: int) -> dict:
    """The [grid] table, every value checked for its field, its size bounded."""
    grid = _table(path, doc, "grid")
    points = 1
    for k, v in grid.items():
        if k.startswith("gyro."):
            _check_keys(f"{path} [grid]", [k[5:]], _GYRO_FIELDS)
        else:
            _check_keys(f"{path} [grid]", [k], _CONFIG_FIELDS - {"algorithm"})
        if not isinstance(v, list) or not v:
            raise InputError(f"{path}: grid '{k}' must be a non-empty list")
        points *= len(v)
        if points * n_algorithms > MAX_CASES:
            raise InputError(f"{path}: the grid has more than {MAX_CASES} cases (grid points × "
                             "algorithms); split the scenario")
    out = {k: [_check_value(f"{path} [grid] {k}", k, x) for x in v] for k, v in grid.items()}
    for k, v in out.items():  # a table column holds one kind of value
        kinds = {"number" if _is_number(x, inf=True) else type(x).__name__ for x in v}
        if len(kinds) > 1:
            raise InputError(f"{path}: grid '{k}' mixes {' and '.join(sorted(kinds))} values; "
                             "a results column holds one kind")
    return out


def load_scenario(path) -> Scenario:
    """Parse and check a TOML scenario; errors name the file and the key.

    Every value is checked for what its field takes (a finite number, an integer, a
    string, three numbers …) and every configuration of the grid is validated before
    anything runs (:meth:`~strapdown.analysis.evaluate.EvaluationConfig.validate`: sample
    counts up to :data:`~strapdown.analysis.evaluate.MAX_SAMPLES`, rates up to Nyquist);
    the file is at most :data:`MAX_SCENARIO_BYTES`, the grid at most :data:`MAX_CASES` cases.
    Anything wrong is an :class:`~strapdown.InputError`.
    """
    path = Path(path)
    doc = _read_toml(path)
    _check_keys(str(path), doc, _TOP)
    base, gyro = _base(path, doc)
    algorithms = _strings(path, doc, "algorithms", None)
    for a in algorithms:
        try:
            parse_spec(a)
        except ValueError as exc:
            raise InputError(f"{path}: {exc}") from None
    if len(set(algorithms)) != len(algorithms):
        raise InputError(f"{path}: an algorithm spec appears twice")
    try:
        kind = motion_kind(base.get("motion", EvaluationConfig.motion))
    except ValueError:
        kind = None  # an unknown motion is refused with its case below
    velocity = kind is not None and kind.has_metric("velocity_error_rate_m_s2")
    metrics = _strings(path, doc, "metrics",
                       list(SCULLING_DEFAULT_METRICS if velocity else DEFAULT_METRICS))
    if "predicted_drift_rad_s" in metrics:  # a law in the table comes with what it means
        metrics += [m for m in LAW_COLUMNS if m not in metrics]
    bad = [m for m in metrics if m not in METRICS]
    if bad:
        raise InputError(f"{path}: unknown metric(s) {shown(bad, 80)}; choose from "
                         f"{', '.join(sorted(METRICS))}")
    grid = _grid(path, doc, len(algorithms))
    seed = doc.get("seed")
    if seed is not None and (not isinstance(seed, int) or isinstance(seed, bool) or seed < 0):
        raise InputError(f"{path}: seed must be a non-negative integer, got {shown(seed, 30)}")
    scn = Scenario(base, gyro, tuple(algorithms), tuple(metrics), grid, seed)
    try:
        cases(scn)  # validates every configuration before anything runs
    except ValueError as exc:
        raise InputError(f"{path}: {exc}") from None
    return scn


def _point_config(scn: Scenario, p: int, params: dict) -> tuple[dict, GyroErrors | None,
                                                                   int | None]:
    """Configuration fields, gyro errors and noise seed of grid point ``p``."""
    cfg_fields = dict(scn.base)
    gyro = dict(scn.gyro)
    for k, v in params.items():
        if k.startswith("gyro."):
            gyro[k[5:]] = v
        else:
            cfg_fields[k] = v
    try:
        errors = GyroErrors(**gyro) if gyro else None
    except (TypeError, ValueError) as exc:
        raise InputError(f"grid point {p} ({shown(params, 120)}): gyro: {exc}") from None
    seed = None
    if errors is not None and not errors.is_ideal:
        if scn.seed is None:
            raise InputError("the scenario has random gyro errors; give a top-level seed")
        seed = int(np.random.SeedSequence([scn.seed, p]).generate_state(1)[0])
    return cfg_fields, errors, seed


def cases(scn: Scenario) -> list[Case]:
    """Every case of a scenario, in table order (grid point major, algorithm minor).

    Two cases may have the same configuration (a repeated grid value, or a grid field the
    algorithm spec sets itself): they share one result (:attr:`Case.key`), computed once,
    and each keeps its own grid point and labels in the table.
    """
    keys = list(scn.grid)
    out: list[Case] = []
    points = itertools.product(*(scn.grid[k] for k in keys)) if keys else iter([()])
    for p, values in enumerate(points):
        params = dict(zip(keys, values, strict=True))
        cfg_fields, errors, seed = _point_config(scn, p, params)
        for a in scn.algorithms:
            try:
                cfg = EvaluationConfig.of(**{**cfg_fields, **parse_spec(a)}, gyro=errors,
                                          seed=seed)
                cfg.validate()
                _ = cfg.samples
                _check_runs(cfg)
                _check_metrics(cfg, scn.metrics)
            except (ValueError, TypeError, OverflowError, ArithmeticError) as exc:
                raise InputError(f"case {len(out)} ({a}, {shown(params, 120)}): {exc}"
                                 ) from None
            out.append(Case(len(out), p, params, a, cfg, scn.metrics))
    if not out:
        raise InputError("the grid is empty")
    return out


#: Largest relative gyro scale-factor error and misalignment entry a scenario may set
#: (100 %: beyond, the sensor measures another motion, not the one configured).
MAX_RELATIVE_ERROR = 1.0


def _check_runs(cfg: EvaluationConfig) -> None:
    """What :meth:`EvaluationConfig.validate` leaves to run time, so that a scenario that
    validates also runs: the motion is built (pure spin needs a spin rate), and each gyro
    error stays within what the samples resolve — a bias, Gauss–Markov σ and white noise
    per sample (``σ·√h``) turning the body by at most π per sample (Nyquist, as the motion
    rates), scale factors and misalignments within ±:data:`MAX_RELATIVE_ERROR`."""
    if cfg.kind.truth is not None:
        try:
            cfg.kind.truth(cfg)  # the motion is built (pure spin needs a spin rate)
        except ValueError as exc:  # name the scenario's key, not the command line's option
            raise InputError(str(exc).replace("--spin-rate-dps", "spin_rate_dps")) from None
    e = cfg.gyro
    if e is None:
        return
    h = cfg.h
    turns = {"bias": float(np.max(np.abs(e.bias))) * h,
             "gm_sigma": float(np.max(e.gm_sigma)) * h,
             "white_noise": float(e.white_noise) * math.sqrt(h)}
    for name, angle in turns.items():
        if not angle <= math.pi:
            raise InputError(f"gyro {name} turns the body by {angle:.3g} rad per sample at "
                             f"{cfg.sample_rate_hz:g} Hz; at most π (Nyquist)")
    for name in ("scale_factor", "misalignment"):
        big = float(np.max(np.abs(getattr(e, name))))
        if not big <= MAX_RELATIVE_ERROR:
            raise InputError(f"gyro {name} must lie within ±{MAX_RELATIVE_ERROR:g} (relative), "
                             f"got {big:g}")


def _check_metrics(cfg: EvaluationConfig, metrics: Iterable[str]) -> None:
    """The metrics must be the motion's: velocity metrics on the sculling motion, attitude
    metrics elsewhere (``update_period_s`` and ``samples`` on both)."""
    kind = cfg.kind
    bad = [m for m in metrics if not kind.has_metric(m)]
    if kind.metrics is not None:
        what = f"the {cfg.motion} motion has the velocity metrics " + ", ".join(kind.metrics)
    else:
        what = f"the {cfg.motion} motion has no velocity metrics (those are the sculling's)"
    if bad:
        raise InputError(f"metric(s) {', '.join(bad)} do not apply: {what}")


def case_metrics(case: Case) -> dict:
    """Evaluate one case's configuration; its metrics (JSON-ready), what the case store
    keeps under :attr:`Case.key` — shared by every case with that configuration. Picklable
    for workers."""
    d = run_evaluation(case.config).to_dict()
    out: dict = {}
    for m in case.metrics:
        v = d.get(m)
        if isinstance(v, (list, tuple)):
            for i, x in enumerate(v):
                out[f"{m}[{i}]"] = _scalar(x)
        else:
            out[m] = _scalar(v)
    return out


def case_row(case: Case, metrics: dict) -> dict:
    """The table row of ``case``: its own labels (case, grid point, algorithm), then the
    metrics of its configuration."""
    return {"case": case.index, **case.params, "algorithm": case.algorithm, **metrics}


def run_case(case: Case) -> dict:
    """Evaluate one case; returns its table row (JSON-ready)."""
    return case_row(case, case_metrics(case))


def _scalar(v):
    if v is None:
        return None
    if isinstance(v, (bool, str)):
        return v
    if isinstance(v, (int, np.integer)):
        return int(v)
    return float(v)


@dataclass(frozen=True)
class SweepResult:
    """What a sweep did: case counts and the table paths (None until the grid is complete)."""

    total: int
    skipped: int
    computed: int
    csv: Path | None
    parquet: Path | None

    @property
    def complete(self) -> bool:
        return self.csv is not None


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a sweep; its finished cases are saved and a rerun resumes.

    ``str()`` is the one line the command line prints, e.g. ``interrupted, 9/30 cases done;
    rerun the same command to resume``.
    """

    def __init__(self, done: int, total: int) -> None:
        super().__init__(f"interrupted, {done}/{total} cases done; rerun the same command "
                         "to resume")
        self.done = done
        self.total = total


def _parse_scheduler(scheduler: str) -> tuple[Literal["local", "dask"], str | None]:
    if scheduler == "local":
        return "local", None
    if scheduler.startswith("dask://"):
        addr = scheduler[len("dask://"):]
        if not addr or ":" not in addr:
            raise InputError(f"--scheduler {scheduler!r}: expected dask://HOST:PORT")
        return "dask", "tcp://" + addr
    raise InputError(f"--scheduler must be 'local' or 'dask://HOST:PORT', got {scheduler!r}")


def sweep(scenario: str | os.PathLike[str] | Scenario, out: str | os.PathLike[str], *,
          scheduler: str = "local", workers: int | None = None,
          formats: Iterable[TableFormat] | None = None, max_cases: int | None = None,
          progress: bool = False, log: Callable[[str], None] | None = None) -> SweepResult:
    """Run (or finish) a scenario's grid; see the module docstring.

    Parameters
    ----------
    scenario : path or Scenario
    out : path
        Output directory (created). Finished cases live in ``out/cases``.
    scheduler : str
        ``"local"`` (a process pool) or ``"dask://HOST:PORT"`` (a Dask cluster); a string,
        not a Literal, because of the address.
    workers : int, optional
        Local pool size (default: CPU count); 1 runs in this process.
    formats : subset of {"csv", "parquet"}, optional
        The tables written; default :func:`default_formats` (CSV, and Parquet when pyarrow
        is installed). Asking for Parquet without pyarrow is an InputError.
    max_cases : int, optional
        Compute at most this many new cases, then stop (the table is written
        only when the grid is complete).
    progress : bool
        Progress bar (tqdm) on stderr.
    log : callable, optional
        Receives one status line before the run (cases done, to run, where); the outcome
        is the returned :class:`SweepResult`.

    Raises
    ------
    SweepInterrupted
        On Ctrl-C (a ``KeyboardInterrupt``), after stopping the workers; it says how many
        cases are saved.

    Whatever stops a sweep, the directories it created and left empty (``out/cases`` before
    the first finished case) are removed again.
    """
    kind, address = _parse_scheduler(scheduler)
    formats = _check_options(default_formats() if formats is None else tuple(formats),
                             workers, max_cases)
    scn = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"{out} exists and is not a directory")
    all_cases = cases(scn)
    store = out / "cases"
    made, d = [], store  # the directories this call creates: removed again if left empty
    while not d.exists() and d != d.parent:
        made.append(d)
        d = d.parent
    store.mkdir(parents=True, exist_ok=True)
    try:
        return _sweep(scn, out, store, all_cases, kind, address, workers, formats,
                      max_cases, progress, log or (lambda _m: None))
    except BaseException:
        for d in made:  # deepest first: a failed first run leaves no empty directories
            try:
                d.rmdir()
            except OSError:  # not empty (a finished case) or already gone: kept
                break
        raise


def _sweep(scn: Scenario, out: Path, store: Path, all_cases: list[Case], kind: str,
           address: str | None, workers: int | None, formats: tuple, max_cases: int | None,
           progress: bool, say: Callable[[str], None]) -> SweepResult:
    """:func:`sweep` once the scenario is checked and ``store`` exists."""
    for stale in store.glob(".*.json.*"):  # temp files of a killed run (never a finished case)
        stale.unlink(missing_ok=True)
    first = {c.key: c for c in reversed(all_cases)}  # each configuration's first case
    stored = {k for k in first if (store / f"{k}.json").is_file()}
    pending = [first[k] for k in dict.fromkeys(c.key for c in all_cases) if k not in stored]
    skipped = sum(c.key in stored for c in all_cases)
    if max_cases is not None:
        pending = pending[:max_cases]
    shared = "" if len(first) == len(all_cases) else f" ({len(first)} distinct configurations)"
    say(f"{len(all_cases)} cases{shared}: {skipped} already done, {len(pending)} to run "
        f"({'local pool' if kind == 'local' else address})")

    def finish(case: Case, metrics: dict) -> None:
        write_text(store / f"{case.key}.json", json.dumps({"key": case.key, "metrics": metrics}))

    from tqdm import tqdm

    try:
        with tqdm(total=len(pending), disable=not progress, unit="case",
                  file=sys.stderr) as bar:
            if kind == "dask":
                _run_dask(address, pending, finish, bar)
            else:
                _run_local(pending, workers, finish, bar)
    except KeyboardInterrupt:
        done = sum((store / f"{c.key}.json").is_file() for c in all_cases)
        raise SweepInterrupted(done, len(all_cases)) from None
    if not all((store / f"{k}.json").is_file() for k in first):
        return SweepResult(len(all_cases), skipped, len(pending), None, None)
    rows = [case_row(c, _stored(store / f"{c.key}.json", c)) for c in all_cases]
    table = _arrow_table(rows) if "parquet" in formats else None  # fails before any write
    csv_path = _write_csv(out / "results.csv", rows)
    pq = _write_parquet(out / "results.parquet", table) if table is not None else None
    return SweepResult(len(all_cases), skipped, len(pending), csv_path, pq)


def _stored(path: Path, case: Case) -> dict:
    """The metrics a case file holds (files of earlier versions held a labelled row)."""
    data = json.loads(path.read_text(encoding="utf-8"))
    if "metrics" in data:
        return data["metrics"]
    labels = {"case", "algorithm", *case.params}
    return {k: v for k, v in data["row"].items() if k not in labels}


def _check_options(formats: tuple, workers: int | None, max_cases: int | None) -> tuple:
    """The table formats, once the sweep's options are checked (InputError naming one)."""
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise InputError(f"formats must be a non-empty subset of csv, parquet; got {formats}")
    if "parquet" in formats:
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise InputError("Parquet output needs pyarrow: pip install 'strapdown[parquet]', "
                             "or ask for --format csv") from None
    if workers is not None and workers < 1:
        raise InputError(f"workers must be at least 1, got {workers}")
    if max_cases is not None and max_cases < 0:
        raise InputError(f"max_cases must be non-negative, got {max_cases}")
    return formats


def _run_local(pending, workers, finish, bar) -> None:
    if not pending:
        return
    if workers == 1:
        for c in pending:
            finish(c, case_metrics(c))
            bar.update()
        return
    import multiprocessing

    from strapdown._core import compile_notice
    from strapdown._core.signals import interrupts_deferred

    # Workers ignore Ctrl-C (the parent alone reports it) and carry the compile notice; on
    # any exception, Ctrl-C included, they are terminated at once. The parent's Ctrl-C and
    # SIGTERM are deferred to between results, from after the workers are forked (they keep
    # the command line's handlers) until they are gone: raised inside the pool's iterator,
    # one could leave a lock held that terminate() then waits on for ever.
    ctx = multiprocessing.get_context()
    said = ctx.Value("b", 0)
    with ctx.Pool(workers, initializer=compile_notice.worker_initializer,
                  initargs=(said, compile_notice.active())) as pool, \
            interrupts_deferred() as check:
        try:
            results = pool.imap_unordered(_run_numbered, enumerate(pending))
            while True:
                check()
                try:
                    i, row = results.next(timeout=POLL_S)
                except multiprocessing.TimeoutError:
                    continue
                except StopIteration:
                    break
                finish(pending[i], row)
                bar.update()
            pool.close()
            pool.join()
        finally:
            _terminate(pool, ctx)  # done here, still deferred; the pool's exit repeats it


def _terminate(pool, ctx) -> None:
    """``pool.terminate()``, with any worker still alive :data:`KILL_AFTER_S` later killed.

    terminate() sends each worker SIGTERM and waits for it without a limit. A worker may not
    end on it: under test (a CPU burner beside), 1 interrupted sweep in 18 kept a worker
    blocked on its queue's lock with SIGTERM never handled, and the sweep hung. A worker's
    SystemExit dropped in a finaliser ends the same way. SIGKILL cannot be missed.
    """
    from strapdown._core.signals import after

    workers = [p for p in ctx.active_children() if p.is_alive()]
    guard = after(KILL_AFTER_S, lambda: [p.kill() for p in workers if p.is_alive()])
    try:
        pool.terminate()
    finally:
        guard.cancel()


def _run_numbered(item: tuple[int, Case]) -> tuple[int, dict]:
    """``(i, case)`` → ``(i, metrics)``: a pool result that names its case."""
    i, case = item
    return i, case_metrics(case)


def _run_dask(address, pending, finish, bar) -> None:
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise InputError("--scheduler dask:// needs dask.distributed: "
                         "pip install 'strapdown[dask]'") from None
    if not pending:
        return
    try:
        client = Client(address, timeout="10s")
    except OSError as exc:
        raise InputError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
    try:
        futures = client.map(case_metrics, pending, pure=False)
        by_future = dict(zip(futures, pending, strict=True))
        for fut in as_completed(futures):
            finish(by_future[fut], fut.result())
            bar.update()
    finally:
        client.close()


def _columns(rows) -> list[str]:
    cols: list[str] = []
    for r in rows:
        cols += [k for k in r if k not in cols]
    return cols


def _text(v) -> str:
    """A table value as CSV text: floats round-trip (repr), missing values are empty."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return ""
    return repr(v) if isinstance(v, float) else str(v)


def _write_csv(path: Path, rows) -> Path:
    cols = _columns(rows)
    return write_text(path, csv_table(cols, [[_text(r.get(c)) for c in cols] for r in rows]))


def _arrow_table(rows):
    """The rows as a pyarrow table (an InputError when a column mixes types)."""
    import pyarrow as pa

    cols = _columns(rows)
    try:
        return pa.Table.from_pydict({c: [r.get(c) for r in rows] for c in cols})
    except (pa.ArrowInvalid, pa.ArrowTypeError) as exc:
        raise InputError(f"the results cannot be written as Parquet ({shown(str(exc), 160)}); "
                         "nothing written") from None


def _write_parquet(path: Path, table) -> Path:
    import pyarrow.parquet as pq

    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path
