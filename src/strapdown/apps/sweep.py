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

A *case* is one grid point with one algorithm. Cases are numbered grid-point
major, algorithm minor. Each finished case is written at once, atomically, to
``OUT/cases/<key>.json`` where the key is a hash of the case's full
configuration; a rerun skips every case whose file exists, so a crash or
Ctrl-C loses no finished case, and a changed scenario never reuses a stale
result. When every case is done the tidy table — one row per case: ``case``,
the grid parameters, ``algorithm``, the metrics — is written as
``results.csv`` and ``results.parquet`` (pyarrow; the ``parquet`` extra).
A table with ``predicted_drift_rad_s`` also gets ``measured_over_law`` and
``law_status`` (resolved, below float64 floor, higher order in a dominates, gyro
errors included: :mod:`strapdown.analysis.law`), so no ratio goes out without its
meaning.

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

from strapdown.algorithms.spec import parse_spec
from strapdown.analysis.evaluate import METRICS, EvaluationConfig, MetricName, evaluate
from strapdown.io.files import atomic_path, csv_table, write_text
from strapdown.truth.sensors import GyroErrors

__all__ = ["FORMATS", "Case", "Scenario", "SweepInterrupted", "SweepResult", "TableFormat",
           "cases", "load_scenario", "run_case", "sweep"]

# The metric names a scenario may ask for are the evaluation's (METRICS, MetricName: keys of
# Evaluation.to_dict), defined in strapdown.analysis.evaluate.
DEFAULT_METRICS: tuple[MetricName, ...] = ("max_error_rad", "rms_error_rad",
                                           "cone_axis_drift_rad_s", "predicted_drift_rad_s")
#: Added to a table that has the law's drift: the ratio and its meaning (analysis.law).
LAW_COLUMNS: tuple[MetricName, ...] = ("measured_over_law", "law_status")
#: The table formats a finished sweep writes.
TableFormat = Literal["csv", "parquet"]
FORMATS: tuple[TableFormat, ...] = get_args(TableFormat)
_CONFIG_FIELDS = {f.name for f in dataclasses.fields(EvaluationConfig)} - {"gyro", "seed"}
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
        c = dataclasses.asdict(self.config)
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
        raise ValueError(f"{where}: unknown key(s) {bad}; allowed: {', '.join(sorted(allowed))}")


def load_scenario(path) -> Scenario:
    """Parse and check a TOML scenario; errors name the file and the key."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such scenario file")
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    _check_keys(str(path), doc, _TOP)
    base: dict = {}
    for sec in _SECTIONS:
        part = doc.get(sec, {})
        if not isinstance(part, dict):
            raise ValueError(f"{path}: [{sec}] must be a table")
        _check_keys(f"{path} [{sec}]", part, _CONFIG_FIELDS - {"algorithm"})
        dup = set(part) & set(base)
        if dup:
            raise ValueError(f"{path}: {sorted(dup)} set in more than one section")
        base.update(part)
    if "krylov_rates" in base:
        base["krylov_rates"] = tuple(base["krylov_rates"])
    gyro = doc.get("gyro", {})
    _check_keys(f"{path} [gyro]", gyro, _GYRO_FIELDS)
    algorithms = doc.get("algorithms")
    if not algorithms or not isinstance(algorithms, list):
        raise ValueError(f"{path}: 'algorithms' must be a non-empty list of specs")
    for a in algorithms:
        parse_spec(a)
    if len(set(algorithms)) != len(algorithms):
        raise ValueError(f"{path}: an algorithm spec appears twice")
    metrics = doc.get("metrics", list(DEFAULT_METRICS))
    if not isinstance(metrics, list) or not metrics:
        raise ValueError(f"{path}: 'metrics' must be a non-empty list")
    if "predicted_drift_rad_s" in metrics:  # a law in the table comes with what it means
        metrics += [m for m in LAW_COLUMNS if m not in metrics]
    grid = doc.get("grid", {})
    for k, v in grid.items():
        if k.startswith("gyro."):
            _check_keys(f"{path} [grid]", [k[5:]], _GYRO_FIELDS)
        else:
            _check_keys(f"{path} [grid]", [k], _CONFIG_FIELDS - {"algorithm"})
        if not isinstance(v, list) or not v:
            raise ValueError(f"{path}: grid '{k}' must be a non-empty list")
    seed = doc.get("seed")
    if seed is not None and (not isinstance(seed, int) or seed < 0):
        raise ValueError(f"{path}: seed must be a non-negative integer, got {seed!r}")
    scn = Scenario(base, gyro, tuple(algorithms), tuple(metrics), grid, seed)
    all_cases = cases(scn)  # validates every configuration before anything runs
    bad = [m for m in scn.metrics if m not in METRICS]
    if bad:
        raise ValueError(f"{path}: unknown metric(s) {bad}; choose from "
                         f"{', '.join(sorted(METRICS))}")
    if not all_cases:
        raise ValueError(f"{path}: the grid is empty")
    return scn


def cases(scn: Scenario) -> list[Case]:
    """Every case of a scenario, in table order (grid point major, algorithm minor)."""
    keys = list(scn.grid)
    out: list[Case] = []
    points = list(itertools.product(*(scn.grid[k] for k in keys))) if keys else [()]
    for p, values in enumerate(points):
        params = dict(zip(keys, values, strict=True))
        cfg_fields = dict(scn.base)
        gyro = dict(scn.gyro)
        for k, v in params.items():
            if k.startswith("gyro."):
                gyro[k[5:]] = v
            else:
                cfg_fields[k] = v
        errors = GyroErrors(**gyro) if gyro else None
        seed = None
        if errors is not None and not errors.is_ideal:
            if scn.seed is None:
                raise ValueError("the scenario has random gyro errors; give a top-level seed")
            seed = int(np.random.SeedSequence([scn.seed, p]).generate_state(1)[0])
        for a in scn.algorithms:
            cfg = EvaluationConfig(**{**cfg_fields, **parse_spec(a)}, gyro=errors, seed=seed)
            try:
                cfg.validate()
                _ = cfg.samples
            except ValueError as exc:
                raise ValueError(f"case {len(out)} ({a}, {params}): {exc}") from None
            out.append(Case(len(out), p, params, a, cfg, scn.metrics))
    return out


def run_case(case: Case) -> dict:
    """Evaluate one case; returns its table row (JSON-ready). Picklable for workers."""
    d = evaluate(case.config).to_dict()
    row = {"case": case.index, **case.params, "algorithm": case.algorithm}
    for m in case.metrics:
        v = d.get(m)
        if isinstance(v, (list, tuple)):
            for i, x in enumerate(v):
                row[f"{m}[{i}]"] = _scalar(x)
        else:
            row[m] = _scalar(v)
    return row


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
            raise ValueError(f"--scheduler {scheduler!r}: expected dask://HOST:PORT")
        return "dask", "tcp://" + addr
    raise ValueError(f"--scheduler must be 'local' or 'dask://HOST:PORT', got {scheduler!r}")


def sweep(scenario: str | os.PathLike[str] | Scenario, out: str | os.PathLike[str], *,
          scheduler: str = "local", workers: int | None = None,
          formats: Iterable[TableFormat] = FORMATS, max_cases: int | None = None,
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
    formats : subset of {"csv", "parquet"}
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
    """
    kind, address = _parse_scheduler(scheduler)
    formats = _check_options(tuple(formats), workers, max_cases)
    scn = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    say = log or (lambda _m: None)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"{out} exists and is not a directory")
    store = out / "cases"
    store.mkdir(parents=True, exist_ok=True)
    for stale in store.glob(".*.json.*"):  # temp files of a killed run (never a finished case)
        stale.unlink(missing_ok=True)
    all_cases = cases(scn)
    pending = [c for c in all_cases if not (store / f"{c.key}.json").is_file()]
    skipped = len(all_cases) - len(pending)
    if max_cases is not None:
        pending = pending[:max_cases]
    say(f"{len(all_cases)} cases: {skipped} already done, {len(pending)} to run "
        f"({'local pool' if kind == 'local' else address})")

    def finish(case: Case, row: dict) -> None:
        write_text(store / f"{case.key}.json", json.dumps(
            {"key": case.key, "index": case.index, "row": row}))

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
    done = sum((store / f"{c.key}.json").is_file() for c in all_cases)
    if done < len(all_cases):
        return SweepResult(len(all_cases), skipped, len(pending), None, None)
    rows = [json.loads((store / f"{c.key}.json").read_text(encoding="utf-8"))["row"]
            for c in all_cases]
    csv_path = _write_csv(out / "results.csv", rows)
    pq = _write_parquet(out / "results.parquet", rows) if "parquet" in formats else None
    return SweepResult(len(all_cases), skipped, len(pending), csv_path, pq)


def _check_options(formats: tuple, workers: int | None, max_cases: int | None) -> tuple:
    """The table formats, once the sweep's options are checked (ValueError naming one)."""
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise ValueError(f"formats must be a non-empty subset of csv, parquet; got {formats}")
    if "parquet" in formats:
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise ValueError("Parquet output needs pyarrow: pip install 'strapdown[parquet]', "
                             "or ask for --format csv") from None
    if workers is not None and workers < 1:
        raise ValueError(f"workers must be at least 1, got {workers}")
    if max_cases is not None and max_cases < 0:
        raise ValueError(f"max_cases must be non-negative, got {max_cases}")
    return formats


def _run_local(pending, workers, finish, bar) -> None:
    if not pending:
        return
    if workers == 1:
        for c in pending:
            finish(c, run_case(c))
            bar.update()
        return
    import multiprocessing

    from strapdown._core import compile_notice

    # Workers ignore Ctrl-C (the parent alone reports it) and carry the compile notice; on
    # any exception, Ctrl-C included, leaving the block terminates them at once.
    ctx = multiprocessing.get_context()
    said = ctx.Value("b", 0)
    with ctx.Pool(workers, initializer=compile_notice.worker_initializer,
                  initargs=(said, compile_notice.active())) as pool:
        for i, row in pool.imap_unordered(_run_numbered, enumerate(pending)):
            finish(pending[i], row)
            bar.update()
        pool.close()
        pool.join()


def _run_numbered(item: tuple[int, Case]) -> tuple[int, dict]:
    """``(i, case)`` → ``(i, row)``: a pool result that names its case."""
    i, case = item
    return i, run_case(case)


def _run_dask(address, pending, finish, bar) -> None:
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise ValueError("--scheduler dask:// needs dask.distributed: "
                         "pip install 'strapdown[dask]'") from None
    if not pending:
        return
    try:
        client = Client(address, timeout="10s")
    except OSError as exc:
        raise ValueError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
    try:
        futures = client.map(run_case, pending, pure=False)
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


def _write_parquet(path: Path, rows) -> Path:
    import pyarrow as pa
    import pyarrow.parquet as pq

    cols = _columns(rows)
    table = pa.Table.from_pydict({c: [r.get(c) for r in rows] for c in cols})
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path
