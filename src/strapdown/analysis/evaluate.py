"""One configuration end to end: motion → gyro → algorithm → analysis.

:func:`evaluate` is what ``strapdown evaluate`` runs. It returns an
:class:`Evaluation` whose :meth:`Evaluation.to_dict` gives the documented
JSON keys.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, get_args

import numpy as np
from numpy.typing import NDArray

from strapdown import analysis
from strapdown._core.errors import InputError
from strapdown._core.kinds import InputKind
from strapdown._core.validation import positive, positive_int
from strapdown.algorithms.coning import CoefficientSet
from strapdown.algorithms.family import Rk4Step, StructureName
from strapdown.algorithms.precision import run_mp
from strapdown.algorithms.spec import (
    AlgorithmName,
    AlgorithmSpec,
    CoefficientName,
    algorithms_taking,
)
from strapdown.algorithms.structures import increment_structure, run_structure
from strapdown.analysis.law import LawResolution, judge_law
from strapdown.truth import sensors
from strapdown.truth.motions import ClassicalConing, KrylovMotion, Motion, PureSpin, SpinConing

if TYPE_CHECKING:
    from strapdown.analysis.sculling import ScullingEvaluation

__all__ = [
    "MAX_SAMPLES",
    "METRICS",
    "MOTIONS",
    "SCULLING_METRICS",
    "Evaluation",
    "EvaluationConfig",
    "MetricName",
    "MotionName",
    "build_motion",
    "evaluate",
    "run_evaluation",
]

#: The reference motions an evaluation runs on (see :func:`build_motion`).
MotionName = Literal["coning", "spin", "spin-coning", "krylov", "sculling"]
MOTIONS: tuple[MotionName, ...] = get_args(MotionName)
#: The numerical results of an evaluation: keys of :meth:`Evaluation.to_dict` a sweep may
#: tabulate.
MetricName = Literal["max_error_rad", "rms_error_rad", "cone_axis_drift_rad_s",
                     "predicted_drift_rad_s", "drift_rate_rad_s", "accumulated_drift_rad",
                     "update_period_s", "samples", "chain_cone_axis_drift_rad_s",
                     "drift_points", "measured_over_law", "law_status",
                     "velocity_error_rate_m_s2", "predicted_velocity_error_rate_m_s2",
                     "velocity_rate_over_law", "max_velocity_error_m_s",
                     "max_position_error_m"]
#: The metrics of the sculling motion (:mod:`strapdown.analysis.sculling`); the attitude
#: metrics belong to the other motions.
SCULLING_METRICS: tuple[MetricName, ...] = (
    "velocity_error_rate_m_s2", "predicted_velocity_error_rate_m_s2", "velocity_rate_over_law",
    "max_velocity_error_m_s", "max_position_error_m", "update_period_s", "samples")
METRICS: tuple[MetricName, ...] = get_args(MetricName)
RATE_ALGORITHMS = algorithms_taking("rate")
#: Most samples (or computation steps) one evaluation simulates: 10⁸ increments take
#: 2.4 GB as float64 with their truth.
MAX_SAMPLES = 1e8


@dataclass(frozen=True)
class EvaluationConfig:
    """Everything that defines one evaluation (SI units; degrees only where named).

    ``samples`` is ``round(duration · sample_rate)`` increments, reduced to a
    multiple of N for the conventional structure so every increment is used;
    for rate algorithms it is the number of rate samples covering
    ``[0, duration]`` (``round(duration · rate) + 1``). ``coefficients=None``
    means the algorithm's default: ``table3`` for ``rotvec`` (the
    classical-coning optimum), ``derived`` for the rate algorithms (the
    designer's set, quadrature error included); ``rk4`` has none.

    ``motion="sculling"`` is classical sculling (:mod:`strapdown.analysis.sculling`):
    ``angle_amplitude_deg`` θ0 about body x, ``accel_amplitude`` A (m/s²) along body y,
    ``frequency_hz`` Ω/2π, ``phase_deg`` ψ; it runs the velocity algorithms (``rotvec``,
    conventional or single-chain).
    """

    motion: MotionName = "coning"
    half_angle_deg: float = 1.0
    cone_rate_hz: float = 1.0
    spin_rate_dps: float = 0.0
    sample_rate_hz: float = 10_000.0
    duration: float = 2.0
    algorithm: AlgorithmName = "rotvec"
    subsamples: int = 3
    coefficients: CoefficientName | None = None
    structure: StructureName = "conventional"
    rk4_step: Rk4Step = "2td"
    krylov_rates: tuple[float, float, float] = (0.15, 0.25, 0.05)
    alpha: float | None = None
    beta: float | None = None
    step: float | None = None
    exact_exp: bool = False
    precision: int | None = None
    gyro: sensors.GyroErrors | None = field(default=None)
    seed: int | None = None
    angle_amplitude_deg: float = 1.0
    accel_amplitude: float = 10.0
    frequency_hz: float = 10.0
    phase_deg: float = 0.0

    @property
    def spec(self) -> AlgorithmSpec:
        """The configured algorithm (validated)."""
        return AlgorithmSpec(self.algorithm, subsamples=self.subsamples,
                             coefficients=self.coefficients, structure=self.structure,
                             rk4_step=self.rk4_step, alpha=self.alpha, beta=self.beta,
                             step=self.step, exact_exp=self.exact_exp)

    def validate(self) -> None:
        if self.motion not in MOTIONS:
            raise ValueError(f"unknown motion {self.motion!r}; choose one of {', '.join(MOTIONS)}")
        spec = self.spec
        if self.precision is not None:
            if spec.family.stepped:  # the quaternion algorithms: float64 only
                raise ValueError(f"{self.algorithm} runs in float64 only; drop --precision")
            positive_int(self.precision, "precision (digits)")
            if self.gyro is not None and not self.gyro.is_ideal:
                raise ValueError("arbitrary precision runs take ideal increments only")
        positive(self.sample_rate_hz, "sample rate (Hz)")
        positive(self.duration, "duration (s)")
        if self.motion == "sculling":
            from strapdown.analysis.sculling import validate_sculling

            self._validate_limits()
            validate_sculling(self)
            return
        self._validate_motion()
        self._validate_limits()

    def _validate_limits(self) -> None:
        """Sizes and rates the simulation can represent (checked before anything is
        allocated): at most :data:`MAX_SAMPLES` samples (or steps), and no motion rate that
        turns the body by more than π in one sample (beyond Nyquist nothing is resolved)."""
        n = self.duration * self.sample_rate_hz
        if self.step is not None:
            positive(self.step, "step (s)")
            n = max(n, self.duration / self.step)
        if not n <= MAX_SAMPLES:
            raise InputError(f"duration {self.duration:g} s at {self.sample_rate_hz:g} Hz gives "
                             f"{n:.3g} samples; at most {MAX_SAMPLES:.0e} per evaluation")
        h = 1.0 / self.sample_rate_hz
        rates = {"cone rate": 2 * math.pi * abs(self.cone_rate_hz),
                 "spin rate": math.radians(abs(self.spin_rate_dps))}
        if self.motion == "sculling":  # validate_sculling checks the vibration
            return
        if self.motion == "krylov":
            rates = {"krylov rate": max(abs(float(k)) for k in self.krylov_rates)}
        for what, w in rates.items():
            if not w * h <= math.pi:
                raise InputError(f"the {what} turns {w * h:.3g} rad in one sample at "
                                 f"{self.sample_rate_hz:g} Hz; at most π (Nyquist)")
        if self.motion != "spin" and self.motion != "krylov" and not abs(
                self.half_angle_deg) <= 180.0:
            raise InputError(f"half angle must be within ±180°, got {self.half_angle_deg:g}")

    def _validate_motion(self) -> None:
        if self.motion == "krylov":
            if len(self.krylov_rates) != 3 or not all(map(math.isfinite, self.krylov_rates)):
                raise ValueError(f"--krylov-rates needs three finite numbers, got "
                                 f"{self.krylov_rates}")
        elif self.motion != "spin":
            if not math.isfinite(self.cone_rate_hz) or self.cone_rate_hz == 0:
                raise ValueError(f"cone rate must be finite and non-zero, got {self.cone_rate_hz}")
            if not math.isfinite(self.half_angle_deg):
                raise ValueError(f"half angle must be finite, got {self.half_angle_deg}")
        if not math.isfinite(self.spin_rate_dps):
            raise ValueError(f"spin rate must be finite, got {self.spin_rate_dps}")

    @property
    def h(self) -> float:
        return 1.0 / self.sample_rate_hz

    @property
    def resolved_coefficients(self) -> CoefficientName | None:
        return self.spec.resolved_coefficients

    def _step(self) -> float:
        """The computation step ΔT (s) of the quaternion algorithms (ValueError without one)."""
        if self.step is None:
            raise ValueError(f"{self.algorithm} needs --step (the computation step ΔT, s)")
        return self.step

    @property
    def samples(self) -> int:
        spec = self.spec
        if spec.family.stepped:  # whole computation steps of sub-interval increments
            steps = round(self.duration / self._step())
            if steps < 1:
                raise ValueError(f"duration {self.duration} s is shorter than one step")
            return steps * spec.min_samples
        if spec.input_kind == "rate":
            n = round(self.duration * self.sample_rate_hz) + 1
            if n < spec.min_samples:
                raise ValueError(f"duration {self.duration} s at {self.sample_rate_hz} Hz gives "
                                 f"{n} rate samples; {self.algorithm} needs at least "
                                 f"{spec.min_samples}")
            return n
        n = round(self.duration * self.sample_rate_hz)
        if self.structure == "conventional":
            n -= n % self.subsamples
        if n < self.subsamples:
            raise ValueError(
                f"duration {self.duration} s at {self.sample_rate_hz} Hz gives {n} samples, "
                f"fewer than N = {self.subsamples}"
            )
        return n


def build_motion(cfg: EvaluationConfig) -> Motion:
    """The reference motion a configuration names (the sculling motion:
    :func:`strapdown.analysis.sculling.build_sculling`)."""
    if cfg.motion == "sculling":
        raise InputError("the sculling motion drives the velocity algorithms; evaluate it "
                         "with strapdown.analysis.evaluate.run_evaluation")
    if cfg.motion == "krylov":
        return KrylovMotion(*map(float, cfg.krylov_rates))
    a = math.radians(cfg.half_angle_deg)
    om = 2.0 * math.pi * cfg.cone_rate_hz
    ws = math.radians(cfg.spin_rate_dps)
    if cfg.motion == "coning":
        return ClassicalConing(a, om)
    if cfg.motion == "spin":
        if ws == 0:
            raise ValueError("pure spin needs a non-zero --spin-rate-dps")
        return PureSpin(ws)
    return SpinConing(a, om, ws)


@dataclass(frozen=True)
class Evaluation:
    """Result of :func:`evaluate` (rad, s)."""

    config: EvaluationConfig
    t: NDArray[np.float64]
    err: NDArray[np.float64]
    angle: NDArray[np.float64]
    chain: NDArray[np.int_]
    drift: analysis.DriftEstimate
    chain_drifts: tuple[analysis.DriftEstimate, ...]
    cone_axis: NDArray[np.float64] | None
    predicted: float | None
    update_period: float
    samples: int
    accumulated: NDArray[np.float64] | None = None

    @property
    def cone_axis_drift(self) -> float | None:
        if self.cone_axis is None:
            return None
        return float(self.drift.rate @ self.cone_axis)

    def to_dict(self) -> dict[str, Any]:
        """The documented JSON record."""
        c = self.config
        return {
            "motion": c.motion,
            "algorithm": c.algorithm,
            "structure": c.structure,
            "subsamples": c.subsamples,
            "coefficients": c.resolved_coefficients,
            "precision_digits": c.precision,
            "drift_rate_rad_s": [float(x) for x in self.drift.rate],
            "cone_axis_drift_rad_s": self.cone_axis_drift,
            "predicted_drift_rad_s": self.predicted,
            "drift_method": self.drift.method,
            "drift_points": self.drift.points,
            "chain_cone_axis_drift_rad_s": (
                None if self.cone_axis is None
                else [float(d.rate @ self.cone_axis) for d in self.chain_drifts]
            ),
            "max_error_rad": float(self.angle.max()),
            "rms_error_rad": float(np.sqrt(np.mean(self.angle**2))),
            "update_period_s": self.update_period,
            "samples": self.samples,
            "accumulated_drift_rad": (None if self.accumulated is None
                                      else float(self.accumulated.max())),
            **self._law_keys(),
            **self._quaternion_coefficients(),
        }

    def law(self) -> LawResolution:
        """Whether the measured/law ratio means anything (:func:`~.law.judge_law`)."""
        c = self.config
        return judge_law(self.cone_axis_drift, self.predicted,
                         half_angle=math.radians(c.half_angle_deg), duration=c.duration,
                         updates=max(1.0, c.duration / self.update_period),
                         digits=c.precision, ideal_gyro=c.gyro is None or c.gyro.is_ideal)

    def _law_keys(self) -> dict[str, Any]:
        res = self.law()
        return {"measured_over_law": res.ratio, "law_status": res.status,
                "law_floor_rad_s": res.floor, "law_note": res.note or None}

    def _quaternion_coefficients(self) -> dict[str, Any]:
        from strapdown.algorithms.quaternion import ALGORITHMS, STATED

        c = self.config
        name = c.algorithm
        if not c.spec.family.stepped or name not in ALGORITHMS:
            return {}
        a0, b0 = STATED[name]
        return {"alpha": a0 if c.alpha is None else c.alpha,
                "beta": (b0 if c.beta is None else c.beta) if c.algorithm == "miller" else None,
                "exact_exp": c.exact_exp, "step_s": c.step}


def run_evaluation(cfg: EvaluationConfig) -> Evaluation | ScullingEvaluation:
    """:func:`evaluate`, or for ``motion="sculling"``
    :func:`strapdown.analysis.sculling.evaluate_sculling` (what ``strapdown evaluate``,
    ``compare`` and ``sweep`` run)."""
    if cfg.motion == "sculling":
        from strapdown.analysis.sculling import evaluate_sculling

        cfg.validate()
        return evaluate_sculling(cfg)
    return evaluate(cfg)


def evaluate(cfg: EvaluationConfig, *, coefficients: CoefficientSet | None = None) -> Evaluation:
    """Run one configuration and analyse it (an attitude motion; the sculling motion:
    :func:`run_evaluation`).

    Parameters
    ----------
    cfg : EvaluationConfig
    coefficients : CoefficientSet, optional
        Overrides ``cfg.coefficients`` of a ``rotvec`` configuration (e.g. a user matrix).
    """
    cfg.validate()
    motion = build_motion(cfg)
    spec = cfg.spec
    if coefficients is not None:
        return _evaluate_user_set(cfg, motion, coefficients)
    if spec.family.stepped:
        return _evaluate_quaternion(cfg, motion)
    h, n = cfg.h, cfg.samples
    if cfg.precision is not None:
        s = spec.run_mp(motion, h=h, samples=n, digits=cfg.precision)
        t, err, ang, chain, start = s.t, s.err, s.angle, s.chain, s.startup
    else:
        sol = spec.run(_gyro(cfg, motion, spec.input_kind, h, n), q0=motion.attitude(0.0))
        err, ang = analysis.attitude_errors(sol.t, sol.q, motion)
        t, chain, start = sol.t, sol.chain, sol.startup
    law = spec.drift_law()
    predicted = None
    if isinstance(motion, ClassicalConing) and law is not None:  # cfg.motion == "coning"
        predicted = law.predict(motion.half_angle, motion.cone_rate, h)
    return _finish(cfg, motion, t, err, ang, chain, start, predicted, spec.update_period(h), n)


def _gyro(cfg: EvaluationConfig, motion: Motion, kind: InputKind, h: float,
          n: int) -> sensors.GyroRecord:
    if kind == "rate":
        return sensors.rate_samples(motion, h, n, errors=cfg.gyro, rng=cfg.seed)
    return sensors.increments(motion, h, n, errors=cfg.gyro, rng=cfg.seed)


def _evaluate_user_set(cfg: EvaluationConfig, motion: Motion, cs: CoefficientSet) -> Evaluation:
    """A rotation-vector configuration with a user's coefficient set."""
    if cfg.algorithm != "rotvec":
        raise ValueError(f"a coefficient set overrides rotvec configurations, not "
                         f"{cfg.algorithm}")
    if cs.n != cfg.subsamples:
        raise ValueError(f"coefficient set has N = {cs.n}, configuration says {cfg.subsamples}")
    h, n = cfg.h, cfg.samples
    if cfg.precision is not None:
        s = run_mp(motion, cs, structure=increment_structure(cfg.structure), h=h, samples=n,
                   digits=cfg.precision)
        t, err, ang, chain, start = s.t, s.err, s.angle, s.chain, s.startup
    else:
        rec = sensors.increments(motion, h, n, errors=cfg.gyro, rng=cfg.seed)
        sol = run_structure(increment_structure(cfg.structure), rec.data, cs, h=h,
                            q0=motion.attitude(0.0))
        err, ang = analysis.attitude_errors(sol.t, sol.q, motion)
        t, chain, start = sol.t, sol.chain, sol.startup
    predicted = None
    if isinstance(motion, ClassicalConing) and cs.classical_optimum:  # cfg.motion == "coning"
        predicted = analysis.table1_prediction(motion.half_angle, motion.cone_rate, h, cs.n)
    return _finish(cfg, motion, t, err, ang, chain, start, predicted,
                   cfg.spec.update_period(h), n)


def _evaluate_quaternion(cfg: EvaluationConfig, motion: Motion) -> Evaluation:
    spec = cfg.spec
    n = cfg.samples
    rec = sensors.increments(motion, cfg._step() / spec.min_samples, n, errors=cfg.gyro,
                             rng=cfg.seed)
    sol = spec.run_increments(rec.data, h=cfg._step() / spec.min_samples,
                              q0=motion.attitude(0.0))
    err, ang = analysis.attitude_errors(sol.t, sol.q, motion)
    acc = analysis.accumulated_drift(sol.q, motion.attitude(sol.t))
    ev = _finish(cfg, motion, sol.t, err, ang, sol.chain, 0, None, cfg._step(), n)
    return dataclasses.replace(ev, accumulated=acc)


def _finish(cfg, motion, t, err, ang, chain, start, predicted, update_period, samples):
    # drift from the first steady-state output on (a start-up transient is a step, not a drift)
    chains = analysis.chain_drift_rate(t[start:], err[start:], chain[start:],
                                       period=motion.period)
    if len(chains) == 1:
        drift = chains[0]
    else:
        drift = analysis.DriftEstimate(
            np.mean([d.rate for d in chains], axis=0),
            chains[0].method + f" (mean of {len(chains)} chains)",
            sum(d.points for d in chains),
        )
    return Evaluation(
        config=cfg, t=t, err=err, angle=ang, chain=chain, drift=drift, chain_drifts=chains,
        cone_axis=motion.cone_axis, predicted=predicted, update_period=update_period,
        samples=samples,
    )
