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
Errors
    ``δq = q_est ⊗ q_true*`` (reference frame), ``δφ_n = log δq``, angle
    ``2 atan2(|vec δq|, |w δq|)``. Drift rate: least-squares slope of the error
    against time, sampled at whole periods of periodic motions.
Randomness
    Every random quantity takes a seed or a :class:`numpy.random.Generator`.

Data flows one way: motion → sensor → algorithm (coning correction + update
structure) → analysis → report.
"""

from strapdown import analysis, rotation
from strapdown.algorithms import coning, structures
from strapdown.algorithms.coning import CoefficientSet, coefficient_set, rotation_vectors
from strapdown.algorithms.structures import AttitudeSolution, conventional, realtime
from strapdown.truth import motions, sensors

__version__ = "0.1.0"

__all__ = [
    "AttitudeSolution",
    "CoefficientSet",
    "analysis",
    "coefficient_set",
    "coning",
    "conventional",
    "motions",
    "realtime",
    "rotation",
    "rotation_vectors",
    "sensors",
    "structures",
]
