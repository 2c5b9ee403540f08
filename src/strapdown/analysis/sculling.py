"""Classical sculling end to end: motion → exact gyro and accelerometer increments → velocity
algorithm → rectified velocity-error rate, against the designer's sculling law.

``strapdown evaluate --motion sculling`` (and ``compare``/``sweep`` with
``motion = "sculling"``) runs :func:`evaluate_sculling`. The motion is Savage (1998b)'s
classical sculling, ``θ0 sin Ωt`` about body x with ``A sin(Ωt + ψ)`` m/s² along body y,
no gravity, in a non-rotating frame (:func:`strapdown.truth.sculling.classical_sculling`,
exact increments). The algorithm is the N-subsample velocity update of
:mod:`strapdown.algorithms.velocity` in the conventional or single-chain structure
(``rotvec`` specs: Li & Zhang (2017) eq. 6 for the coning part, the designer's sculling
set, Ignagni (1998), for the velocity part).

The rectified velocity-error rate is the least-squares slope of the navigation-frame
velocity error (computed − exact) through the outputs on whole vibration periods from the
first period on (:func:`strapdown.analysis.accuracy.drift_rate`; the periodic part and a
start-up offset cancel); the law is ``−c · θ0 A cos ψ (Ωh)^{2N}`` along navigation z,
``c = N!(N+1)!/(2N+2)!`` (:func:`strapdown.algorithms.velocity.sculling_law`; the rate-input
duals ``rate-single``/``rate-three`` on rate and specific-force samples, float64:
:func:`strapdown.algorithms.velocity.rate_sculling_law`), first order
in θ0 — at a realistic amplitude the θ0³ terms it leaves out may dominate (see
``strapdown reproduce sculling``).

``--motion coning-force`` (:func:`evaluate_coning_force`) is a body coning (half angle
``a`` = ``half_angle_deg``, ``Ω`` = 2π ``cone_rate_hz``) in a constant specific force
``f`` = ``accel_amplitude`` m/s² along the cone axis — a body at rest in gravity coning
about the vertical (:class:`strapdown.truth.coning_force.ConingInForce`, exact increments).
Same algorithms, rate and outputs; the law is the coning-in-force one,
``−c · a² f (Ωh)^order`` along the cone axis (navigation x), with the default velocity set
(:func:`strapdown.algorithms.velocity.coning_force_law`: order 2N for the conventional
structure, 4 for the single chain), leading order in ``a``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from strapdown._core.errors import InputError
from strapdown.algorithms.velocity import (
    NavStructure,
    coning_force_law,
    effective_velocity_set,
    nav_structures,
    rate_sculling_law,
    rate_velocity_algorithms,
    sculling_law,
)
from strapdown.analysis.accuracy import drift_rate
from strapdown.navigation import integrate_inertial, integrate_inertial_mp, integrate_inertial_rates
from strapdown.truth.sculling import ScullingMotion, classical_sculling

if TYPE_CHECKING:
    from strapdown.analysis.evaluate import EvaluationConfig

__all__ = ["ScullingEvaluation", "build_coning_force", "build_sculling", "evaluate_coning_force",
           "evaluate_sculling", "validate_coning_force", "validate_sculling"]

#: Most samples an arbitrary-precision sculling run takes (each sample is a few hundred
#: multi-precision operations; 10⁵ at 40 digits take about a minute).
MAX_MP_SCULLING_SAMPLES = 200_000
#: Fewest digits of an arbitrary-precision run (float64 carries about 16).
MIN_DIGITS = 17


def _finite(name: str, v: float) -> float:
    v = float(v)
    if not math.isfinite(v):
        raise InputError(f"{name} must be finite, got {v}")
    return v


def validate_sculling(cfg: EvaluationConfig) -> None:
    """What the sculling motion takes (InputError naming the field otherwise): a ``rotvec``
    algorithm in the conventional or single-chain structure with its default coning set,
    N = 1–6, ideal sensors, finite amplitudes and phase, a non-zero frequency resolved by the
    sample rate (Ωh ≤ π), and in arbitrary precision at least :data:`MIN_DIGITS` digits and
    at most :data:`MAX_MP_SCULLING_SAMPLES` samples."""
    from strapdown.algorithms.coning import MAX_SUBSAMPLES

    if cfg.algorithm in rate_velocity_algorithms():
        _validate_rate(cfg)
    elif cfg.algorithm not in _increment_velocity_algorithms():
        raise InputError(f"the sculling motion runs the velocity algorithms "
                         f"({', '.join(_increment_velocity_algorithms())}, N = 1–"
                         f"{MAX_SUBSAMPLES}; rate input: "
                         f"{', '.join(rate_velocity_algorithms())}); {cfg.algorithm} "
                         "integrates attitude only")
    else:
        _validate_increment_velocity(cfg, "the sculling motion")
    if cfg.gyro is not None and not cfg.gyro.is_ideal:
        raise InputError("the sculling motion takes ideal sensors only (no gyro errors)")
    theta = _finite("angle amplitude (deg)", cfg.angle_amplitude_deg)
    if abs(theta) > 180.0:
        raise InputError(f"angle amplitude must be within ±180°, got {theta:g}")
    _finite("acceleration amplitude (m/s²)", cfg.accel_amplitude)
    _finite("phase (deg)", cfg.phase_deg)
    f = _finite("sculling frequency (Hz)", cfg.frequency_hz)
    if f == 0.0:
        raise InputError("sculling frequency must be non-zero")
    if not 2 * math.pi * abs(f) / cfg.sample_rate_hz <= math.pi:
        raise InputError(f"the sculling frequency {f:g} Hz is above half the sample rate "
                         f"({cfg.sample_rate_hz:g} Hz; Nyquist)")
    if cfg.precision is not None:
        if cfg.precision < MIN_DIGITS:
            raise InputError(f"precision must be at least {MIN_DIGITS} digits (float64 is "
                             f"~16), got {cfg.precision}")
        if cfg.samples > MAX_MP_SCULLING_SAMPLES:
            raise InputError(f"{cfg.samples} samples in arbitrary precision; at most "
                             f"{MAX_MP_SCULLING_SAMPLES} (shorten --duration or lower the rate)")


def _increment_velocity_algorithms() -> tuple[str, ...]:
    """The registered increment families with an N-subsample velocity counterpart (asked of
    each family: :meth:`~strapdown.algorithms.family.Family.velocity`)."""
    from strapdown.algorithms.spec import REGISTRY, AlgorithmSpec

    return tuple(name for name, fam in REGISTRY.items()
                 if fam.input_kind == "increment" and fam.coning_sets
                 and fam.velocity(AlgorithmSpec(name)) is not None)


def _validate_increment_velocity(cfg: EvaluationConfig, what: str) -> None:
    """The increment velocity algorithm's structure, coefficients and N (``what``: the
    motion, for the message)."""
    from strapdown.algorithms.coning import MAX_SUBSAMPLES

    fam = cfg.spec.family
    if not cfg.spec.update_structure.runs_velocity:
        raise InputError(f"the velocity algorithms run in the {' or '.join(nav_structures())} "
                         f"structure, not {cfg.structure}")
    if cfg.coefficients not in (None, fam.default_coefficients):
        raise InputError(f"the velocity algorithms use the designer's sets (coning: "
                         f"{fam.default_coefficients}); coefficients {cfg.coefficients} do not "
                         f"apply to {what}")
    if not 1 <= cfg.subsamples <= MAX_SUBSAMPLES:
        raise InputError(f"N (subsamples) must be 1–{MAX_SUBSAMPLES} for the velocity "
                         f"algorithms, got {cfg.subsamples}")


def _validate_rate(cfg: EvaluationConfig) -> None:
    """The rate-input duals (:func:`strapdown.navigation.inertial.integrate_inertial_rates`):
    their own structure only (conventional), coefficients derived or paper, float64."""
    if cfg.spec.family.velocity(cfg.spec) is None:  # an interleaved structure (sliding)
        raise InputError(f"the rate-input velocity algorithms have one structure (an update "
                         f"every td or 3 td), not {cfg.structure}")
    if cfg.precision is not None:
        raise InputError(f"{cfg.algorithm} on the sculling motion runs in float64 only; "
                         "drop --precision")


def build_sculling(cfg: EvaluationConfig) -> ScullingMotion:
    """The classical-sculling motion a configuration names (SI units)."""
    return classical_sculling(math.radians(cfg.angle_amplitude_deg),
                              2 * math.pi * cfg.frequency_hz, cfg.accel_amplitude,
                              math.radians(cfg.phase_deg))


@dataclass(frozen=True)
class ScullingEvaluation:
    """Result of :func:`evaluate_sculling` (m/s, m, s).

    ``t`` output times, ``dv``/``dp`` navigation-frame velocity and position errors
    (computed − exact), ``rate`` the rectified velocity-error rate (m/s²) and ``predicted``
    the law's, ``rate_method``/``rate_points`` how the rate was fitted.
    """

    config: EvaluationConfig
    t: NDArray[np.float64]
    dv: NDArray[np.float64]
    dp: NDArray[np.float64]
    rate: NDArray[np.float64]
    rate_method: str
    rate_points: int
    predicted: NDArray[np.float64] | None
    update_period: float
    samples: int
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def measured_over_law(self) -> float | None:
        """Measured / law along the law's axis (navigation z for sculling, x for coning in
        a force; None without a law or with a zero law)."""
        if self.predicted is None or not np.any(self.predicted):
            return None
        k = int(np.argmax(np.abs(self.predicted)))
        return float(self.rate[k] / self.predicted[k])

    def to_dict(self) -> dict[str, Any]:
        """The documented JSON record."""
        c = self.config
        return {
            "motion": c.motion, "algorithm": c.algorithm, "structure": c.structure,
            "subsamples": c.subsamples,
            "coefficients": c.coefficients or c.spec.family.default_coefficients,
            "precision_digits": c.precision,
            "angle_amplitude_deg": c.angle_amplitude_deg, "accel_amplitude_m_s2": c.accel_amplitude,
            "frequency_hz": c.frequency_hz, "phase_deg": c.phase_deg,
            "velocity_error_rate_m_s2": [float(x) for x in self.rate],
            "predicted_velocity_error_rate_m_s2": (
                None if self.predicted is None else [float(x) for x in self.predicted]),
            "velocity_rate_over_law": self.measured_over_law,
            "velocity_rate_method": self.rate_method, "velocity_rate_points": self.rate_points,
            "max_velocity_error_m_s": float(np.max(np.linalg.norm(self.dv, axis=1))),
            "max_position_error_m": float(np.max(np.linalg.norm(self.dp, axis=1))),
            "update_period_s": self.update_period, "samples": self.samples,
        } | self.extra


def _errors(cfg: EvaluationConfig, motion: ScullingMotion, h: float,
            samples: int) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                   NDArray[np.float64], int, float]:
    """Output times, velocity and position errors, first steady output, update period."""
    structure = cast(NavStructure, cfg.structure)  # validate_sculling: one of NAV_STRUCTURES
    if cfg.algorithm in rate_velocity_algorithms():
        t_s = np.arange(samples) * h
        sol = integrate_inertial_rates(motion.rate(t_s), motion.specific_force(t_s), td=h,
                                       coefficients=cfg.coefficients or "derived",
                                       algorithm=cfg.algorithm, q0=motion.attitude(0.0))
        return (sol.t, sol.v - motion.velocity(sol.t), sol.p - motion.position(sol.t), 0,
                sol.update_period)
    if cfg.precision is not None:
        s = integrate_inertial_mp(motion, cfg.subsamples, h=h, samples=samples,
                                  digits=cfg.precision, structure=structure)
        period = cfg.spec.update_structure.update_period(cfg.subsamples, h)
        return s.t, s.dv, s.dp, s.startup, period
    edges = np.arange(samples + 1) * h
    sol = integrate_inertial(motion.increments(edges), motion.velocity_increments(edges),
                             cfg.subsamples, h=h, structure=structure,
                             q0=motion.attitude(0.0))
    return (sol.t, sol.v - motion.velocity(sol.t), sol.p - motion.position(sol.t),
            sol.startup, sol.update_period)


def evaluate_sculling(cfg: EvaluationConfig) -> ScullingEvaluation:
    """Run the velocity algorithm on the exact classical-sculling motion and measure its
    rectified velocity-error rate (module docstring); ``cfg.motion == "sculling"``."""
    validate_sculling(cfg)
    motion = build_sculling(cfg)
    h, samples = cfg.h, cfg.samples
    t, dv, dp, start, period = _errors(cfg, motion, h, samples)
    vib = 2 * math.pi / abs(motion.frequency)
    ref = max(t[start], vib) if t[-1] >= 2 * vib else t[start]
    sel = t >= ref - 1e-9 * vib
    if np.count_nonzero(sel) < 2:
        sel = np.ones(t.size, dtype=bool)
    est = drift_rate(t[sel], dv[sel], period=vib, reference_time=ref, h=period)
    rate_input = cfg.algorithm in rate_velocity_algorithms()
    law = (rate_sculling_law(cfg.coefficients or "derived", cfg.algorithm) if rate_input
           else sculling_law(cfg.subsamples)).predict(
        math.radians(cfg.angle_amplitude_deg), cfg.accel_amplitude, math.radians(cfg.phase_deg),
        2 * math.pi * cfg.frequency_hz, h)
    predicted = np.array([0.0, 0.0, law])
    extra = {} if rate_input else {
        "velocity_set": effective_velocity_set(cast(NavStructure, cfg.structure))}
    return ScullingEvaluation(cfg, t, dv, dp, np.asarray(est.rate, dtype=np.float64),
                              est.method, est.points, predicted, period, samples, extra)


# ------------------------------------------------------------ coning in a constant force
def validate_coning_force(cfg: EvaluationConfig) -> None:
    """What the coning-in-force motion takes: the increment velocity algorithms (``rotvec``,
    conventional or single-chain, N = 1–6, default sets), ideal sensors, a finite half angle
    within ±90° and a non-zero cone rate resolved by the sample rate, a finite force; in
    arbitrary precision the limits of :func:`validate_sculling`."""
    from strapdown.algorithms.coning import MAX_SUBSAMPLES

    if cfg.algorithm not in _increment_velocity_algorithms():
        raise InputError(f"the coning-force motion runs the increment velocity algorithms "
                         f"({', '.join(_increment_velocity_algorithms())}, N = 1–"
                         f"{MAX_SUBSAMPLES}); {cfg.algorithm} has no law here")
    _validate_increment_velocity(cfg, "this motion")
    if cfg.gyro is not None and not cfg.gyro.is_ideal:
        raise InputError("the coning-force motion takes ideal sensors only (no gyro errors)")
    a = _finite("half angle (deg)", cfg.half_angle_deg)
    if not abs(a) < 90.0:
        raise InputError(f"half angle must be within ±90° for coning in a force, got {a:g}")
    _finite("force along the cone axis (m/s²)", cfg.accel_amplitude)
    f = _finite("cone rate (Hz)", cfg.cone_rate_hz)
    if f == 0.0:
        raise InputError("cone rate must be non-zero")
    if not 2 * math.pi * abs(f) / cfg.sample_rate_hz <= math.pi:
        raise InputError(f"the cone rate {f:g} Hz is above half the sample rate "
                         f"({cfg.sample_rate_hz:g} Hz; Nyquist)")
    if cfg.precision is not None:
        if cfg.precision < MIN_DIGITS:
            raise InputError(f"precision must be at least {MIN_DIGITS} digits (float64 is "
                             f"~16), got {cfg.precision}")
        if cfg.samples > MAX_MP_SCULLING_SAMPLES:
            raise InputError(f"{cfg.samples} samples in arbitrary precision; at most "
                             f"{MAX_MP_SCULLING_SAMPLES} (shorten --duration or lower the rate)")


def build_coning_force(cfg: EvaluationConfig):
    """The coning-in-force motion a configuration names (SI units; force along the cone
    axis, navigation x)."""
    from strapdown.truth.coning_force import ConingInForce

    return ConingInForce(math.radians(cfg.half_angle_deg), 2 * math.pi * cfg.cone_rate_hz,
                         (float(cfg.accel_amplitude), 0.0, 0.0))


def evaluate_coning_force(cfg: EvaluationConfig) -> ScullingEvaluation:
    """The velocity algorithm on a body coning in a constant specific force (module
    docstring): rectified velocity-error rate (m/s², navigation frame; the cone axis is x)
    against the coning-in-force law, on whole cone periods from the first on."""
    validate_coning_force(cfg)
    motion = build_coning_force(cfg)
    t, dv, dp, start, period = _errors(cfg, motion, cfg.h, cfg.samples)
    cone = 2 * math.pi / abs(motion.cone_rate)
    ref = max(t[start], cone) if t[-1] >= 2 * cone else t[start]
    sel = t >= ref - 1e-9 * cone
    if np.count_nonzero(sel) < 2:
        sel = np.ones(t.size, dtype=bool)
    est = drift_rate(t[sel], dv[sel], period=cone, reference_time=ref, h=period)
    law = coning_force_law(cfg.subsamples, cast(NavStructure, cfg.structure)).predict(
        motion.half_angle, motion.axial_force(), motion.cone_rate, cfg.h)
    predicted = np.array([law, 0.0, 0.0])
    extra = {"half_angle_deg": cfg.half_angle_deg, "cone_rate_hz": cfg.cone_rate_hz,
             "force_along_cone_axis_m_s2": cfg.accel_amplitude,
             "velocity_set": effective_velocity_set(cast(NavStructure, cfg.structure))}
    return ScullingEvaluation(cfg, t, dv, dp, np.asarray(est.rate, dtype=np.float64),
                              est.method, est.points, predicted, period, cfg.samples, extra)
