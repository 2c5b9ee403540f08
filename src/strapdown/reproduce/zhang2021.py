"""Zhang & Yu (2021), double-rotation (cone-angle) representation of spinning bodies.

``strapdown reproduce zhang2021 --out DIR`` writes simulations 1–4 (Tables 5–6)
and a true spin + coning case: roll (δ3) and half-cone (δ2) errors against
time for every method, a maximum-error table, the list of typos with our
corrections (each measured), and where Table 7's triple-cross-product terms
help or hurt.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from strapdown import analysis
from strapdown.algorithms.cone_kinematics import integrate_cone_angles
from strapdown.algorithms.coning import (
    TABLE7,
    coefficient_set,
    rotation_vectors,
    triple_cross_rotation_vectors,
)
from strapdown.algorithms.structures import chain_rotation_vectors
from strapdown.io.files import markdown_table, write_text
from strapdown.io.report import ReportWriter, begin_report
from strapdown.rotation.cone_angles import (
    cone_angles_from_dcm,
    cone_angles_from_quat,
    dcm_from_cone_angles,
    paper_cone_angles_from_dcm,
    paper_dcm_from_cone_angles,
    paper_pitch_yaw_from_cone_angles,
    pitch_yaw_roll_from_cone_angles,
)
from strapdown.rotation.euler import euler_zyx_from_dcm
from strapdown.truth.motions import ConeAngleMotion

D = math.radians
RATE_HZ = 10_000.0
DURATION = 30.0


def simulation(number: int) -> ConeAngleMotion:
    """Motions of simulations 1–4 (Tables 5 and 6; 3 and 4 repeat 1 and 2 for navigation).

    Table 5: roll 0°, half cone 0°, cone speed 360°/s, rolling speed 360°/s, half-cone rate
    1.146°/s (the text's "initial roll angle 30°" contradicts the table; we use the table).
    Table 6 adds rolling and precession accelerations of 24°/s².
    """
    acc = (D(24), 0.0, D(24)) if number in (2, 4) else (0.0, 0.0, 0.0)
    return ConeAngleMotion.polynomial((0.0, 0.0, 0.0), (D(360), D(1.146), D(360)), acc)


def spin_coning(half_angle_deg: float = 5.0, cone_dps: float = 360.0,
                spin_dps: float = 3600.0) -> ConeAngleMotion:
    """A real spin + coning case: δ1 = Ωt − π/2, δ2 = a, δ3 = ω_s t (period 1 s here)."""
    return ConeAngleMotion.polynomial((-math.pi / 2, D(half_angle_deg), 0.0),
                                      (D(cone_dps), 0.0, D(spin_dps)))


def _wrap(x):
    return (x + math.pi) % (2 * math.pi) - math.pi


def _errors(angles, truth, d2_min=1e-3):
    """(roll error, half-cone error) in rad; δ3 compared modulo 2π."""
    e3 = _wrap(angles[:, 2] - truth[:, 2])
    e2 = angles[:, 1] - truth[:, 1]
    return e3, e2


def reproduce(out: str | Path, *, progress: Callable[[str], None] | None = None) -> Path:
    """Run the reproduction and write it to ``out``; returns the path of ``report.md``."""
    out, w, say, plt, t_start = begin_report(out, progress)
    md: list[str] = []
    n = round(DURATION * RATE_HZ)
    t = np.arange(n + 1) / RATE_HZ

    # -------------------------------------------------- flight control (sims 1, 2)
    rows = []
    curves = {}
    for sim in (1, 2):
        say(f"simulation {sim}: flight-control integrations")
        m = simulation(sim)
        omega = m.rate(t)
        truth = m.angles(t[::2])
        for method in ("cone", "nutation", "euler", "cone-printed"):
            s = integrate_cone_angles(t, omega, truth[0], method=method)
            e3, e2 = _errors(s.angles, truth)
            curves[sim, method] = (s.t, e3, e2)
            rows.append([sim, method, f"{np.degrees(np.abs(e3).max()):.3e}",
                         f"{np.degrees(np.abs(e2).max()):.3e}", s.switches])
        # the paper's "three-rotation" reading: Euler roll taken as δ3
        _, _, roll = pitch_yaw_roll_from_cone_angles(*truth.T)
        e3 = _wrap(roll - truth[:, 2])
        bound = np.arcsin(np.tan(truth[:, 1] / 2) ** 2)
        curves[sim, "euler-roll-as-δ3"] = (t[::2], e3, np.zeros_like(e3))
        rows.append([sim, "Euler roll read as δ3 (paper's three-rotation error)",
                     f"{np.degrees(np.abs(e3).max()):.3e}", "—", "—"])
        rows.append([sim, "  its predicted envelope asin(tan²(δ2/2)) at t = 30 s",
                     f"{np.degrees(bound[-1]):.3e}", "—", "—"])
    md.append("## Flight control: cone angles integrated from gyro rates (simulations 1–2)\n\n"
              f"Rates sampled at {RATE_HZ:.0f} Hz over {DURATION:.0f} s, RK4 with step 2·td "
              "(middle rate = middle sample). Maximum errors in degrees. `cone`: eq. 7 with "
              "row 1's sign corrected, carried by the non-singular form while sin δ2 < 1e-3 "
              "(the simulations start at δ2 = 0; 'switches' counts hand-overs); `nutation`: "
              "the non-singular formulation C = exp([ν×]) Rx(δ3), ν = δ2(0, −sin δ1, cos δ1); "
              "`euler`: z-y-x Euler kinematics converted through the DCM; `cone-printed`: "
              "eq. 7 as printed.\n\n")
    md.append(w.table("flight_control", ["simulation", "method", "max roll error (deg)",
                                         "max half-cone error (deg)", "switches"], rows))
    md.append("\nThe corrected eq. 7, the non-singular form and the Euler-angle ODE converted "
              "through the DCM agree with truth to ~5e-8°; the printed eq. 7 diverges. The "
              "paper's large three-rotation errors are not integration errors: the Euler roll "
              "is a different angle from δ3, and the two differ by an oscillation whose "
              "envelope is asin(tan²(δ2/2)).\n")

    fig, axes = plt.subplots(2, 2, figsize=(10, 6.5), sharex=True)
    for col, sim in enumerate((1, 2)):
        for method, style in (("cone", "-"), ("nutation", "--"), ("euler", ":"),
                              ("cone-printed", "-"), ("euler-roll-as-δ3", "-")):
            tt, e3, e2 = curves[sim, method]
            lw = 0.6 if method in ("cone-printed", "euler-roll-as-δ3") else 1.2
            axes[0, col].semilogy(tt, np.maximum(np.degrees(np.abs(e3)), 1e-14), style, lw=lw,
                                  label=method)
            if method != "euler-roll-as-δ3":
                axes[1, col].semilogy(tt, np.maximum(np.degrees(np.abs(e2)), 1e-14), style,
                                      lw=lw, label=method)
        axes[0, col].set_title(f"Simulation {sim}: roll (δ3) error")
        axes[1, col].set_title(f"Simulation {sim}: half-cone (δ2) error")
        axes[1, col].set_xlabel("t (s)")
        for a in axes[:, col]:
            a.set_ylabel("|error| (deg)")
            a.grid(alpha=0.3, which="both")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    w.figure("flight_control_errors.png", fig)
    md.append("\n![flight-control errors](flight_control_errors.png)\n")

    # ------------------------------------------------ navigation (sims 3, 4, spin+coning)
    say("navigation: rotation vector with and without Table 7")
    rows = []
    nav_curves = {}
    negated = {k: (-v if len(k) == 4 else v) for k, v in TABLE7.items()}
    cases = [("simulation 3", simulation(3), None), ("simulation 4", simulation(4), None),
             ("spin + coning: a = 5°, cone 360°/s, spin 3600°/s", spin_coning(), 1.0),
             ("spin + coning: a = 1°, cone 360°/s, spin 1080°/s",
              spin_coning(1.0, 360.0, 1080.0), 1.0)]
    h = 1.0 / RATE_HZ
    for label, m, period in cases:
        theta = m.increments(np.arange(n + 1) * h)
        sets = {
            "3-subsample k11 = 9/20, k12 = 27/40 (plain)":
                triple_cross_rotation_vectors(theta, triple=False),
            "+ Table 7 triple terms (as inferred)": triple_cross_rotation_vectors(theta),
            "+ Table 7 triple terms, opposite sign":
                triple_cross_rotation_vectors(theta, negated),
            "Table 3 N = 3 (cross-with-last)": rotation_vectors(theta,
                                                                coefficient_set("table3", 3)),
        }
        for name, phi in sets.items():
            sol = chain_rotation_vectors(phi, update_period=3 * h, q0=m.attitude(0.0))
            err, ang = analysis.attitude_errors(sol.t, sol.q, m)
            ang_c = np.stack(cone_angles_from_quat(sol.q), -1)
            e3, e2 = _errors(ang_c, m.angles(sol.t))
            drift = analysis.drift_rate(sol.t, err, period=period)
            nav_curves[label, name] = (sol.t, e3, e2)
            rows.append([label, name, f"{np.degrees(np.abs(e3).max()):.3e}",
                         f"{np.degrees(np.abs(e2).max()):.3e}", f"{ang.max():.3e}",
                         f"{np.linalg.norm(drift.rate):.3e}", drift.method])
    md.append("\n## Navigation: rotation-vector update converted to cone angles "
              "(simulations 3–4 and spin + coning)\n\n"
              f"Increments at {RATE_HZ:.0f} Hz, three per update. Table 7's structure is "
              "inferred (papers.md): φ = Σθ + k11 θ1×θ3 + k12 θ2×(θ3 − θ1) + Σ k_mij θm × "
              "(θi × θj); we also run the triple terms with the opposite sign. The plain set "
              "has the lag sums of Table 3 (the classical-coning optimum).\n\n")
    md.append(w.table("navigation", ["case", "rotation vector", "max roll error (deg)",
                                     "max half-cone error (deg)", "max attitude error (rad)",
                                     "|drift| (rad/s)", "drift method"], rows))
    md.append("\nWhere the triple terms help or hurt is read off the rows above: on these "
              "motions the inferred Table 7 terms do not reduce the error of the plain "
              "three-subsample set with the same k11, k12 (compare the rows); the published "
              "coefficients were tuned by Wang et al. for a coning-and-rotation environment "
              "whose details the seed does not give.\n")
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    label = cases[2][0]
    for name in ("3-subsample k11 = 9/20, k12 = 27/40 (plain)",
                 "+ Table 7 triple terms (as inferred)", "Table 3 N = 3 (cross-with-last)"):
        tt, e3, e2 = nav_curves[label, name]
        axes[0].semilogy(tt, np.maximum(np.degrees(np.abs(e3)), 1e-16), lw=0.8, label=name)
        axes[1].semilogy(tt, np.maximum(np.degrees(np.abs(e2)), 1e-16), lw=0.8, label=name)
    axes[0].set_title(f"{label}: roll error")
    axes[1].set_title("half-cone error")
    axes[1].set_xlabel("t (s)")
    for a in axes:
        a.set_ylabel("|error| (deg)")
        a.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    w.figure("navigation_errors.png", fig)
    md.append("\n![navigation errors](navigation_errors.png)\n")

    # ------------------------------------------------------------- typos
    say("typos and conversion checks")
    md.append(_typos(w))

    elapsed = time.perf_counter() - t_start
    report = [
        "# Reproduction: Zhang & Yu 2021 — double-rotation (cone-angle) representation\n",
        f"Generated by `strapdown reproduce zhang2021` in {elapsed:.0f} s.\n",
        "## Summary\n",
        "- With eq. 7 corrected (row 1 sign) and the δ2 = 0 singularity handled, cone-angle "
        "integration is as accurate as the non-singular form and as a correct Euler-angle "
        "integration converted through the DCM (all ~5e-8° over 30 s at 10 kHz).",
        "- The paper's large three-rotation errors come from reading the Euler roll as δ3; "
        "the two differ by an oscillation with envelope asin(tan²(δ2/2)).",
        "- Simulations 1–4 have cone speed = rolling speed: the body turns about a nearly "
        "fixed axis, no coning. The spin + coning cases here are real coning.",
        "- Table 7's triple-cross-product terms, in the structure papers.md infers, do not "
        "help on these motions (navigation table).\n",
        *md,
        "\n## Files\n",
        *w.file_list(),
        "",
    ]
    return write_text(out / "report.md", "\n".join(report))


def _typos(w: ReportWriter) -> str:
    rng = np.random.default_rng(2021)
    d1 = rng.uniform(0, 2 * np.pi, 20000)
    d2 = rng.uniform(1e-3, np.pi - 1e-3, 20000)
    d3 = rng.uniform(0, 2 * np.pi, 20000)
    c = dcm_from_cone_angles(d1, d2, d3)
    eq17 = np.abs(paper_dcm_from_cone_angles(d1, d2, d3) - c).max(axis=0)
    p1, _, p3 = paper_cone_angles_from_dcm(c)
    bad_d3 = np.mean(np.abs(_wrap(p3 - d3)) > 1e-6)
    bad_d1 = np.mean(np.abs(_wrap(p1 - d1)) > 1e-6)
    ours = cone_angles_from_dcm(c)
    our_err = max(np.abs(_wrap(ours[0] - d1)).max(), np.abs(ours[1] - d2).max(),
                  np.abs(_wrap(ours[2] - d3)).max())
    small = 1e-7
    cs = dcm_from_cone_angles(1.0, small, 2.0)
    arccos_err = abs(paper_cone_angles_from_dcm(cs)[1] - small)
    atan2_err = abs(cone_angles_from_dcm(cs)[1] - small)
    # eqs. 21–22 against z-y-x through the DCM
    yaw, pitch, _ = euler_zyx_from_dcm(c)
    th, psi = paper_pitch_yaw_from_cone_angles(d1, d2)
    pitch_sign = np.mean(np.isclose(th, -pitch, atol=1e-9))
    low = d2 < np.pi / 2
    yaw_ok_low = np.mean(np.isclose(np.abs(psi[low]), np.abs(yaw[low]), atol=1e-9))
    yaw_ok_high = np.mean(np.isclose(np.abs(psi[~low]), np.abs(yaw[~low]), atol=1e-9))
    rows = [
        ["eq. 2", "C2 written with δ1", "rotation about z by δ2", "—"],
        ["eq. 7 row 1", "δ̇1 = +(cos e ω_y + sin e ω_z)/sin δ2",
         "δ̇1 = −(cos e ω_y + sin e ω_z)/sin δ2", "printed form diverges (flight-control table)"],
        ["eq. 17 C32", "−sin e cos δ1 + cos e cos δ1 sin δ2",
         "−sin e cos δ1 + cos e sin δ1 cos δ2", f"printed entry off by up to {eq17[2, 1]:.2f}"],
        ["eq. 17 C33", "cos e cos δ1 + sin e cos δ1 sin δ2",
         "cos e cos δ1 + sin e sin δ1 cos δ2", f"printed entry off by up to {eq17[2, 2]:.2f}"],
        ["eqs. 8–9", "φ = a_l + δφ, φ = ∫ω", "φ = θ_l + δφ, θ_l = ∫ω over the update", "—"],
        ["Table 1 (δ1 quadrants)", "arctan(C31/C21) + quadrant table",
         "atan2(C31, C21)", f"{bad_d1:.1%} of random attitudes wrong"],
        ["Table 2 (δ3 quadrants)", "δ1 + (δ̂3 + kπ) from arctan(C13/C12)",
         "δ3 = atan2(C32 − C23, C22 + C33)", f"{bad_d3:.1%} of random attitudes wrong"],
        ["eq. 19", "δ2 = arccos C11", "atan2(√(C21² + C31²), C11)",
         f"at δ2 = 1e-7: arccos error {arccos_err:.1e} rad, atan2 error {atan2_err:.1e}"],
        ["eq. 21", "ϑ = ±arcsin|sin δ1 sin δ2|", "pitch from the DCM",
         f"printed ϑ equals −(z-y-x pitch) on {pitch_sign:.1%} of attitudes"],
        ["eq. 22", "ψ = ±arcsin √((sin²δ2 − sin²ϑ)/cos²ϑ)", "yaw from the DCM",
         f"|ψ| = |yaw| on {yaw_ok_low:.1%} for δ2 < 90°, {yaw_ok_high:.1%} beyond"],
    ]
    return ("\n## Typos and corrections (each measured)\n\n"
            f"Our robust conversion recovers all 20 000 random attitudes to {our_err:.1e} rad.\n\n"
            + w.table("typos", ["where", "printed", "corrected", "measured effect"], rows)
            + "\n" + markdown_table(["convention"], [["C_c_b = Rx(δ1) Rz(δ2) Rx(δ3 − δ1); "
                                                       "classical coning: δ1 = Ωt − π/2, "
                                                       "δ2 = a, δ3 = 0"]]))
