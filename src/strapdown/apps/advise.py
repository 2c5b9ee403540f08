"""Which attitude algorithm to fly in a vibration environment: ``strapdown advise``.

The environment is the cross-spectrum of the body rates — estimated from a gyro log by
Welch's method, or read from a file — and the drift each candidate algorithm would have
there is predicted by summing its exact classical-coning response over the coning
(quadrature) spectrum (:mod:`strapdown.analysis.spectrum`; pseudo-coning in the sense of
Ignagni (1996)). The candidates are every registered structure and N of the rotation
vector, the finite-amplitude sets, and the windowed rate families and RK4 (those of the
log's input kind). Costs (operations per second) come from the caller — the command line
counts them in the C the exporter generates (:mod:`strapdown.codegen.export_c`). The
recommendation is the cheapest candidate within the drift budget (and ``max_ops``); with
no coning content in the log, the cheapest candidate.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from strapdown._core.validation import positive
from strapdown.algorithms.coning import MAX_SUBSAMPLES
from strapdown.algorithms.family import InputKind
from strapdown.algorithms.finite_amplitude import TRIPLE
from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.algorithms.structures import STRUCTURES
from strapdown.analysis.spectrum import PAIRS, coning_spectrum, cross_spectra, predict_drift
from strapdown.io.readers import ImuLog

__all__ = ["PSD_COLUMNS", "Advice", "Candidate", "advise", "candidate_specs", "coning_content",
           "log_spectrum", "read_psd", "write_figure"]

#: Columns of a ``--psd`` CSV: frequency (Hz) and the imaginary parts of the one-sided
#: cross-spectral densities G_yz, G_zx, G_xy (rad²/s²/Hz, scipy's conj(X) Y convention).
PSD_COLUMNS = ("f_hz", "im_gyz", "im_gzx", "im_gxy")
_RAD_S_TO_DEG_H = 180.0 / math.pi * 3600.0


@dataclass(frozen=True)
class Candidate:
    """One algorithm with its predicted drift (deg/h, norm of the drift vector) and cost."""

    spec: AlgorithmSpec
    predicted_drift_deg_h: float
    ops_per_s: float

    def to_dict(self) -> dict[str, object]:
        return {"spec": str(self.spec), "predicted_drift_deg_h": self.predicted_drift_deg_h,
                "ops_per_s": self.ops_per_s}


@dataclass(frozen=True)
class Advice:
    """The ranking (lowest predicted drift first), the Pareto front and the recommendation."""

    candidates: tuple[Candidate, ...]
    pareto: tuple[str, ...]
    recommended: Candidate
    reason: str
    coning_detected: bool

    def to_dict(self) -> dict[str, object]:
        return {"candidates": [c.to_dict() for c in self.candidates],
                "recommended": str(self.recommended.spec), "reason": self.reason,
                "coning_detected": self.coning_detected, "pareto": list(self.pareto)}


def candidate_specs(kind: InputKind | None) -> list[AlgorithmSpec]:
    """The candidates for a log of ``kind`` (None: both kinds)."""
    out: list[AlgorithmSpec] = []
    if kind in (None, "increment"):
        for n in range(1, MAX_SUBSAMPLES + 1):
            for structure in STRUCTURES:
                out.append(AlgorithmSpec("rotvec", subsamples=n, structure=structure))
        for n in range(2, MAX_SUBSAMPLES + 1):
            for triple in TRIPLE:
                out.append(AlgorithmSpec("rotvec", subsamples=n, structure=triple,
                                         coefficients="finite-amplitude"))
    if kind in (None, "rate"):
        for text in ("rate-single", "rate-two", "rate-three", "rate-three:structure=sliding",
                     "rk4"):
            out.append(AlgorithmSpec.parse(text))
    return out


def log_spectrum(log: ImuLog, *, nperseg: int = 256
                 ) -> tuple[NDArray[np.float64], NDArray[np.complex128], int]:
    """Welch cross-spectra of a log's body rates (increments divided by h): frequencies,
    ``G`` (F, 3, 3) and the number of averaged segments."""
    rates = log.data / log.h if log.kind == "increment" else log.data
    seg = min(int(nperseg), rates.shape[0])
    f, g = cross_spectra(rates, 1.0 / log.h, nperseg=seg)
    return f, g, max(1, 2 * rates.shape[0] // seg - 1)


def read_psd(path: str | Path) -> tuple[NDArray[np.float64], NDArray[np.complex128]]:
    """A ``--psd`` CSV (:data:`PSD_COLUMNS`, uniform increasing frequencies) as CSDs (F, 3, 3)
    holding the imaginary parts (the real parts do not drift an algorithm)."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    if not rows or tuple(c.strip() for c in rows[0]) != PSD_COLUMNS:
        raise ValueError(f"{path}: a PSD file needs the header {','.join(PSD_COLUMNS)}")
    try:
        vals = np.array([[float(x) for x in r] for r in rows[1:] if r], dtype=np.float64)
    except ValueError:
        raise ValueError(f"{path}: every PSD value must be a number") from None
    if vals.ndim != 2 or vals.shape[0] < 2 or vals.shape[1] != 4 or not np.all(
            np.isfinite(vals)):
        raise ValueError(f"{path}: need at least two finite rows of four values")
    df = np.diff(vals[:, 0])
    if np.any(df <= 0) or np.ptp(df) > 1e-6 * df.mean():
        raise ValueError(f"{path}: f_hz must increase in uniform steps")
    g = np.zeros((vals.shape[0], 3, 3), dtype=np.complex128)
    for col, (i, j) in enumerate(PAIRS, start=1):
        g[:, i, j] = 1j * vals[:, col]
        g[:, j, i] = -1j * vals[:, col]
    return vals[:, 0], g


def coning_content(f: NDArray[np.float64], g: NDArray[np.complex128],
                   segments: int | None) -> bool:
    """Whether the spectrum cones: some axis pair's coning power exceeds four standard
    errors of a Welch estimate of incoherent axes (``|∫C| > 4 √(P_i P_j / segments)``); for
    a file spectrum (``segments`` None), any coning power above 1e-12 of the rate power."""
    c = np.atleast_1d(np.abs(np.trapezoid(coning_spectrum(g), f, axis=0)))
    p = np.atleast_1d(np.trapezoid(np.real(np.stack([g[:, k, k] for k in range(3)], axis=-1)),
                                   f, axis=0))
    for col, (i, j) in enumerate(PAIRS):
        scale = math.sqrt(max(p[i] * p[j], 0.0))
        if segments is None:
            if c[col] > 1e-12 * max(scale, np.max(np.abs(g.imag)) * (f[-1] - f[0])):
                return True
        elif scale > 0 and c[col] > 4 * scale / math.sqrt(segments):
            return True
    return False


def advise(f: NDArray[np.float64], g: NDArray[np.complex128], h: float,
           specs: Sequence[AlgorithmSpec], cost: Callable[[AlgorithmSpec, float], float], *,
           budget_deg_h: float | None = None, max_ops: float | None = None,
           coning_detected: bool = True) -> Advice:
    """Rank ``specs`` by the drift predicted from the CSDs ``g`` at ``f`` (Hz) for samples
    every ``h`` seconds, with ``cost(spec, h)`` operations per second."""
    h = positive(h, "h (sample interval)")
    if budget_deg_h is not None:
        positive(budget_deg_h, "--budget-deg-h")
    if max_ops is not None:
        positive(max_ops, "--max-ops")
    cands = []
    for spec in specs:
        d = float(np.linalg.norm(predict_drift(spec, f, g, h))) * _RAD_S_TO_DEG_H
        cands.append(Candidate(spec, d, float(cost(spec, h))))
    cands.sort(key=lambda c: (c.predicted_drift_deg_h, c.ops_per_s))
    pool = [c for c in cands if max_ops is None or c.ops_per_s <= max_ops]
    if not pool:
        raise ValueError(f"no candidate needs at most --max-ops {max_ops:g} operations/s "
                         f"(the cheapest needs {min(c.ops_per_s for c in cands):.3g})")
    cheapest = min(pool, key=lambda c: (c.ops_per_s, c.predicted_drift_deg_h))
    if not coning_detected:
        rec, why = cheapest, "no coning content in the spectrum: the cheapest algorithm"
    elif budget_deg_h is None:
        rec = min(pool, key=lambda c: (c.predicted_drift_deg_h, c.ops_per_s))
        why = "no budget given: the lowest predicted drift"
    else:
        ok = [c for c in pool if c.predicted_drift_deg_h <= budget_deg_h]
        rec = min(ok, key=lambda c: (c.ops_per_s, c.predicted_drift_deg_h)) if ok else min(
            pool, key=lambda c: (c.predicted_drift_deg_h, c.ops_per_s))
        why = (f"the cheapest within {budget_deg_h:g} deg/h" if ok else
               f"none meets {budget_deg_h:g} deg/h: the lowest predicted drift")
    return Advice(tuple(cands), _pareto(cands), rec, why, coning_detected)


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
    """Predicted drift against cost (log–log), the Pareto front joined, the recommendation
    ringed; written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from strapdown.io.files import save_figure

    floor = 1e-30
    fig, ax = plt.subplots(figsize=(8, 5))
    x = [c.ops_per_s for c in advice.candidates]
    y = [max(c.predicted_drift_deg_h, floor) for c in advice.candidates]
    ax.scatter(x, y, s=14, color="0.5", label="candidates")
    by = {str(c.spec): c for c in advice.candidates}
    px = [by[s].ops_per_s for s in advice.pareto]
    py = [max(by[s].predicted_drift_deg_h, floor) for s in advice.pareto]
    ax.plot(px, py, "-o", color="C0", ms=4, label="Pareto front")
    r = advice.recommended
    ax.scatter([r.ops_per_s], [max(r.predicted_drift_deg_h, floor)], s=120, facecolors="none",
               edgecolors="C3", linewidths=2, label=f"recommended: {r.spec}")
    ax.set(xscale="log", yscale="log", xlabel="operations per second",
           ylabel="predicted drift (deg/h)", title="strapdown advise")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    try:
        return save_figure(fig, path, dpi=120)
    finally:
        plt.close(fig)
