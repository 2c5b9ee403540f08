"""Attitude and heading reference: a multiplicative error-state EKF (Wang, Wang & Wang, eqs. 30–35).

The filter (Wang, Wang & Wang's attitude filter, rebuilt from the paper's text
and made well-posed — docs/reproductions.md says what the paper leaves open —
with the accelerometer and magnetometer handling of Laidig & Seel (2023)):

- **state** ``x = [δθ_b, δb_g]``: attitude error in the body frame
  (``q_true = q̂ ⊗ q(δθ_b)``) and gyro-bias error; with the paper's raw
  accelerometer model also the manoeuvre (non-gravitational) acceleration in the
  body frame as a first-order Gauss–Markov (Singer) process ``ȧ = −a/τ + w``;
  optionally the accelerometer bias ``δb_a`` (``estimate_acc_bias``);
- **propagation** of the attitude by any of the library's algorithms on the
  bias-corrected gyro: ``rate-single``, ``rate-three`` (conventional or
  ``structure=sliding``), ``rk4`` (step 2 td) and ``rotvec:N=…`` (on
  increments formed from the rates by the trapezoid rule); covariance by
  ``Φ = [[exp(−[φ×]), −T I], [0, I]]`` (and ``e^{−T/τ} I`` on the Singer state),
  with a tilt noise proportional to the rotation rate (``tilt_rate_noise``);
- **updates** at every attitude output: a zero-rate update of the bias while
  the sensor is at rest (gyro and accelerometer variance below thresholds);
  the accelerometer — by default the specific force rotated into the reference
  frame through a second-order Butterworth low-pass, whose states follow every
  correction (an almost-inertial frame, Laidig & Seel's), taken as gravity on its
  horizontal axes (without a magnetometer its gain stays off the heading, which then is
  the gyro's alone); or the paper's ``f = C_b_n g_up + a_b`` for every sample — and
  the magnetometer as a heading measurement: the field, rotated with the attitude
  of the magnetometer's delay earlier (estimated online), gives the heading of its
  horizontal part; the innovation variance carries the tilt uncertainty through
  the dip, the gain stays off roll and pitch (magnetic disturbances never reach
  them); sequential, exact for the gain used, then reset;
- **magnetic disturbances** (Laidig & Seel (2023), Sec. 2.5): the field's
  low-passed norm and dip against a reference learned slowly while undisturbed;
  a new field is accepted after ``mag_new_s`` of consistent rotation; a disturbed
  field is rejected for at most ``mag_reject_s`` (a budget that refills while
  undisturbed), then used de-weighted (``mag_disturbed_factor``);
- **gating**: an accelerometer or heading innovation whose NIS exceeds a χ²
  threshold is rejected. Recovery: when innovations keep failing the gate although
  the measurement itself looks clean — the accelerometer quiet (low variance,
  norm g) for ``recover_acc_s``, or an undisturbed field for ``recover_mag_s`` —
  the filter, not the sensor, must be wrong: it inflates the affected covariance
  and accepts again;
- **initial attitude** from the mean accelerometer and magnetometer over
  ``init_window_s`` (TRIAD) when none is given; the reference field (norm, dip,
  heading) is learned there too, unless given. A window that is not still (the rest
  detector's statistics, :func:`start_is_still`) but whose first ``init_still_min_s``
  are — a record that starts moving within the window — starts still over those; one
  that is not still either way is a **start in motion**: the samples
  of its own window (``moving_start_window_s``) are turned into the first sample's body
  frame by the gyro before they are averaged, their motion sets the low-pass model's
  initial motion power, the initial attitude uncertainty is ``moving_start_sigma0``, the
  low-pass accelerometer model waits for its low-pass to settle, the field's reference
  norm and dip follow the measurement for ``moving_start_mag_s`` while the heading
  follows the field's through a low-pass (``moving_start_heading_s``), and gravity's norm is
  learned from the low-passed specific force (within ``acc_scale_tol`` of the nominal
  one, not while the body turns) until the first rest measures it.

:func:`ekf` is causal (one pass, no sample after the estimate's own is used);
:func:`offline_ekf` adds a backward pass and combines the two (Fraser & Potter
(1969)) for post-processing — acausal. Output: one row per input sample, the first
the initial attitude (:class:`AhrsResult`).

Frames: the filter runs in ENU (x east, y north, z up); ``frame="NED"``
returns q_NED_b. Heading is magnetic unless ``declination_deg`` is given.
Without a magnetometer heading is not observed: it is the gyro's integral from
the initial yaw (0 unless ``q0`` is given) and :attr:`AhrsResult.heading_observed`
is False.

The per-sample loop is :func:`strapdown.ahrs._kernel.ekf_kernel` (numba); what
each output did with its measurements is a :class:`strapdown.ahrs.flags.MeasurementFlag`.
"""

from __future__ import annotations

import math
import typing
import warnings
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from strapdown._core.validation import as_quaternions
from strapdown.ahrs import _kernel as K
from strapdown.ahrs.flags import MeasurementFlag
from strapdown.ahrs.saturation import clipped, declip, gyro_range, warn_if_saturated
from strapdown.rotation.quaternion import quat_from_rotvec, quat_multiply

__all__ = ["AccelerometerUnusedWarning", "AhrsConfig", "AhrsResult", "attitude_from_acc_mag",
           "butterworth", "ekf", "offline_ekf", "start_is_still", "window_bias_sigma"]

G = 9.80665
#: The online hard-iron estimate's ridge, a fraction of the trace of its normal matrix: the
#: directions the rotations leave unobserved stay near zero; the observed ones are
#: shrunk by 0.3 % or less (3 × 1e-3 when the three are observed alike; 1e-2 shrank a
#: turning body's offset by 4 %) (``_kernel._hard_iron_span``).
HI_RIDGE = 1e-3
#: The online estimate replaces the offset applied when it has moved from it by more than
#: this fraction of itself (each change learns the field's reference again from one
#: sample; at 0.02 the many changes walked the heading: simulated 1.5 m pendulum with a 30 %
#: offset 0.64× → 1.46× VQF).
HI_UPDATE = 0.2
#: q_NED_ENU: rotation by π about (1, 1, 0)/√2 (swaps x and y, flips z).
Q_NED_ENU = np.array([0.0, math.sqrt(0.5), math.sqrt(0.5), 0.0])
#: :class:`AccelerometerUnusedWarning` is raised when at least this share of the filter
#: epochs skipped the low-pass accelerometer update as implausible (``ACC_DISTURBED``).
ACC_UNUSED_SHARE = 0.5


class AccelerometerUnusedWarning(UserWarning):
    """The low-pass accelerometer model skipped most of its updates because the
    accelerometer's norm disagrees with the gravity the filter assumed, which no rest
    measured (a start in motion that never came to rest) nor learned
    (``AhrsConfig.acc_scale_tol``): the tilt there is the gyro's alone. A norm short of it
    is an accelerometer scale error beyond ``acc_lowpass_norm_tol`` (pass the gravity this
    accelerometer measures as ``AhrsConfig(gravity=...)``); a long one may also be a
    sustained acceleration, which the test is there to skip (a coordinated turn)."""


@dataclass(frozen=True)
class AhrsConfig:
    """Filter tuning (SI units). Defaults work on consumer MEMS IMUs at 100–1000 Hz; the
    defaults marked "(CV)" were chosen by cross-validation on BROAD (Laidig et al.
    (2021); docs/reproductions.md gives the held-out figures); ``tilt_rate_noise`` and
    ``acc_motion_leak`` by the cross-validation across kinds of data (BROAD's groups, the
    simulated scenario kinds with and without magnetometer; ``benchmarks/ahrs_cv_kinds.py``).

    Parameters
    ----------
    gyro_noise : float
        Gyro white-noise density (angle random walk), rad/s/√Hz (CV).
    gyro_bias_rw : float
        Bias random walk, rad/s/√s (CV).
    gyro_bias_sigma0 : float
        Initial bias uncertainty, rad/s. Default 0.01 (0.6 °/s). A still initial window
        (:func:`start_is_still`) measures the bias instead, unless ``gyro_bias0`` is given:
        it starts at the window's mean rate with the uncertainty a rest of that length
        gives the filter, ``rest_noise / √init_window_s`` (when smaller). (A record that
        moves within a second of its start is never at rest for ``rest_min_s``: with
        0.01, the first second of motion taught the bias 2.7 °/s on OpenAXES's
        triangle-150-carpus, 4.6° total error causal against VQF's 0.7°.)
    tilt_rate_noise : float
        Tilt process noise per unit rotation rate, rad/√Hz per rad/s: the gyro's
        scale-factor and misalignment errors make the tilt more uncertain the faster
        the sensor turns, ``Q_tilt = tilt_rate_noise² |ω|² T`` on the two horizontal
        axes (0 switches it off). Default 2.1e-3, chosen with ``acc_motion_leak`` by the
        cross-validation across kinds of data (issue 25); BROAD's alone chose 4.2e-3. A
        logger whose timing is worse than its stamps say — about 50 Hz, samples stamped
        on another clock, a few lost, then placed on a uniform grid — errs in proportion
        to the rate too, and wants 0.005–0.01 (RepoIMU's pendulum: 1.02× → 0.95× VQF
        causal at 0.01, offline 1.00× → 1.01×), at a cost on clean data (the simulated
        pendulums 0.51–0.74× → 1.1×; docs/reproductions.md, "RepoIMU's pendulum").
        :func:`ekf` raises it where the data ask for it (``tilt_adapt_level``).
    tilt_adapt_level, tilt_adapt_s, tilt_adapt_max : float
        The tilt's rate noise adapted to the accelerometer (causal filter only): the
        low-pass model's NIS per second, ``NIS / T`` (each NIS counted at most as the
        gate; with ``R = density²/T`` it does not change with the sample rate), is averaged
        over ``tilt_adapt_s`` (s); above ``tilt_adapt_level`` (1/s) the variance
        ``tilt_rate_noise² |ω|² T`` is multiplied by that average over the level, at most
        ``tilt_adapt_max`` — an innovation-based adaptive process noise (Mohamed & Schwarz
        (1999)). Innovations persistently larger than the model allows mean a tilt off by
        more than its covariance says, which the gyro's errors at speed leave behind (a
        gyro clipped through a flip: 33° missed, inclination 6.4° → 1.7° over the 20 s
        after it, ``tests/ahrs/test_tilt_adapt.py``); the grown variance lets the
        accelerometer correct it, and it grows with the rate only, so a slow body — a
        turning vehicle, whose sustained acceleration raises the power too — keeps its
        tilt. Defaults 5 /s, 1 s, 25 (up to 5 × the rate noise's standard deviation, about
        the 0.01 a fixed value needed on RepoIMU's pendulum): chosen on RepoIMU's pendulum
        (causal 1.018× → 0.986× VQF; the average exceeds 5 /s on 28–95 % of its
        segments' epochs, on BROAD's trials on 0–28 %); held out: RepoIMU's T-stick without
        its test 05, whose gyro is clipped for a thousand samples and every filter is
        40–160° off (1.079× → 1.055×), BROAD unchanged, OpenAXES causal 0.01–0.03° worse
        (median 0.67× / 0.58× → 0.67× / 0.59×), the simulated steel frame 0.86× → 0.91×
        (docs/reproductions.md, "Innovations larger than the model allows").
        :func:`offline_ekf`'s passes do not adapt: there it cost the T-stick (offline
        1.34× → 1.40×) and OpenAXES's inclination (0.95× → 1.01×) and gained nothing on
        RepoIMU. ``math.inf`` as the level switches it off.
    heading_rate_noise : float
        The same for the heading axis, applied while the field is undisturbed. Default
        7e-4 (a third of the tilt's): in BROAD's fast rotations the gyro alone drifted
        0.4 °/s in heading (15° over 35 s at 300–600 °/s, the same for VQF's 6D filter),
        while with 0 the heading's standard deviation stayed at its rest value of 0.4°;
        the field, weighed by that, hardly corrected the drift (trial 08: 5.3° against
        VQF's 3.3°; 2.9° with 7e-4). Not while the field is disturbed: a disturbed field
        used de-weighted after ``mag_reject_s`` would pull a grown heading variance by
        degrees (attached-magnet trials: 1.1× → 1.7× VQF). Not in :func:`offline_ekf`
        (``offline_heading_rate_noise``). Larger values weigh BROAD's field in motion,
        which is itself off by a few degrees there, too much (2.1e-3: causal mean 1.3×
        VQF).
    gyro_scale_sigma : float
        For an **uncalibrated gyro on a body that keeps turning one way** (a spinning
        projectile, a circling vehicle): the standard deviation of the gyro's relative
        scale-factor error per axis (consumer MEMS, untrimmed: about 0.01). A scale error
        ``s`` reads ``(1 + s) ω``; while the rotation is sustained, ``s ω̄`` is a slowly
        varying bias that the bias state can follow if its variance lets it: each epoch the
        bias's variance is raised to at least ``(σ_s ω̄_a)²`` on each axis, ``ω̄`` the
        bias-corrected rate averaged over ``gyro_scale_tau``. An oscillation averages out of
        ``ω̄``: its scale error is a bounded attitude error, not a bias. Default 0 (off):
        with a calibrated gyro the looser bias only follows the field's and the
        accelerometer's errors (BROAD's fifteen trials with 0.01: causal 0.83× → 1.53×
        VQF). On the suite's spinning body with a 1 % scale error (σ of the draw; up to
        8 °/s of heading drift) it holds the heading to 1.6–2.4° causal, 1.8–2.7° offline,
        against 10–15° and 5.6–8.3° without it (seeds 2, 6, 13, 16; VQF 36–52°); with 2 %,
        3.2–4.9° against 21–94°; docs/reproductions.md, "A gyro that is not calibrated".
    gyro_scale_tau : float
        The averaging time of ``ω̄`` for ``gyro_scale_sigma``, s. Default 20, the best of
        5, 20 and 60 s on the suite with 1 % / 0.5 % gyro errors (ten seeds, geometric
        mean of ours / VQF causal over the scenarios: 0.40, 0.39, 0.41): a hand-held or
        swinging rotation averages out (hand-held 1.23× with 5 s, 1.05× with 20 s, as
        without the floor), while a spin-up takes longer to loosen the bias.
    singer_sigma : float
        Raw model: steady-state standard deviation of the manoeuvre acceleration, m/s².
        Default 2.
    singer_tau : float
        Its correlation time, s. Default 0.2.
    acc_noise : float
        Raw accelerometer model (``acc_model="raw"``): measurement noise
        density (white noise plus vibration), m/s²/√Hz. Default 0.03. All
        measurement noises are densities — an update every ``T`` s uses
        ``R = density²/T`` — so the filter does not change with the
        propagation algorithm's update period.
    acc_model : {"lowpass", "raw"}
        ``lowpass`` (default): the specific force rotated into the reference
        frame and low-passed over ``acc_lowpass_s`` is gravity — manoeuvre
        accelerations average out (Laidig & Seel (2023), VQF); 6 states.
        ``raw``: the paper's model, each sample ``f = C_b_n g_up + a_b`` with the
        Singer manoeuvre state ``a_b``; 9 states.
    acc_lowpass_s : float
        Time constant of the second-order Butterworth low-pass (Laidig & Seel's
        τ_acc, cut-off √2/(2πτ)), s (CV).
    acc_lowpass_noise : float
        Noise density of the low-passed horizontal specific force, m/s²/√Hz (CV).
    acc_motion_leak : float
        Fraction κ of the horizontal motion acceleration that the low-pass lets through:
        the low-passed measurement's variance grows by ``κ² τ ā²`` (τ: ``acc_lowpass_s``;
        ``ā²``: the variance over τ — moving mean square less the square of the moving
        mean — of the low-passed reference-frame specific force less a ``MOTION_SLOW`` (4)
        times slower mean of it, horizontal axes; ``_kernel._motion_variance``), so a
        body whose accelerometer never sees gravity alone — a
        swing, a circle, a spin at a lever arm — is weighed by what the data show, and a
        tilt error that a burst of rotation leaves behind, which stays in the mean, is not
        taken for motion (until 2026-12-04 the mean square: docs/reproductions.md). 0
        switches it off. Default 0.25, with ``tilt_rate_noise`` chosen by the
        cross-validation across kinds of data (``benchmarks/ahrs_cv_kinds.py``;
        docs/reproductions.md).
    acc_gate_lowpass : float
        NIS gate of the low-passed measurement (χ², 2 dof, 99.9 %: 13.82).
    acc_lowpass_norm_tol : float
        The low-passed measurement is skipped (``ACC_DISTURBED``) when its norm departs
        from gravity's — as measured over ``init_window_s`` — by more than this fraction:
        a sustained acceleration, such as a coordinated turn's, does not average out
        (a horizontal one of a g lengthens it by ≈ a²/2: 1.5 % at 0.17 g, a 10° bank).
        Default 0.015 — physical, not tuned: BROAD's handheld motions never reach it.
    acc_scale_tol : float
        The accelerometer scale error the low-pass model allows for while no still
        start or rest has measured gravity's norm (a start in motion): the norm is then
        learned as the mean of the low-passed specific force's norm (a running mean, then
        a moving one over ``MOTION_SLOW`` × ``acc_lowpass_s``, 8.4 s), and
        ``acc_lowpass_norm_tol`` is taken about it once the mean spans that time, when it
        lies within this fraction of ``gravity`` — about the nominal otherwise. A swing's
        or a shake's acceleration averages out, a scale error does not; a sustained turn
        lengthens the norm too, so nothing is learned while the averaged rate about the
        vertical is a turn's (``_kernel.LEARN_MAX_TURN`` to ``LEARN_MIN_SPIN``, 0.03–2
        rad/s). Default 0.02, an untrimmed consumer accelerometer's ±1–2 % (RepoIMU's
        pendulum: +0.15, +1.2 and +1.5 % by segment; OpenAXES's robot −3.4 and −4.3 %, beyond
        it, run as with the nominal). 0 switches it off (the nominal g until a rest).
        Measured: docs/reproductions.md ("An accelerometer that is not calibrated, in a
        start in motion").
    acc_gate_mode : {"hard", "soft"}
        Beyond the gate: reject (hard, default) or de-weight (soft, Huber-type).
    lever_arm : float
        Raw model only: distance (m) from the centre of rotation used to widen
        the accelerometer noise by the centripetal and tangential accelerations
        the gyro sees. Default 0.1.
    heading_noise : float
        Magnetometer heading noise density, rad/√Hz (CV; local field distortion
        dominates the sensor noise indoors). The heading update's innovation
        variance also carries the tilt uncertainty times tan(dip), and its gain never
        reaches roll and pitch.
    acc_gate, mag_gate : float
        NIS thresholds: χ² with 3 dof at 99.9 % (16.27) for the raw accelerometer; for
        the heading 4.0 (CV; 1 dof at 95.4 %).
    mag_adapt_s : float
        The field heading's measurement variance adapted to its innovations (both filters,
        and the C export): the heading NIS against the unadapted variance
        (``heading_noise²/T``), each counted at most as the gate (``mag_gate``), is averaged
        over this many seconds — on an undisturbed field, outside recoveries and away from a
        clipped gyro sample (``gyro_clip_s``) — and above 1, a consistent filter's mean, the
        variance is multiplied by that average (an innovation-based adaptive measurement
        noise, Mohamed & Schwarz (1999)); so the factor stays below the gate, and a field
        off by more than the gate's width of the widened variance is still rejected (a
        magnet carried along, whose field the norm and dip tests can miss:
        ``tests/ahrs/test_ahrs.py``; counted up to 16 instead, it was used 30 % of the time
        and turned the heading by 4.7°). At a steep dip the heading measured through the
        attitude carries the tilt's error times tan(dip); where the tilt is worse than its
        covariance says (a swinging body, whose accelerometer never sees gravity alone)
        every innovation looked like a disturbance and the gate rejected a clean field for
        good (RepoIMU's pendulum, dip 72°: 97–100 % of it from the eighth second; the
        offline estimate 1.67× offlineVQF). Near a clipped gyro sample the factor is 1: the
        heading is wrong there with the missed rotation, and the gate keeps it out. Default
        2 s (1, 2, 3 and 5 s compared: RepoIMU's pendulum and the simulated suite do not
        tell them apart, BROAD's causal mean is best at 2 s; docs/reproductions.md); 0
        switches it off.
    mag_norm_tol : float
        The field is disturbed when its (low-passed) norm departs from the reference
        by more than this fraction … Default 0.12, not cross-validated: above the
        lab field's own variation over BROAD's undisturbed trials (−3 % … +11 %,
        5th–95th percentile of the norm's departure from its initial value) and below
        what a magnet attached 4 cm away adds (17–20 %); the folds had learned
        3.5–7 %, which called undisturbed motion disturbed (docs/reproductions.md).
    mag_dip_tol : float
        … or its dip angle by more than this, rad (CV).
    mag_settle_s : float
        The field must stay within the tolerances this long before it is undisturbed
        again, s. Default 0.5 (Laidig & Seel's magMinUndisturbedTime).
    mag_reference_s : float
        Time constant with which the reference norm and dip follow an undisturbed
        field, s. Default 20.
    mag_current_s : float
        Time constant of the low-pass of the field's norm and dip before they are
        compared, s. Default 0.05.
    mag_new_s, mag_new_min_rate : float
        A disturbed field that stays consistent for ``mag_new_s`` seconds of rotation
        faster than ``mag_new_min_rate`` (rad/s) becomes the new reference (a new
        place, not a magnet that turns with the sensor). Defaults 20 s, 0.35 rad/s.
    mag_reject_s : float
        A disturbed field is rejected for at most this many seconds (the budget
        refills ``mag_disturbed_factor`` times faster while undisturbed); beyond it,
        it is used with its noise density scaled by √``mag_disturbed_factor``, the
        innovation gate still rejecting what disagrees with the gyro. Default 10 —
        set from the gyro, not cross-validated: a hand-held consumer gyro alone drifts
        in heading by up to ≈ 0.1 °/s in motion (measured on BROAD, VQF's 6D estimate
        alike), about 1° in 10 s; ``math.inf`` rejects a disturbed field for as long as it
        lasts. (Laidig & Seel's magMaxRejectionTime is 60 s; a
        cross-validated 60 s with a narrow tolerance lost 3.8× to VQF on a held-out
        mild disturbance, docs/reproductions.md.)
    mag_disturbed_factor, mag_disturbed_power : float
        That variance factor, times the squared departure from the reference in
        tolerances (norm or dip, the larger) to this power: a mild disturbance is
        de-weighted, a strong one all but rejected. Defaults 2 (Laidig & Seel's
        magRejectionFactor) and 0; not cross-validated.
    offline_heading_rate_noise : float
        ``heading_rate_noise`` in both passes of :func:`offline_ekf`. Default 2.5e-4,
        about a third of the causal filter's: the smoother bridges a drifting stretch with
        the gyro from both sides, and a heading variance grown as fast as the causal
        filter's weighed the field in motion — off by a few degrees there on BROAD — more
        than the other pass (BROAD offline 1.523° at 2.5e-4, 1.516° at 0, 1.583° at 7e-4);
        with none, the passes' heading did not follow the gyro's slow drift on a fast
        spin, 0.1° over 20 s (the suite's spin-coning offline 1.08× offlineVQF at 0,
        0.89× at 2.5e-4, 0.74× at 7e-4; docs/reproductions.md, "The offline passes'
        heading rate noise"). Except where the gyro outruns that model: when the forward
        pass's gate rejects (or, at the variance before ``mag_adapt_s`` widened it, would
        reject) more than ``HEADING_ESCAPED_SHARE`` (a quarter) of the epochs whose field
        is undisturbed, both passes run again with ``heading_rate_noise``
        (the result's ``config`` says so; an uncalibrated gyro on a sustained spin, 1 %
        scale error at 540 °/s: offline 81–118° → 5.6–8.3°, the causal filter 10–15°,
        offlineVQF 19–28°; BROAD's trials and the calibrated suite never reach it).
    offline_mag_reject_s : float
        The rejection budget of :func:`offline_ekf`'s backward pass, s; may be
        ``math.inf`` (default): there a disturbed field is rejected for as long as it
        lasts. The forward pass has already bridged the stretch with ``mag_reject_s``;
        the backward pass bridges it from the far side on the gyro alone, and the
        two-filter combination weights each by its covariance, which grows with the
        distance from the last clean fix. A backward pass that also used the disturbed
        field after its budget carried an error the combination could not see: on
        BROAD's 2 cm attached-magnet trial the smoothed estimate was 3.85° against
        the forward pass's 1.99° (with ``math.inf``: 1.96°). Not cross-validated;
        chosen on all fifteen trials (docs/reproductions.md).
    offline_smooth_s : float
        The last step of :func:`offline_ekf`: what of the combined attitude varies faster
        than this (s) about the bias-corrected gyro's own path is removed — the
        correction from that path is low-passed forward and backward (second-order
        Butterworth, cut-off √2/(2πτ), zero phase). Over seconds the gyro is the better
        sensor; what moves the estimate off its path at a swing's or a shake's frequency
        is the low-passed accelerometer's residual motion (the causal low-pass's ripple,
        the same in both passes, so the two-filter combination keeps it). Default 4, 0
        switches it off. Chosen on the generalisation suite (seeds 0–2, from 1, 2.1, 4 and
        8 s; error after fitting a constant world and body alignment: pendulums
        1.4–1.6× offlineVQF → 0.3–1.4×), checked held out on BROAD and OpenAXES
        (docs/reproductions.md).
    offline_lowpass_wait : float
        :func:`offline_ekf`'s backward pass starts its low-pass accelerometer model from
        the forward pass's (the low-passed specific force in the reference frame and the
        motion power through it, at the record's end; afresh, averaging, when the record
        ends at rest: the forward pass's low-pass still lags the motion before it, which
        cost the noise-free vehicle's stop 0.42° → 0.63°) and takes no low-pass update for
        its first this many ``acc_lowpass_s`` unless the accelerometer is quiet. Started
        as if its input had been constant, the low-pass answers periodic motion with a
        transient that decays over about its time constant (second-order Butterworth,
        ζ = 1/√2): on the simulated spin-coning, the true reference-frame specific force so
        filtered backwards from the record's end was off gravity by up to 0.8° for 2 s,
        against 0.17° in steady state. Meanwhile the pass holds its tilt on the gyro, its
        covariance grows, and the two-filter combination weighs the forward pass there.
        Default 2, chosen on the generalisation suite (1, 2 or 3; offline spin-coning
        1.42× → 1.09× offlineVQF, twenty seeds), checked held out on BROAD (unchanged:
        its trials end at rest) and OpenAXES (docs/reproductions.md); 0 updates at once.
    offline_hard_iron_min_explained : float
        :func:`offline_ekf` estimates the magnetometer's hard-iron offset from the gyro over
        the whole record (:func:`strapdown.ahrs.hard_iron.hard_iron`) and subtracts it when
        it explains at least this fraction of the field's change that the rotation alone
        does not, the record's two halves agree on it and without it the field's norm is
        markedly steadier (:mod:`strapdown.ahrs.hard_iron`; a value above 1 never subtracts
        it). Default 0.3: on BROAD's calibrated magnetometers the offsets found explain
        0–4 % (subtracted, they made the offline filter worse: 0.81× → 1.43× offlineVQF),
        on its attached-magnet trials 28–43 %, where the halves disagree (the magnet is
        there for part of the trial); on the simulated recordings with an offset of 30 % of
        the field's norm 44–96 % where the body swings, shakes or spins, and the halves
        agree (docs/reproductions.md, "A magnetometer that is not calibrated").
    offline_consistency_gate : float
        :func:`offline_ekf`'s two passes share one model of the gyro: where their tilts
        contradict each other — the NIS of their difference's horizontal part against the
        sum of their covariances (χ², 2 degrees of freedom) above this — that model broke
        there (a gyro past its range, samples lost), and their combination is the mean of
        two wrong estimates. The tilt there is taken from the accelerometer directly, as
        Laidig & Seel's (2023) offline VQF takes it everywhere: the specific force turned
        into the bias-corrected gyro's own path, low-passed forward and backward over
        ``acc_lowpass_s``, is up; the heading is kept; the switch is low-passed too
        (``_direct_tilt``). Default 50 (p ≈ 1e-11 for consistent passes), the smallest of
        13.8, 25, 50 and 100 that left OpenAXES's medians and the simulated suite unchanged
        but for the steel frame (offline 0.54× → 0.69× offlineVQF, seeds 0–5: its
        carrying acceleration at 0.05 Hz, which no low-pass removes, sets the passes apart
        too): RepoIMU's pendulum 1.054× → 1.003× offlineVQF, its T-stick 1.46× → 1.34×
        (a gyro clipped at 7.4 rad/s), BROAD unchanged (docs/reproductions.md, "Where the
        passes contradict each other"). ``math.inf`` switches it off.
    gyro_range : float
        The gyro's range (full scale), rad/s, on every axis: a rate at 0.98 of it or beyond
        is taken as clipped (:func:`strapdown.ahrs.saturation.clipped`). Default 0: found
        from the record — the lowest level of the axes whose plateaus
        :func:`~strapdown.ahrs.saturation.gyro_plateaus` finds
        (:class:`~strapdown.ahrs.saturation.GyroSaturationWarning`), none when it finds
        none; a range is a property of the sensor, so taking it from the whole record does
        not make :func:`ekf` acausal (the C export takes it as given, ``gyro_range`` of
        the config it is generated from). ``math.inf``: never clipped.
    gyro_clip_s : float
        Near a clipped gyro sample the attitude misses the rotation beyond the range, and
        both filters distrust what the gyro carried there. :func:`ekf` (and the C export)
        does not apply the low-pass accelerometer's norm test (``acc_lowpass_norm_tol``)
        for this many seconds after a clipped sample: the low-pass then mixes specific
        forces turned by two attitudes and its norm departs from gravity's without any
        sustained acceleration — it called the accelerometer disturbed and left the tilt
        on the gyro alone for as long as that lasted (RepoIMU's T-stick, test 05: for most
        of each trial). Its limit: a sustained acceleration that coincides with the clip
        (thrust on a body spinning beyond the range) is taken for gravity's direction while
        the test is off. :func:`offline_ekf` takes its tilt from the accelerometer directly
        within this many seconds of every clipped sample, as where its passes contradict
        each other (``offline_consistency_gate``, ``_direct_tilt``): both passes carry the
        missed rotation on — the forward pass after each clip, the backward pass before
        it — so their combination is wrong on both sides before their tilts contradict.
        Default 2.1 s, one ``acc_lowpass_s``, the low-pass's own span (1 and 3 s offline,
        5 s causal, measured within 0.02×); 0 switches both off. Nothing changes where no
        range is known or reached: BROAD, OpenAXES, the suite and RepoIMU's pendulum.
        RepoIMU's T-stick (clipped at 7.4 rad/s in its tests 05 and 10), chosen there:
        causal 1.11× → 1.03× VQF, offline 1.34× → 1.06× offlineVQF (0.99× without test
        05, where every filter is lost); held out, the suite's 0.3 m pendulum read by a
        gyro clipped at 60 % / 80 % of its peak rate: causal 1.35× / 1.75× → 1.02× /
        1.05× VQF, offline 1.31× / 1.26× → 1.00× / 1.03× (docs/reproductions.md, "A gyro
        past its range").
    gyro_declip : bool
        Where one or two axes of the gyro are at its range (``gyro_range``, given or found
        from the record) and the field tells their rates apart — at least 5.7° off a clipped
        axis (``saturation.DECLIP_ACROSS``), off the plane of two, never three — take those
        axes' rates from the field's turn instead (:func:`strapdown.ahrs.saturation.declip`:
        exact for a turn about a clipped axis alone; the field's noise does not accumulate
        over a run of samples); and where the plateaus' steps find no range, find one the
        field shows the body turning beyond (a spin-up past the range:
        :func:`~strapdown.ahrs.saturation.field_plateaus`). Measured: the T-stick's causal
        1.03× → 0.35× VQF, the suite's 0.3 m pendulum clipped at 60 % 1.02× → 0.17×
        (docs/reproductions.md, "The rate beyond the range, from the field"). Done before
        anything else sees the gyro, in :func:`ekf`, :func:`offline_ekf` and the C export
        alike (there with the range given). Default on; nothing changes where no range is
        known or reached, or without a field. The field must be sampled at the gyro's rate
        (a held sample is skipped), calibrated and clean where it is used: a hard-iron
        offset scales the rate taken, and a disturbance's own turn is read as the body's.
    hard_iron_s : float
        :func:`ekf` estimates the magnetometer's hard-iron offset online, the causal form of
        :func:`strapdown.ahrs.hard_iron.hard_iron` (``_kernel._hard_iron_span``): every
        0.1 s the field's change against the gyro's own rotation (the filter's attitude
        without its corrections), ``G m − G_p m_p = (G − G_p) b``, is added to
        least-squares sums that forget with this time constant (s; 0 switches the estimate
        off). Once the estimate has, for ``hard_iron_hold_s``,
        explained at least ``hard_iron_min_explained`` of the field's change that the
        rotation leaves, steadied the field's norm (:data:`~strapdown.ahrs.hard_iron.
        STEADIER_MAX`) and drifted by no more than
        :data:`~strapdown.ahrs.hard_iron.SPREAD_MAX` of itself, it is subtracted from
        every later sample (again when it moves by more than :data:`HI_UPDATE` of itself;
        back to none when it explains less than none); the field's reference norm and dip
        are learned again from the corrected field, and its reference heading is the
        corrected sample's in the filter's own frame, so that the heading does not jump
        (``MeasurementFlag.MAG_OFFSET``); the magnetometer-delay estimator takes the
        corrected field too. Default 30. :func:`offline_ekf` subtracts its own
        whole-record estimate instead (``offline_hard_iron_min_explained``) and runs its
        passes without this one.
    hard_iron_hold_s : float
        See ``hard_iron_s``; s. Default 5.
    hard_iron_min_explained : float
        See ``hard_iron_s``. Default 0.3, as ``offline_hard_iron_min_explained``.
    mag_delay_s : float
        Delay of the magnetometer behind the gyro, s: each field sample is rotated
        with the attitude of that long ago (rounded to whole filter epochs). With
        ``estimate_mag_delay`` the estimator's starting value. Default 0.
    estimate_mag_delay : bool
        Estimate the delay online, causally (default on): the candidate of 0 …
        ``mag_delay_max_s`` whose gyro best explains how the field turns in the body
        frame (``ṁ = −ω × m``), averaged over ``mag_delay_tau_s``.
    mag_delay_max_s, mag_delay_tau_s : float
        Its largest candidate and averaging time, s. Defaults 0.02, 10.
    acc_lowpass_settle : bool
        No low-pass accelerometer update until the low-pass has averaged its first
        ``acc_lowpass_s``, unless the accelerometer is quiet (the rest detector's test)
        (default off; the offline backward pass sets it). During those
        epochs the low-pass output is a running mean of a few samples, which in motion is
        not gravity, while its motion-power term is still zero: a pass started in motion
        from an already-converged estimate (the backward pass, at the record's end) was
        dragged by degrees (spin-coning: 6.9°), and the two-filter combination, trusting
        its small covariance, took it.
    heading_bridge_noise : bool
        While a disturbed field is rejected, the heading's process noise is at least the
        tilt's rate noise, ``tilt_rate_noise² |ω|² T``: the gyro's scale-factor and
        misalignment errors act about the vertical as about the horizontal axes, and with
        the field rejected nothing bounds them (on BROAD's attached-magnet trials the gyro
        alone drifted 14° in heading over a 55 s disturbance while the covariance claimed
        0.56°). Default off; :func:`offline_ekf`'s backward pass sets it: it bridges every
        disturbance on the gyro alone (``offline_mag_reject_s``), and the two-filter
        combination weighs it by this covariance. (On in the causal filter, the grown
        variance made the disturbed field, used de-weighted after ``mag_reject_s``, pull
        the heading by degrees.)
    mag_delay_z : float
        The estimator changes the delay in use only when the best candidate's mean
        residual is lower by ``z`` standard deviations of that difference (estimated as
        for white noise, ``(4/3) z² res_min / N``); otherwise the delay stays. A steady
        spin, whose rate barely changes over the candidates, cannot tell the delays apart,
        and a noise-picked wrong delay turned the field by ω times the error (spin-coning:
        1.4° heading excursions). Default 0.5 (the white-noise formula overstates the
        spread: the field's differenced noise telescopes over slowly varying rates).
    gyro_sample : {"interval", "point"}
        What a gyro sample is. ``interval`` (default, CV): the mean rate over the sample
        period that ends at its time stamp — what a MEMS IMU's decimation filter
        delivers, and what VQF, Madgwick's filter and Fusion assume when they turn
        each sample over the step that ends at it; the propagation algorithms take
        their samples as points, so their attitude refers to half a period earlier
        and each output is predicted that half period ahead on the bias-corrected gyro
        (causal). ``point``: the rate at the stamp (the library's rate algorithms'
        convention, and an exact simulation's).
    acc_sample : {"interval", "point"}
        What an accelerometer sample is, beside interval gyro samples. ``interval``
        (default): a mean over the sample period, like the gyro's — an IMU whose gyro and
        accelerometer pass the same decimation filter — so it refers to the middle of the
        period, where the filter's attitude refers. ``point``: the specific force at the
        stamp (an exact simulation's, VQF's convention): each sample is turned back half a
        period to the middle of the period (``_kernel._at_state_time``), as a
        ``mag_sample="point"`` field is. The wrong convention misplaces gravity by half a
        period of rotation: on the generalisation suite's noise-free ``rests`` (50 Hz,
        quintic turns at up to 84 °/s, point samples) the default's inclination RMSE is
        0.10° (0.2° after each turn, decaying over the low-pass's seconds), 0.002° with
        ``point`` [m]. With the suite's sensor errors the convention moves the ratios to VQF
        by at most 0.03 (geometric means over five seeds; rests 1.05× → 1.02×). Real
        recordings lean to ``interval`` or cannot tell: BROAD's mean total 1.720° causal
        against 1.750° with ``point`` (fast-rotation trial 08: 2.90° against 3.14°),
        OpenAXES's causal median 0.530° against 0.518°.
    mag_sample : {"point", "interval"}
        What a magnetometer sample is, beside interval gyro samples. ``point``
        (default): the field at the stamp — a magnetometer is read at an instant, without
        the IMU's decimation filter — so each sample is turned back half a period to the
        middle of the period, where the filter's attitude refers (on a body spinning at
        9.4 rad/s sampled at 400 Hz that half period is 0.67° of heading; in the
        generalisation suite's spin-coning recording it took the causal total error from
        0.31° to 0.28° with a fixed delay, 0.35° to 0.25° with the estimated one [m]).
        ``interval``: a mean over the period, like the gyro's.
    latency_s : float
        A further latency of the IMU's samples behind the motion they measure (its
        internal filters' group delay), s: each output attitude is predicted that far
        ahead too. Causal. Default 0.
    acc_norm_tol : float
        Raw model only: skip the accelerometer when its norm departs from g by
        more than this fraction (sustained manoeuvres, impacts). Default 0.25.
    recover_acc_s, recover_mag_s : float
        Seconds of consecutive NIS rejections of clean-looking measurements
        (accelerometer quiet; field undisturbed) after which the covariance is
        inflated by ``recover_angle`` and measurements are accepted again. Defaults
        2 s and 20 s. The field's 20 s equal ``mag_new_s``: a field that contradicts the
        gyro is not taken as the truth by recovery sooner than a changed field is by the
        new-reference rule (with 10 s, a body-fixed 19 µT anomaly that looked
        undisturbed at some orientations was accepted after 10 s and turned the heading
        22°). The causal filter never recovers on BROAD's fifteen trials with either
        value, so they do not inform it.
    recover_angle : float
        Standard deviation added on recovery, rad. Default 0.1.
    rest_gyro, rest_acc : float
        Rest when the gyro's standard deviation over ``rest_tau`` is below
        ``rest_gyro`` (rad/s), its mean below ``rest_gyro_mean``, and the
        accelerometer's standard deviation below ``rest_acc`` (m/s²), its mean's norm
        within ``rest_acc`` of gravity as the accelerometer measured it over the initial
        window (CV). (Against the nominal 9.80665 m/s², an accelerometer reading 3.7 %
        low — the OpenAXES sensors — was never at rest, and its gyro bias was learned in
        motion only: median total error 3.6° against 1.7° on those recordings [m].)
    rest_gyro_mean : float
        The largest gyro mean that can be a bias at rest, rad/s. Default 0.035 (2 °/s,
        Laidig & Seel's biasClip): a slow steady rotation is not rest.
    rest_min_s : float
        Zero-rate updates start once rest has been detected this long, s (Laidig &
        Seel's restMinT): one quiet sample at the start of a motion is not rest.
    rest_noise : float
        Noise density of the zero-rate bias measurement, rad/s/√Hz. Default 1.2e-4.
    rest_tau : float
        Averaging time of the rest detector, s. Default 0.5.
    estimate_acc_bias : bool
        Add the accelerometer bias to the state (+3 states). Off by default:
        it is observable only through attitude changes, and a consumer IMU's
        factory calibration usually leaves less than the filter can resolve.
    acc_bias_sigma0 : float
        Its initial uncertainty, m/s². Default 0.1.
    acc_bias_rw : float
        Its random walk, m/s²/√s. Default 1e-4.
    gating : bool
        Innovation gating and magnetic-disturbance handling (default on).
    rest_update : bool
        Zero-rate bias updates at rest (default on).
    use_accelerometer, use_magnetometer : bool
        Switch the aiding off (the magnetometer is off anyway without data).
    init_window_s : float
        Averaging window for the initial attitude and the reference field, s.
    init_still_min_s : float
        A start whose ``init_window_s`` is not still but whose first this many seconds are
        (a record that starts moving within the window: a pendulum released, a robot set
        going, a logger started just before the motion) starts still over those: their
        means give the initial attitude, gravity's norm and the gyro bias, as a still
        window's do. Default 0.25 (half the window); a value at or above
        ``init_window_s`` switches it off. Without it such a start was a start in motion,
        whose attitude averages a second of the motion: RepoIMU's pendulum segments, which
        start moving 0.25–0.5 s after their first sample, ended 1.57–1.72× VQF's error on
        five of eleven (causal mean 1.069× → 1.018×); OpenAXES's two circles at speed 150
        (causal 0.85× / 0.76× → 0.62× / 0.50×), held out (docs/reproductions.md, "A
        still start shorter than the window").
    attitude_sigma0 : float
        Initial attitude uncertainty, rad. Default 0.05.
    moving_start_sigma0 : float
        Initial attitude uncertainty when the initial window is not still (a start in
        motion, :func:`start_is_still`), rad, every axis. The window's mean specific force
        then holds the motion's mean acceleration, ``Δv/T`` over the window (a swing's
        metres per second over half a second: tens of degrees of tilt, and through the
        field's dip more of heading). Default 0.3. With 0.05 every later measurement
        failed the gates: simulated records cut in motion ended 12–350 times VQF's error.
    moving_start_window_s : float
        The window over which a start in motion averages its specific force and field,
        turned into the first sample's frame by the gyro, for the initial attitude, s
        (whether the start is still is decided over ``init_window_s``). What its mean has
        not averaged out also sets the low-pass model's initial motion power (``ā²`` of
        ``acc_motion_leak``; ``_start_motion_power``: the change of the mean from the
        window's first half to its second), so the first low-passed measurements of a start
        in motion are weighed by the motion the window showed instead of as if it were
        still. The mean's error is the motion's ``Δv/T``: a 70° swing of a 0.3 m pendulum
        (period 1.1 s) moved the half-second window's mean by tens of degrees. Default 1
        (0.5, 1 and 2 s compared on the simulated records and BROAD's trials cut in
        motion: BROAD 1.30× / 1.15× / 1.17× VQF; the 0.3 m pendulum needs 1 s, the 0.8 m
        one loses at 2 s; docs/reproductions.md).
    moving_start_mag_s : float
        After a start in motion, the magnetometer's reference norm and dip follow the
        measurement for this long, s: the dip is measured with the estimated tilt, wrong
        at such a start, and a reference learned from it called the true field
        disturbed and kept the heading from converging. Default 5.
    moving_start_heading_s : float
        Meanwhile the heading is recovered at every epoch, its variance grown by
        ``heading_noise² T / τ²`` against the field's ``heading_noise² / T``, so that it
        follows the field's heading as a first-order low-pass of this time constant τ, s
        (the gain per epoch is about T/τ whatever the sample rate): the heading measured at
        such a start is wrong with the start's tilt, through the field's dip, until the
        accelerometer has corrected it, and a swinging body's field swings with it.
        Default 0.4; ``math.inf``: no growth (a running mean). Before, the variance grew by
        1 rad²/s, a time constant of 13 ms: the heading followed each sample and ended the
        phase where the field's swing put it (RepoIMU's pendulum: −40° against VQF's −2°
        on one start). Chosen from 0.013, 0.4, 1, 2 s and ∞ on BROAD's trials and the
        simulated suite cut in motion, calibrated and not (docs/reproductions.md); 0.4 s
        keeps the 0.3 m pendulum's start (whose tilt converges last) at 0.39× VQF.
    declination_deg : float
        Magnetic declination (east positive); 0 gives a magnetic-north heading.
    gravity : float
        m/s². Default 9.80665.
    """

    gyro_noise: float = 1.4e-3
    gyro_bias_rw: float = 2.5e-6
    gyro_bias_sigma0: float = 0.01
    tilt_rate_noise: float = 2.1e-3
    tilt_adapt_level: float = 5.0
    tilt_adapt_s: float = 1.0
    tilt_adapt_max: float = 25.0
    heading_rate_noise: float = 7e-4
    gyro_scale_sigma: float = 0.0
    gyro_scale_tau: float = 20.0
    singer_sigma: float = 2.0
    singer_tau: float = 0.2
    acc_noise: float = 0.03
    heading_noise: float = 0.0126
    acc_gate: float = 16.27
    mag_gate: float = 4.0
    mag_adapt_s: float = 2.0
    mag_norm_tol: float = 0.12
    mag_dip_tol: float = 0.12215
    acc_model: str = "lowpass"
    acc_lowpass_s: float = 2.1
    acc_lowpass_noise: float = 0.0252
    acc_gate_lowpass: float = 13.82
    acc_motion_leak: float = 0.25
    acc_lowpass_norm_tol: float = 0.015
    acc_scale_tol: float = 0.02
    acc_gate_mode: str = "hard"
    lever_arm: float = 0.1
    acc_norm_tol: float = 0.25
    mag_settle_s: float = 0.5
    mag_reference_s: float = 20.0
    mag_current_s: float = 0.05
    mag_new_s: float = 20.0
    mag_new_min_rate: float = 0.349
    mag_reject_s: float = 10.0
    mag_disturbed_factor: float = 2.0
    mag_disturbed_power: float = 0.0
    offline_heading_rate_noise: float = 2.5e-4
    offline_mag_reject_s: float = math.inf
    offline_smooth_s: float = 4.0
    offline_lowpass_wait: float = 2.0
    offline_hard_iron_min_explained: float = 0.3
    offline_consistency_gate: float = 50.0
    gyro_range: float = 0.0
    gyro_clip_s: float = 2.1
    gyro_declip: bool = True
    hard_iron_s: float = 30.0
    hard_iron_hold_s: float = 5.0
    hard_iron_min_explained: float = 0.3
    mag_delay_s: float = 0.0
    estimate_mag_delay: bool = True
    mag_delay_max_s: float = 0.02
    mag_delay_tau_s: float = 10.0
    mag_delay_z: float = 0.5
    acc_lowpass_settle: bool = False
    heading_bridge_noise: bool = False
    gyro_sample: str = "interval"
    acc_sample: str = "interval"
    mag_sample: str = "point"
    latency_s: float = 0.0
    recover_acc_s: float = 2.0
    recover_mag_s: float = 20.0
    recover_angle: float = 0.1
    rest_gyro: float = 0.04
    rest_gyro_mean: float = 0.035
    rest_min_s: float = 0.5
    rest_acc: float = 0.28
    rest_noise: float = 1.2e-4
    rest_tau: float = 0.5
    estimate_acc_bias: bool = False
    acc_bias_sigma0: float = 0.1
    acc_bias_rw: float = 1e-4
    gating: bool = True
    rest_update: bool = True
    use_accelerometer: bool = True
    use_magnetometer: bool = True
    init_window_s: float = 0.5
    init_still_min_s: float = 0.25
    attitude_sigma0: float = 0.05
    moving_start_sigma0: float = 0.3
    moving_start_mag_s: float = 5.0
    moving_start_heading_s: float = 0.4
    moving_start_window_s: float = 1.0
    declination_deg: float = 0.0
    gravity: float = G

    def __post_init__(self):
        if self.acc_model not in ("lowpass", "raw"):
            raise ValueError(f"AhrsConfig.acc_model must be 'lowpass' or 'raw', got "
                             f"{self.acc_model!r}")
        if self.gyro_sample not in ("interval", "point"):
            raise ValueError(f"AhrsConfig.gyro_sample must be 'interval' or 'point', got "
                             f"{self.gyro_sample!r}")
        if self.acc_sample not in ("interval", "point"):
            raise ValueError(f"AhrsConfig.acc_sample must be 'interval' or 'point', got "
                             f"{self.acc_sample!r}")
        if self.mag_sample not in ("interval", "point"):
            raise ValueError(f"AhrsConfig.mag_sample must be 'interval' or 'point', got "
                             f"{self.mag_sample!r}")
        if self.acc_gate_mode not in ("soft", "hard"):
            raise ValueError(f"AhrsConfig.acc_gate_mode must be 'soft' or 'hard', got "
                             f"{self.acc_gate_mode!r}")
        for name, v in asdict(self).items():
            if isinstance(v, (bool, str)):
                continue
            if not math.isfinite(v) and not (name in _MAY_BE_INFINITE and v == math.inf):
                raise ValueError(f"AhrsConfig.{name} must be finite, got {v!r}")
            if name in _ANY_SIGN:
                continue
            if name in _NON_NEGATIVE:
                if not v >= 0:
                    raise ValueError(f"AhrsConfig.{name} must be ≥ 0, got {v!r}")
            elif not v > 0:
                raise ValueError(f"AhrsConfig.{name} must be positive, got {v!r}")
        if self.tilt_adapt_max < 1:
            raise ValueError(f"AhrsConfig.tilt_adapt_max must be ≥ 1, got "
                             f"{self.tilt_adapt_max!r}")
        if self.mag_disturbed_factor < 1:
            raise ValueError(f"AhrsConfig.mag_disturbed_factor must be ≥ 1, got "
                             f"{self.mag_disturbed_factor!r}")


#: AhrsConfig fields that may be +∞, negative, or zero.
_MAY_BE_INFINITE = ("mag_reject_s", "offline_mag_reject_s", "moving_start_heading_s",
                    "offline_consistency_gate", "tilt_adapt_level", "gyro_range")
_ANY_SIGN = ("declination_deg",)
_NON_NEGATIVE = ("lever_arm", "acc_motion_leak", "tilt_rate_noise", "heading_rate_noise",
                 "gyro_scale_sigma", "offline_heading_rate_noise", "offline_smooth_s",
                 "offline_lowpass_wait", "gyro_range", "gyro_clip_s", "mag_adapt_s",
                 "mag_reject_s", "rest_min_s", "mag_delay_s", "latency_s", "mag_delay_max_s",
                 "mag_disturbed_power", "offline_mag_reject_s", "mag_delay_z", "hard_iron_s",
                 "hard_iron_hold_s", "hard_iron_min_explained", "acc_scale_tol")


@dataclass(frozen=True)
class AhrsResult:
    """Filter output: one row per input sample.

    Row 0 is the initial state at the first time stamp (the initial attitude, bias
    and covariance). A row where a filter epoch ended (:attr:`epoch`) holds the
    estimate after that epoch's propagation and measurement updates; with an
    algorithm whose update period spans several samples (``rate-three``, ``rk4``,
    ``rotvec:N≥2``) the rows in between — and after the last epoch — hold the
    attitude propagated from the last epoch by single-period steps on the
    bias-corrected gyro (output only, causal: the filter state is not changed),
    its bias and covariance held.

    Attributes
    ----------
    t : ndarray (n,)
        The input time stamps (s).
    index : ndarray (n,)
        Sample index of each row (``arange(n)``).
    epoch : ndarray (n,) of bool
        True where a filter epoch ended at this sample.
    q : ndarray (n, 4)
        q_n_b in :attr:`frame`.
    frame : {"ENU", "NED"}
    heading_observed : bool
        False without a magnetometer (heading is the gyro's integral).
    gyro_bias : ndarray (n, 3)
        Estimated gyro bias, rad/s.
    accel : ndarray (n, 3)
        Estimated manoeuvre acceleration in the body frame, m/s².
    flags : ndarray (n,) of int
        Bitwise or of :class:`~strapdown.ahrs.flags.MeasurementFlag` per row (0 where
        no epoch ended).
    nis : ndarray (n, 2)
        Accelerometer and heading NIS (NaN where there was no update).
    attitude_sigma : ndarray (n, 3)
        Standard deviation of δθ_b, rad.
    algorithm : str
    acc_bias : ndarray (n, 3) or None
        Estimated accelerometer bias, m/s² (with ``estimate_acc_bias``).
    mag_delay_s : ndarray (n,) or None
        The magnetometer delay in use at each row, s (estimated online with
        ``estimate_mag_delay``); None without a magnetometer.
    smoothed : bool
        True for :func:`offline_ekf`'s output: acausal, every row uses the whole record.
    start_still : bool
        The record started still — its initial window, or that window's first
        ``init_still_min_s`` (:func:`start_is_still`); False: the filter started in
        motion (see the module docstring).
    mag_offset : ndarray (3,) or None
        The hard-iron offset subtracted from the field (body frame, the field's unit): by
        :func:`offline_ekf`, its whole-record estimate
        (``AhrsConfig.offline_hard_iron_min_explained``); by :func:`ekf`, the online
        estimate's at the end (``AhrsConfig.hard_iron_s``; the flag
        ``MeasurementFlag.MAG_OFFSET`` marks the samples where it changed). None when none
        was.
    gyro_clipped, gyro_recovered : int
        The gyro samples at its range (``AhrsConfig.gyro_range``, given or found; 0 when
        none is known), and how many of them had their clipped rates taken from the field
        (``AhrsConfig.gyro_declip``).
    """

    t: np.ndarray
    index: np.ndarray
    epoch: np.ndarray
    q: np.ndarray
    frame: str
    heading_observed: bool
    gyro_bias: np.ndarray
    accel: np.ndarray
    flags: np.ndarray
    nis: np.ndarray
    attitude_sigma: np.ndarray
    algorithm: str
    config: AhrsConfig = field(repr=False, default_factory=AhrsConfig)
    acc_bias: np.ndarray | None = None
    mag_delay_s: np.ndarray | None = None
    smoothed: bool = False
    start_still: bool = True
    mag_offset: np.ndarray | None = None
    gyro_clipped: int = 0
    gyro_recovered: int = 0

    def __post_init__(self):
        n = self.t.shape[0]
        for name in ("index", "epoch", "q", "gyro_bias", "accel", "flags", "nis",
                     "attitude_sigma", "acc_bias", "mag_delay_s"):
            a = getattr(self, name)
            if a is not None and a.shape[0] != n:
                raise ValueError(f"AhrsResult.{name} has {a.shape[0]} rows, t has {n}: one "
                                 "row per sample")

    def fraction(self, flag: MeasurementFlag | int) -> float:
        """Share of filter epochs with any of ``flag``'s bits set (NaN without epochs), e.g.
        ``result.fraction(MeasurementFlag.MAG_USED)``."""
        f = self.flags[self.epoch]
        return float(np.mean((f & flag) != 0)) if f.size else math.nan


def attitude_from_acc_mag(acc, mag=None, *, declination_deg: float = 0.0) -> np.ndarray:
    """q_ENU_b from one specific-force vector (and a magnetic field vector), by TRIAD.

    Up is the specific force at rest; north is the field's horizontal part
    rotated by the declination. Without ``mag`` the yaw is zero (x_b's
    horizontal projection points east).
    """
    from strapdown._core.scaling import pow2_exponent

    f = np.asarray(acc, float)
    if f.shape != (3,) or not np.all(np.isfinite(f)) or not np.any(f):
        raise ValueError(f"acc must be a finite non-zero (3,) vector, got {f!r}")
    # only directions are used: scaling by 2^-e (exact) keeps norms in range for any input
    f = np.ldexp(f, -pow2_exponent(f))
    up = f / np.linalg.norm(f)
    if mag is None:
        ref = np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        east = ref - up * (ref @ up)
        east /= np.linalg.norm(east)
        north = np.cross(up, east)
    else:
        m = np.asarray(mag, float)
        if m.shape != (3,) or not np.all(np.isfinite(m)):
            raise ValueError(f"mag must be a finite (3,) vector, got {m!r}")
        m = np.ldexp(m, -pow2_exponent(m))
        mh = m - up * (m @ up)
        if np.linalg.norm(mh) < 1e-6 * max(float(np.linalg.norm(m)), 1e-300):
            raise ValueError("the magnetic field is vertical: heading is undefined")
        mnorth = mh / np.linalg.norm(mh)
        d = math.radians(declination_deg)
        east_m = np.cross(mnorth, up)
        north = math.cos(d) * mnorth - math.sin(d) * east_m
        east = np.cross(north, up)
    c_b_n = np.column_stack([east, north, up])  # columns: reference axes in body
    from strapdown.rotation.dcm import quat_from_dcm

    return quat_from_dcm(c_b_n.T)


def _algorithm(spec: str):
    """Kernel arguments for a propagation algorithm spec (see AlgorithmSpec.propagation)."""
    from strapdown.algorithms.spec import AlgorithmSpec

    return AlgorithmSpec.parse(spec).propagation()


def _check(name, a, n):
    a = np.ascontiguousarray(a, dtype=np.float64)
    if a.shape != (n, 3):
        raise ValueError(f"{name} must have shape ({n}, 3) to match the gyro, got {a.shape}")
    if not np.isfinite(a).all():
        bad = ~np.all(np.isfinite(a), axis=1)
        raise ValueError(f"{name} has NaN or infinity in row {int(np.argmax(bad))}")
    return a


def _validate(t, gyro, acc, mag, cfg: AhrsConfig, frame: str):
    """The record checked: (rate record, acc, mag — zeros when absent —, heading observed).

    Raises ValueError naming the problem: the frame, the time stamps and gyro
    (:func:`strapdown.algorithms.rate.check_rate_record`), the shapes, a NaN's
    row, an accelerometer not in m/s² of specific force, a magnetometer reading zero.
    """
    from strapdown.algorithms.rate import check_rate_record

    if frame not in ("ENU", "NED"):
        raise ValueError(f"frame must be 'ENU' or 'NED', got {frame!r}")
    rec = check_rate_record(t, gyro, min_samples=4)
    n = rec.t.size
    acc = _check("acc", acc, n)
    have_mag = mag is not None and cfg.use_magnetometer
    mag = _check("mag", mag, n) if mag is not None else np.zeros((n, 3))
    a_norm = np.median(np.linalg.norm(acc, axis=1))
    if not 0.5 * cfg.gravity < a_norm < 2.0 * cfg.gravity:
        raise ValueError(f"the accelerometer's median norm is {a_norm:.4g}; expected about "
                         f"{cfg.gravity} m/s² (is it in g, or not specific force?)")
    if have_mag and np.median(np.linalg.norm(mag, axis=1)) == 0:
        raise ValueError("the magnetometer reads zero; pass mag=None for no heading")
    return rec, acc, mag, have_mag


def _window_samples(seconds: float, td: float) -> int:
    """A start's window of ``seconds`` in samples ``td`` apart, at least 2 — here and in the
    C export (:mod:`strapdown.codegen.ahrs_c`), which buffers it."""
    return max(2, round(seconds / td))


def _init_window(rec, cfg: AhrsConfig) -> int:
    """Samples of the initial window (at least 2, at most the record)."""
    return min(rec.t.size, _window_samples(cfg.init_window_s, rec.td))


def _moving_window(rec, cfg: AhrsConfig) -> int:
    """Samples of a start in motion's window (``moving_start_window_s``; at least 2, at
    most the record)."""
    return min(rec.t.size, _window_samples(cfg.moving_start_window_s, rec.td))


def _start_motion_power(rec, acc, cfg: AhrsConfig, path=None) -> float:
    """A start in motion's initial motion power for the low-pass model (``_kernel``'s
    ``dyn2``, m²/s⁴): over ``moving_start_window_s``, the specific force turned into the
    first sample's frame; the change of its mean from the window's first half to its second,
    across the whole mean's direction, squared — what the window's mean has not averaged
    out, the error the low-pass's first output (a running mean over ``acc_lowpass_s``)
    starts with. A fast rotation's or a shake's acceleration, which averages out within
    each half, adds little (the raw mean square across the mean took a hand-held 600 °/s
    rotation's lever-arm acceleration for motion and cost BROAD's trial 07 cut in motion
    0.96× → 3.05× VQF). The kernel's moving mean square then forgets it with time
    constant ``acc_lowpass_s``. 0 when the mean is zero. ``path``: the gyro's path over
    that window (:func:`_window_path`), when already computed."""
    a = _derotated(rec, acc, _moving_window(rec, cfg), path=path)
    m = a.mean(axis=0)
    n = float(np.linalg.norm(m))
    if not n > 0.0:
        return 0.0
    u = m / n
    k = a.shape[0] // 2
    d = a[k:].mean(axis=0) - a[:k].mean(axis=0)
    return max(0.0, float(d @ d - (d @ u) ** 2))


def start_is_still(t, gyro, acc, config: AhrsConfig | None = None) -> bool:
    """Whether a record starts still, as the filter decides it: its initial window
    (``init_window_s``), or else the window's first ``init_still_min_s``, passes the rest
    detector's statistics — the gyro's variance (summed over the axes) below
    ``rest_gyro²``, its mean's norm below ``rest_gyro_mean`` and the accelerometer's
    variance below ``rest_acc²`` (gravity's norm is not known yet, so it is not tested).
    Otherwise the filter starts in motion (see the module docstring). Arguments as for
    :func:`ekf`."""
    cfg = config or AhrsConfig()
    rec = _validate(t, gyro, acc, None, cfg, "ENU")[0]
    return _still_window(rec, np.ascontiguousarray(acc, dtype=np.float64), cfg) > 0


def _still_min_window(rec, cfg: AhrsConfig) -> int:
    """Samples of ``init_still_min_s`` (at least 2, at most the initial window)."""
    return min(_init_window(rec, cfg), _window_samples(cfg.init_still_min_s, rec.td))


def _still_window(rec, acc, cfg: AhrsConfig) -> int:
    """The samples of a still start's window: the initial window's when it is still
    (:func:`_still`), else ``init_still_min_s``'s when the window's first samples are, else
    0 (a start in motion)."""
    w = _init_window(rec, cfg)
    if _still(rec, acc, cfg, w):
        return w
    m = _still_min_window(rec, cfg)
    return m if m < w and _still(rec, acc, cfg, m) else 0


def _still(rec, acc, cfg: AhrsConfig, w: int | None = None) -> bool:
    """Whether the first ``w`` samples (default: the initial window) of a validated record
    pass the rest detector's statistics (:func:`start_is_still`)."""
    w = _init_window(rec, cfg) if w is None else w
    g, a = rec.omega[:w], acc[:w]
    return bool(np.sum(np.var(g, axis=0)) < cfg.rest_gyro ** 2
                and np.linalg.norm(g.mean(axis=0)) < cfg.rest_gyro_mean
                and np.sum(np.var(a, axis=0)) < cfg.rest_acc ** 2)


def _window_path(rec, w: int, q0=None) -> np.ndarray:
    """The gyro's attitude (``rate-single``) over the first ``w`` samples as DCMs (w, 3, 3),
    from the first sample into the frame that ``q0`` (default: identity, the first
    sample's body frame) relates the first sample to."""
    from strapdown.algorithms.rate import rate_attitude
    from strapdown.rotation.dcm import dcm_from_quat

    return dcm_from_quat(rate_attitude(rec.t[:w], rec.omega[:w], algorithm="rate-single",
                                       q0=q0).q)


def _derotated(rec, x, w: int, q0=None, path=None) -> np.ndarray:
    """The first ``w`` rows of ``x`` (body-frame vectors) turned along the gyro's attitude
    (:func:`_window_path`; ``path``: that path, already computed for the same ``w`` and
    ``q0``)."""
    c = _window_path(rec, w, q0) if path is None else path
    return np.einsum("nij,nj->ni", c, x[:w])


def _initial_attitude(rec, acc, mag, have_mag: bool, cfg: AhrsConfig, q0, frame: str,
                      still: int, path=None):
    """q_ENU_b at the start and the body-frame field there (None without heading).

    Without ``q0``, the initial window's mean specific force and field give the attitude
    by TRIAD (:func:`attitude_from_acc_mag`); a window that is not still is first turned
    into its first sample's frame by the gyro (a rotating body's mean would otherwise
    average over the rotation: a 1.5 Hz spin turns 270° in half a second). ``still``: the
    samples of a still start's window (:func:`_still_window`; 0: a start in motion).
    ``path``: the gyro's path over a moving window (:func:`_window_path`), when already
    computed.
    """
    if q0 is None:
        w = still if still else _moving_window(rec, cfg)
        if not still and path is None:  # one gyro path for both sensors
            path = _window_path(rec, w)
        a = acc[:w] if still else _derotated(rec, acc, w, path=path)
        m0 = None
        if have_mag:
            m0 = (mag[:w] if still else _derotated(rec, mag, w, path=path)).mean(axis=0)
        return attitude_from_acc_mag(a.mean(axis=0), m0,
                                     declination_deg=cfg.declination_deg), m0
    q_init = as_quaternions(q0, "q0").reshape(4)
    q_init = q_init / np.linalg.norm(q_init)
    if frame == "NED":  # the filter runs in ENU
        q_init = quat_multiply(np.array([0.0, -Q_NED_ENU[1], -Q_NED_ENU[2], 0.0]), q_init)
    return q_init, (mag[0] if have_mag else None)


def _reference_field(rec, mag, q_init, m0, q0, mag_reference, cfg: AhrsConfig):
    """(norm, dip, heading) of the local field in ENU — dip down positive, heading from
    east to north, rad — given (``mag_reference``), or learned (see :func:`ekf`)."""
    from strapdown.rotation.dcm import dcm_from_quat

    if mag_reference is not None:  # the local field is known (ENU)
        mn = np.asarray(mag_reference, float)
        if mn.shape != (3,) or not np.all(np.isfinite(mn)) or not np.linalg.norm(mn) > 0:
            raise ValueError(f"mag_reference must be a finite non-zero (3,) ENU vector, "
                             f"got {mag_reference!r}")
    elif q0 is None:
        mn = dcm_from_quat(q_init) @ m0
    else:  # learn the field over the window along the gyro-propagated attitude
        mn = _derotated(rec, mag, _init_window(rec, cfg), q_init).mean(axis=0)
    return (float(np.linalg.norm(mn)), math.atan2(-mn[2], math.hypot(mn[0], mn[1])),
            math.atan2(mn[1], mn[0]))


def butterworth(tau: float, ts: float) -> tuple[float, float, float, float, float]:
    """Second-order Butterworth low-pass coefficients ``(b0, b1, b2, a1, a2)`` (a0 = 1)
    for time constant ``tau`` at period ``ts``: cut-off ``√2/(2π tau)``, by the bilinear
    transform (Laidig & Seel (2023), VQF's ``filterCoeffs``); a pass-through when
    ``tau < ts/2`` (a cut-off above 90 % of Nyquist)."""
    if tau < ts / 2:
        return 1.0, 0.0, 0.0, 0.0, 0.0
    c = math.tan(math.pi * math.sqrt(2.0) / (2.0 * math.pi * tau) * ts)
    d = c * c + math.sqrt(2.0) * c + 1.0
    b0 = c * c / d
    return b0, 2.0 * b0, b0, 2.0 * (c * c - 1.0) / d, (1.0 - math.sqrt(2.0) * c + c * c) / d


def _derived(cfg: AhrsConfig, ref, use_mag: bool, h: float, te: float,
             start: _Start) -> dict:
    """The kernel parameters that are not config fields of the same name: the reference
    field ``ref`` (norm, dip, heading), the switches, and what depends on the epoch
    period ``te`` — the low-pass coefficients and averaging counts, the reference's
    gain per epoch — or on the sample period ``h`` — the magnetometer delay and its
    estimator, in samples."""
    lp = butterworth(cfg.acc_lowpass_s, te)
    mc = butterworth(cfg.mag_current_s, te)
    lp_init_n = max(1, math.ceil(cfg.acc_lowpass_s / te - 1e-9))
    from strapdown.ahrs.hard_iron import SPAN_S, SPREAD_MAX, STEADIER_MAX

    hi_span = max(1, round(SPAN_S / te))
    return {"ref_norm": ref[0], "ref_dip": ref[1], "ref_heading": ref[2],
            "use_magnetometer": use_mag, "soft_gate": cfg.acc_gate_mode == "soft",
            "acc_lowpass": cfg.acc_model == "lowpass",
            **dict(zip(("lp_b0", "lp_b1", "lp_b2", "lp_a1", "lp_a2"), lp, strict=True)),
            **dict(zip(("mc_b0", "mc_b1", "mc_b2", "mc_a1", "mc_a2"), mc, strict=True)),
            "lp_init_n": lp_init_n,
            "lp_settle": 0 if cfg.acc_lowpass_settle or not start.still else -lp_init_n,
            "mc_init_n": max(1, math.ceil(cfg.mag_current_s / te - 1e-9)),
            "dyn_k": 1.0 - math.exp(-te / cfg.acc_lowpass_s),
            "dyn_k2": 1.0 - math.exp(-te / (K.MOTION_SLOW * cfg.acc_lowpass_s)),
            "mag_ref_k": 1.0 - math.exp(-te / cfg.mag_reference_s),
            "scale_k": 1.0 - math.exp(-te / cfg.gyro_scale_tau),
            "adapt_k": 1.0 - math.exp(-te / cfg.tilt_adapt_s),
            "clip_level": cfg.gyro_range if cfg.gyro_range < math.inf else 0.0,
            "clip_s": cfg.gyro_clip_s,
            "mag_adapt_k": 1.0 - math.exp(-te / cfg.mag_adapt_s) if cfg.mag_adapt_s > 0 else 0.0,
            "mag_delay": round(cfg.mag_delay_s / h),
            "mag_delay_max": max(round(cfg.mag_delay_max_s / h), round(cfg.mag_delay_s / h)),
            "mag_delay_alpha": min(1.0, h / cfg.mag_delay_tau_s), "store_covariance": False,
            "meas_lead": (0.5 * h if cfg.gyro_sample == "interval" and cfg.mag_sample == "point"
                          else 0.0),
            "acc_lead": (0.5 * h if cfg.gyro_sample == "interval" and cfg.acc_sample == "point"
                         else 0.0),
            "gravity_measured": start.gravity, "gravity_known": start.gravity_known,
            "gravity_learned": start.gravity_learned,
            "mag_provisional_s": start.mag_provisional_s,
            "provisional_heading_q": (cfg.heading_noise / cfg.moving_start_heading_s) ** 2,
            "hi_on": use_mag and cfg.hard_iron_s > 0, "hi_span": hi_span,
            "hi_forget": math.exp(-hi_span * te / cfg.hard_iron_s) if cfg.hard_iron_s > 0
            else 0.0, "hi_ridge": HI_RIDGE, "hi_min_explained": cfg.hard_iron_min_explained,
            "hi_steadier": STEADIER_MAX, "hi_spread": SPREAD_MAX, "hi_update": HI_UPDATE,
            "hi_hold_s": cfg.hard_iron_hold_s,
            "hi_min_spans": cfg.hard_iron_hold_s / (hi_span * te)}


def _params(cfg: AhrsConfig, ref, use_mag: bool, h: float, te: float,
            start: _Start) -> K.Params:
    """The kernel's parameter record: the config's fields of the same name and
    :func:`_derived`'s for the sample period ``h`` and the epoch period ``te``.

    Every value is converted to its field's type (float, int or bool), so the
    compiled kernel's signature — and numba's cache entry — never changes.
    """
    derived = _derived(cfg, ref, use_mag, h, te, start)
    types = typing.get_type_hints(K.Params)
    return K.Params(**{f: types[f](derived[f] if f in derived else getattr(cfg, f))
                       for f in K.Params._fields})


def _propagation(a: dict) -> tuple[K.Propagation, K.Window]:
    """The kernel's propagation records from :func:`_algorithm`'s dict, types fixed (so
    the compiled kernel's signature never changes)."""
    prop = K.Propagation(is_rate=bool(a["is_rate"]), stride=int(a["stride"]),
                         end_off=int(a["end_off"]), lag=int(a["lag"]),
                         start_c=float(a["start_c"]), rk4=bool(a["rk4"]))
    window = K.Window(*(np.ascontiguousarray(a[f], np.int64 if f in ("offsets", "pi", "pj")
                                             else np.float64) for f in K.Window._fields))
    return prop, window


def _initial_covariance(cfg: AhrsConfig, attitude_sigma0: float | None = None,
                        yaw_known_about=None, gyro_bias_sigma0: float | None = None
                        ) -> np.ndarray:
    """P0: attitude (``attitude_sigma0``, default the config's; :class:`_Start` widens it
    after a start in motion — about every axis but ``yaw_known_about``, the reference
    vertical in the body, when given: without a magnetometer the start's yaw is a
    convention, not an estimate, and keeps the config's σ), gyro bias
    (``gyro_bias_sigma0``, default the config's; a still window narrows it) (and the raw
    model's manoeuvre acceleration, the accelerometer bias)."""
    singer = cfg.acc_model == "raw"
    nx = 6 + 3 * singer + 3 * cfg.estimate_acc_bias
    P0 = np.zeros((nx, nx))
    sigma = cfg.attitude_sigma0 if attitude_sigma0 is None else attitude_sigma0
    P0[:3, :3] = np.eye(3) * sigma**2
    if yaw_known_about is not None:
        u = np.asarray(yaw_known_about, float)
        P0[:3, :3] -= (sigma**2 - cfg.attitude_sigma0**2) * np.outer(u, u)
    sb = cfg.gyro_bias_sigma0 if gyro_bias_sigma0 is None else gyro_bias_sigma0
    P0[3:6, 3:6] = np.eye(3) * sb**2
    if singer:
        P0[6:9, 6:9] = np.eye(3) * cfg.singer_sigma**2
    if cfg.estimate_acc_bias:
        P0[-3:, -3:] = np.eye(3) * cfg.acc_bias_sigma0**2
    return P0


def _run(rec, acc, mag, prop: K.Propagation, window: K.Window, params: K.Params,
         init: K.Initial):
    """Run the compiled loop into per-sample outputs whose row 0 is the initial state;
    returns (outputs, number of epochs)."""
    h = rec.td
    x = rec.omega if prop.is_rate else 0.5 * h * (rec.omega[1:] + rec.omega[:-1])
    n = rec.t.size
    nc = n if params.store_covariance else 1
    out = K.Outputs(q=np.empty((n, 4)), gyro_bias=np.empty((n, 3)), accel=np.zeros((n, 3)),
                    acc_bias=np.zeros((n, 3)), sample=np.empty(n, np.int64),
                    flags=np.zeros(n, np.int64), nis=np.empty((n, 2)),
                    attitude_sigma=np.empty((n, 3)), attitude_cov=np.empty((nc, 3, 3)),
                    bias_var=np.empty((nc, 3)), mag_delay=np.zeros(n, np.int64),
                    mag_nis0=np.full(n, np.nan))
    out.q[0] = init.q
    out.gyro_bias[0] = init.gyro_bias
    out.nis[0] = np.nan
    out.attitude_sigma[0] = np.sqrt(np.diag(init.P)[:3])
    out.attitude_cov[0] = init.P[:3, :3]
    out.bias_var[0] = np.diag(init.P)[3:6]
    out.mag_delay[0] = params.mag_delay
    k, g, g_known, *rest = K.ekf_kernel(K.Sensors(np.ascontiguousarray(x), acc, mag,
                                                  float(h)), prop, window, params, init, out)
    return (out, k, _Gravity(float(g), bool(g_known), float(rest[7])), np.array(rest[:3]),
            np.array(rest[3:7]))


def _fill_between_epochs(rec, q, bias, last):
    """Rows of ``q`` (ENU) that are not epochs (``last[i] < i``): propagated from the row
    before by one single-period step (``rate-single``, ``td/2 (ω₀ + ω₁) + c td² ω₀ × ω₁``
    with the derived c = 1/6, see :mod:`strapdown.algorithms.rate`) on the gyro corrected
    by the bias of the last epoch. In place."""
    n = rec.t.size
    off = np.arange(n) - last  # samples since the last epoch (0 at epochs and row 0)
    h = rec.td
    for j in range(1, int(off.max()) + 1 if n else 1):  # a few samples at most
        i = np.flatnonzero(off == j)
        w0 = rec.omega[i - 1] - bias[i]
        w1 = rec.omega[i] - bias[i]
        phi = 0.5 * h * (w0 + w1) + h * h / 6.0 * np.cross(w0, w1)
        q[i] = quat_multiply(q[i - 1], quat_from_rotvec(phi))


def _fill(rec, out: K.Outputs, k: int) -> np.ndarray:
    """Complete the kernel's per-sample outputs in place: rows that are neither row 0 nor
    an epoch get the last epoch's bias and covariance and the attitude propagated from
    it (:func:`_fill_between_epochs`), flags 0 and no NIS. Returns the epoch mask."""
    n = rec.t.size
    epoch = np.zeros(n, bool)
    epoch[out.sample[:k]] = True
    held = np.flatnonzero(~epoch[1:]) + 1  # rows that are neither epochs nor row 0
    if held.size:
        last = np.maximum.accumulate(np.where(epoch, np.arange(n), 0))  # last epoch row
        for a in (out.gyro_bias, out.accel, out.acc_bias, out.attitude_sigma, out.mag_delay,
                  *((out.attitude_cov, out.bias_var) if out.bias_var.shape[0] == n else ())):
            a[held] = a[last[held]]
        out.nis[held] = np.nan
        out.mag_nis0[held] = np.nan
        _fill_between_epochs(rec, out.q, out.gyro_bias, last)
    return epoch


def _result(rec, out: K.Outputs, epoch, frame: str, have_mag: bool, algorithm: str,
            cfg: AhrsConfig, start: _Start, smoothed: bool = False) -> AhrsResult:
    """The :class:`AhrsResult` of completed per-sample outputs (:func:`_fill`): the
    attitudes after the initial one predicted over half a sample period
    (``gyro_sample="interval"``) plus ``latency_s``, then turned into ``frame``."""
    q, bias = out.q, out.gyro_bias
    half = 0.5 * rec.td if cfg.gyro_sample == "interval" and not smoothed else 0.0
    lead = cfg.latency_s + half  # a smoothed result is at the stamps already (_to_stamps)
    if lead > 0:  # predict each attitude but the initial one over the latency (causal)
        q = np.empty_like(out.q)
        K.predict(out.q, rec.omega, bias, float(lead), q)
    if frame == "NED":
        q = quat_multiply(Q_NED_ENU, q)
    return AhrsResult(rec.t, np.arange(rec.t.size), epoch, q, frame, have_mag, bias,
                      out.accel, out.flags, out.nis, out.attitude_sigma, algorithm, cfg,
                      out.acc_bias if cfg.estimate_acc_bias else None,
                      out.mag_delay * rec.td if have_mag else None, smoothed, start.still)


class _Gravity(typing.NamedTuple):
    """Gravity's norm at the end of a pass: as this accelerometer measures it (``norm``),
    whether a still start or a rest measured it (``known``; else assumed), and, when not,
    the norm the pass learned (``learned``, ``AhrsConfig.acc_scale_tol``; NaN: none)."""

    norm: float
    known: bool
    learned: float


class _Start(typing.NamedTuple):
    """How a pass starts: the initial window still (else a start in motion); gravity's
    norm as this accelerometer measures it — measured (``gravity_known``) or, after a
    start in motion, the nominal one (the kernel then learns it, ``acc_scale_tol``) until a
    rest measures it; after a start in motion
    whose attitude comes from the window, its wider initial uncertainty and the time the
    field's reference follows the measurement (0: not at all); the low-pass model's
    initial motion power (a start in motion's, :func:`_start_motion_power`; else 0); and,
    for a backward pass whose forward pass never measured gravity's norm, the norm that
    pass learned (``AhrsConfig.acc_scale_tol``; NaN: none, the learning starts afresh);
    the samples of a still start's window (:func:`_still_window`; 0: none averaged)."""

    still: bool
    gravity: float
    gravity_known: bool
    attitude_sigma0: float
    mag_provisional_s: float = 0.0
    gyro_bias_sigma0: float | None = None  #: None: the config's
    motion_power: float = 0.0
    gravity_learned: float = math.nan
    window: int = 0


def _start(rec, acc, cfg: AhrsConfig, q0, mag_reference, still: int, path=None) -> _Start:
    """The forward pass's :class:`_Start`: a still window's (``still`` samples,
    :func:`_still_window`; 0: a start in motion) mean specific force's norm is gravity as
    this accelerometer measures it, scale error included. A start in motion
    widens the initial uncertainty only when the attitude is the window's (no ``q0``), and
    makes the reference field provisional only when it is also learned there. ``path``: the
    gyro's path over a moving window, when already computed."""
    if still:
        return _Start(True, float(np.linalg.norm(acc[:still].mean(axis=0))), True,
                      cfg.attitude_sigma0, window=still)
    power = (_start_motion_power(rec, acc, cfg, path) if cfg.acc_model == "lowpass"
             else 0.0)
    if q0 is not None:
        return _Start(False, float(cfg.gravity), False, cfg.attitude_sigma0,
                      motion_power=power)
    return _Start(False, float(cfg.gravity), False, cfg.moving_start_sigma0,
                  cfg.moving_start_mag_s if mag_reference is None else 0.0, motion_power=power)


def _setup(t, gyro, acc, mag, cfg: AhrsConfig, q0, gyro_bias0, mag_reference, frame):
    """:func:`ekf`'s record and initial state: the config with the gyro's range resolved
    (:func:`_with_range`), the clipped and recovered sample counts (:func:`_declipped`),
    then what :func:`_prepare` returns for the validated record with the rate beyond that
    range taken from the field."""
    rec, acc, mag, have_mag = _validate(t, gyro, acc, mag, cfg, frame)
    cfg = _with_range(cfg, _saturated(rec, mag, have_mag, cfg, "ekf", 5))
    rec, clip = _declipped(rec, mag, have_mag, cfg)
    return (cfg, clip,
            *_prepare(rec, acc, mag, have_mag, cfg, q0, gyro_bias0, mag_reference, frame))


def _prepare(rec, acc, mag, have_mag: bool, cfg: AhrsConfig, q0, gyro_bias0, mag_reference,
             frame):
    """Initial state of a record :func:`_validate` has checked (and :func:`_declipped`
    completed): (rec, acc, mag, have_mag, q_init (ENU), b0, reference field (norm, dip,
    heading), :class:`_Start`)."""
    w_still = _still_window(rec, acc, cfg)  # 0: a start in motion
    # a start in motion: one gyro path over its window for what needs it, its motion power
    # (the low-pass model) and its attitude (without q0)
    need = not w_still and (q0 is None or cfg.acc_model == "lowpass")
    path = _window_path(rec, _moving_window(rec, cfg)) if need else None
    start = _start(rec, acc, cfg, q0, mag_reference, w_still, path)
    q_init, m0 = _initial_attitude(rec, acc, mag, have_mag, cfg, q0, frame, w_still, path)
    ref = (_reference_field(rec, mag, q_init, m0, q0, mag_reference, cfg) if have_mag
           else (0.0, 0.0, 0.0))
    if gyro_bias0 is not None:
        b0 = _check("gyro_bias0", [gyro_bias0], 1)[0]
    elif start.still:
        b0, sigma = _window_bias(rec, cfg, start.window)
        start = start._replace(gyro_bias_sigma0=sigma)
    else:
        b0 = np.zeros(3)
    return rec, acc, mag, have_mag, q_init, b0, ref, start


def _window_bias(rec, cfg: AhrsConfig, w: int) -> tuple[np.ndarray, float]:
    """A still start's window of ``w`` samples as a rest: the gyro bias is its mean rate,
    with :func:`window_bias_sigma`."""
    return rec.omega[:w].mean(axis=0), window_bias_sigma(cfg, w, rec.td)


def window_bias_sigma(cfg: AhrsConfig, w: int, td: float) -> float:
    """The gyro bias's initial σ after a still window of ``w`` samples ``td`` apart: what
    the zero-rate update gives a rest that long (``rest_noise / √(w td)``), or
    ``gyro_bias_sigma0`` when that is smaller."""
    return min(cfg.gyro_bias_sigma0, cfg.rest_noise / math.sqrt(w * td))


def _filter(rec, acc, mag, have_mag: bool, cfg: AhrsConfig, algorithm: str, q_init, b0,
            ref, start: _Start, store_covariance: bool = False, lowpass=None,
            lowpass_wait_s: float = 0.0):
    """One causal pass: the completed per-sample outputs (ENU; with the attitude and bias
    covariances when ``store_covariance``), the epoch mask, gravity's norm at the end,
    with whether a rest measured it and, if not, its learned norm (:class:`_Gravity`),
    the online hard-iron offset and the
    low-pass model's state at the end (``_kernel.Initial.lowpass``). ``lowpass``: that
    state to start from (None: the low-pass averages its first epochs), with no low-pass
    update for ``lowpass_wait_s`` unless the accelerometer is quiet."""
    prop, window = _propagation(_algorithm(algorithm))
    up = None  # without a magnetometer a widened start keeps the yaw's σ (a convention)
    if not have_mag and start.attitude_sigma0 != cfg.attitude_sigma0:
        from strapdown.rotation.dcm import dcm_from_quat

        up = dcm_from_quat(q_init)[2]  # the reference vertical in the body: C_n_b's third row
    if lowpass is None:  # none carried: the low-pass averages its first epochs
        lowpass = np.array([np.nan, np.nan, np.nan, start.motion_power])
    init = K.Initial(q_init, b0, _initial_covariance(cfg, start.attitude_sigma0, up,
                                                     start.gyro_bias_sigma0),
                     np.asarray(lowpass, float),
                     math.ceil(lowpass_wait_s / (prop.stride * rec.td) - 1e-9))
    params = _params(cfg, ref, have_mag, rec.td, prop.stride * rec.td, start)._replace(
        store_covariance=store_covariance)
    out, k, gravity, offset, lowpass = _run(rec, acc, mag, prop, window, params, init)
    return out, _fill(rec, out, k), gravity, offset, lowpass


def ekf(t, gyro, acc, mag=None, *, algorithm: str = "rate-single",
        config: AhrsConfig | None = None, q0=None, gyro_bias0=None,
        mag_reference=None, frame: str = "ENU") -> AhrsResult:
    """Run the AHRS filter over uniformly sampled gyro, accelerometer and magnetometer data.

    The multiplicative error-state EKF of Wang, Wang & Wang (eqs. 30–35), made
    well-posed (see the module docstring).

    Parameters
    ----------
    t : array_like (n,)
        Sample times (s), uniform.
    gyro : array_like (n, 3)
        Body rates, rad/s.
    acc : array_like (n, 3)
        Specific force, m/s² (≈ +g up at rest).
    mag : array_like (n, 3), optional
        Magnetic field, any unit (µT typical). None: no heading (see the module docstring).
    algorithm : str
        Attitude propagation: ``rate-single`` (default), ``rate-three``,
        ``rate-three:structure=sliding``, ``rk4``, ``rotvec:N=3`` …
    config : AhrsConfig, optional
    q0 : array_like (4,), optional
        Initial q_n_b in ``frame``; default from the accelerometer and magnetometer.
    gyro_bias0 : array_like (3,), optional
        Initial bias estimate, rad/s, with uncertainty ``gyro_bias_sigma0``. Default: the
        mean rate over a still initial window (``AhrsConfig.gyro_bias_sigma0``), else
        zero.
    mag_reference : array_like (3,), optional
        The local magnetic field in ENU (same unit as ``mag``). Default: learned
        over ``init_window_s`` — averaged at rest when ``q0`` is None, else
        rotated into the reference frame along the gyro-propagated attitude.
    frame : {"ENU", "NED"}

    Returns
    -------
    AhrsResult
        One row per input sample, the first the initial attitude at ``t[0]``.

    Raises
    ------
    ValueError
        On invalid input, naming the problem.
    """
    cfg, clip, rec, acc, mag, have_mag, q_init, b0, ref, start = _setup(
        t, gyro, acc, mag, config or AhrsConfig(), q0, gyro_bias0, mag_reference, frame)
    out, epoch, gravity, offset, _ = _filter(rec, acc, mag, have_mag, cfg, algorithm, q_init,
                                             b0, ref, start)
    result = replace(_result(rec, out, epoch, frame, have_mag, algorithm, cfg, start),
                     mag_offset=offset if np.any(offset) else None, gyro_clipped=clip[0],
                     gyro_recovered=clip[1])
    _warn_if_accelerometer_unused(result, acc, gravity, cfg, "ekf")
    return result


def _backward(rec, acc, mag, have_mag: bool, cfg: AhrsConfig, algorithm: str, fwd, ref,
              gravity: _Gravity, lowpass):
    """The same filter over the time-reversed record (gyro negated), started from the
    forward pass's last attitude and bias and with its reference field; the
    magnetometer, which leads in reversed time, advanced by the forward pass's median
    delay; its rejection budget is ``offline_mag_reject_s``; its low-pass accelerometer
    model continues from the forward pass's at the end (``lowpass``; None: it averages its
    first epochs) and waits ``offline_lowpass_wait``. Returns its completed outputs in
    forward sample order."""
    n = rec.t.size
    d = int(np.median(fwd.mag_delay)) if have_mag else 0
    mag_b = np.concatenate([mag[d:], np.repeat(mag[-1:], d, axis=0)])[::-1] if d else mag[::-1]
    omega = rec.omega
    if cfg.gyro_sample == "interval":
        # sample k's rate is the mean over (t_k−1, t_k): in reversed time that interval ends
        # at sample k − 1, so each reversed sample takes the rate of the next forward one
        omega = np.concatenate([omega[1:], omega[-1:]])
    rec_b = replace(rec, omega=np.ascontiguousarray(-omega[::-1]))
    # started from the forward pass's last estimate, with its uncertainty (not the
    # initial one: the record's end is rarely a rest, and a start-up uncertainty there let
    # the first seconds of motion pull the bias by degrees per second); and no low-pass
    # accelerometer update until its low-pass has settled (acc_lowpass_settle); its heading
    # covariance grows with the rotation while it bridges a disturbance (heading_bridge_noise)
    sig_att = math.sqrt(float(np.max(np.linalg.eigvalsh(fwd.attitude_cov[-1]))))
    sig_bias = math.sqrt(float(np.max(fwd.bias_var[-1])))
    cfg_b = replace(cfg, estimate_mag_delay=False, mag_delay_s=0.0, acc_lowpass_settle=True,
                    heading_bridge_noise=True, mag_reject_s=cfg.offline_mag_reject_s,
                    attitude_sigma0=max(sig_att, 1e-4), gyro_bias_sigma0=max(sig_bias, 1e-6))
    # its start is the forward pass's end: still or not, no window is averaged; gravity is
    # what the forward pass ended with
    out, epoch, *_ = _filter(rec_b, np.ascontiguousarray(acc[::-1]),
                             np.ascontiguousarray(mag_b), have_mag, cfg_b, algorithm,
                             _backward_start(fwd, rec, cfg), -fwd.gyro_bias[-1], ref,
                             _Start(True, gravity.norm, gravity.known, cfg_b.attitude_sigma0,
                                    gravity_learned=gravity.learned), True, lowpass,
                             cfg.offline_lowpass_wait * cfg.acc_lowpass_s)
    _to_stamps(out, rec_b.omega, rec, cfg)
    out.q[0] = fwd.q[-1]  # its start, at the last stamp (_to_stamps keeps a first row)
    rev = np.arange(n)[::-1]
    for f in ("q", "gyro_bias", "accel", "acc_bias", "flags", "nis", "attitude_sigma",
              "attitude_cov", "bias_var", "mag_nis0"):
        getattr(out, f)[:] = getattr(out, f)[rev]
    out.gyro_bias[:] *= -1.0
    return out, epoch[rev]


def _backward_start(fwd, rec, cfg: AhrsConfig) -> np.ndarray:
    """The backward pass's initial attitude: the forward pass's last, at the last stamp,
    predicted half a period on (with interval gyro samples): the backward pass's attitudes
    refer to the middle of each period in its own time, half a period *after* the stamp,
    and its first step turns its start back a whole period. Without it a spinning record's
    backward pass started half a period of rotation off (spin-coning, 9.4 rad/s at 400 Hz:
    0.67°, most of it heading, which the field takes seconds to pull back)."""
    if cfg.gyro_sample != "interval":
        return fwd.q[-1]
    return quat_multiply(fwd.q[-1], quat_from_rotvec(0.5 * rec.td
                                                     * (rec.omega[-1] - fwd.gyro_bias[-1])))


def _widen_still_start(bwd, w: int, cfg: AhrsConfig) -> None:
    """Where the record starts still, the backward pass's attitude covariance over that
    window (its first ``w`` samples, :func:`_still_window`) is widened by ``recover_angle²``
    on every axis, in place, as an accelerometer recovery widens it: the forward pass has
    measured the attitude there at rest (the window's TRIAD, then its updates), while the
    backward pass arrives from the motion with the gyro's errors through it — timing,
    scale, lost samples — outside its covariance, and its accelerometer low-pass cannot
    check it against a rest shorter than itself. The two-filter combination then takes
    the rest's attitude there. RepoIMU's pendulum (test 04 trial 3 segment 2): the
    backward pass reached the 0.9 s still start 6.8° off with σ 0.4°, the forward pass
    was 0.7° off with σ 2.9°, and the combination followed the backward pass."""
    bwd.attitude_cov[:w] += cfg.recover_angle ** 2 * np.eye(3)


def _combine(fwd, bwd) -> np.ndarray:
    """Fraser–Potter two-filter combination, in place on ``fwd``: per sample, the
    attitude ``q_f ⊗ exp(G δ)`` with ``δ = log(q_f* ⊗ q_b)`` (body frame) and
    ``G = P_f (P_f + P_b)⁻¹``, its covariance ``P_f − G P_f``; the gyro bias weighted
    by the inverse variances. Returns, per sample, how far the two passes' tilts
    disagree: the NIS of δ's horizontal part in the reference frame against the same
    part of ``P_f + P_b`` (χ² with 2 degrees of freedom where the passes are
    consistent)."""
    from strapdown.rotation.dcm import dcm_from_quat
    from strapdown.rotation.quaternion import quat_conjugate, rotvec_from_quat

    dq = quat_multiply(quat_conjugate(fwd.q), bwd.q)
    delta = rotvec_from_quat(dq)  # |δ| ≤ π: the log folds the sign of w
    pf, pb = fwd.attitude_cov, bwd.attitude_cov
    c = dcm_from_quat(fwd.q)[:, :2, :]  # the reference frame's horizontal rows of C_n_b
    dn = np.einsum("nij,nj->ni", c, delta)
    sn = np.einsum("nij,njk,nlk->nil", c, pf + pb, c)
    tilt_nis = np.einsum("ni,ni->n", dn, np.linalg.solve(sn, dn[..., None])[..., 0])
    g = np.linalg.solve(pf + pb, pf).transpose(0, 2, 1)  # P_f (P_f + P_b)⁻¹ (symmetric P)
    fwd.q[:] = quat_multiply(fwd.q, quat_from_rotvec(np.einsum("nij,nj->ni", g, delta)))
    fwd.attitude_cov[:] = pf - g @ pf
    fwd.attitude_sigma[:] = np.sqrt(np.maximum(np.diagonal(fwd.attitude_cov, axis1=1,
                                                           axis2=2), 0.0))
    wf, wb = 1.0 / fwd.bias_var, 1.0 / bwd.bias_var
    fwd.gyro_bias[:] = (wf * fwd.gyro_bias + wb * bwd.gyro_bias) / (wf + wb)
    fwd.bias_var[:] = 1.0 / (wf + wb)
    return tilt_nis


def _gyro_smooth(rec, out: K.Outputs, cfg: AhrsConfig) -> None:
    """In place on the combined passes (at the stamps): ``q ← LP(c) ⊗ q_g``, where ``q_g``
    is the bias-corrected gyro's own path (:func:`_kernel.gyro_path`, the combined bias),
    ``c = q ⊗ q_g*`` the correction from it in the reference frame, made sign-continuous,
    and LP the second-order Butterworth of time constant ``offline_smooth_s`` (cut-off
    √2/(2πτ)) run forward and backward on c's components, then normalised
    (``AhrsConfig.offline_smooth_s``). Skipped when off, or when the record is too short
    or the cut-off above half the sample rate."""
    from scipy.signal import sosfiltfilt

    from strapdown.rotation.quaternion import quat_conjugate

    sos = _zero_phase_sos(cfg.offline_smooth_s, rec)
    if sos is None:
        return
    q_g = _gyro_path(rec, out, cfg)
    c = quat_multiply(out.q, quat_conjugate(q_g))
    flip = np.einsum("ij,ij->i", c[1:], c[:-1]) < 0
    c[1:] *= np.where(np.logical_xor.accumulate(flip), -1.0, 1.0)[:, None]
    c = sosfiltfilt(sos, c, axis=0, padlen=_SMOOTH_PAD)
    out.q[:] = quat_multiply(c / np.linalg.norm(c, axis=1, keepdims=True), q_g)


#: Samples padded at each end by the offline steps' zero-phase filter (scipy's default for
#: one second-order section); a record must be longer.
_SMOOTH_PAD = 9


def _gyro_path(rec, out: K.Outputs, cfg: AhrsConfig) -> np.ndarray:
    """The bias-corrected gyro's own path at the stamps, from the identity
    (:func:`_kernel.gyro_path`, ``out``'s gyro bias): what the offline steps smooth about
    (:func:`_gyro_smooth`) and turn the specific force along (:func:`_direct_tilt`)."""
    q_g = np.empty_like(out.q)
    K.gyro_path(rec.omega, out.gyro_bias, float(rec.td), cfg.gyro_sample == "interval", q_g)
    return q_g


def _zero_phase_sos(tau: float, rec):
    """The second-order Butterworth of time constant ``tau`` (cut-off √2/(2πτ), as
    :func:`butterworth`) at the record's period, as scipy's second-order sections for the
    offline steps' forward-backward filtering (``sosfiltfilt``, padded by
    :data:`_SMOOTH_PAD`); None when ``tau`` is not positive, the cut-off is not below half
    the sample rate or the record is too short to pad."""
    from scipy.signal import butter

    fc = math.sqrt(2.0) / (2.0 * math.pi * tau) if tau > 0 else math.inf
    if not fc < 0.5 / rec.td or rec.t.size <= _SMOOTH_PAD:
        return None
    return butter(2, fc, fs=1.0 / rec.td, output="sos")


def _direct_tilt(rec, acc, out: K.Outputs, bad: np.ndarray, cfg: AhrsConfig) -> None:
    """In place on the smoothed combination (at the stamps): where the passes' model of the
    gyro broke (``bad``: their tilts contradict each other — ``tilt_nis`` from
    :func:`_combine` above ``offline_consistency_gate`` — or a clipped gyro is near,
    :func:`_near_clip`), the tilt is the accelerometer's, taken directly — the
    specific force turned into the bias-corrected gyro's own path (:func:`_kernel.gyro_path`,
    the combined bias), low-passed forward and backward (second-order Butterworth of time
    constant ``acc_lowpass_s``, zero phase) and that direction taken as up, the structure
    of Laidig & Seel's (2023) offline VQF — the heading kept. The switch is the indicator
    of the contradiction low-passed the same way, so the estimate moves between the two
    over the low-pass's seconds. Nothing changes where the passes agree everywhere."""
    from scipy.signal import sosfiltfilt

    from strapdown.rotation.quaternion import quat_conjugate, quat_rotate, rotvec_from_quat

    n = rec.t.size
    sos = _zero_phase_sos(cfg.acc_lowpass_s, rec) if bad.any() else None
    if sos is None:
        return
    q_g = _gyro_path(rec, out, cfg)
    up = sosfiltfilt(sos, quat_rotate(q_g, acc), axis=0, padlen=_SMOOTH_PAD)
    norm = np.linalg.norm(up, axis=1)
    use = norm > 0.0
    up = up / np.where(use, norm, 1.0)[:, None]
    # the shortest rotation taking up onto the vertical, about a horizontal axis
    w = np.sqrt(np.maximum(0.5 * (1.0 + up[:, 2]), 0.0))
    ok = use & (w > 1e-6)
    ws = np.where(ok, w, 1.0)
    lift = np.column_stack([ws, 0.5 * up[:, 1] / ws, -0.5 * up[:, 0] / ws, np.zeros(n)])
    q_d = quat_multiply(lift, q_g)
    d = quat_multiply(out.q, quat_conjugate(q_d))  # keep the combination's heading
    twist = np.column_stack([d[:, 0], np.zeros(n), np.zeros(n), d[:, 3]])
    tn = np.linalg.norm(twist, axis=1)
    ok &= tn > 0.0  # no heading to keep where the two differ by a half turn about a level axis
    twist = np.where(ok[:, None], twist / np.where(ok, tn, 1.0)[:, None], [1.0, 0.0, 0.0, 0.0])
    q_d = quat_multiply(twist, q_d)
    weight = np.clip(sosfiltfilt(sos, bad.astype(float), padlen=_SMOOTH_PAD), 0.0, 1.0)
    weight[~ok] = 0.0
    dq = quat_multiply(quat_conjugate(out.q), q_d)
    step = rotvec_from_quat(dq)
    out.q[:] = quat_multiply(out.q, quat_from_rotvec(weight[:, None] * step))


def _saturated(rec, mag, have_mag: bool, cfg: AhrsConfig, where: str, stacklevel: int):
    """The clipped axes the record shows, warned about
    (:func:`~strapdown.ahrs.saturation.warn_if_saturated`): the plateaus entered by a step,
    or else, with a field to take the rate from (``gyro_declip``), those the field shows the
    body turning beyond (:func:`~strapdown.ahrs.saturation.field_plateaus`)."""
    use_field = have_mag and cfg.gyro_declip
    return warn_if_saturated(rec.omega, where, stacklevel, mag if use_field else None,
                             rec.td if use_field else None)


def _with_range(cfg: AhrsConfig, found) -> AhrsConfig:
    """``cfg`` with ``gyro_range`` 0 (found from the record) replaced by the range the gyro
    is found clipped at (:func:`~strapdown.ahrs.saturation.gyro_range` of ``found``), or
    by ``math.inf`` (none) when it is not."""
    if cfg.gyro_range != 0.0:
        return cfg
    return replace(cfg, gyro_range=gyro_range(found) or math.inf)


def _declipped(rec, mag, have_mag: bool, cfg: AhrsConfig):
    """``rec`` with the rate beyond the gyro's range (``gyro_range``, resolved by
    :func:`_with_range`) taken from the field where one or two axes are clipped
    (:func:`~strapdown.ahrs.saturation.declip`; ``gyro_declip``, with a field); as it is
    otherwise. Before everything else sees the gyro, the initial window included, as the C
    export does sample by sample. Also returns (the samples at the range, those of them
    recovered)."""
    n_clipped = int(clipped(rec.omega, cfg.gyro_range).sum())
    if not (cfg.gyro_declip and have_mag and n_clipped):
        return rec, (n_clipped, 0)
    omega, done = declip(rec.omega, mag, cfg.gyro_range, rec.td)
    n_done = int(done.any(axis=1).sum())
    return (replace(rec, omega=omega) if n_done else rec), (n_clipped, n_done)


def _near_clip(rec, cfg: AhrsConfig) -> np.ndarray:
    """The samples within ``gyro_clip_s`` of one at the gyro's range (``gyro_range``,
    resolved by :func:`_with_range`; :func:`~strapdown.ahrs.saturation.clipped`); all
    False when none is or the window is 0."""
    from scipy.ndimage import maximum_filter1d

    near = clipped(rec.omega, cfg.gyro_range)
    if cfg.gyro_clip_s <= 0.0 or not near.any():
        return np.zeros_like(near)
    w = round(cfg.gyro_clip_s / rec.td)  # the window's half width, samples
    return maximum_filter1d(near, 2 * w + 1, mode="constant", cval=False)


def offline_ekf(t, gyro, acc, mag=None, *, algorithm: str = "rate-single",
                config: AhrsConfig | None = None, q0=None, gyro_bias0=None,
                mag_reference=None, frame: str = "ENU") -> AhrsResult:
    """The AHRS for post-processing (acausal): :func:`ekf` run forward, then backward.

    Every estimate uses the whole record, so this is not a real-time filter. The
    forward pass is :func:`ekf`; the backward pass is the same filter over the
    time-reversed record (gyro negated; with interval samples each reversed sample takes
    the next forward sample's rate, the mean over the period that ends at it in reversed
    time), started from the forward pass's last attitude, bias and their uncertainty
    (the largest standard deviation of each), with its reference field and (advanced by
    it) its estimated magnetometer delay; both passes' attitudes are predicted to the
    stamps (they refer to the middle of the sample period, which lies on opposite sides
    of the stamp for the two) and combined sample by sample by the two-filter
    (Fraser–Potter) rule, each weighted by its attitude covariance (the backward pass's
    widened over a still start's window, which the forward pass measured at rest:
    ``_widen_still_start``) — so the
    low-pass lag of one pass cancels the lead of the other, and the first seconds,
    where the forward filter is still converging, get the backward estimate (when the record
    ends in motion, the backward pass's accelerometer low-pass continues the forward pass's
    and waits ``offline_lowpass_wait``; when it ends still and the forward pass, started in
    motion, never measured gravity's norm, that still end measures it for the backward pass,
    as a still start does); last, what
    of the combination varies faster than ``offline_smooth_s`` about the bias-corrected
    gyro's own path is removed (zero-phase; :class:`AhrsConfig`), and where the passes' tilts
    contradict each other (``offline_consistency_gate``) or a clipped gyro is near
    (``gyro_clip_s``) the tilt is the accelerometer's, taken directly. Before the passes, a
    hard-iron offset of the magnetometer found from the gyro over the whole record is
    subtracted when the tests of ``offline_hard_iron_min_explained`` pass
    (:mod:`strapdown.ahrs.hard_iron`; ``AhrsResult.mag_offset``); the passes run without
    the online estimate (``hard_iron_s``). Arguments
    as for :func:`ekf`; the result has ``smoothed`` set, its flags, NIS and
    manoeuvre acceleration are the forward pass's.

    Raises
    ------
    ValueError
        On invalid input, naming the problem.
    """
    cfg = config or AhrsConfig()
    rec, acc, mag, have_mag = _validate(t, gyro, acc, mag, cfg, frame)
    cfg = _with_range(cfg, _saturated(rec, mag, have_mag, cfg, "offline_ekf", 4))
    rec, clip = _declipped(rec, mag, have_mag, cfg)
    offset = _hard_iron_offset(rec, mag, have_mag, cfg)
    if offset is not None:
        mag = mag - offset
    rec, acc, mag, have_mag, q_init, b0, ref, start = _prepare(rec, acc, mag, have_mag, cfg,
                                                                q0, gyro_bias0, mag_reference,
                                                                frame)
    cfg_pass = _pass_config(cfg)
    fwd, epoch, gravity, _, lowpass = _filter(rec, acc, mag, have_mag, cfg_pass, algorithm,
                                              q_init, b0, ref, start, True)
    if (cfg.offline_heading_rate_noise < cfg.heading_rate_noise
            and _clean_field_rejected(fwd.flags, fwd.mag_nis0, cfg.mag_gate)
            > HEADING_ESCAPED_SHARE):
        # the heading left its covariance: the passes again, with the causal rate noise
        cfg = replace(cfg, offline_heading_rate_noise=cfg.heading_rate_noise)
        cfg_pass = _pass_config(cfg)
        fwd, epoch, gravity, _, lowpass = _filter(rec, acc, mag, have_mag, cfg_pass,
                                                  algorithm, q_init, b0, ref, start, True)
    _to_stamps(fwd, rec.omega, rec, cfg)
    # a record that ends at rest: the backward pass's low-pass averages that rest afresh
    # (the forward pass's still lags the motion before it)
    end_still = _still(replace(rec, omega=rec.omega[::-1]), acc[::-1], cfg)
    if end_still and not gravity.known:
        # the forward pass started moving and no rest measured gravity's norm; a still end
        # measures it, as a still start does, for the backward pass, which starts there
        gravity = _Gravity(float(np.linalg.norm(acc[-_init_window(rec, cfg):].mean(axis=0))),
                           True, math.nan)
    bwd, _ = _backward(rec, acc, mag, have_mag, cfg_pass, algorithm, fwd, ref, gravity,
                       None if end_still else lowpass)
    if start.still:
        _widen_still_start(bwd, start.window, cfg)
    tilt_nis = _combine(fwd, bwd)
    _gyro_smooth(rec, fwd, cfg)
    if cfg.use_accelerometer:
        broken = (tilt_nis > cfg.offline_consistency_gate) | _near_clip(rec, cfg)
        _direct_tilt(rec, acc, fwd, broken, cfg)
    result = replace(_result(rec, fwd, epoch, frame, have_mag, algorithm, cfg, start,
                             smoothed=True), mag_offset=offset, gyro_clipped=clip[0],
                     gyro_recovered=clip[1])
    _warn_if_accelerometer_unused(result, acc, gravity, cfg, "offline_ekf")
    return result


def _pass_config(cfg: AhrsConfig) -> AhrsConfig:
    """The configuration :func:`offline_ekf`'s forward and backward passes run with: the
    heading rate noise ``offline_heading_rate_noise``, no online hard-iron estimate (the
    passes share the reference field and the whole record's offset) and no adapted tilt
    noise (``tilt_adapt_level``; it cost there, :class:`AhrsConfig`)."""
    return replace(cfg, heading_rate_noise=cfg.offline_heading_rate_noise, hard_iron_s=0.0,
                   tilt_adapt_level=math.inf)


#: :func:`offline_ekf` runs its passes again with the causal ``heading_rate_noise`` when
#: its forward pass's innovation gate rejected (or, at the unadapted variance of
#: ``mag_adapt_s``, would have rejected) more than this share of the epochs whose field
#: was undisturbed (:func:`_clean_field_rejected`).
HEADING_ESCAPED_SHARE = 0.25


def _clean_field_rejected(flags: np.ndarray, nis0: np.ndarray | None = None,
                          gate: float = math.inf) -> float:
    """The share of the epochs with an undisturbed field (used or rejected, not
    ``MAG_DISTURBED``) whose field the innovation gate rejected — or would have rejected
    at the unadapted variance (``nis0`` beyond ``gate``: ``Outputs.mag_nis0``, NaN where
    a recovery forced the update; ``mag_adapt_s`` widens the variance, and a heading that
    runs away then leaves a smaller share of rejections, while the evidence that it left
    its covariance is the same); 0 when there are none.

    A consistent filter's gate rejects a clean field's innovation with the gate's
    false-alarm probability — ``P(χ²₁ > mag_gate)``, 4.6 % at the default 4 — and a
    quarter of them (:data:`HEADING_ESCAPED_SHARE`, over five times that) says the
    heading has left its covariance for good: the gyro drifts in heading faster than its
    model allows and the field, rejected, no longer pulls it back (the case and its
    figures: ``AhrsConfig.offline_heading_rate_noise``). Measured shares: BROAD's fifteen
    trials 0–1.2 %, the suite's scenarios 0–6.5 %; the runaways 64–74 %.
    """
    clean = (flags & int(MeasurementFlag.MAG_DISTURBED)) == 0
    seen = clean & ((flags & int(MeasurementFlag.MAG_USED | MeasurementFlag.MAG_REJECTED)) > 0)
    n = int(np.count_nonzero(seen))
    if n == 0:
        return 0.0
    out = (flags & int(MeasurementFlag.MAG_REJECTED)) > 0
    if nis0 is not None:
        out |= nis0 > gate  # NaN compares False
    return float(np.count_nonzero(seen & out)) / n


def _warn_if_accelerometer_unused(result: AhrsResult, acc,
                                  gravity: _Gravity,
                                  cfg: AhrsConfig, caller: str) -> None:
    """Warn (:class:`AccelerometerUnusedWarning`) when gravity's norm was never measured —
    no still start, no rest, and (offline) no still end — and the (forward) pass skipped
    at least ``ACC_UNUSED_SHARE`` of its low-pass accelerometer updates as implausible
    while the accelerometer's median norm lies further from the assumed gravity than
    ``acc_lowpass_norm_tol``: the filter then ran on the gyro alone, which its result
    would not show. ``acc``: the specific force the filter was given (m/s²)."""
    g, known = gravity.norm, gravity.known
    if known or not cfg.gating or cfg.acc_model != "lowpass":
        return
    share = result.fraction(MeasurementFlag.ACC_DISTURBED)
    if not share >= ACC_UNUSED_SHARE:  # the norms' median only when it may warn
        return
    norm = float(np.median(np.linalg.norm(acc, axis=1)))
    off = norm / g - 1.0
    if abs(off) <= cfg.acc_lowpass_norm_tol:
        return
    if off < 0.0:  # no motion keeps the low-passed specific force short for long
        why = ("a scale error (or a wrong AhrsConfig.gravity): no sustained motion keeps the "
               "low-passed specific force shorter than gravity")
    else:
        why = ("a sustained acceleration (a coordinated turn, which the test is there to "
               "skip) or a scale error")
    warnings.warn(
        f"{caller}: {100 * share:.1f} % of the accelerometer updates were skipped and the "
        f"tilt there is the gyro's alone: the record starts in motion, no rest measured "
        f"gravity's norm, and the accelerometer's median norm {norm:.4g} m/s² is "
        f"{100 * off:+.1f} % from the assumed {g:.6g} m/s² (AhrsConfig.gravity), beyond "
        f"acc_lowpass_norm_tol ({100 * cfg.acc_lowpass_norm_tol:.1f} %) — {why}. If the "
        f"accelerometer's scale is off, pass the gravity it measures as "
        f"AhrsConfig(gravity=...).", AccelerometerUnusedWarning, stacklevel=3)


def _hard_iron_offset(rec, mag, have_mag: bool, cfg: AhrsConfig) -> np.ndarray | None:
    """The field's hard-iron offset to subtract before :func:`offline_ekf`'s passes
    (:func:`strapdown.ahrs.hard_iron.hard_iron` on the validated record), or None: no
    field, too short a record, an offset that explains less than
    ``offline_hard_iron_min_explained``, one the record's halves disagree on (beyond
    :data:`~strapdown.ahrs.hard_iron.SPREAD_MAX`: not constant, so not a hard iron) or one
    whose removal hardly steadies the field's norm (above
    :data:`~strapdown.ahrs.hard_iron.STEADIER_MAX`)."""
    from strapdown.ahrs.hard_iron import SPREAD_MAX, STEADIER_MAX, _hard_iron

    if not have_mag or cfg.offline_hard_iron_min_explained > 1:
        return None
    try:
        est = _hard_iron(rec.omega, mag, rec.td, gyro_sample=cfg.gyro_sample)
    except ValueError:  # fewer than two spans: nothing to learn from
        return None
    ok = (est.explained >= cfg.offline_hard_iron_min_explained and est.spread <= SPREAD_MAX
          and est.steadier <= STEADIER_MAX)
    return est.offset if ok else None


def _to_stamps(out: K.Outputs, omega, rec, cfg: AhrsConfig) -> None:
    """In place: a pass's attitudes, which refer to the middle of each sample period with
    interval gyro samples (half a period before the stamp in the pass's own time, so half
    a period *after* it for the backward pass), predicted to the stamps, so that the two
    passes are combined at the same instants; ``omega`` in the pass's own time."""
    if cfg.gyro_sample == "interval":
        q = np.empty_like(out.q)
        K.predict(out.q, omega, out.gyro_bias, 0.5 * rec.td, q)
        out.q[:] = q
