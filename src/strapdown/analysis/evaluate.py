"""One configuration end to end: motion → gyro → algorithm → analysis.

:func:`evaluate` is what ``strapdown evaluate`` runs. It returns an
:class:`Evaluation` whose :meth:`Evaluation.to_dict` gives the documented
JSON keys.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, get_args

import numpy as np
from numpy.typing import NDArray

from strapdown import analysis
from strapdown._core.errors import InputError
from strapdown._core.kinds import InputKind
from strapdown._core.validation import positive, positive_int
from strapdown.algorithms.coning import CoefficientSet
from strapdown.algorithms.precision import run_mp
from strapdown.algorithms.spec import (
    AlgorithmSpec,
    CoefficientName,
    parse_spec,
)
from strapdown.algorithms.structures import increment_structure, run_structure
from strapdown.analysis.law import LawResolution, judge_law
from strapdown.truth import sensors
from strapdown.truth.motions import ClassicalConing, KrylovMotion, Motion, PureSpin, SpinConing

if TYPE_CHECKING:
    from strapdown.analysis.sculling import ScullingEvaluation

__all__ = [
    "CONFIG_FIELDS",
    "MAX_SAMPLES",
    "METRICS",
    "MOTIONS",
    "MOTION_REGISTRY",
    "SCULLING_METRICS",
    "SPEC_FIELDS",
    "Evaluation",
    "EvaluationConfig",
    "MetricName",
    "MotionKind",
    "MotionName",
    "build_motion",
    "evaluate",
    "motion_kind",
    "register_motion",
    "run_evaluation",
]

#: The reference motions of the shipped registry (:data:`MOTION_REGISTRY`).
MotionName = Literal["coning", "spin", "spin-coning", "krylov", "sculling", "coning-force"]
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
#: Most samples (or computation steps) one evaluation simulates: 10⁸ increments take
#: 2.4 GB as float64 with their truth.
MAX_SAMPLES = 1e8
#: The spec fields an evaluation's configuration reads through its :class:`AlgorithmSpec`
#: (they may be given flat to :meth:`EvaluationConfig.of`, a sweep's scenario …).
SPEC_FIELDS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(AlgorithmSpec))


@dataclass(frozen=True)
class MotionKind:
    """A registered reference motion: what it checks, its truth, its law and its runner.

    Attributes
    ----------
    name : str
        Registry name (``--motion``, ``motion =`` of a scenario).
    truth : callable (EvaluationConfig) -> Motion, or None
        The closed-form motion a configuration names (None: the motion has its own runner).
    check : callable (EvaluationConfig) -> None
        Its parameters' checks (ValueError/InputError naming the problem).
    rates : callable (EvaluationConfig) -> dict[str, float]
        Its rates (rad/s) by name, held to Nyquist (at most π per sample).
    cone : bool
        Whether it has a half cone angle (held to ±180°).
    law : callable (AlgorithmSpec, Motion, float) -> float or None
        The drift (rad/s about its cone axis) the algorithm's law predicts at samples every
        ``h`` seconds, where the motion has one.
    user_law : callable (CoefficientSet, Motion, float) -> float or None
        The same for a user's coefficient set.
    runner : callable (EvaluationConfig) -> Evaluation-like, or None
        An evaluation of its own (None: :func:`evaluate`, attitude against ``truth``).
    metrics : tuple of MetricName, or None
        The metrics it has (None: the attitude metrics, every one but the velocity ones).
    """

    name: str
    truth: Callable[[EvaluationConfig], Motion] | None
    check: Callable[[EvaluationConfig], None]
    rates: Callable[[EvaluationConfig], dict[str, float]]
    cone: bool = False
    law: Callable[[AlgorithmSpec, Motion, float], float | None] = lambda spec, m, h: None
    user_law: Callable[[CoefficientSet, Motion, float], float | None] = lambda cs, m, h: None
    runner: Callable[[EvaluationConfig], Any] | None = None
    metrics: tuple[MetricName, ...] | None = None

    def has_metric(self, metric: str) -> bool:
        """Whether an evaluation on this motion reports ``metric``."""
        if self.metrics is not None:
            return metric in self.metrics
        return metric not in set(SCULLING_METRICS) - {"update_period_s", "samples"}


def _finite_spin(cfg: EvaluationConfig) -> None:
    if not math.isfinite(cfg.spin_rate_dps):
        raise ValueError(f"spin rate must be finite, got {cfg.spin_rate_dps}")


def _check_cone(cfg: EvaluationConfig) -> None:
    if not math.isfinite(cfg.cone_rate_hz) or cfg.cone_rate_hz == 0:
        raise ValueError(f"cone rate must be finite and non-zero, got {cfg.cone_rate_hz}")
    if not math.isfinite(cfg.half_angle_deg):
        raise ValueError(f"half angle must be finite, got {cfg.half_angle_deg}")
    _finite_spin(cfg)


def _check_krylov(cfg: EvaluationConfig) -> None:
    if len(cfg.krylov_rates) != 3 or not all(map(math.isfinite, cfg.krylov_rates)):
        raise ValueError(f"--krylov-rates needs three finite numbers, got {cfg.krylov_rates}")
    _finite_spin(cfg)


def _cone_rates(cfg: EvaluationConfig) -> dict[str, float]:
    return {"cone rate": 2 * math.pi * abs(cfg.cone_rate_hz),
            "spin rate": math.radians(abs(cfg.spin_rate_dps))}


def _cone(cfg: EvaluationConfig) -> tuple[float, float, float]:
    """(half angle rad, cone rate rad/s, spin rate rad/s)."""
    return (math.radians(cfg.half_angle_deg), 2.0 * math.pi * cfg.cone_rate_hz,
            math.radians(cfg.spin_rate_dps))


def _pure_spin(cfg: EvaluationConfig) -> Motion:
    ws = math.radians(cfg.spin_rate_dps)
    if ws == 0:
        raise ValueError("pure spin needs a non-zero --spin-rate-dps")
    return PureSpin(ws)


def _coning_law(spec: AlgorithmSpec, motion: Motion, h: float) -> float | None:
    law = spec.drift_law()
    if not isinstance(motion, ClassicalConing) or law is None:
        return None
    return law.predict(motion.half_angle, motion.cone_rate, h)


def _coning_user_law(cs: CoefficientSet, motion: Motion, h: float) -> float | None:
    if not isinstance(motion, ClassicalConing) or not cs.classical_optimum:
        return None
    return analysis.table1_prediction(motion.half_angle, motion.cone_rate, h, cs.n)


def _no_truth(cfg: EvaluationConfig) -> Motion:
    raise InputError(f"the {cfg.motion} motion drives the velocity algorithms; evaluate it "
                     "with strapdown.analysis.evaluate.run_evaluation")


def _check_sculling(cfg: EvaluationConfig) -> None:
    from strapdown.analysis.sculling import validate_sculling

    validate_sculling(cfg)


def _run_sculling(cfg: EvaluationConfig) -> Any:
    from strapdown.analysis.sculling import evaluate_sculling

    return evaluate_sculling(cfg)


#: Every registered reference motion by name, in the order the command line lists them.
#: Add one with :func:`register_motion` (its truth, checks, rates and law).
MOTION_REGISTRY: dict[str, MotionKind] = {}


def register_motion(kind: MotionKind) -> MotionKind:
    """Add a reference motion to the registry (its name must be new)."""
    global MOTIONS
    if not isinstance(kind, MotionKind):
        raise ValueError(f"a motion must be a MotionKind, got {type(kind).__name__}")
    if kind.name in MOTION_REGISTRY:
        raise ValueError(f"a motion named {kind.name!r} is already registered")
    MOTION_REGISTRY[kind.name] = kind
    MOTIONS = tuple(MOTION_REGISTRY)
    return kind


def motion_kind(name: object) -> MotionKind:
    """The registered motion ``name`` (ValueError listing them)."""
    found = MOTION_REGISTRY.get(name) if isinstance(name, str) else None
    if found is None:
        raise ValueError(f"unknown motion {name!r}; choose one of {', '.join(MOTIONS)}")
    return found


MOTIONS: tuple[str, ...] = ()
register_motion(MotionKind("coning", lambda c: ClassicalConing(*_cone(c)[:2]), _check_cone,
                           _cone_rates, cone=True, law=_coning_law, user_law=_coning_user_law))
register_motion(MotionKind("spin", _pure_spin, _finite_spin, _cone_rates))
register_motion(MotionKind("spin-coning", lambda c: SpinConing(*_cone(c)), _check_cone,
                           _cone_rates, cone=True))
register_motion(MotionKind("krylov", lambda c: KrylovMotion(*map(float, c.krylov_rates)),
                           _check_krylov,
                           lambda c: {"krylov rate": max(abs(float(k)) for k in c.krylov_rates)}))
register_motion(MotionKind("sculling", None, _check_sculling, lambda c: {},
                           runner=_run_sculling, metrics=SCULLING_METRICS))


def _check_coning_force(cfg: EvaluationConfig) -> None:
    from strapdown.analysis.sculling import validate_coning_force

    validate_coning_force(cfg)


def _run_coning_force(cfg: EvaluationConfig) -> Any:
    from strapdown.analysis.sculling import evaluate_coning_force

    return evaluate_coning_force(cfg)


# a body coning in a constant specific force (strapdown.analysis.sculling, issue 26)
register_motion(MotionKind("coning-force", None, _check_coning_force, _cone_rates, cone=True,
                           runner=_run_coning_force, metrics=SCULLING_METRICS))
if tuple(MOTION_REGISTRY) != get_args(MotionName):  # the shipped motions: one list of names
    raise RuntimeError(f"the motions {tuple(MOTION_REGISTRY)} and MotionName "
                       f"{get_args(MotionName)} disagree")


@dataclass(frozen=True)
class EvaluationConfig:
    """Everything that defines one evaluation (SI units; degrees only where named): a
    registered motion with its parameters, the sensor, and the algorithm — an
    :class:`~strapdown.algorithms.spec.AlgorithmSpec` (``spec``).

    ``samples`` is ``round(duration · sample_rate)`` increments, reduced to whole updates
    where the structure needs them (the conventional structure) so every increment is used;
    for rate algorithms it is the number of rate samples covering
    ``[0, duration]`` (``round(duration · rate) + 1``). The spec's ``coefficients=None``
    means the algorithm's default: ``table3`` for ``rotvec`` (the classical-coning
    optimum), ``derived`` for the rate algorithms (the designer's set, quadrature error
    included); ``rk4`` has none. :meth:`of` takes the spec's fields flat.

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
    spec: AlgorithmSpec = field(default_factory=AlgorithmSpec)
    krylov_rates: tuple[float, float, float] = (0.15, 0.25, 0.05)
    precision: int | None = None
    gyro: sensors.GyroErrors | None = field(default=None)
    seed: int | None = None
    angle_amplitude_deg: float = 1.0
    accel_amplitude: float = 10.0
    frequency_hz: float = 10.0
    phase_deg: float = 0.0

    @classmethod
    def of(cls, **fields: Any) -> EvaluationConfig:
        """A configuration from flat fields: the spec's (``algorithm``, ``subsamples``,
        ``structure`` …, :data:`SPEC_FIELDS`) build its :class:`AlgorithmSpec`, the rest are
        the configuration's own."""
        spec = {k: fields.pop(k) for k in SPEC_FIELDS if k in fields}
        if "spec" in fields and spec:
            raise ValueError(f"give spec or its fields {sorted(spec)}, not both")
        if spec:
            fields["spec"] = AlgorithmSpec(**spec)
        return cls(**fields)

    def flat(self) -> dict[str, Any]:
        """The configuration as flat fields (the spec's beside the rest, as :meth:`of`
        takes them; ``dataclasses.asdict`` for the gyro errors)."""
        d = dataclasses.asdict(self)
        d.update(d.pop("spec"))
        return d

    def with_spec(self, text: str) -> EvaluationConfig:
        """This configuration with the spec string ``text``'s fields set on its spec (the
        others kept): ``compare`` and ``sweep`` run each of their specs so."""
        return dataclasses.replace(self, spec=dataclasses.replace(self.spec, **parse_spec(text)))

    # the spec's fields, read through it (the configuration holds the spec, not copies)
    algorithm = property(lambda self: self.spec.algorithm, doc="The spec's family name.")
    subsamples = property(lambda self: self.spec.subsamples, doc="The spec's N.")
    coefficients = property(lambda self: self.spec.coefficients,
                            doc="The spec's coefficient set as given (None: the default).")
    structure = property(lambda self: self.spec.structure, doc="The spec's update structure.")
    rk4_step = property(lambda self: self.spec.rk4_step, doc="The spec's RK4 step.")
    alpha = property(lambda self: self.spec.alpha, doc="The spec's alpha.")
    beta = property(lambda self: self.spec.beta, doc="The spec's beta.")
    step = property(lambda self: self.spec.step, doc="The spec's computation step (s).")
    exact_exp = property(lambda self: self.spec.exact_exp, doc="The spec's exact_exp.")

    @property
    def kind(self) -> MotionKind:
        """The registered motion (ValueError when unknown)."""
        return motion_kind(self.motion)

    def validate(self) -> None:
        kind = self.kind
        spec = self.spec
        if not isinstance(spec, AlgorithmSpec):
            raise ValueError(f"spec must be an AlgorithmSpec, got {type(spec).__name__}")
        if self.precision is not None:
            if spec.family.stepped:  # the quaternion algorithms: float64 only
                raise ValueError(f"{self.algorithm} runs in float64 only; drop --precision")
            positive_int(self.precision, "precision (digits)")
            if self.gyro is not None and not self.gyro.is_ideal:
                raise ValueError("arbitrary precision runs take ideal increments only")
        positive(self.sample_rate_hz, "sample rate (Hz)")
        positive(self.duration, "duration (s)")
        if kind.truth is None:  # a motion with its own runner checks itself after the sizes
            self._validate_limits()
            kind.check(self)
            return
        kind.check(self)
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
        kind = self.kind
        for what, w in kind.rates(self).items():
            if not w * h <= math.pi:
                raise InputError(f"the {what} turns {w * h:.3g} rad in one sample at "
                                 f"{self.sample_rate_hz:g} Hz; at most π (Nyquist)")
        if kind.cone and not abs(self.half_angle_deg) <= 180.0:
            raise InputError(f"half angle must be within ±180°, got {self.half_angle_deg:g}")

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
        n = spec.update_structure.usable_samples(round(self.duration * self.sample_rate_hz),
                                                 self.subsamples)
        if n < self.subsamples:
            raise ValueError(
                f"duration {self.duration} s at {self.sample_rate_hz} Hz gives {n} samples, "
                f"fewer than N = {self.subsamples}"
            )
        return n


#: Every field :meth:`EvaluationConfig.of` takes (the spec's flat beside the rest).
CONFIG_FIELDS: tuple[str, ...] = (
    *(f.name for f in dataclasses.fields(EvaluationConfig) if f.name != "spec"), *SPEC_FIELDS)


def build_motion(cfg: EvaluationConfig) -> Motion:
    """The reference motion a configuration names: its registered truth (the sculling
    motion has its own runner: :func:`strapdown.analysis.sculling.build_sculling`)."""
    kind = cfg.kind
    return (kind.truth or _no_truth)(cfg)


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
        """The coefficients the family reports for itself (the quaternion algorithms')."""
        spec = self.config.spec
        return spec.family.record(spec)


def run_evaluation(cfg: EvaluationConfig) -> Evaluation | ScullingEvaluation:
    """:func:`evaluate`, or for ``motion="sculling"``
    :func:`strapdown.analysis.sculling.evaluate_sculling` (what ``strapdown evaluate``,
    ``compare`` and ``sweep`` run)."""
    runner = cfg.kind.runner
    if runner is not None:
        cfg.validate()
        return runner(cfg)
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
    predicted = cfg.kind.law(spec, motion, h)
    return _finish(cfg, motion, t, err, ang, chain, start, predicted, spec.update_period(h), n)


def _gyro(cfg: EvaluationConfig, motion: Motion, kind: InputKind, h: float,
          n: int) -> sensors.GyroRecord:
    if kind == "rate":
        return sensors.rate_samples(motion, h, n, errors=cfg.gyro, rng=cfg.seed)
    return sensors.increments(motion, h, n, errors=cfg.gyro, rng=cfg.seed)


def _evaluate_user_set(cfg: EvaluationConfig, motion: Motion, cs: CoefficientSet) -> Evaluation:
    """A rotation-vector configuration with a user's coefficient set."""
    if not cfg.spec.family.coning_sets:
        raise ValueError(f"a coefficient set overrides the configurations of a family with "
                         f"coning sets (rotvec), not {cfg.algorithm}")
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
    predicted = cfg.kind.user_law(cs, motion, h)
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
