"""A gyro past its range: the rate it reads stops at its full scale while the body turns on.

No filter sees the rotation beyond the range: the attitude misses it, by degrees per
plateau, until the accelerometer and the magnetometer pull it back. RepoIMU's T-stick
(Szczęsna et al. (2016)) clips at 7.35 rad/s on its x axis on up to a fifth of a trial's
samples, and VQF is tens of degrees off there (docs/reproductions.md, "RepoIMU's
T-stick"). :func:`gyro_plateaus` finds the signature in a record and :func:`ekf
<strapdown.ahrs.ekf>` and :func:`offline_ekf <strapdown.ahrs.offline_ekf>` warn with it
(:class:`GyroSaturationWarning`); where it finds none, a range entered smoothly (a spin-up)
is found by the field (:func:`field_plateaus`). Where one or two axes are clipped
(:func:`clipped`, at the range :func:`gyro_range` or ``AhrsConfig.gyro_range``) and the
field tells their rates apart, ``ekf`` and ``offline_ekf`` take those rates from the
field's turn instead
(:func:`declip`, ``AhrsConfig.gyro_declip``); and near a clipped sample both distrust the
attitude the gyro carried: ``ekf`` suspends its low-pass accelerometer's norm test,
``offline_ekf`` takes its tilt from the accelerometer directly (``AhrsConfig.gyro_clip_s``).

The signature, per axis: plateaus near the axis's largest rate — at least :data:`MIN_RUN`
samples whose rate changes by no more than :data:`FLAT` of itself per sample — each entered
by a step of at least :data:`STEP` of the level, at least :data:`MIN_RUNS` of them, at a
level of at least :data:`MIN_LEVEL`. A smooth peak cannot be both: flat over three samples
needs a second difference below 0.2 % of the rate per sample², and a step of 2 % into it one
of 1.8 %. A steady turn or spin is flat but is not entered by a step (the suite's loiter,
0.06–0.17 rad/s, and its spin at 9.4 rad/s give none), and a robot's constant-rate legs
(OpenAXES, 0.2–0.45 rad/s, two to three plateaus) lie below :data:`MIN_LEVEL`. Measured
[m]: none on BROAD's fifteen trials, OpenAXES's sixteen recordings and the suite (seeds 0–4);
tests 05 and 10 of the T-stick (25–34 plateaus each, 112–1189 samples); RepoIMU's pendulum,
whose third segments clip at 10.3–10.5 rad/s on 2–26 samples, is not found (its plateaus
wander by more than :data:`FLAT`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from strapdown.ahrs import _kernel as K

__all__ = ["DECLIP_ACROSS", "FIELD_MIN_S", "FIELD_RATIO", "FLAT", "MIN_LEVEL", "MIN_RUN",
           "MIN_RUNS", "NEAR", "STEP", "GyroSaturationWarning", "Plateaus", "clipped", "declip",
           "field_plateaus", "gyro_plateaus", "gyro_range", "warn_if_saturated"]

#: Largest change per sample, relative to the rate, within a plateau.
FLAT = 0.002
#: Smallest step, relative to the level, that enters a plateau.
STEP = 0.02
#: Plateaus count within this fraction of the axis's largest |rate|.
NEAR = 0.9
#: Samples in a plateau, at least.
MIN_RUN = 3
#: Plateaus on an axis, at least.
MIN_RUNS = 2
#: Smallest level, rad/s: below every MEMS gyro's full scale (the smallest common one,
#: 125 °/s, is 2.18 rad/s).
MIN_LEVEL = 2.0
#: :func:`field_plateaus`: an axis flat near its largest rate for at least this long in all
#: (s), where the field turns at least :data:`FIELD_RATIO` times faster than the gyro reads.
#: BROAD's smooth peaks are flat so for at most 0.08 s a trial, RepoIMU's pendulum's clipped
#: ones for 0.1 s; the suite's spin clipped at 60–80 % for 35 s [m].
FIELD_MIN_S = 0.5
#: :func:`field_plateaus`: the field's turn over the flat samples, against the gyro's
#: reading there. Measured where the gyro is not clipped: 0.994–1.009 (the suite's steady
#: spin at 9.4 rad/s and its pendulums' peaks, seeds 0–4); where it is: 1.15–1.66 (the
#: suite's 0.3 m pendulum and spin-coning clipped at 60 and 80 %), 1.17–1.63 (the
#: T-stick's tests 10 and 05); the T-stick's test 06 reads 1.05 over 0.9 s [m].
FIELD_RATIO = 1.1
#: :func:`declip` takes a clipped axis's rate from the field only where the field's part
#: across that axis is at least this fraction of its norm (the sine of the angle between
#: them: 5.7°; for two clipped axes, its part along the third); a field nearly along the
#: axis turns too little about it to tell the rate, and the field's noise is amplified by
#: the inverse. Chosen among 0.3, 0.2, 0.1, 0.05 and 0.02 on the suite's spin-coning read by
#: a gyro clipped at 60 % and 80 % of its peak rate (the range given): its field comes
#: within 8.2° of the spin axis (0.143) once a coning cycle, and 0.3 and 0.2 left those
#: samples as read and the filter 95–109° off, 0.1 and below recovered every sample and
#: gave 1.1–1.5° (seeds 0–2); the T-stick's and the clipped pendulums' fields lie well
#: across (docs/reproductions.md, "The rate beyond the range, from the field").
DECLIP_ACROSS = 0.1

_AXES = "xyz"


class GyroSaturationWarning(UserWarning):
    """The gyro looks clipped at its range (:func:`gyro_plateaus`): the rotation beyond it
    is missing from every attitude there, ours and any other filter's."""


@dataclass(frozen=True)
class Plateaus:
    """An axis whose rate stops at a level: ``axis`` (0–2), the number of plateaus
    ``runs``, the mean of their levels ``level`` (|rate|, rad/s) and their ``samples`` in
    all."""

    axis: int
    runs: int
    level: float
    samples: int


def gyro_plateaus(omega: ArrayLike) -> list[Plateaus]:
    """The axes of a gyro record (rad/s, shape (n, 3)) that show a clipped gyro's
    signature (module docstring); empty when none does. One compiled pass over the record
    (:func:`strapdown.ahrs._kernel.gyro_plateau_runs`): it runs before every
    :func:`~strapdown.ahrs.ekf`."""
    w = np.ascontiguousarray(omega, dtype=np.float64)
    if w.ndim != 2 or w.shape[1] != 3:
        raise ValueError(f"omega must have shape (n, 3), got {w.shape}")
    return [p for p in _plateaus(w, STEP) if p.runs >= MIN_RUNS and p.level >= MIN_LEVEL]


def _plateaus(w: np.ndarray, step: float) -> list[Plateaus]:
    """Every axis's plateaus near its largest rate, entered by a step of at least ``step``
    of the level (:func:`strapdown.ahrs._kernel.gyro_plateau_runs`; ``w`` contiguous,
    float64, (n, 3)), as one :class:`Plateaus` per axis."""
    runs, samples, level = np.zeros(3, np.int64), np.zeros(3, np.int64), np.zeros(3)
    K.gyro_plateau_runs(w, NEAR, FLAT, step, MIN_RUN, runs, samples, level)
    return [Plateaus(a, int(runs[a]), float(level[a]), int(samples[a])) for a in range(3)]


def field_plateaus(omega: ArrayLike, mag: ArrayLike, h: float) -> list[Plateaus]:
    """The axes of a gyro record that stop at a level the field shows the body turning
    beyond: a gyro clipped at its range and entered smoothly (a spin-up), which
    :func:`gyro_plateaus` does not take for clipping without a step into the plateau.

    Per axis: the plateaus of :func:`gyro_plateaus` without the entering step (a steady
    spin or turn is such a plateau too; one plateau may do), at a level of at least
    :data:`MIN_LEVEL`, lasting :data:`FIELD_MIN_S` s in all. At that level,
    :func:`declip` recovers the rates ``ω̂_a`` of the samples at it (at least
    :data:`FIELD_MIN_S` s of them); the field's turn over them against the reading,
    ``Σ sign(ω_a) ω̂_a / Σ |ω_a|``, must be at least :data:`FIELD_RATIO`. The signed sum
    telescopes, and the field's noise averages out of it where a sum of magnitudes would
    not. ``mag`` at the gyro's stamps, ``h`` the period. Empty when none does."""
    w = np.ascontiguousarray(omega, dtype=np.float64)
    m = np.asarray(mag, dtype=np.float64)
    if w.ndim != 2 or w.shape[1] != 3 or m.shape != w.shape:
        raise ValueError(f"omega and mag must have the same shape (n, 3), got {w.shape} and "
                         f"{m.shape}")
    found = []
    for p in _plateaus(w, 0.0):
        if not (p.runs >= 1 and p.level >= MIN_LEVEL and p.samples * h >= FIELD_MIN_S):
            continue
        g, done = declip(w, m, p.level, h)
        sel = done[:, p.axis]
        if sel.sum() * h < FIELD_MIN_S:
            continue
        turn = float(np.sum(np.sign(w[sel, p.axis]) * g[sel, p.axis]))
        if turn >= FIELD_RATIO * float(np.sum(np.abs(w[sel, p.axis]))):
            found.append(p)
    return found


def gyro_range(found: list[Plateaus]) -> float:
    """The range a record's gyro clips at: the lowest level among the axes ``found``
    (:func:`gyro_plateaus`; one range for all three axes, as a MEMS gyro's full scale
    is), 0 when none is."""
    return min((p.level for p in found), default=0.0)


def clipped(omega: ArrayLike, level: float) -> np.ndarray:
    """The samples of ``omega`` (rad/s, shape (n, 3)) at a gyro range ``level`` (rad/s):
    an axis's rate at :data:`~strapdown.ahrs._kernel.CLIP_NEAR` (0.98) of it or beyond, as
    :func:`~strapdown.ahrs.ekf`'s kernel takes them. Boolean, shape (n,); all False when
    ``level`` is 0 or infinite (no range known)."""
    w = np.asarray(omega, dtype=np.float64)
    if not 0.0 < level < np.inf:
        return np.zeros(w.shape[0], dtype=bool)
    return np.any(np.abs(w) >= K.CLIP_NEAR * level, axis=1)


def declip(omega: ArrayLike, mag: ArrayLike, level: float, h: float) -> tuple[np.ndarray,
                                                                            np.ndarray]:
    """The rate beyond a gyro's range, taken from the magnetometer: the clipped axes'
    readings replaced by the rates the field's turn shows.

    A field constant in the reference frame turns in the body frame. Over sample ``k``'s
    period (the gyro's interval sample: its mean rate from ``t_{k−1}`` to ``t_k``), a turn by
    θ about the unit axis ``n`` takes ``m_{k−1}`` to ``m_k`` with, exactly (the Cayley form
    of the rotation), ``−Δm/h = c × m̄``: ``Δm = m_k − m_{k−1}``, ``m̄ = (m_k + m_{k−1})/2``
    and ``c = (2/h) tan(θ/2) n``, the rate ``ω = (θ/h) n`` stretched by ``tan(θ/2)/(θ/2)``.
    With the unclipped axes' readings in ``c`` (stretched by less than 0.2 % below 0.15 rad
    a sample), the clipped axes' part ``u`` of ``c`` solves ``Σ_s u_s (e_s × m̄) = −Δm/h −
    ω_⊥ × m̄`` in the least-squares sense (one axis: ``u = (e_a × m̄)·r / |e_a × m̄|²``; two:
    their 2 × 2 normal equations); the rates taken are ``u`` shrunk back,
    ``ω_s = u_s atan(|c| h/2) / (|c| h/2)``: exact for a turn about a clipped axis alone, up
    to nearly π/h (the test below applies to ``m̄``, whose part across the axis shrinks by
    cos(θ/2): near π/h a sample is left as read). The sum over a run of samples telescopes
    to the field's first and last samples there, so the field's noise does not accumulate
    into the attitude (to second order in the field's norm).

    Taken on samples ``k ≥ 1`` where one or two axes are at the range (``|ω_s| ≥``
    :data:`~strapdown.ahrs._kernel.CLIP_NEAR` ``level``, as :func:`clipped`). Both field
    samples must be finite and fresh: a sample equal to the one before was held (a
    magnetometer slower than the gyro), carries no turn and makes the next carry two
    periods', so both are skipped — the field must be sampled at the gyro's rate (held at
    half of it, nothing is recovered; interpolated, its turn is spread over the held
    period). The field must tell the clipped axes' rates apart: the normal equations'
    determinant at least ``DECLIP_ACROSS²`` times ``|m̄|²`` per axis — one axis, the
    field's part across it at least :data:`DECLIP_ACROSS` of its norm; two, its part along
    the third axis. A turn about the field itself is invisible to it, so three clipped axes
    are kept as read, as is every other sample. Units of the field cancel. The field must
    be calibrated and undisturbed where it is used: a hard-iron offset ``b`` scales the rate
    taken, sample by sample, by between ``1/(1 + β)`` and ``1/(1 − β)`` (β: ``b``'s part
    across the axis over the field's), about 1 over whole turns; a disturbance's own turn
    is read as the body's.

    Parameters
    ----------
    omega : array_like, shape (n, 3)
        Gyro rates, rad/s (interval samples).
    mag : array_like, shape (n, 3)
        The field at the same stamps, any units.
    level : float
        The gyro's range, rad/s (0 or infinite: none; nothing is replaced).
    h : float
        The sample period, s.

    Returns
    -------
    omega : ndarray, shape (n, 3)
        The rates with the recovered samples replaced (a copy).
    recovered : ndarray of bool, shape (n, 3)
        Which readings were replaced.
    """
    w = np.array(omega, dtype=np.float64)
    m = np.asarray(mag, dtype=np.float64)
    if w.ndim != 2 or w.shape[1] != 3 or m.shape != w.shape:
        raise ValueError(f"omega and mag must have the same shape (n, 3), got {w.shape} and "
                         f"{m.shape}")
    out = np.zeros(w.shape, dtype=bool)
    if not 0.0 < level < np.inf or w.shape[0] < 2:
        return w, out
    near = np.abs(w) >= K.CLIP_NEAR * level
    n_near = near.sum(axis=1)
    use = (n_near == 1) | (n_near == 2)
    use[0] = False
    use[1:] &= np.all(np.isfinite(m[1:]), axis=1) & np.all(np.isfinite(m[:-1]), axis=1)
    # a field sample equal to the one before was held, not read again: it carries no turn,
    # and the next fresh one carries two periods' (a magnetometer slower than the gyro)
    held = np.zeros(w.shape[0], dtype=bool)
    held[1:] = np.all(m[1:] == m[:-1], axis=1)
    use[1:] &= ~held[1:] & ~held[:-1]
    rows = np.flatnonzero(use)
    if rows.size == 0:
        return w, out
    nr = near[rows]
    mb = 0.5 * (m[rows] + m[rows - 1])
    c = np.where(nr, 0.0, w[rows])  # the unclipped axes' readings; then the Cayley vector
    r = -(m[rows] - m[rows - 1]) / h - np.cross(c, mb)
    mm = np.einsum("ij,ij->i", mb, mb)
    two = nr.sum(axis=1) == 2
    # the clipped axes a (and b): the first (and last) clipped one
    a = np.argmax(nr, axis=1)
    b = 2 - np.argmax(nr[:, ::-1], axis=1)
    ea = np.cross(np.eye(3)[a], mb)
    eb = np.cross(np.eye(3)[b], mb)
    g_aa = np.einsum("ij,ij->i", ea, ea)
    g_ab = np.einsum("ij,ij->i", ea, eb)
    g_bb = np.einsum("ij,ij->i", eb, eb)
    r_a = np.einsum("ij,ij->i", ea, r)
    r_b = np.einsum("ij,ij->i", eb, r)
    det = np.where(two, g_aa * g_bb - g_ab * g_ab, g_aa)
    ok = det >= DECLIP_ACROSS**2 * np.where(two, mm * mm, mm)
    d = np.where(ok, det, 1.0)
    u_a = np.where(two, (g_bb * r_a - g_ab * r_b) / d, r_a / d)
    u_b = np.where(two, (g_aa * r_b - g_ab * r_a) / d, 0.0)
    idx = np.arange(rows.size)
    c[idx, a] = u_a
    c[idx[two], b[two]] = u_b[two]
    x = 0.5 * h * np.linalg.norm(c, axis=1)
    shrink = np.where(x > 0.0, np.arctan(x) / np.where(x > 0.0, x, 1.0), 1.0)
    for ax, u, sel in ((a, u_a, ok), (b, u_b, ok & two)):
        w[rows[sel], ax[sel]] = shrink[sel] * u[sel]
        out[rows[sel], ax[sel]] = True
    return w, out


def warn_if_saturated(omega: ArrayLike, where: str, stacklevel: int = 3,
                      mag: ArrayLike | None = None, h: float | None = None) -> list[Plateaus]:
    """Warn (:class:`GyroSaturationWarning`) about every axis :func:`gyro_plateaus` finds —
    or, when it finds none and a field ``mag`` at the gyro's stamps (period ``h``) is
    given, every axis :func:`field_plateaus` finds — naming ``where`` (the function the
    record went to; ``stacklevel`` as :func:`warnings.warn`'s, counted from here: 3 points
    at the caller of the function that calls this); returns them. ``mag`` given means the
    caller takes the rate beyond the range from it (:func:`declip`), and the warning says
    so."""
    found = gyro_plateaus(omega)
    how = "each entered by a step"
    field = mag is not None and h is not None
    if not found and mag is not None and h is not None:
        found = field_plateaus(omega, mag, h)
        how = f"where the field turns at least {FIELD_RATIO:g} times faster"
    beyond = ("the rotation beyond it is taken from the magnetometer where the field tells "
              "it (AhrsConfig.gyro_declip) and is missing from the attitude elsewhere"
              if field else "the rotation beyond it is missing from the attitude there "
              "(no field to take it from, or AhrsConfig.gyro_declip off)")
    for p in found:
        warnings.warn(
            f"{where}: gyro axis {_AXES[p.axis]} stops at {p.level:.3g} rad/s "
            f"({np.degrees(p.level):.0f} °/s) on {p.samples} samples in {p.runs} plateaus, "
            f"{how}: it looks clipped at its range; {beyond} (a gyro range above the "
            f"motion's rate avoids it)", GyroSaturationWarning, stacklevel=stacklevel)
    return found
