"""Which attitude algorithm to fly in a vibration environment: ``strapdown advise``.

The environment is the cross-spectrum of the body rates — estimated from a gyro log by
Welch's method, or read from a file — and the drift each candidate algorithm would have
there is predicted by summing its exact classical-coning response over the coning
(quadrature) spectrum (:mod:`strapdown.analysis.spectrum`; pseudo-coning in the sense of
Ignagni (1996)). The candidates are every registered family's own
(:meth:`~strapdown.algorithms.family.Family.candidates`: every structure and N of the
rotation vector and its finite-amplitude sets, each rate family in its structures), those
of the log's input kind. Costs (operations per second) come from the caller — the command line
counts them in the C the exporter generates (:mod:`strapdown.codegen.export_c`). The
recommendation is the cheapest candidate within the drift budget (and ``max_ops``); with
no coning content in the log, the cheapest candidate.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from strapdown._core.errors import InputError, shown
from strapdown._core.validation import positive
from strapdown.algorithms.family import InputKind
from strapdown.algorithms.spec import REGISTRY, AlgorithmSpec
from strapdown.analysis.accuracy import drift_rate
from strapdown.analysis.spectrum import (
    PAIRS,
    cross_spectra,
    predict_drift,
    predict_drift_stderr,
)
from strapdown.io.readers import ImuLog
from strapdown.rotation.error import attitude_error_vector

__all__ = ["NEGLIGIBLE_DEG_H", "NEGLIGIBLE_FRACTION", "PSD_COLUMNS", "SPECTRUM_MIN_SAMPLES",
           "VERIFY_MIN_SAMPLES", "Advice", "Candidate", "Reference", "advise",
           "candidate_specs", "coning_content", "gap_notes", "log_reference", "log_spectrum",
           "read_psd", "unresolved_fraction", "verified_drift_deg_h", "write_figure"]

#: Columns of a ``--psd`` CSV: frequency (Hz) and the imaginary parts of the one-sided
#: cross-spectral densities G_yz, G_zx, G_xy (rad²/s²/Hz, scipy's conj(X) Y convention).
PSD_COLUMNS = ("f_hz", "im_gyz", "im_gzx", "im_gxy")
_RAD_S_TO_DEG_H = 180.0 / math.pi * 3600.0
#: "No coning content" means the cheapest candidate's drift (predicted plus four standard
#: errors of the estimate, and measured on the log when verified) stays below this fraction
#: of the budget ...
NEGLIGIBLE_FRACTION = 1e-3
#: ... or, without a budget, below this drift (deg/h; about 5e-12 rad/s, well above the
#: float64 floor of about 1e-15 rad/s measured with pure spin in reproduce high-order).
NEGLIGIBLE_DEG_H = 1e-6
#: Share of the rate variance below the spectrum's resolution above which an unverified
#: spectrum cannot call a log free of coning.
UNRESOLVED_LIMIT = 0.1
#: Standard errors a spectral drift must exceed to count as coning.
SIGNIFICANCE = 4.0


#: Upsampling factor of the band-limited reference attitude (its accuracy is stated by
#: comparing it with half of it).
REFERENCE_UPSAMPLE = 16
#: The reference's integrator on the upsampled increments: the single chain N = 6
#: (drift ∝ (Ωh)^12 at the fine step; no amplitude-cubed term, see reproduce high-order).
_REFERENCE_SPEC = "rotvec:N=6:structure=single-chain"
#: Fraction of the log at either end left out of a verified drift (the FFT's periodic wrap).
EDGE_FRACTION = 0.1
#: Fewest samples a log's spectrum (Welch) needs, and the fewest the verification needs.
SPECTRUM_MIN_SAMPLES, VERIFY_MIN_SAMPLES = 16, 64


@dataclass(frozen=True)
class Reference:
    """Band-limited reference attitude of a log at its sample times ``t`` (from 0, the log's
    start), the window ``(t_lo, t_hi)`` drifts are measured over, and the reference's own
    accuracy (deg/h): the drift of the half-upsampled reference against it."""

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    window: tuple[float, float]
    upsample: int
    accuracy_deg_h: float


def _fine_increments(log: ImuLog, m: int) -> NDArray[np.float64]:
    """Increments over steps ``h/m`` of the band-limited rate that reproduces the log: the
    log (mirrored, so the periodic extension has no jump) in the FFT, each bin divided by the
    response of its samples (an increment over ``h``, or a point sample) and multiplied by
    that of an increment over ``h/m``, zero-padded to ``m`` times the length."""
    x = np.concatenate([log.data, log.data[::-1]])
    n2 = x.shape[0]
    spec = np.fft.rfft(x, axis=0)
    a = np.pi * np.fft.rfftfreq(n2, log.h) * log.h  # π f h
    safe = np.where(a > 0, a, 1.0)
    if log.kind == "increment":  # tone e^{iωt}: increment over h ∝ sin(a)/a e^{−ia}
        resp = np.where(a > 0, np.sin(safe / m) / np.sin(safe), 1.0 / m) * np.exp(
            -1j * a * (1 - 1.0 / m))
    else:  # point samples at the steps' starts: an increment over h/m
        resp = log.h / m * np.where(a > 0, np.sin(safe / m) / (safe / m), 1.0) * np.exp(
            1j * a / m)
    f = spec * resp[:, None]
    if n2 % 2 == 0:
        f[-1] *= 0.5  # the Nyquist bin is shared by ± Nyquist in the longer series
    padded = np.zeros((n2 * m // 2 + 1, 3), dtype=np.complex128)
    padded[:f.shape[0]] = f
    return np.fft.irfft(padded, n2 * m, axis=0)[: log.data.shape[0] * m] * m


def _reference_attitude(log: ImuLog, m: int) -> NDArray[np.float64]:
    """Reference attitude at the log's sample times ``k h`` (k = 1 … n; from identity at 0)."""
    sol = AlgorithmSpec.parse(_REFERENCE_SPEC).run_increments(_fine_increments(log, m),
                                                              h=log.h / m)
    idx = np.rint(sol.t / (log.h / m)).astype(np.int64)
    q = np.full((log.data.shape[0] + 1, 4), np.nan)
    on = idx % m == 0
    q[idx[on] // m] = sol.q[on]
    q[0] = (1.0, 0.0, 0.0, 0.0)
    return q


def log_reference(log: ImuLog, *, upsample: int = REFERENCE_UPSAMPLE) -> Reference:
    """The band-limited reference attitude of ``log`` (see :func:`_fine_increments`),
    integrated by the single chain N = 6 at ``h/upsample``; its accuracy is the drift of the
    ``upsample/2`` reference against it over the window."""
    if upsample < 4 or upsample % 2:
        raise ValueError(f"upsample must be an even number ≥ 4, got {upsample}")
    n = log.data.shape[0]
    if n < VERIFY_MIN_SAMPLES:
        raise InputError(f"verifying on the log needs at least {VERIFY_MIN_SAMPLES} samples, "
                         f"got {n} (--no-verify)")
    t = np.arange(n + 1) * log.h
    window = (float(t[round(EDGE_FRACTION * n)]), float(t[round((1 - EDGE_FRACTION) * n)]))
    q = _reference_attitude(log, upsample)
    half = _reference_attitude(log, upsample // 2)
    ok = ~np.isnan(q[:, 0]) & ~np.isnan(half[:, 0])
    acc = _drift_deg_h(t[ok], half[ok], q[ok], window)
    return Reference(t, q, window, upsample, acc)


def _drift_deg_h(t: NDArray[np.float64], q: NDArray[np.float64], q_ref: NDArray[np.float64],
                 window: tuple[float, float]) -> float:
    """|least-squares slope| (deg/h) of ``log(q ⊗ q_ref*)`` over ``window``."""
    tol = 1e-6 * (window[1] - window[0])  # the same samples whatever the times' round-off
    sel = (t >= window[0] - tol) & (t <= window[1] + tol)
    if np.count_nonzero(sel) < 2:
        raise ValueError("fewer than two attitude outputs inside the verification window")
    err = attitude_error_vector(q[sel], q_ref[sel])
    return float(np.linalg.norm(drift_rate(t[sel], err).rate)) * _RAD_S_TO_DEG_H


def verified_drift_deg_h(spec: AlgorithmSpec, log: ImuLog, ref: Reference) -> float:
    """|drift| (deg/h) of ``spec`` run on ``log`` against the band-limited reference, over
    the reference's window (the least-squares slope of the error)."""
    n = log.data.shape[0]
    if spec.input_kind == "increment":
        sol = spec.run_increments(log.data, h=log.h)
    else:
        sol = spec.run_rates(np.arange(n) * log.h, log.data)
    k = int(getattr(sol, "startup", 0))
    idx = np.rint(sol.t[k:] / log.h).astype(np.int64)
    keep = (idx >= 0) & (idx <= n)
    return _drift_deg_h(ref.t[idx[keep]], sol.q[k:][keep], ref.q[idx[keep]], ref.window)


@dataclass(frozen=True)
class Candidate:
    """One algorithm with its predicted drift (deg/h, norm of the drift vector), cost, and
    the drift measured on the log against the band-limited reference (None: not verified)."""

    spec: AlgorithmSpec
    predicted_drift_deg_h: float
    ops_per_s: float
    measured_drift_deg_h: float | None = None

    def to_dict(self) -> dict[str, object]:
        return {"spec": str(self.spec), "predicted_drift_deg_h": self.predicted_drift_deg_h,
                "measured_drift_deg_h": self.measured_drift_deg_h, "ops_per_s": self.ops_per_s}


@dataclass(frozen=True)
class Advice:
    """The ranking (lowest predicted drift first), the Pareto front, the recommendation and
    the coning verdict (``"detected"``, ``"absent"`` or ``"undecided"``, with its reason)."""

    candidates: tuple[Candidate, ...]
    pareto: tuple[str, ...]
    recommended: Candidate
    reason: str
    coning: str
    coning_note: str
    #: The drift budget the recommendation had to meet (deg/h; None: none given).
    budget_deg_h: float | None = None
    #: Why predicted and measured drift differ by more than :data:`GAP_FACTOR`, a
    #: sentence per reason (:func:`gap_notes`).
    gap_notes: tuple[str, ...] = ()

    @property
    def coning_detected(self) -> bool:
        return self.coning == "detected"

    def to_dict(self) -> dict[str, object]:
        return {"candidates": [c.to_dict() for c in self.candidates],
                "recommended": str(self.recommended.spec), "reason": self.reason,
                "coning_detected": self.coning_detected, "coning": self.coning,
                "coning_note": self.coning_note, "pareto": list(self.pareto),
                "budget_deg_h": self.budget_deg_h, "gap_notes": list(self.gap_notes)}


def candidate_specs(kind: InputKind | None) -> list[AlgorithmSpec]:
    """The candidates for a log of ``kind`` (None: both kinds): every registered family's
    own (:meth:`~strapdown.algorithms.family.Family.candidates`), increment families first,
    each kind in registry order."""
    kinds: tuple[InputKind, ...] = ("increment", "rate") if kind is None else (kind,)
    return [spec for k in kinds for fam in REGISTRY.values() if fam.input_kind == k
            for spec in fam.candidates()]


def log_spectrum(log: ImuLog, *, nperseg: int = 256
                 ) -> tuple[NDArray[np.float64], NDArray[np.complex128], int]:
    """Welch cross-spectra of a log's body rates (increments divided by h): frequencies,
    ``G`` (F, 3, 3) and the number of averaged segments."""
    rates = log.data / log.h if log.kind == "increment" else log.data
    seg = min(int(nperseg), rates.shape[0])
    f, g = cross_spectra(rates, 1.0 / log.h, nperseg=seg)
    return f, g, max(1, 2 * rates.shape[0] // seg - 1)


def unresolved_fraction(log: ImuLog, f: NDArray[np.float64], g: NDArray[np.complex128]
                        ) -> float:
    """The largest share, over the axes, of a log's rate variance that its spectrum does not
    hold above 0 Hz (content slower than the Welch resolution, removed with the segments'
    means): the spectrum cannot say such a log is free of coning."""
    rates = log.data / log.h if log.kind == "increment" else log.data
    var = np.var(rates, axis=0)
    keep = f > 0
    held = np.trapezoid(np.real(np.stack([g[keep, k, k] for k in range(3)], axis=-1)),
                        f[keep], axis=0)
    tiny = 1e-20 * (np.mean(rates, axis=0) ** 2 + var) + 1e-300
    share = np.where(var > tiny, 1.0 - held / np.where(var > tiny, var, 1.0), 0.0)
    return float(np.clip(np.max(share), 0.0, 1.0))


def read_psd(path: str | Path, sample_rate_hz: float | None = None
             ) -> tuple[NDArray[np.float64], NDArray[np.complex128]]:
    """A ``--psd`` CSV (:data:`PSD_COLUMNS`, uniform increasing frequencies from 0 Hz up) as
    CSDs (F, 3, 3) holding the imaginary parts (the real parts do not drift an algorithm).

    With ``sample_rate_hz`` a column whose coning power (``Σ |value| Δf``, rad²/s²) exceeds
    ``(π · sample_rate_hz)²`` — rates turning the body by more than π per sample, beyond
    Nyquist like a log's (:data:`strapdown.io.readers.MAX_SAMPLE_ANGLE`) — is refused at the
    row where it does. Anything wrong with the file is an :class:`~strapdown.InputError`
    naming it (and the row, where there is one).
    """
    from strapdown.io.readers import input_file

    path = input_file(path, "PSD file")
    raw = path.read_bytes()
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start)
        where = "the header row" if line == 0 else f"data row {line}"
        bad = shown(raw[exc.start:exc.start + 8], 40)
        raise InputError(f"{path}: not UTF-8 text (bytes {bad} in {where}); expected a PSD "
                         "CSV") from None
    try:
        rows = list(csv.reader(text.splitlines()))
    except csv.Error as exc:
        raise InputError(f"{path}: unreadable CSV ({shown(str(exc), 120)})") from None
    if not rows or tuple(c.strip() for c in rows[0]) != PSD_COLUMNS:
        raise InputError(f"{path}: a PSD file needs the header {','.join(PSD_COLUMNS)}")
    data = [(r, row) for r, row in enumerate(rows[1:], start=1) if row]
    for r, row in data:
        if len(row) != 4:
            raise InputError(f"{path}: data row {r} has {len(row)} fields; need four values")
    try:
        vals = np.array([[float(x) for x in row] for _, row in data], dtype=np.float64)
    except ValueError:
        raise InputError(f"{path}: every PSD value must be a number") from None
    if vals.shape[0] < 2:
        raise InputError(f"{path}: need at least two rows of four values, got {vals.shape[0]}")
    bad = ~np.all(np.isfinite(vals), axis=1)
    if np.any(bad):
        raise InputError(f"{path}: NaN or infinity in data row {data[int(np.argmax(bad))][0]}")
    f = vals[:, 0]
    if f[0] < 0:
        raise InputError(f"{path}: f_hz must not be negative, got {f[0]:g} in data row 1")
    df = np.diff(f)  # no overflow: finite and (below) non-negative increasing
    if np.any(df <= 0) or np.ptp(df) > 1e-6 * df.mean():
        raise InputError(f"{path}: f_hz must increase in uniform steps")
    if sample_rate_hz is not None:
        _check_psd_power(path, vals, float(df.mean()), sample_rate_hz, data)
    g = np.zeros((vals.shape[0], 3, 3), dtype=np.complex128)
    for col, (i, j) in enumerate(PAIRS, start=1):
        g[:, i, j] = 1j * vals[:, col]
        g[:, j, i] = -1j * vals[:, col]
    return f, g


def _check_psd_power(path: Path, vals: NDArray[np.float64], df: float, fs: float,
                     data: list) -> None:
    """Refuse a column of a PSD file whose coning power exceeds ``(π fs)²`` (see
    :func:`read_psd`), at the data row where its running sum does."""
    limit = (math.pi * fs) ** 2
    with np.errstate(over="ignore"):
        power = np.cumsum(np.abs(vals[:, 1:]), axis=0) * df
    over = ~(power <= limit)
    if np.any(over):
        k, col = divmod(int(np.argmax(over.ravel())), 3)
        raise InputError(f"{path}: data row {data[k][0]} ({PSD_COLUMNS[col + 1]} = "
                         f"{vals[k, col + 1]:.3g}): the column's coning power Σ |value| Δf "
                         f"exceeds (π × {fs:g} Hz)² = {limit:.3g} rad²/s² there, rates turning "
                         "the body by more than π per sample; check the units (rad²/s²/Hz) "
                         "and --sample-rate-hz")


def coning_content(predicted: float, stderr: float, measured: float | None, level: float, *,
                   segments: int | None, accuracy: float = 0.0, unresolved: float = 0.0
                   ) -> tuple[str, str]:
    """The coning verdict from the candidates' largest drift (deg/h; the largest predicted,
    and the larger measured of it and the cheapest): ``"absent"`` when the
    prediction plus :data:`SIGNIFICANCE` standard errors (and its drift measured on the log,
    when verified) lie below the negligible ``level``; ``"detected"`` when the prediction is
    significant or the measured drift exceeds both the level and :data:`SIGNIFICANCE` times
    the reference's ``accuracy``; otherwise ``"undecided"`` (the log is too short, or more
    than :data:`UNRESOLVED_LIMIT` of its rate variance lies below the spectrum's resolution
    and no measurement speaks for it)."""
    seg = "a file spectrum" if segments is None else f"{segments} Welch segments"
    bound = predicted + SIGNIFICANCE * stderr
    blind = measured is None and unresolved > UNRESOLVED_LIMIT
    if bound <= level and (measured is None or measured <= level) and not blind:
        return "absent", (f"no coning content: every algorithm's drift is below the "
                          f"negligible {level:.3g} deg/h (predicted {predicted:.3g} + "
                          f"{SIGNIFICANCE:g}σ = {bound:.3g} from {seg}" + (
                              "" if measured is None else f"; measured {measured:.3g}") + ")")
    if measured is not None and measured > max(level, SIGNIFICANCE * accuracy):
        return "detected", (f"coning content: an algorithm drifts {measured:.3g} "
                            "deg/h on the log")
    if predicted > max(level, SIGNIFICANCE * stderr):
        return "detected", (f"coning content: the largest predicted drift "
                            f"{predicted:.3g} deg/h exceeds {SIGNIFICANCE:g}σ ({seg})")
    if blind:
        return "undecided", (f"cannot decide: {unresolved:.0%} of the rates' variance lies "
                             "below the spectrum's resolution (a longer --nperseg, or verify "
                             "on the log); ranked as if coning")
    return "undecided", (f"too short to decide: the largest predicted drift "
                         f"{predicted:.3g} ± {stderr:.3g} deg/h ({seg}) is neither significant "
                         f"nor below the negligible {level:.3g} deg/h; ranked as if coning")


def advise(f: NDArray[np.float64], g: NDArray[np.complex128], h: float,
           specs: Sequence[AlgorithmSpec], cost: Callable[[AlgorithmSpec, float], float], *,
           budget_deg_h: float | None = None, max_ops: float | None = None,
           segments: int | None = None, unresolved: float = 0.0,
           measure: Callable[[AlgorithmSpec], float] | None = None, verify: int = 8,
           accuracy_deg_h: float = 0.0) -> Advice:
    """Rank ``specs`` by the drift predicted from the CSDs ``g`` at ``f`` (Hz) for samples
    every ``h`` seconds, with ``cost(spec, h)`` operations per second; ``segments`` the Welch
    segments behind ``g`` (None: a file spectrum, exact). With ``measure`` (spec → drift
    measured on the log, deg/h; reference accurate to ``accuracy_deg_h``) up to ``verify``
    candidates are run on the log, and the recommendation must meet the budget measured too;
    ``unresolved`` is :func:`unresolved_fraction` of the log (0 for a file spectrum).
    """
    h = positive(h, "h (sample interval)")
    if budget_deg_h is not None:
        positive(budget_deg_h, "--budget-deg-h")
    if max_ops is not None:
        positive(max_ops, "--max-ops")
    if verify < 0:
        raise ValueError(f"--verify must be ≥ 0, got {verify}")
    cands = []
    for spec in specs:
        with np.errstate(over="ignore", invalid="ignore"):  # refused below
            d = float(np.linalg.norm(predict_drift(spec, f, g, h))) * _RAD_S_TO_DEG_H
        if not math.isfinite(d):
            raise InputError(f"the drift predicted for {spec} overflows: the spectrum's coning "
                             "power is too large (check its units: rad²/s²/Hz)")
        cands.append(Candidate(spec, d, float(cost(spec, h))))
    cands.sort(key=lambda c: (c.predicted_drift_deg_h, c.ops_per_s))
    pool = [c for c in cands if max_ops is None or c.ops_per_s <= max_ops]
    if not pool:
        raise ValueError(f"no candidate needs at most --max-ops {max_ops:g} operations/s "
                         f"(the cheapest needs {min(c.ops_per_s for c in cands):.3g})")
    cheapest = min(pool, key=lambda c: (c.ops_per_s, c.predicted_drift_deg_h))
    worst = max(pool, key=lambda c: (c.predicted_drift_deg_h, -c.ops_per_s))
    measured: dict[str, float] = {}
    if measure is not None and verify > 0:
        for c in (cheapest, worst):
            measured[str(c.spec)] = measure(c.spec)
    stderr = 0.0 if segments is None else float(np.linalg.norm(predict_drift_stderr(
        worst.spec, f, g, h, segments))) * _RAD_S_TO_DEG_H
    level = NEGLIGIBLE_DEG_H if budget_deg_h is None else NEGLIGIBLE_FRACTION * budget_deg_h
    top = max(measured, key=lambda k: measured[k]) if measured else None
    state, note = coning_content(worst.predicted_drift_deg_h, stderr,
                                 None if top is None else measured[top], level,
                                 segments=segments, accuracy=accuracy_deg_h,
                                 unresolved=unresolved)
    if state == "detected" and top is not None and note.startswith("coning content: an"):
        note = note.replace("an algorithm", top, 1)
    if state == "absent":
        rec, why = cheapest, "no coning content: the cheapest algorithm"
    else:
        rec, why = _choose(pool, budget_deg_h, measure if verify > 0 else None, verify,
                           measured)
    final = tuple(replace(c, measured_drift_deg_h=measured.get(str(c.spec))) for c in cands)
    by = {str(c.spec): c for c in final}
    return Advice(final, _pareto(final), by[str(rec.spec)], why, state, note, budget_deg_h,
                  gap_notes(final, accuracy_deg_h, segments))


#: Predicted and measured drift disagree when one exceeds the other by more than this.
GAP_FACTOR = 2.0


def _ratios(specs: list[tuple[str, float]]) -> str:
    return ", ".join(f"{s} ({r:.3g}×)" for s, r in specs)


def gap_notes(cands: Sequence[Candidate], accuracy_deg_h: float = 0.0,
              segments: int | None = None) -> tuple[str, ...]:
    """One sentence per reason why the verified candidates' measured drift differs from
    the predicted by more than :data:`GAP_FACTOR` (empty when none does).

    The prediction is each algorithm's classical coning response summed over the coning
    spectrum: second order in the rates, the mean rate removed. A measured drift within
    :data:`SIGNIFICANCE` times the reference's accuracy is the reference's floor; a larger
    one holds what the prediction leaves out — terms of higher order in the amplitude (the
    conventional N ≥ 4 sets' amplitude-cubed term), and for the rate algorithms their
    interpolation of the sampled rates and the mean rate (spin); a smaller one can come
    from the Welch estimate's leakage or higher-order terms cancelling part of the drift.
    """
    floor = SIGNIFICANCE * accuracy_deg_h
    groups: dict[str, list[tuple[str, float]]] = {}
    for c in cands:
        m, p = c.measured_drift_deg_h, c.predicted_drift_deg_h
        if m is None:
            continue
        ratio = m / p if p > 0 else math.inf
        if 1.0 / GAP_FACTOR <= ratio <= GAP_FACTOR:
            continue
        spec = c.spec
        if m <= floor:
            key = "floor"
        elif ratio < 1.0:
            key = "below"
        elif spec.input_kind == "rate":
            key = "rate"
        elif spec.family.amplitude_cubed(spec):
            key = "cubed"
        else:
            key = "higher"
        groups.setdefault(key, []).append((str(spec), ratio))
    seg = "a file spectrum" if segments is None else f"{segments} Welch segments"
    why = {
        "floor": lambda g: (f"measured at the reference's accuracy (≤ {floor:.2g} deg/h, "
                            f"{SIGNIFICANCE:g}× its {accuracy_deg_h:.2g}): {_ratios(g)} — "
                            "these measurements cannot resolve a drift that small"),
        "rate": lambda g: (f"measured above {GAP_FACTOR:g}× the prediction: {_ratios(g)} — "
                           "the prediction is the classical coning response only (second "
                           "order in the rates, the mean rate removed); a rate algorithm's "
                           "drift on a log can also hold terms it does not contain: its "
                           "interpolation of the sampled rates, higher orders in the "
                           "amplitude and their coupling with the mean rate (spin)"),
        "cubed": lambda g: (f"measured above {GAP_FACTOR:g}× the prediction: {_ratios(g)} — "
                            "at N ≥ 4 the conventional sets have a term of third order in the "
                            "amplitude that the spectral prediction (second order in the "
                            "rates) does not contain; it dominates once the second-order "
                            "drift is small (reproduce high-order)"),
        "higher": lambda g: (f"measured above {GAP_FACTOR:g}× the prediction: {_ratios(g)} — "
                             "the spectral prediction is second order in the rates; the "
                             "drift on the log can also hold terms of higher order in the "
                             "amplitude, which dominate where the second-order drift is "
                             "small"),
        "below": lambda g: (f"measured below 1/{GAP_FACTOR:g} of the prediction: "
                            f"{_ratios(g)} — the prediction comes from an estimated spectrum "
                            f"({seg}) whose leakage and bias can overstate the coning power, "
                            "and terms of higher order in the amplitude can cancel part of "
                            "the second-order drift"),
    }
    order = ("rate", "cubed", "higher", "below", "floor")
    return tuple(why[k](groups[k]) + "." for k in order if k in groups)


def _choose(pool: list[Candidate], budget: float | None,
            measure: Callable[[AlgorithmSpec], float] | None, verify: int,
            measured: dict[str, float]) -> tuple[Candidate, str]:
    """The recommendation among ``pool`` (lowest predicted drift first): the cheapest within
    the budget — predicted and, with ``measure``, measured on the log (the first ``verify``
    candidates in that order are run; ``measured`` collects their drifts)."""
    by_cost = sorted(pool, key=lambda c: (c.ops_per_s, c.predicted_drift_deg_h))
    order = pool if budget is None else [c for c in by_cost if c.predicted_drift_deg_h <= budget]
    if not order:
        order = pool
        head = f"none meets {budget:g} deg/h predicted: the lowest predicted drift"
        if measure is None:
            return pool[0], head
    if measure is None:
        if budget is None:
            return pool[0], "no budget given: the lowest predicted drift"
        return order[0], f"the cheapest within {budget:g} deg/h"
    tried = order[:verify]
    for c in tried:
        key = str(c.spec)
        if key not in measured:
            measured[key] = measure(c.spec)
    if budget is not None and order is not pool:
        for c in tried:
            if measured[str(c.spec)] <= budget:
                return c, (f"the cheapest within {budget:g} deg/h, predicted and measured on "
                           "the log")
    best = min(tried, key=lambda c: (measured[str(c.spec)], c.ops_per_s))
    if budget is None:
        return best, (f"no budget given: the lowest measured drift of the {len(tried)} lowest "
                      "predicted")
    return best, (f"none of the {len(tried)} cheapest candidates predicted within "
                  f"{budget:g} deg/h meets it measured on the log: the lowest measured drift"
                  if order is not pool else head + " (lowest measured of those verified)")


def _pareto(cands: Sequence[Candidate]) -> tuple[str, ...]:
    """Specs no other candidate beats in both drift and cost, cheapest first (drifts that
    agree to 1e-9 relative are ties: the same leading-order law)."""
    front, best = [], math.inf
    for c in sorted(cands, key=lambda c: (c.ops_per_s, c.predicted_drift_deg_h)):
        if c.predicted_drift_deg_h < best * (1 - 1e-9):  # ties within round-off do not count
            front.append(str(c.spec))
            best = c.predicted_drift_deg_h
    return tuple(front)


def write_figure(advice: Advice, path: str | Path) -> Path:
    """Drift against cost (log–log): every candidate's predicted drift, the Pareto front
    joined, the drift measured on the log where verified (joined to its prediction; those
    more than :data:`GAP_FACTOR` off marked), the budget line and the recommendation ringed
    and named; written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from strapdown.io.files import save_figure

    floor = 1e-30
    fig, ax = plt.subplots(figsize=(8.5, 5.5))
    x = [c.ops_per_s for c in advice.candidates]
    y = [max(c.predicted_drift_deg_h, floor) for c in advice.candidates]
    ax.scatter(x, y, s=16, color="0.55", zorder=2, label="predicted (every candidate)")
    by = {str(c.spec): c for c in advice.candidates}
    px = [by[s].ops_per_s for s in advice.pareto]
    py = [max(by[s].predicted_drift_deg_h, floor) for s in advice.pareto]
    ax.plot(px, py, "-o", color="C0", ms=4, zorder=3, label="Pareto front (predicted)")
    ver = [c for c in advice.candidates if c.measured_drift_deg_h is not None]
    if ver:
        for c in ver:
            ax.plot([c.ops_per_s] * 2, [max(c.predicted_drift_deg_h, floor),
                                        max(float(c.measured_drift_deg_h or 0.0), floor)],
                    ":", color="C1", lw=1, zorder=3)
        off = [c for c in ver if not _agree(c)]
        on = [c for c in ver if _agree(c)]
        if on:
            ax.scatter([c.ops_per_s for c in on],
                       [max(float(c.measured_drift_deg_h or 0.0), floor) for c in on],
                       marker="D", s=30, color="C1", zorder=4,
                       label=f"measured on the log (within {GAP_FACTOR:g}× of predicted)")
        if off:
            ax.scatter([c.ops_per_s for c in off],
                       [max(float(c.measured_drift_deg_h or 0.0), floor) for c in off],
                       marker="D", s=30, color="C1", edgecolors="k", linewidths=1.2,
                       zorder=4, label=f"measured, more than {GAP_FACTOR:g}× off predicted "
                       "(why: the command's output)")
    if advice.budget_deg_h is not None:
        ax.axhline(advice.budget_deg_h, color="C2", ls="--", lw=1.5, zorder=1,
                   label=f"budget {advice.budget_deg_h:g} deg/h")
    r = advice.recommended
    ry = max(r.predicted_drift_deg_h if r.measured_drift_deg_h is None
             else r.measured_drift_deg_h, floor)
    ax.scatter([r.ops_per_s], [ry], s=180, facecolors="none", edgecolors="C3", linewidths=2,
               zorder=5, label=f"recommended: {r.spec}")
    said = f"predicted {r.predicted_drift_deg_h:.3g}" + (
        "" if r.measured_drift_deg_h is None else f", measured {r.measured_drift_deg_h:.3g}")
    lx = np.log10(np.clip(np.asarray(x, float), 1e-300, None))
    ly = np.log10(np.asarray(y, float))
    right = math.log10(max(r.ops_per_s, 1e-300)) < float(lx.min() + lx.max()) / 2
    low = math.log10(ry) < float(ly.min() + ly.max()) / 2
    ax.annotate(f"recommended\n{r.spec}\n{said} deg/h", (r.ops_per_s, ry),
                xytext=(45 if right else -170, 30 if low else -55), textcoords="offset points",
                fontsize=7, color="C3",
                arrowprops={"arrowstyle": "-", "color": "C3", "lw": 0.8}, zorder=6)
    ax.set(xscale="log", yscale="log", xlabel="operations per second",
           ylabel="drift (deg/h)", title="strapdown advise: drift against cost")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2,
              frameon=False)
    fig.tight_layout()
    try:
        return save_figure(fig, path, dpi=120)
    finally:
        plt.close(fig)


def _agree(c: Candidate) -> bool:
    """Whether a verified candidate's measured drift is within :data:`GAP_FACTOR` of its
    prediction."""
    m, p = c.measured_drift_deg_h, c.predicted_drift_deg_h
    return m is not None and p > 0 and 1.0 / GAP_FACTOR <= m / p <= GAP_FACTOR
