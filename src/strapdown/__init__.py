"""strapdown — attitude algorithms for strapdown inertial systems on high-dynamic bodies.

Conventions (written once, followed everywhere; see ``docs/conventions.md``)
---------------------------------------------------------------------------
Frames
    ``b`` is the body (sensor) frame, ``n`` the reference frame (navigation or
    cone frame; Earth rate is ignored). A direction cosine matrix is named so
    that subscripts cancel: ``C_n_b`` maps body vectors into the reference
    frame, ``v_n = C_n_b @ v_b`` (the papers' :math:`C_b^n`). Likewise ``q_n_b``.
Attitude update
    ``q_n_b(k) = q_n_b(k-1) ⊗ q(φ_k)``, ``φ_k`` the body-frame rotation vector
    of the interval.
Quaternions
    Hamilton product, scalar first ``[w, x, y, z]``; ``v_n = q ⊗ [0, v_b] ⊗ q*``;
    kinematics ``q̇ = ½ q ⊗ [0, ω_b]``. ``q`` and ``-q`` are the same attitude
    and every comparison treats them so. ``scipy.spatial.transform.Rotation``
    interop uses ``scalar_first=True``.
Rotation vector
    ``q(φ) = [cos(|φ|/2), sin(|φ|/2) φ/|φ|]`` with a series branch below
    :data:`strapdown.rotation.SMALL_ANGLE`. DCM form (Li & Zhang 2017 eq. 9):
    ``I + f1 (φ×) + f2 (φ×)²``.
Gyro data
    Angular increments ``Δθ_i = ∫ ω dt`` (rad) over sample interval ``i``;
    rates ``ω_k`` (rad/s). ``h`` is the (sub)sample interval, ``N`` the number
    of subsamples per rotation-vector update, ``T = N h`` the update interval.
Units and arrays
    SI and radians inside; degrees only in names that say so. Vectors
    ``(..., 3)``, quaternions ``(..., 4)``, DCMs ``(..., 3, 3)``; time series
    put time first. float64 throughout.
Navigation
    :func:`navigate` (and :class:`NavStream`, the same over a log fed in chunks, bit for
    bit) on the WGS-84 Earth in NED: gyro (rad) and accelerometer (m/s) increments, each
    covering the interval that *ends* at its stamp, so the first increment of a log
    stamped ``t_1`` starts at ``t₀ = t_1 − h``, the time of the initial state (position
    in rad and m above the ellipsoid, NED velocity, ``q_n_b``). The :class:`NavSolution`
    holds row 0 = that initial state, then one row per update stamped at its end.
    :func:`navigate_rates` does the same from rate and specific-force samples with any
    rate family that has a velocity counterpart (``Family.velocity``).
    ``strapdown nav`` writes the same rows with the z-y-x Euler angles (deg) beside the
    quaternion; from a rate log ``t₀`` is the first sample's stamp.
Errors
    ``δq = q_est ⊗ q_true*`` (reference frame), ``δφ_n = log δq``, angle
    ``2 atan2(|vec δq|, |w δq|)``. Drift rate: least-squares slope of the error
    against time, sampled at whole periods of periodic motions.
Randomness
    Every random quantity takes a seed or a :class:`numpy.random.Generator`.

Data flows one way: motion → sensor → algorithm (coning correction + update
structure) → analysis → report.

Layout (imports point only down this list; ``make lint`` enforces it)
--------------------------------------------------------------------
``cli``
    the ``strapdown`` command, one module per command.
``apps``, ``reproduce``, ``codegen``
    applications (run a log, compare, sweep, bench, AHRS on logs and BROAD), the paper
    reproductions, generated C flight code.
``design``
    exact coefficient design (sympy) and numerical optimisation.
``analysis``
    errors, drift rates and analytic predictions, one configuration evaluated end to end,
    BROAD's metrics.
``ahrs``, ``navigation``
    the error-state EKF; navigation (``navigate``, the inertial integrator of the sculling
    studies) with its compiled kernels and their plain-Python twins.
``algorithms``
    the algorithm model (:class:`AlgorithmSpec` and its registry), coning sets, update
    structures, rate-input and quaternion algorithms, cone kinematics, streaming, the
    velocity update, the arbitrary-precision path, the compiled kernels and their
    plain-Python twins.
``truth``, ``io``
    reference motions, sensor and trajectory models; log readers and file output.
``rotation``
    quaternions, rotation vectors, DCMs, Euler and cone angles.

The names below are the recommended entry points; each is imported on first use, so
``import strapdown`` stays cheap.
"""

from __future__ import annotations

import importlib
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("strapdown")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

#: Public name → module that defines it (imported lazily by :func:`__getattr__`).
_EXPORTS = {
    # the algorithm model
    "AlgorithmSpec": "strapdown.algorithms.spec",
    "REGISTRY": "strapdown.algorithms.spec",
    "ALGORITHMS": "strapdown.algorithms.spec",
    "parse_spec": "strapdown.algorithms.spec",
    # structures, coning sets, rate algorithms, streaming
    "AttitudeSolution": "strapdown.algorithms.structures",
    "conventional": "strapdown.algorithms.structures",
    "realtime": "strapdown.algorithms.structures",
    "single_chain": "strapdown.algorithms.structures",
    "windowed": "strapdown.algorithms.structures",
    "CoefficientSet": "strapdown.algorithms.coning",
    "coefficient_set": "strapdown.algorithms.coning",
    "rotation_vectors": "strapdown.algorithms.coning",
    "rate_attitude": "strapdown.algorithms.rate",
    "RotvecStream": "strapdown.algorithms.streaming",
    # navigation on the WGS-84 Earth (NED)
    "navigate": "strapdown.navigation",
    "navigate_rates": "strapdown.navigation",
    "NavStream": "strapdown.navigation",
    "NavSolution": "strapdown.navigation",
    # the AHRS
    "AhrsConfig": "strapdown.ahrs",
    "ekf": "strapdown.ahrs",
    # truth
    "ClassicalConing": "strapdown.truth.motions",
    "PureSpin": "strapdown.truth.motions",
    "SpinConing": "strapdown.truth.motions",
    "KrylovMotion": "strapdown.truth.motions",
    # analysis
    "attitude_errors": "strapdown.analysis",
    "drift_rate": "strapdown.analysis",
    "evaluate": "strapdown.analysis.evaluate",
    "EvaluationConfig": "strapdown.analysis.evaluate",
    # input
    "read_imu": "strapdown.io",
    "InputError": "strapdown._core.errors",
    # the compiled kernels built ahead of their first use
    "warmup": "strapdown.apps.warmup",
}
#: Subpackages reachable as attributes (``strapdown.rotation``, ``strapdown.motions`` …).
_MODULES = {
    "rotation": "strapdown.rotation",
    "algorithms": "strapdown.algorithms",
    "analysis": "strapdown.analysis",
    "ahrs": "strapdown.ahrs",
    "navigation": "strapdown.navigation",
    "design": "strapdown.design",
    "io": "strapdown.io",
    "truth": "strapdown.truth",
    "motions": "strapdown.truth.motions",
    "sensors": "strapdown.truth.sensors",
    "coning": "strapdown.algorithms.coning",
    "structures": "strapdown.algorithms.structures",
}

__all__ = sorted([*_EXPORTS, *_MODULES, "__version__"])


def __getattr__(name: str):
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name]), name)
    elif name in _MODULES:
        value = importlib.import_module(_MODULES[name])
    else:
        raise AttributeError(f"module 'strapdown' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return __all__
