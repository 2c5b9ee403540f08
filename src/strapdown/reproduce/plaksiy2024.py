"""Plaksiy (2024), numerical-analytical optimisation of orientation algorithms on the
Krylov-angle spherical model.

``strapdown reproduce plaksiy2024 --out DIR`` writes Tables 1–3 under the
stated settings and under the settings that reproduce the printed numbers,
the accumulated-drift-versus-time figures before and after optimisation
(the paper's Figures 2–3), our own optimisation of each algorithm, a
transfer table for the optimised sets, and a verdict on the paper's claims.

Settings (papers.md, seed 003):

* **stated** — angles ``k_i t`` with k = (0.15, 0.25, 0.05), step 0.1 s,
  200 s, Miller's α = 33/80, β = 57/80;
* **reproducing** — angles ``2 k_i t`` (equivalently step 0.2 s over 400 s),
  and A1 with α = 9/20, β = 27/40. Only these give the printed Table 1.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from strapdown import analysis
from strapdown.algorithms.quaternion import (
    ALGORITHMS,
    STATED,
    QuaternionAlgorithm,
    quaternion_attitude,
    subintervals,
)
from strapdown.design.optimize import optimize
from strapdown.io.files import write_text
from strapdown.io.report import begin_report
from strapdown.truth.motions import ClassicalConing, KrylovMotion, Motion

K = (0.15, 0.25, 0.05)
K2 = tuple(2 * k for k in K)
STEP = 0.1
DURATION = 200.0
LABEL = {"miller": "A1 (Miller)", "panov": "A2 (Panov)", "power": "A3 (power)"}
PRINTED_T1 = {"miller": 1.073e-6, "panov": 1.029e-6, "power": 0.78e-6}
PRINTED_T3 = {"miller": 0.225e-6, "panov": 0.421e-7, "power": 0.471e-7}
#: Table 2 (optimised coefficients as printed).
PRINTED_T2 = {"miller": (-151 / 20, 347 / 40), "panov": (4000321 / 6000000, 0.0),
              "power": (99994 / 300000, 0.0)}
REPRODUCING_A1 = (9 / 20, 27 / 40)
#: Horizon (s) of the long-run check of the "non-growing" claim.
LONG = 3200.0


class DriftRun:
    """Increments and truth of one motion/step, reused across coefficient evaluations."""

    def __init__(self, motion: Motion, name: str, step: float = STEP,
                 duration: float = DURATION):
        sub = subintervals(name)
        n = round(duration / step)
        self.name = name
        self.step = step
        self.theta = motion.increments(np.arange(n * sub + 1) * (step / sub))
        self.t = np.arange(n + 1) * step
        self.q_true = motion.attitude(self.t)
        self.q0 = self.q_true[0]

    def series(self, alpha: float, beta: float = 0.0, exact_exp: bool = False) -> np.ndarray:
        alg = QuaternionAlgorithm(self.name, alpha, beta if self.name == "miller" else 0.0,
                                  exact_exp)
        sol = quaternion_attitude(self.theta, alg, step=self.step, q0=self.q0)
        return analysis.accumulated_drift(sol.q, self.q_true)

    def max_drift(self, x) -> float:
        x = np.atleast_1d(x)
        return float(self.series(*x).max())


def growth(series: np.ndarray) -> float:
    """Max over the second half of the run divided by the max over the first half."""
    h = series.size // 2
    return float(series[h:].max() / max(series[1:h].max(), 1e-300))


def _coeffs(name, pair):
    return pair if name == "miller" else (pair[0],)


def reproduce(out: str | Path, *, progress: Callable[[str], None] | None = None) -> Path:
    """Run the reproduction and write it to ``out``; returns the path of ``report.md``."""
    out, w, say, plt, t_start = begin_report(out, progress)
    md: list[str] = []

    runs = {(k, n): DriftRun(KrylovMotion(*k), n) for k in (K, K2) for n in ALGORITHMS}

    # ----------------------------------------------------------- Tables 1, 3
    say("Tables 1 and 3 under both settings")
    rows1, rows3 = [], []
    for n in ALGORITHMS:
        stated = runs[K, n].max_drift(_coeffs(n, STATED[n]))
        first = REPRODUCING_A1 if n == "miller" else STATED[n]
        repro = runs[K2, n].max_drift(_coeffs(n, first))
        repro_stated = runs[K2, n].max_drift(_coeffs(n, STATED[n]))
        exact = runs[K2, n].series(*_coeffs(n, first), exact_exp=True).max()
        dev = repro / PRINTED_T1[n] - 1
        rows1.append([LABEL[n], f"{PRINTED_T1[n]:.4g}", f"{stated:.4g}",
                      f"{PRINTED_T1[n] / stated:.2f}", f"{repro:.4g}", f"{dev:+.2%}",
                      f"{repro_stated:.4g}", f"{exact:.4g}",
                      "reproduced" if abs(dev) <= 0.005 else "differs"])
        t2 = _coeffs(n, PRINTED_T2[n])
        st3 = runs[K, n].max_drift(t2)
        re3 = runs[K2, n].max_drift(t2)
        dev3 = re3 / PRINTED_T3[n] - 1
        rows3.append([LABEL[n], ", ".join(f"{c:.7g}" for c in t2), f"{PRINTED_T3[n]:.4g}",
                      f"{st3:.4g}", f"{re3:.4g}", f"{dev3:+.2%}",
                      "reproduced" if abs(dev3) <= 0.01 else "differs"])
    md.append("## Table 1 — accumulated drift of the published algorithms (rad)\n\n"
              "Maximum over t ∈ (0, 200] s of 2|vec(Λ_true* ∘ Λ)|, step 0.1 s, k = (0.15, "
              "0.25, 0.05). *Stated*: angles k_i t and the stated coefficients. "
              "*Reproducing*: angles 2k_i t (the same as step 0.2 s over 400 s) and A1 with "
              "α = 9/20, β = 27/40. The last columns separate the truncation of eq. 7 "
              "(exact exponential map instead).\n\n")
    md.append(w.table("table1", ["algorithm", "printed", "stated settings", "printed/stated",
                                 "reproducing settings", "vs printed",
                                 "2k with stated A1 coefficients", "reproducing, exact exp",
                                 "status"], rows1))
    md.append("\n## Table 3 — accumulated drift with the paper's optimised coefficients "
              "(Table 2)\n\n")
    md.append(w.table("table3", ["algorithm", "Table 2 coefficients", "printed",
                                 "stated settings", "reproducing settings", "vs printed",
                                 "status"], rows3))

    # ------------------------------------------------------------ Figures 2–3
    say("drift versus time before and after optimisation")
    fig, axes = plt.subplots(3, 1, figsize=(7.5, 8), sharex=True)
    series = {}
    for ax, n in zip(axes, ALGORITHMS, strict=True):
        first = REPRODUCING_A1 if n == "miller" else STATED[n]
        before = runs[K2, n].series(*_coeffs(n, first))
        after = runs[K2, n].series(*_coeffs(n, PRINTED_T2[n]))
        series[n] = (before, after)
        t = runs[K2, n].t
        ax.plot(t, before * 1e6, label="published coefficients")
        ax.plot(t, after * 1e6, label="paper's optimised (Table 2)")
        ax.set_ylabel("µrad")
        ax.set_title(f"{LABEL[n]}: accumulated drift (reproducing settings)", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    axes[-1].set_xlabel("t (s)")
    fig.tight_layout()
    w.figure("drift_vs_time.png", fig)
    md.append("\n## Figures 2–3 — accumulated drift versus time\n\n"
              "![drift versus time](drift_vs_time.png)\n")

    # ------------------------------------------------------- our optimisation
    say("our optimisation from the published optima")
    rows_opt = []
    ours = {}
    for n in ALGORITHMS:
        run = runs[K2, n]
        x0 = np.array(_coeffs(n, PRINTED_T2[n]))
        res = optimize(run.max_drift, x0, xatol=1e-10, fatol=0.0, maxiter=400)
        ours[n] = tuple(res.x)
        rows_opt.append([LABEL[n], ", ".join(f"{c:.7g}" for c in x0), f"{res.start_fun:.4g}",
                         ", ".join(f"{c:.9g}" for c in res.x), f"{res.fun:.4g}",
                         f"{res.fun / res.start_fun:.3f}", res.evaluations])
    md.append("\n## Our optimisation\n\n"
              "Nelder–Mead (scipy, deterministic; xatol 1e-10, at most 400 iterations) on the "
              "maximum accumulated drift, reproducing settings, started from the paper's "
              "Table 2 coefficients.\n\n")
    md.append(w.table("optimisation", ["algorithm", "start (Table 2)", "start drift",
                                       "our optimum", "our drift", "ours/paper's",
                                       "evaluations"], rows_opt))

    # ------------------------------------------------------------- transfer
    say("transfer of the optimised sets")
    cases = [
        ("tuned motion: 2k, step 0.1 s", KrylovMotion(*K2), 0.1),
        ("stated k, step 0.1 s", KrylovMotion(*K), 0.1),
        ("2k, step 0.05 s", KrylovMotion(*K2), 0.05),
        ("2k, step 0.2 s", KrylovMotion(*K2), 0.2),
        ("k = (0.4, 0.1, 0.7), step 0.1 s", KrylovMotion(0.4, 0.1, 0.7), 0.1),
        ("k = (0.05, 0.3, 0.2), step 0.1 s", KrylovMotion(0.05, 0.3, 0.2), 0.1),
        ("classical coning a = 5°, 0.2 Hz, step 0.1 s",
         ClassicalConing(math.radians(5.0), 2 * math.pi * 0.2), 0.1),
    ]
    rows_tr = []
    for n in ALGORITHMS:
        first = REPRODUCING_A1 if n == "miller" else STATED[n]
        sets = {"published": _coeffs(n, first), "paper's optimum": _coeffs(n, PRINTED_T2[n]),
                "our optimum": ours[n]}
        for label, motion, step in cases:
            run = DriftRun(motion, n, step=step)
            vals = {s: run.max_drift(c) for s, c in sets.items()}
            base = vals["published"]
            rows_tr.append([LABEL[n], label, f"{base:.3g}",
                            f"{vals['paper' + chr(39) + 's optimum']:.3g}",
                            f"{vals['paper' + chr(39) + 's optimum'] / base:.3g}",
                            f"{vals['our optimum']:.3g}", f"{vals['our optimum'] / base:.3g}"])
    md.append("\n## Transfer: the optimised sets on other conditions\n\n"
              "Maximum accumulated drift over 200 s (rad); ratios are to the published "
              "coefficients on the same condition (below 1 = better).\n\n")
    md.append(w.table("transfer", ["algorithm", "condition", "published", "paper's optimum",
                                   "ratio", "our optimum", "ratio"], rows_tr))

    # --------------------------------------------------------------- verdict
    say("long-horizon check of the non-growing claim")
    rows_v = []
    for n in ALGORITHMS:
        before, after = series[n]
        red = before.max() / after.max()
        long_run = DriftRun(KrylovMotion(*K2), n, duration=LONG)
        long_after = long_run.series(*_coeffs(n, PRINTED_T2[n]))
        slope_after = float(np.polyfit(long_run.t, long_after, 1)[0])
        slope_before = float(np.polyfit(runs[K2, n].t, before, 1)[0])
        g200, glong = growth(after), growth(long_after)
        rows_v.append([LABEL[n], f"{red:.1f}×", "holds" if red >= 10 else "does not hold",
                       f"{growth(before):.2f}", f"{g200:.2f}", f"{glong:.2f}",
                       f"{slope_before:.2e}", f"{slope_after:.2e}",
                       "holds over 200 s only" if g200 <= 1.2 < glong else
                       ("holds" if glong <= 1.2 else "does not hold")])
    md.append("\n## Verdict on the paper's claims\n\n"
              "*Order-of-magnitude reduction*: max drift before / after (Table 1 / Table 3, "
              "reproducing settings). *Growth*: max over the second half of a run divided by "
              "the max over the first half (≈ 2 for linear growth, ≈ 1 for a bounded "
              f"oscillation; non-growing at ≤ 1.2), over the paper's 200 s and over {LONG:.0f} s. "
              "*Residual drift*: least-squares slope of the accumulated drift. Within 200 s "
              "the optimised errors look bounded; over a longer run every one of them grows "
              "again — the optimisation reduces the drift rate on the tuned motion, it does "
              "not remove it (A1 keeps the largest residual drift). Optimising on one motion "
              "also overfits: see the transfer table.\n\n")
    md.append(w.table("verdict", ["algorithm", "reduction", "order of magnitude",
                                  "growth before (200 s)", "growth after (200 s)",
                                  f"growth after ({LONG:.0f} s)", "drift rate before (rad/s)",
                                  f"drift rate after, {LONG:.0f} s (rad/s)", "non-growing"],
                      rows_v))

    elapsed = time.perf_counter() - t_start
    report = [
        "# Reproduction: Plaksiy — optimisation of orientation algorithms on the Krylov-angle "
        "spherical model\n",
        f"Generated by `strapdown reproduce plaksiy2024` in {elapsed:.0f} s.\n",
        "## Summary\n",
        "- Table 1 reproduces to the printed digits only with angles 2k_i t (equivalently step "
        "0.2 s over 400 s) and A1 with α = 9/20, β = 27/40; with the stated settings every "
        "value is about 32 times smaller (fourth-order algorithms, doubled step).",
        "- Table 3 reproduces with Table 2's coefficients under the same settings.",
        "- Our optimiser, started from Table 2, finds optima at least as good on the tuned "
        "motion (for A1 nine times better); on other motions and steps the tuned sets are "
        "often worse than the published ones (transfer table): optimising to one motion "
        "overfits.",
        "- The optimised errors look non-growing over the paper's 200 s but grow again over "
        "longer runs; the drift rate is reduced, not removed (verdict table).\n",
        *md,
        "\n## Files\n",
        *w.file_list(),
        "",
    ]
    return write_text(out / "report.md", "\n".join(report))
