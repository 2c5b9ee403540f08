"""One configuration end to end: motion → gyro → algorithm → analysis.

:func:`evaluate` is what ``strapdown evaluate`` runs. It returns an
:class:`Evaluation` whose :meth:`Evaluation.to_dict` gives the documented
JSON keys.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from strapdown import analysis
from strapdown._core.validation import positive, positive_int
from strapdown.algorithms.coning import MAX_SUBSAMPLES, CoefficientSet, coefficient_set
from strapdown.algorithms.precision import run_mp, run_rk4_mp, run_windowed_mp
from strapdown.algorithms.structures import STRUCTURES, run_structure
from strapdown.truth import sensors
from strapdown.truth.motions import ClassicalConing, KrylovMotion, Motion, PureSpin, SpinConing

__all__ = ["MOTIONS", "Evaluation", "EvaluationConfig", "build_motion", "evaluate"]

MOTIONS = ("coning", "spin", "spin-coning", "krylov")
ALGORITHMS = ("rotvec", "rate-single", "rate-three", "rk4", "miller", "panov", "power")
RATE_ALGORITHMS = ("rate-single", "rate-three", "rk4")
QUATERNION_ALGORITHMS = ("miller", "panov", "power")


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
    """

    motion: str = "coning"
    half_angle_deg: float = 1.0
    cone_rate_hz: float = 1.0
    spin_rate_dps: float = 0.0
    sample_rate_hz: float = 10_000.0
    duration: float = 2.0
    algorithm: str = "rotvec"
    subsamples: int = 3
    coefficients: str | None = None
    structure: str = "conventional"
    rk4_step: str = "2td"
    krylov_rates: tuple[float, float, float] = (0.15, 0.25, 0.05)
    alpha: float | None = None
    beta: float | None = None
    step: float | None = None
    exact_exp: bool = False
    precision: int | None = None
    gyro: sensors.GyroErrors | None = field(default=None)
    seed: int | None = None

    def validate(self) -> None:
        if self.motion not in MOTIONS:
            raise ValueError(f"unknown motion {self.motion!r}; choose one of {', '.join(MOTIONS)}")
        if self.algorithm not in ALGORITHMS:
            raise ValueError(
                f"unknown algorithm {self.algorithm!r}; choose one of {', '.join(ALGORITHMS)}"
            )
        if self.algorithm in QUATERNION_ALGORITHMS:
            if self.step is None:
                raise ValueError(f"{self.algorithm} needs --step (the computation step ΔT, s)")
            positive(self.step, "step")
            if self.precision is not None:
                raise ValueError(f"{self.algorithm} runs in float64 only; drop --precision")
            if self.coefficients is not None:
                raise ValueError(f"{self.algorithm} takes --alpha/--beta, not --coefficients")
            if self.beta is not None and self.algorithm != "miller":
                raise ValueError(f"{self.algorithm} has one coefficient (--alpha)")
        elif self.alpha is not None or self.beta is not None or self.exact_exp:
            raise ValueError("--alpha, --beta and --exact-exp belong to miller, panov and power")
        if self.algorithm in RATE_ALGORITHMS:
            from strapdown.algorithms import rate

            if self.structure not in rate.STRUCTURES[self.algorithm]:
                raise ValueError(
                    f"{self.algorithm} supports the structures "
                    f"{', '.join(rate.STRUCTURES[self.algorithm])}, not {self.structure!r}"
                )
            if self.algorithm == "rk4":
                if self.coefficients is not None:
                    raise ValueError("rk4 has no coefficients; drop --coefficients")
                if self.rk4_step not in rate.RK4_STEPS:
                    raise ValueError(f"rk4 step must be one of {', '.join(rate.RK4_STEPS)}")
            elif self.coefficients not in (None, *rate.COEFFICIENTS):
                raise ValueError(f"{self.algorithm} takes coefficients "
                                 f"{' or '.join(rate.COEFFICIENTS)}, not {self.coefficients!r}")
        elif self.algorithm in QUATERNION_ALGORITHMS:
            if self.structure != "conventional":
                raise ValueError(f"{self.algorithm} has the conventional structure only")
        elif self.structure not in STRUCTURES:
            raise ValueError(
                f"unknown structure {self.structure!r}; choose one of {', '.join(STRUCTURES)}"
            )
        positive(self.sample_rate_hz, "sample rate (Hz)")
        positive(self.duration, "duration (s)")
        n = positive_int(self.subsamples, "subsamples N")
        if n > MAX_SUBSAMPLES:
            raise ValueError(f"subsamples N must be at most {MAX_SUBSAMPLES}, got {n}")
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
        if self.precision is not None:
            positive_int(self.precision, "precision (digits)")
            if self.gyro is not None and not self.gyro.is_ideal:
                raise ValueError("arbitrary precision runs take ideal increments only")

    @property
    def h(self) -> float:
        return 1.0 / self.sample_rate_hz

    @property
    def resolved_coefficients(self) -> str | None:
        if self.coefficients is not None or self.algorithm in ("rk4", *QUATERNION_ALGORITHMS):
            return self.coefficients
        return "table3" if self.algorithm == "rotvec" else "derived"

    @property
    def samples(self) -> int:
        if self.algorithm in QUATERNION_ALGORITHMS:
            steps = round(self.duration / self.step)
            if steps < 1:
                raise ValueError(f"duration {self.duration} s is shorter than one step")
            return steps * (3 if self.algorithm == "miller" else 2)
        if self.algorithm in RATE_ALGORITHMS:
            n = round(self.duration * self.sample_rate_hz) + 1
            need = 4 if self.algorithm == "rate-three" else 3 if self.algorithm == "rk4" else 2
            if n < need:
                raise ValueError(f"duration {self.duration} s at {self.sample_rate_hz} Hz gives "
                                 f"{n} rate samples; {self.algorithm} needs at least {need}")
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
    """The reference motion a configuration names."""
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
    t: np.ndarray
    err: np.ndarray
    angle: np.ndarray
    chain: np.ndarray
    drift: analysis.DriftEstimate
    chain_drifts: tuple[analysis.DriftEstimate, ...]
    cone_axis: np.ndarray | None
    predicted: float | None
    update_period: float
    samples: int
    accumulated: np.ndarray | None = None

    @property
    def cone_axis_drift(self) -> float | None:
        if self.cone_axis is None:
            return None
        return float(self.drift.rate @ self.cone_axis)

    def to_dict(self) -> dict:
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
            **self._quaternion_coefficients(),
        }

    def _quaternion_coefficients(self) -> dict:
        c = self.config
        if c.algorithm not in QUATERNION_ALGORITHMS:
            return {}
        from strapdown.algorithms.quaternion import STATED

        a0, b0 = STATED[c.algorithm]
        return {"alpha": a0 if c.alpha is None else c.alpha,
                "beta": (b0 if c.beta is None else c.beta) if c.algorithm == "miller" else None,
                "exact_exp": c.exact_exp, "step_s": c.step}


def evaluate(cfg: EvaluationConfig, *, coefficients: CoefficientSet | None = None) -> Evaluation:
    """Run one configuration and analyse it.

    Parameters
    ----------
    cfg : EvaluationConfig
    coefficients : CoefficientSet, optional
        Overrides ``cfg.coefficients`` (e.g. a user matrix).
    """
    cfg.validate()
    motion = build_motion(cfg)
    if cfg.algorithm in RATE_ALGORITHMS:
        return _evaluate_rate(cfg, motion)
    if cfg.algorithm in QUATERNION_ALGORITHMS:
        return _evaluate_quaternion(cfg, motion)
    cs = coefficients or coefficient_set(cfg.resolved_coefficients, cfg.subsamples)
    if cs.n != cfg.subsamples:
        raise ValueError(f"coefficient set has N = {cs.n}, configuration says {cfg.subsamples}")
    h, n = cfg.h, cfg.samples
    if cfg.precision is not None:
        s = run_mp(motion, cs, structure=cfg.structure, h=h, samples=n, digits=cfg.precision)
        t, err, ang, chain, start = s.t, s.err, s.angle, s.chain, s.startup
    else:
        rec = sensors.increments(motion, h, n, errors=cfg.gyro, rng=cfg.seed)
        sol = run_structure(cfg.structure, rec.data, cs, h=h, q0=motion.attitude(0.0))
        err, ang = analysis.attitude_errors(sol.t, sol.q, motion)
        t, chain, start = sol.t, sol.chain, sol.startup
    predicted = None
    if cfg.motion == "coning" and cs.classical_optimum:
        predicted = analysis.table1_prediction(motion.half_angle, motion.cone_rate, h, cs.n)
    return _finish(cfg, motion, t, err, ang, chain, start, predicted,
                   analysis.update_period(cfg.structure, cs.n, h), n)


def _evaluate_rate(cfg: EvaluationConfig, motion: Motion) -> Evaluation:
    from strapdown.algorithms import rate

    h, n = cfg.h, cfg.samples
    coeffs = cfg.resolved_coefficients
    alg = cfg.algorithm
    sliding = cfg.structure == "sliding"
    if cfg.precision is not None:
        if alg == "rk4":
            s = run_rk4_mp(motion, h=h, samples=n, step=cfg.rk4_step, digits=cfg.precision)
        elif alg == "rate-single":
            s = run_windowed_mp(motion, rate.single_period_algorithm(coeffs), h=h, updates=n - 1,
                                digits=cfg.precision)
        elif sliding:
            s = run_windowed_mp(motion, rate.three_period_algorithm(coeffs), h=h, updates=n - 3,
                                digits=cfg.precision, sliding=True,
                                startup=rate.single_period_algorithm(coeffs))
        else:
            s = run_windowed_mp(motion, rate.three_period_algorithm(coeffs), h=h,
                                updates=(n - 1) // 3, digits=cfg.precision)
        t, err, ang, chain = s.t, s.err, s.angle, s.chain
    else:
        rec = sensors.rate_samples(motion, h, n, errors=cfg.gyro, rng=cfg.seed)
        sol = rate.rate_attitude(rec.t, rec.data, algorithm=alg, structure=cfg.structure,
                                 coefficients=coeffs or "derived", rk4_step=cfg.rk4_step,
                                 q0=motion.attitude(0.0))
        err, ang = analysis.attitude_errors(sol.t, sol.q, motion)
        t, chain = sol.t, sol.chain
    predicted = None
    if cfg.motion == "coning":
        order, c = rate.predicted_drift_law(alg, coefficients=coeffs or "derived",
                                            rk4_step=cfg.rk4_step)
        if order is not None:
            predicted = (-float(c) * motion.half_angle**2 * motion.cone_rate
                         * (motion.cone_rate * h) ** order)
    period = rate.update_period(alg, h, structure=cfg.structure, rk4_step=cfg.rk4_step)
    return _finish(cfg, motion, t, err, ang, chain, 0, predicted, period, n)


def _evaluate_quaternion(cfg: EvaluationConfig, motion: Motion) -> Evaluation:
    from strapdown.algorithms.quaternion import STATED, QuaternionAlgorithm, quaternion_attitude

    a0, b0 = STATED[cfg.algorithm]
    alg = QuaternionAlgorithm(cfg.algorithm, a0 if cfg.alpha is None else cfg.alpha,
                              b0 if cfg.beta is None else cfg.beta, cfg.exact_exp)
    n = cfg.samples
    sub = 3 if cfg.algorithm == "miller" else 2
    rec = sensors.increments(motion, cfg.step / sub, n, errors=cfg.gyro, rng=cfg.seed)
    sol = quaternion_attitude(rec.data, alg, step=cfg.step, q0=motion.attitude(0.0))
    err, ang = analysis.attitude_errors(sol.t, sol.q, motion)
    acc = analysis.accumulated_drift(sol.q, motion.attitude(sol.t))
    ev = _finish(cfg, motion, sol.t, err, ang, sol.chain, 0, None, cfg.step, n)
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
