"""Attitude integration for flight control in cone angles (Zhang & Yu (2021)).

From gyro rate samples, integrated by classical RK4 with step 2·td (the
middle rate is the middle sample, as :mod:`strapdown.algorithms.rate` documents):

``cone``
    Eq. 7 with the corrected sign of row 1:
    ``δ̇1 = −(cos e ω_y + sin e ω_z)/sin δ2``, ``δ̇2 = −sin e ω_y + cos e ω_z``,
    ``δ̇3 = ω_x − tan(δ2/2)(cos e ω_y + sin e ω_z)`` (``e = δ1 − δ3``).
    Singular at δ2 = 0 (where the papers' simulations start). Treatment:
    while ``sin δ2 < switch`` (default 1e-3) the state is carried by the
    non-singular formulation below and handed to eq. 7 once δ2 has grown
    past it; if δ2 later falls below ``switch``, it hands back.
``cone-printed``
    Eq. 7 exactly as printed (row 1 sign wrong), same singularity treatment:
    kept to show that it fails
    (:func:`strapdown.algorithms.errata.printed_cone_rates`, with its measured
    difference).
``nutation``
    Non-singular: ``C_c_b = exp([ν×]) Rx(δ3)``, ``ν = δ2 (0, −sin δ1, cos δ1)``;
    ``[e_x, J_r(ν) e_y, J_r(ν) e_z] (δ̇3, ν̇_y, ν̇_z)ᵀ = Rx(δ3) ω`` (J_r the
    right Jacobian of SO(3)); regular at δ2 = 0, singular only as δ2 → π.
``euler``
    z-y-x yaw–pitch–roll kinematics, converted to cone angles through the DCM
    (singular at pitch ±90°).

All return cone angles (δ1, δ2, δ3) at the step times.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import positive
from strapdown.algorithms import _kernels
from strapdown.algorithms.errata import printed_cone_rates
from strapdown.algorithms.rate import check_rate_record
from strapdown.rotation.cone_angles import cone_angles_from_dcm, dcm_from_cone_angles
from strapdown.rotation.euler import _rx, dcm_from_euler_zyx, euler_zyx_from_dcm

__all__ = [
    "METHODS",
    "ConeAngleSolution",
    "ConeMethod",
    "integrate_cone_angles",
    "integrate_cone_angles_reference",
    "right_jacobian",
]

#: The integration methods (see the module docstring).
ConeMethod = Literal["cone", "cone-printed", "nutation", "euler"]
#: Their names, in the order the documentation lists them.
METHODS: tuple[ConeMethod, ...] = get_args(ConeMethod)


def right_jacobian(nu: NDArray[np.float64]) -> NDArray[np.float64]:
    """``J_r(ν) = I − (1 − cos|ν|)/|ν|² [ν×] + (|ν| − sin|ν|)/|ν|³ [ν×]²`` (series below 1e-4)."""
    a = float(np.linalg.norm(nu))
    k = np.array([[0, -nu[2], nu[1]], [nu[2], 0, -nu[0]], [-nu[1], nu[0], 0]])
    if a < 1e-4:
        c1 = 0.5 - a * a / 24.0
        c2 = 1.0 / 6.0 - a * a / 120.0
    else:
        c1 = (1.0 - np.cos(a)) / (a * a)
        c2 = (a - np.sin(a)) / (a**3)
    return np.eye(3) - c1 * k + c2 * (k @ k)


def _cone_rates(y, w):
    d1, d2, d3 = y
    e = d1 - d3
    a = np.cos(e) * w[1] + np.sin(e) * w[2]
    r1 = -a / np.sin(d2)
    return np.array([r1, -np.sin(e) * w[1] + np.cos(e) * w[2], w[0] - np.tan(d2 / 2) * a])


def _nutation_rates(y, w):
    nu = np.array([0.0, y[0], y[1]])
    j = right_jacobian(nu)
    m = np.column_stack([[1.0, 0.0, 0.0], j[:, 1], j[:, 2]])
    rhs = _rx(np.array(y[2])) @ w
    d3, nuy, nuz = np.linalg.solve(m, rhs)
    return np.array([nuy, nuz, d3])


def _euler_rates(y, w):
    _, th, ph = y
    s, c = np.sin(ph), np.cos(ph)
    q = w[1] * s + w[2] * c
    return np.array([q / np.cos(th), w[1] * c - w[2] * s, w[0] + q * np.tan(th)])


def _to_nutation(d):
    return np.array([-d[1] * np.sin(d[0]), d[1] * np.cos(d[0]), d[2]])


def _from_nutation(y):
    d2 = np.hypot(y[0], y[1])
    d1 = np.arctan2(-y[0], y[1]) if d2 > 0 else 0.0
    return np.array([d1, d2, y[2]])


@dataclass(frozen=True)
class ConeAngleSolution:
    """Cone angles at the step times (δ1 and δ3 unwrapped, rad)."""

    t: NDArray[np.float64]
    angles: NDArray[np.float64]
    method: ConeMethod
    switches: int


def _rk4(f, y, w0, wm, w1, h):
    k1 = f(y, w0)
    k2 = f(y + 0.5 * h * k1, wm)
    k3 = f(y + 0.5 * h * k2, wm)
    k4 = f(y + h * k3, w1)
    return y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


def integrate_cone_angles(t: ArrayLike, omega: ArrayLike, initial: ArrayLike, *,
                          method: ConeMethod = "cone", switch: float = 1e-3
                          ) -> ConeAngleSolution:
    """Integrate cone angles from rate samples (compiled; see the module docstring).

    Parameters
    ----------
    t, omega : array_like (n,), (n, 3)
        Uniform rate samples (rad/s); steps of 2 td use samples 0, 2, 4, …
    initial : (δ1, δ2, δ3) at ``t[0]`` (rad).
    method : {"cone", "cone-printed", "nutation", "euler"}
    switch : float
        ``sin δ2`` below which the eq.-7 methods are carried by the
        non-singular formulation.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    switch = positive(switch, "switch")
    rec = check_rate_record(t, omega, min_samples=3)
    d0 = np.asarray(initial, dtype=np.float64)
    if d0.shape != (3,) or not np.all(np.isfinite(d0)):
        raise ValueError(f"initial must be three finite cone angles, got {initial!r}")
    steps = (rec.omega.shape[0] - 1) // 2
    out = np.empty((steps + 1, 3))
    mode = np.empty(steps + 1, np.int64)
    code = METHODS.index(method)
    y0 = np.array(euler_zyx_from_dcm(dcm_from_cone_angles(*d0))) if method == "euler" else d0
    switches = _kernels.cone_ode_kernel(np.ascontiguousarray(rec.omega), rec.td, y0, code,
                                        switch, out, mode)
    if method == "euler":
        out = np.stack(cone_angles_from_dcm(dcm_from_euler_zyx(out[:, 0], out[:, 1],
                                                                out[:, 2])), -1)
    return ConeAngleSolution(rec.t[0] + np.arange(steps + 1) * 2 * rec.td, _unwrap(out), method,
                             int(switches))


def integrate_cone_angles_reference(t: ArrayLike, omega: ArrayLike, initial: ArrayLike, *,
                                    method: ConeMethod = "cone", switch: float = 1e-3
                                    ) -> ConeAngleSolution:
    """Plain-Python twin of :func:`integrate_cone_angles` (the kernels are tested against it)."""
    rec = check_rate_record(t, omega, min_samples=3)
    d0 = np.asarray(initial, dtype=np.float64)
    w = rec.omega
    steps = (w.shape[0] - 1) // 2
    h = 2.0 * rec.td
    out = np.empty((steps + 1, 3))
    out[0] = d0
    switches = 0
    if method == "euler":
        y = np.array(euler_zyx_from_dcm(dcm_from_cone_angles(*d0)))
        for k in range(steps):
            y = _rk4(_euler_rates, y, w[2 * k], w[2 * k + 1], w[2 * k + 2], h)
            out[k + 1] = cone_angles_from_dcm(dcm_from_euler_zyx(*y))
        return ConeAngleSolution(rec.t[0] + np.arange(steps + 1) * h, _unwrap(out), method, 0)
    if method == "nutation":
        y = _to_nutation(d0)
        for k in range(steps):
            y = _rk4(_nutation_rates, y, w[2 * k], w[2 * k + 1], w[2 * k + 2], h)
            out[k + 1] = _from_nutation(y)
        return ConeAngleSolution(rec.t[0] + np.arange(steps + 1) * h, _unwrap(out), method, 0)
    rates = printed_cone_rates if method == "cone-printed" else _cone_rates
    state = d0.copy()
    singular = np.sin(state[1]) < switch
    y = _to_nutation(state) if singular else state
    for k in range(steps):
        args = (w[2 * k], w[2 * k + 1], w[2 * k + 2], h)
        if singular:
            y = _rk4(_nutation_rates, y, *args)
            state = _from_nutation(y)
            if np.sin(state[1]) >= switch:
                singular, y, switches = False, state.copy(), switches + 1
        else:
            y = _rk4(rates, y, *args)
            state = y
            if np.sin(state[1]) < switch:
                singular, y, switches = True, _to_nutation(state), switches + 1
        out[k + 1] = state
    return ConeAngleSolution(rec.t[0] + np.arange(steps + 1) * h, _unwrap(out), method, switches)


def _unwrap(a):
    a = a.copy()
    a[:, 0] = np.unwrap(a[:, 0])
    a[:, 2] = np.unwrap(a[:, 2])
    return a
