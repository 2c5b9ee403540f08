"""Li & Zhang 2017, "A Real-Time Structure of Attitude Algorithm for High Dynamic Bodies".

``strapdown reproduce li2017 --out DIR`` writes Tables 1–5 (ours beside the
printed values, with a status), the float64 vs arbitrary-precision check,
figures (drift versus Ωh, update period versus N, the real-time sawtooth)
and ``report.md``.

What we measure (papers.md, seed 000):

* Table 1 reproduces (arbitrary precision, small cone angle).
* Table 2 does not: the real-time structure is N interleaved conventional
  chains, each drifting exactly as Table 1; Table 2 is Table 1 with
  ``h → h/N`` (printed/measured = N^{2N}).
* Table 3 works read as "cross with the last subsample"; eq. 6 as printed
  drifts orders of magnitude faster for N ≥ 3.
* Tables 4/5: the 3600 and 7200 °/s rows are 0.6 × ω·T.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

import numpy as np

from strapdown import analysis
from strapdown.algorithms.coning import TABLE3, coefficient_set, table1_drift_constant
from strapdown.algorithms.precision import run_mp
from strapdown.algorithms.structures import run_structure
from strapdown.analysis import sawtooth_amplitude
from strapdown.io.files import markdown_table, write_text
from strapdown.io.report import ReportWriter, begin_report
from strapdown.truth import sensors
from strapdown.truth.motions import ClassicalConing

F = Fraction

#: Printed Table 1 drift constants (× a²Ω(Ωh)^{2N}).
PRINTED_TABLE1 = {1: F(1, 12), 2: F(1, 60), 3: F(1, 280), 4: F(1, 1260), 5: F(1, 5544)}
#: Printed Table 2 (real-time structure) drift constants.
PRINTED_TABLE2 = {1: F(1, 12), 2: F(1, 960), 3: F(1, 204120), 4: F(1, 82575360),
                  5: F(1, 54140625000)}
#: Printed Tables 4/5: angular increment per update (deg) by spin rate (°/s) and N.
PRINTED_TABLE4 = {
    1080: (0.108, 0.216, 0.324, 0.432, 0.54),
    3600: (0.216, 0.432, 0.648, 0.864, 1.08),
    7200: (0.432, 0.864, 1.296, 1.728, 2.16),
    9000: (0.9, 1.8, 2.7, 3.6, 4.5),
}
PRINTED_TABLE5 = {1080: (0.108,) * 5, 3600: (0.216,) * 5, 7200: (0.432,) * 5, 9000: (0.9,) * 5}

#: The paper's simulation settings (Section 4).
PAPER_H = 1e-4
PAPER_HALF_ANGLE_DEG = 1.0
PAPER_CONE_RATE_DPS = 360.0

#: Small half-cone angle where the Table 1 (leading-order) law is checked.
SMALL_A = 1e-6
#: Cone rate used in the accuracy studies (1 Hz); only Ωh matters for the drift constant.
OMEGA = 2.0 * math.pi
#: Samples per cone period: Ωh = 2π/spp (60 → 0.1047, 240 → 0.0262, ...). Multiples of
#: 60 so that every N = 1 … 5 update lands on whole periods.
SPP_GRID = (1200, 480, 240, 120, 60)
DIGITS = 50
NS = (1, 2, 3, 4, 5)


def _omega_h(spp: int) -> float:
    return 2.0 * math.pi / spp


@functools.lru_cache(maxsize=512)
def drift_mp(a: float, spp: int, n: int, structure: str, coefficients: str = "table3",
             periods: int = 2, digits: int = DIGITS) -> float:
    """Cone-axis drift (rad/s) in arbitrary precision, mean over interleaved chains.

    Memoised: the report's tables ask for the same configurations more than once.
    """
    motion = ClassicalConing(a, OMEGA)
    h = motion.period / spp
    cs = coefficient_set(coefficients, n)
    s = run_mp(motion, cs, structure=structure, h=h, samples=periods * spp, digits=digits)
    k = s.startup
    chains = analysis.chain_drift_rate(s.t[k:], s.err[k:, 0], s.chain[k:], period=motion.period)
    assert all(c.method == "whole-periods" for c in chains)
    return float(np.mean([c.rate for c in chains]))


@functools.lru_cache(maxsize=64)
def drift_f64(a: float, spp: int, n: int, structure: str, periods: int = 20) -> float:
    """Cone-axis drift (rad/s) in float64 (same pipeline as ``strapdown evaluate``)."""
    motion = ClassicalConing(a, OMEGA)
    h = motion.period / spp
    rec = sensors.increments(motion, h, periods * spp)
    sol = run_structure(structure, rec.data, coefficient_set("table3", n), h=h,
                        q0=motion.attitude(0.0))
    err, _ = analysis.attitude_errors(sol.t, sol.q, motion)
    k = sol.startup
    chains = analysis.chain_drift_rate(sol.t[k:], err[k:, 0], sol.chain[k:],
                                       period=motion.period)
    return float(np.mean([c.rate for c in chains]))


def _law(a: float, spp: int, n: int) -> float:
    return analysis.table1_prediction(a, OMEGA, (2 * math.pi / spp) / OMEGA, n)


def _const(drift: float, a: float, spp: int, n: int) -> float:
    """Measured drift constant c with drift = −c a²Ω(Ωh)^{2N}."""
    return -drift / (a * a * OMEGA * _omega_h(spp) ** (2 * n))


def _frac(f: Fraction) -> str:
    return f"{f.numerator}/{f.denominator}" if f.denominator != 1 else str(f.numerator)


def _g(x: float, d: int = 6) -> str:
    return f"{x:.{d}g}"


def reproduce(out: str | Path, *, progress: Callable[[str], None] | None = None) -> Path:
    """Run the whole reproduction and write it to ``out``; returns the path of ``report.md``."""
    out, w, say, plt, t_start = begin_report(out, progress)
    md: list[str] = []

    # ---------------------------------------------------------------- Table 1
    say("Table 1: conventional drift constants in arbitrary precision (a = 1e-6 rad)")
    rows1 = []
    t1 = {}
    for n in NS:
        for spp in (240, 60):
            c = _const(drift_mp(SMALL_A, spp, n, "conventional"), SMALL_A, spp, n)
            t1[n, spp] = c
        ratio = t1[n, 60] / float(PRINTED_TABLE1[n])
        ratio240 = t1[n, 240] / float(PRINTED_TABLE1[n])
        ok = abs(ratio - 1) <= 0.02
        status = "reproduced" if ok else "differs"
        note = "" if abs(ratio240 - 1) <= 0.02 else (
            "at Ωh = 0.026 the a⁴ term dominates even at a = 1e-6 (papers.md)")
        rows1.append([n, _frac(PRINTED_TABLE1[n]), _frac(table1_drift_constant(n)),
                      _g(1 / t1[n, 60], 8), _g(ratio, 6), _g(ratio240, 6), status, note])
    md.append("## Table 1 — conventional structure drift\n\n"
              "Drift about the cone axis = −c · a²Ω(Ωh)^{2N}, Table 3 coefficients, measured in "
              f"arbitrary precision ({DIGITS} digits) at a = 1e-6 rad over two cone periods, "
              "sampled at whole periods.\n\n")
    md.append(w.table("table1", ["N", "printed c", "derived c = N!(N+1)!/(2N+2)!",
                                 "measured 1/c (Ωh=0.1047)", "measured/printed (Ωh=0.1047)",
                                 "measured/printed (Ωh=0.0262)", "status", "note"], rows1))

    # ---------------------------------------------------------------- Table 2
    say("Table 2: real-time structure drift in arbitrary precision")
    rows2 = []
    rt_vs_conv = {60: [], 240: []}
    a_cmp = math.radians(PAPER_HALF_ANGLE_DEG)
    abs_small = []
    for n in NS:
        rel = {}
        d_rt = drift_mp(SMALL_A, 60, n, "realtime")
        d_cv = drift_mp(SMALL_A, 60, n, "conventional")
        abs_small.append(abs(d_rt - d_cv))
        c_rt = _const(d_rt, SMALL_A, 60, n)
        for spp in (60, 240):
            dr = drift_mp(a_cmp, spp, n, "realtime")
            dc = drift_mp(a_cmp, spp, n, "conventional")
            rel[spp] = abs(dr / dc - 1)
            rt_vs_conv[spp].append(rel[spp])
        ratio = c_rt / float(PRINTED_TABLE2[n])
        status = "reproduced" if abs(ratio - 1) <= 0.02 else "does not reproduce"
        rows2.append([n, _frac(PRINTED_TABLE2[n]), _g(1 / c_rt, 8), _g(ratio, 6), n ** (2 * n),
                      f"{rel[240]:.1e}", f"{rel[60]:.1e}", f"{abs_small[-1]:.1e}", status])
    md.append("\n## Table 2 — real-time structure drift\n\n"
              "Same motion and coefficients, real-time structure (eq. 15); measured constant at "
              "a = 1e-6 rad, Ωh = 0.1047. Its drift (mean of its N chains) equals the "
              "conventional drift at the same h, so the measured constant is Table 1's; the "
              "printed Table 2 is Table 1 with h → h/N, smaller by N^{2N}. The agreement is "
              "measured at a = 1°, where the drift is well above the arithmetic's resolution. "
              "At a = 1e-6 the chains differ by an absolute ~1e-34 rad/s (last-but-one column), "
              "which is a visible relative difference only where the drift itself is below "
              "1e-25 rad/s (N = 5: 1.8e-25 rad/s).\n\n")
    md.append(w.table("table2", ["N", "printed c", "measured 1/c", "measured/printed", "N^(2N)",
                                 "|realtime/conventional − 1| a=1°, Ωh=0.0262",
                                 "|realtime/conventional − 1| a=1°, Ωh=0.1047",
                                 "|realtime − conventional| a=1e-6 (rad/s)", "status"], rows2))

    # ---------------------------------------------------------------- Table 3
    say("Table 3: coefficient sets and layouts")
    rows3 = []
    for n in NS:
        d_t3 = drift_mp(SMALL_A, 60, n, "conventional", "table3")
        d_lag = drift_mp(SMALL_A, 60, n, "conventional", "lag")
        d_eq6 = drift_mp(SMALL_A, 60, n, "conventional", "eq6-printed")
        status = "reproduced (cross-with-last reading)"
        rows3.append([n, ", ".join(_frac(s) for s in TABLE3[n]) or "—",
                      _g(_const(d_t3, SMALL_A, 60, n) ** -1, 8),
                      _g(_const(d_lag, SMALL_A, 60, n) ** -1, 8),
                      _g(d_eq6 / d_t3, 4), status])
    d_mil = drift_mp(SMALL_A, 60, 3, "conventional", "miller")
    T = 3 * _omega_h(60) / OMEGA
    miller_law = SMALL_A**2 * OMEGA * (OMEGA * T) ** 4 / 6480
    md.append("\n## Table 3 — optimised coefficients\n\n"
              "The printed ς_m only work as φ = Σθ + Σ ς_m θ_{N−m} × θ_N (papers.md); the lag "
              "form spreads each ς_m over all pairs of lag m. Eq. 6 as printed (ς_i on every "
              "θ_i × θ_j) is measured for comparison. a = 1e-6 rad, Ωh = 0.1047, arbitrary "
              "precision.\n\n")
    md.append(w.table("table3", ["N", "ς (printed)", "1/c cross-with-last", "1/c lag form",
                                 "eq. 6 as printed / Table 3 drift", "status"], rows3))
    md.append(f"\nMiller's three-sample set (33/80, 57/80) on the same motion drifts "
              f"{d_mil:+.4e} rad/s against its fourth-order law +a²Ω(ΩT)⁴/6480 = "
              f"{miller_law:+.4e} rad/s (ratio {d_mil / miller_law:.4f}): it is not the "
              f"classical-coning optimum.\n")

    # ------------------------------------------------------------ Tables 4/5
    say("Tables 4/5: rotation per update")
    rows4, rows5 = [], []
    for rate, printed in PRINTED_TABLE4.items():
        for n in NS:
            ours = math.degrees(analysis.rotation_per_update(math.radians(rate), "conventional",
                                                             n, PAPER_H))
            p = printed[n - 1]
            ok = math.isclose(ours, p, rel_tol=1e-9)
            fits = p / (n * PAPER_H)
            rows4.append([rate, n, _g(ours), p, "reproduced" if ok else
                          f"differs: printed = {p / ours:.3g} × ω·T (fits {fits:.0f} °/s)"])
        for n in NS:
            ours = math.degrees(analysis.rotation_per_update(math.radians(rate), "realtime", n,
                                                             PAPER_H))
            p = PRINTED_TABLE5[rate][n - 1]
            ok = math.isclose(ours, p, rel_tol=1e-9)
            rows5.append([rate, n, _g(ours), p, "reproduced" if ok else
                          f"differs: printed = {p / ours:.3g} × ω·h (fits {p / PAPER_H:.0f} °/s)"])
    md.append("\n## Tables 4 and 5 — rotation per attitude update (deg), h = 0.1 ms\n\n"
              "Computed as ω·T (conventional, T = N h) and ω·h (real-time).\n\n")
    md.append(w.table("table4", ["spin °/s", "N", "computed ω·T (deg)", "printed", "status"],
                      rows4))
    md.append("\n")
    md.append(w.table("table5", ["spin °/s", "N", "computed ω·h (deg)", "printed", "status"],
                      rows5))

    # --------------------------------------------------- float64 vs precision
    say("float64 against arbitrary precision at a = 1°")
    a1 = math.radians(PAPER_HALF_ANGLE_DEG)
    rows6 = []
    for n in (1, 2):
        for spp in (240, 60):
            d64 = drift_f64(a1, spp, n, "conventional")
            dmp = drift_mp(a1, spp, n, "conventional")
            rows6.append([n, _g(_omega_h(spp), 4), f"{d64:.6e}", f"{dmp:.6e}",
                          f"{abs(d64 / dmp - 1):.2e}", f"{_law(a1, spp, n):.6e}"])
    md.append("\n## float64 against arbitrary precision (a = 1°)\n\n"
              "Conventional structure, Table 3 coefficients; float64 over 20 cone periods, "
              "arbitrary precision over 2.\n\n")
    md.append(w.table("float64_vs_mp", ["N", "Ωh", "float64 drift (rad/s)",
                                        "arbitrary-precision drift (rad/s)", "relative difference",
                                        "Table 1 law (rad/s)"], rows6))

    # ------------------------------------------------------- drift versus Ωh
    say("drift versus Ωh at a = 1° (arbitrary precision, both structures)")
    rows7 = []
    meas = {}
    for n in NS:
        for spp in SPP_GRID:
            dc = drift_mp(a1, spp, n, "conventional")
            dr = drift_mp(a1, spp, n, "realtime")
            law = _law(a1, spp, n)
            meas[n, spp] = (dc, dr, law)
            ratio = dc / law
            rows7.append([n, _g(_omega_h(spp), 4), f"{dc:.6e}", f"{dr:.6e}", f"{law:.6e}",
                          _g(ratio, 5), "follows Table 1" if abs(ratio - 1) <= 0.02 else
                          "departs from Table 1 (higher order in a dominates)"])
    md.append("\n## Drift versus Ωh at a = 1° — where the Table 1 law holds\n\n"
              "Arbitrary precision, both structures. Table 1 is the leading-order law in a; at "
              "a = 1° and N ≥ 3 an a⁴ term from the neglected Bortz terms dominates at small "
              "Ωh.\n\n")
    md.append(w.table("drift_vs_omega_h", ["N", "Ωh", "conventional (rad/s)", "real-time (rad/s)",
                                           "Table 1 law (rad/s)", "conventional/law", "verdict"],
                      rows7))

    fig, ax = plt.subplots(figsize=(7.5, 5.5))
    oh = np.array([_omega_h(s) for s in SPP_GRID])
    ohl = np.geomspace(oh.min() * 0.8, oh.max() * 1.25, 50)
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(NS)))
    for n, col in zip(NS, colors, strict=True):
        dc = np.array([abs(meas[n, s][0]) for s in SPP_GRID])
        dr = np.array([abs(meas[n, s][1]) for s in SPP_GRID])
        c1 = float(PRINTED_TABLE1[n])
        c2 = float(PRINTED_TABLE2[n])
        ax.loglog(ohl, c1 * a1**2 * OMEGA * ohl ** (2 * n), "-", color=col, lw=1,
                  label=f"N={n}: Table 1 law")
        if n > 1:
            ax.loglog(ohl, c2 * a1**2 * OMEGA * ohl ** (2 * n), ":", color=col, lw=1)
        ax.loglog(oh, dc, "o", color=col, mfc="none", ms=7)
        ax.loglog(oh, dr, "x", color=col, ms=6)
    ax.plot([], [], "ko", mfc="none", label="measured, conventional")
    ax.plot([], [], "kx", label="measured, real-time")
    ax.plot([], [], "k:", label="Table 2 as printed")
    ax.set_xlabel("Ωh (rad)")
    ax.set_ylabel("|drift| about cone axis (rad/s)")
    ax.set_title("Li & Zhang 2017: drift vs Ωh, a = 1°, Ω = 2π rad/s (arbitrary precision)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    w.figure("drift_vs_omega_h.png", fig)

    # ------------------------------------------------------ update period vs N
    fig, ax = plt.subplots(figsize=(5.5, 4))
    nn = np.arange(1, 6)
    ax.plot(nn, nn * PAPER_H * 1e3, "o-", label="conventional (T = N h)")
    ax.plot(nn, np.full(5, PAPER_H * 1e3), "s-", label="real-time (h)")
    ax.set_xlabel("subsamples N")
    ax.set_ylabel("update period (ms)")
    ax.set_title("Update period, h = 0.1 ms (Figure 5)")
    ax.set_xticks(nn)
    ax.grid(alpha=0.3)
    ax.legend()
    w.figure("update_period.png", fig)

    # ----------------------------------------------------------- sawtooth
    say("real-time sawtooth under gyro noise")
    saw = _sawtooth_figure(w, plt)
    md.append("\n## The real-time structure's sawtooth\n\n" + saw)

    # ------------------------------------------------------------ single chain
    say("single chain (designer) against the real-time structure at a = 1°")
    md.append(_single_chain_section(w))

    # ---------------------------------------------------- paper's own setting
    md.append(_paper_setting_note())
    elapsed = time.perf_counter() - t_start

    report = [
        "# Reproduction: Li & Zhang 2017 — real-time structure of attitude algorithm\n",
        "X. Li, S. Zhang, *A Real-Time Structure of Attitude Algorithm for High Dynamic Bodies*, "
        "J. Control Sci. Eng. 2017, 9542423. Generated by `strapdown reproduce li2017` "
        f"(strapdown {_version()}) in {elapsed:.0f} s.\n",
        "## Summary\n",
        "- **Table 1 reproduces**: measured drift constants in arbitrary precision agree with "
        "1/12 … 1/5544 (ratios in `table1.csv`).",
        "- **Table 2 does not reproduce**: the real-time structure drifts exactly like the "
        f"conventional one (largest relative difference at a = 1°: "
        f"{max(rt_vs_conv[240] + rt_vs_conv[60]):.1e}); printed "
        "Table 2 is smaller by N^{2N} (16, 729, 65536, 9765625 for N = 2 … 5). The structure "
        "raises the output rate to 1/h; it does not improve accuracy.",
        "- **Table 3** works only read as cross-with-last (or any layout with the same lag sums); "
        "eq. 6 as printed is far worse for N ≥ 3.",
        "- **Tables 4/5**: the 3600 and 7200 °/s rows are 0.6 × ω·T (they fit 2160 and 4320 °/s).",
        "- At a = 1° the Table 1 law is the small-angle limit: for N ≥ 3 and small Ωh the "
        "measured drift departs from it (figure and `drift_vs_omega_h.csv`).",
        "- The real-time structure's N chains keep their start-up offsets forever (a "
        "noise-free N-periodic sawtooth of 2.9e-11 rad at N = 3, a = 1°).",
        "- What the paper wanted — N-subsample accuracy with an output every h — a single "
        "chain with designed coefficients delivers: same leading-order drift as the "
        "conventional algorithm, one chain, no sawtooth (`single_chain.csv`).\n",
        "![drift versus Ωh](drift_vs_omega_h.png)\n",
        "![update period](update_period.png)\n",
        *md,
        "\n## Files\n",
        *w.file_list(),
        "",
    ]
    return write_text(out / "report.md", "\n".join(report))


def _single_chain_section(w: ReportWriter) -> str:
    """What the paper wanted from the real-time structure, done by one chain."""
    from strapdown.algorithms.structures import single_chain_coefficients

    a1 = math.radians(1.0)
    rows = []
    for n in (2, 3, 4, 5):
        coeffs = ", ".join(_frac(c) for c in single_chain_coefficients(n))
        for spp in (240, 60):
            dc = drift_mp(a1, spp, n, "conventional")
            dr = drift_mp(a1, spp, n, "realtime")
            ds = drift_mp(a1, spp, n, "single-chain")
            dsmall = drift_mp(SMALL_A, spp, n, "single-chain") / drift_mp(
                SMALL_A, spp, n, "conventional")
            rows.append([n, _g(_omega_h(spp), 4), coeffs, f"{dc:.4e}", f"{dr:.4e}", f"{ds:.4e}",
                         _g(ds / dc, 5), _g(dsmall, 5)])
    return ("\n## A genuine single chain\n\n"
            "`strapdown coefficients --form single-chain --subsamples N` derives "
            "φ_k = θ_k + Σ c_m θ_{k−m} × θ_k (one chain, an update every h; c_m = (K_m − "
            "(N−m)/2)/N from the conventional lag sums K_m). Its classical-coning drift "
            "constant equals the conventional N-subsample one at the same h. Drift about the "
            "cone axis in arbitrary precision, a = 1° (last column: single/conventional at "
            "a = 1e-6, where the leading-order law is exact):\n\n"
            + w.table("single_chain", ["N", "Ωh", "c_1 … c_{N−1}", "conventional (rad/s)",
                                       "real-time (rad/s)", "single chain (rad/s)",
                                       "single/conventional (a = 1°)",
                                       "single/conventional (a = 1e-6)"], rows)
            + "\nAt a = 1e-6 the single chain matches the conventional drift wherever the "
            "leading-order law governs both (N = 5 at Ωh = 0.026 is the exception: there the "
            "conventional drift is a⁴-dominated even at a = 1e-6, see Table 1). At a = 1° the "
            "a⁴ terms differ between the algorithms: for N ≥ 4 the conventional (and so the "
            "real-time) drift is a⁴-dominated and the single chain drifts 50–300 times less, "
            "close to the leading-order law; for N = 3 at small Ωh the single chain is worse "
            "(ratio above). The real-time structure matches the conventional drift only "
            "because it is N conventional chains; the single chain gets the same leading-order "
            "accuracy at the same output rate from one chain.\n")


def _version() -> str:
    from strapdown import __version__

    return __version__


def _paper_setting_note() -> str:
    a = math.radians(PAPER_HALF_ANGLE_DEG)
    om = math.radians(PAPER_CONE_RATE_DPS)
    rows = [[n, f"{analysis.table1_prediction(a, om, PAPER_H, n):.3e}"] for n in NS]
    return ("\n## The paper's own setting\n\n"
            "h = 0.1 ms, a = 1°, Ω = 360 °/s gives Ωh = 6.3e-4. Table 1 predicts the drifts below; "
            "for N ≥ 2 they are far below float64 round-off (about 1e-16 rad per update, i.e. "
            "~1e-12 rad/s), so the paper's Figures 6–7 cannot show algorithmic drift for N ≥ 2 "
            "in double precision; we measure the law at larger Ωh instead.\n\n"
            + markdown_table(["N", "Table 1 drift (rad/s)"], rows))


def _sawtooth_figure(w: ReportWriter, plt) -> str:
    """Real-time structure: N interleaved chains that never re-converge."""
    n = 3
    motion = ClassicalConing(math.radians(1.0), OMEGA)
    spp = 600
    h = motion.period / spp
    periods = 20
    cs = coefficient_set("table3", n)
    cases = {}
    single = {}
    for label, noise_dps in (("noise-free", 0.0), ("0.01 °/s/√Hz", 0.01), ("0.1 °/s/√Hz", 0.1)):
        errs = sensors.GyroErrors(white_noise=math.radians(noise_dps))
        rec = sensors.increments(motion, h, periods * spp, errors=errs, rng=20170618)
        sol = run_structure("realtime", rec.data, cs, h=h, q0=motion.attitude(0.0))
        err, _ = analysis.attitude_errors(sol.t, sol.q, motion)
        cases[label] = (sol, err[:, 0], sawtooth_amplitude(err[:, 0], sol.chain, spp))
        # the single chain on the same increments, analysed with the same N-periodic regression
        sc = run_structure("single-chain", rec.data, cs, h=h, q0=motion.attitude(0.0))
        esc, _ = analysis.attitude_errors(sc.t, sc.q, motion)
        single[label] = sawtooth_amplitude(esc[:, 0], np.arange(sc.t.size) % n, spp)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 6.5))
    sol, ex, _ = cases["noise-free"]
    sl = np.arange(ex.size - 12 * n, ex.size)
    trend = np.polyval(np.polyfit(sl, ex[sl], 1), sl)
    for c in range(n):
        idx = sl[sol.chain[sl] == c]
        a1.plot(sol.t[idx], (ex[idx] - trend[sol.chain[sl] == c]) * 1e12, "o-", ms=4,
                label=f"chain {c}")
    a1.plot(sol.t[sl], (ex[sl] - trend) * 1e12, "k-", lw=0.5, alpha=0.6, label="output sequence")
    a1.set_xlabel("t (s)")
    a1.set_ylabel("detrended cone-axis error (prad)")
    a1.set_title(f"Noise-free, N = {n}: the last {12 * n} outputs (start-up offsets persist)")
    a1.legend(fontsize=7)
    for (label, (_, _, off)), col in zip(cases.items(), ("C0", "C1", "C2"), strict=True):
        a2.semilogy(np.arange(off.size) + 0.5, off, "o-", ms=3, color=col,
                    label=f"real-time, {label}")
        a2.semilogy(np.arange(off.size) + 0.5, np.maximum(single[label], 1e-22), "--",
                    color=col, lw=1, label=f"single chain, {label}")
    a2.set_xlabel("cone period")
    a2.set_ylabel("sawtooth amplitude (rad)")
    a2.set_title("N-periodic component per cone period")
    a2.grid(alpha=0.3, which="both")
    a2.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    w.figure("realtime_sawtooth.png", fig)
    rows = [[label, f"{off[0]:.2e}", f"{np.median(off):.2e}", f"{off.max():.2e}",
             f"{np.median(single[label]):.2e}"]
            for label, (_, _, off) in cases.items()]
    table = markdown_table(["gyro white noise", "real-time: first period", "real-time: median",
                            "real-time: max", "single chain: median"], rows)
    return (f"N = {n}, a = 1°, 1 Hz coning, h = {h:.3g} s, {periods} periods, seed 20170618. "
            "Sawtooth amplitude = spread of the per-chain constants when each period's "
            "cone-axis error is regressed on a trend plus one constant per chain.\n\n"
            + table +
            "\nNoise-free, the chains keep the constant offsets their start-ups gave them "
            "(2.9e-11 rad here, against 1e-20 for the single chain on the same increments): "
            "nothing pulls them together, so the output is an N-periodic sawtooth forever. "
            "Under white noise the same regression finds an N-periodic component of the same "
            "size in the single chain (last column), so at these noise levels it measures the "
            "noise itself: every chain sums every increment exactly once, the first-order "
            "noise is common to all chains, and the chains' own second-order divergence is "
            "not resolvable here. The structure gives an output every h, but consecutive "
            "outputs come from different, unconnected solutions.\n\n"
            "![real-time sawtooth](realtime_sawtooth.png)\n")
