"""A body coning in a constant specific force: exact gyro and accelerometer increments,
navigation-frame velocity and position, in float64 and in arbitrary precision.

The attitude is classical coning (:class:`~strapdown.truth.motions.ClassicalConing`, Bortz
(1971); Li & Zhang (2017) eq. 7): ``q_n_b(t)`` the rotation by the half angle ``a`` about
``u(t) = (0, cos Ωt, sin Ωt)``, cone axis the navigation x axis. The specific force is
constant in the navigation frame, ``f_n`` (a body at rest in gravity coning about the
vertical has ``f_n = −g`` along the cone axis), so that

.. math::  v_n(t) = f_n t,\\qquad p_n(t) = ½ f_n t^2,\\qquad
    f_b(t) = C_{b n}(t) f_n = f_n \\cos a − \\sin a\\,(u × f_n) + 2\\sin^2(a/2)\\,u (u·f_n)

(no gravity model, no Earth rate: ``f_n`` is what the accelerometers sense in a non-rotating
frame). With ``c = cos Ωt``, ``s = sin Ωt`` and ``ε = 2 sin²(a/2)``:

``f_bx = f_x cos a − sin a (f_z c − f_y s)``,
``f_by = f_y (1 − ε/2) − f_x sin a s + (ε/2)(f_y cos 2Ωt + f_z sin 2Ωt)``,
``f_bz = f_z (1 − ε/2) + f_x sin a c + (ε/2)(f_y sin 2Ωt − f_z cos 2Ωt)``,

whose integrals over a sample interval are elementary: the accelerometer increments are
exact closed forms. The velocity algorithms' reference increment over an update from
``t0`` is ``Δv_b = C_b_n(t0) f_n T`` (:meth:`ConingInForce.velocity_increment_b0`).

The rectified velocity error this motion shows (a coning × constant-force term the classical
sculling motion lacks) and the sets that cancel it: :mod:`strapdown.design.designer`
(``target="coning-force"``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from strapdown._core.backend import MPMATH, NUMPY, Backend
from strapdown._core.validation import as_times, finite_array
from strapdown.truth.motions import ClassicalConing, _int_cos, _int_sin

__all__ = ["ConingInForce"]


@dataclass(frozen=True)
class ConingInForce(ClassicalConing):
    """Classical coning (half angle ``a``, cone rate ``Ω``) in a constant navigation-frame
    specific force ``f_n`` (module docstring).

    Parameters
    ----------
    half_angle : float
        ``a`` (rad).
    cone_rate : float
        ``Ω`` (rad/s), non-zero.
    force : tuple of 3 floats
        ``f_n`` (m/s²) in the navigation frame (cone axis x).
    """

    force: tuple[float, float, float] = (9.80665, 0.0, 0.0)

    def __post_init__(self):
        super().__post_init__()
        f = finite_array(self.force, "force (m/s²)")
        if f.shape != (3,):
            raise ValueError(f"force must have shape (3,), got {f.shape}")
        if float(self.cone_rate) == 0.0:
            raise ValueError("coning in a force needs a non-zero cone_rate")

    def _f(self, m: Backend):
        return tuple(m.num(float(v)) for v in self.force)

    def _dv(self, m: Backend, t0, dt):
        a, om = self._p(m)
        fx, fy, fz = self._f(m)
        ca, sa = m.cos(a), m.sin(a)
        eh = m.sin(a / 2) ** 2  # ε/2
        i_s, i_c = _int_sin(m, om, t0, dt), _int_cos(m, om, t0, dt)
        i_s2, i_c2 = _int_sin(m, (om, om), t0, dt), _int_cos(m, (om, om), t0, dt)
        ix = fx * ca * dt - sa * (fz * i_c - fy * i_s)
        iy = fy * (1 - eh) * dt - fx * sa * i_s + eh * (fy * i_c2 + fz * i_s2)
        iz = fz * (1 - eh) * dt + fx * sa * i_c + eh * (fy * i_s2 - fz * i_c2)
        return ix, iy, iz

    def specific_force(self, t) -> np.ndarray:
        """Body specific force ``f_b(t) = C_b_n(t) f_n`` (m/s²), shape ``t.shape + (3,)``."""
        q = self.attitude(t)
        f = np.asarray(self.force, dtype=np.float64)
        w, v = q[..., :1], q[..., 1:]
        # C_b_n f = q* ⊗ f ⊗ q: rotate by the conjugate
        tt = 2.0 * np.cross(-v, np.broadcast_to(f, v.shape))
        return f + w * tt + np.cross(-v, tt)

    def velocity_increments(self, edges) -> np.ndarray:
        """Exact accelerometer increments ``∫ f_b dt`` over consecutive ``edges``,
        shape ``(n − 1, 3)`` (m/s)."""
        edges = as_times(edges, "edges", min_len=2)
        parts = self._dv(NUMPY, edges[:-1], edges[1:] - edges[:-1])
        return np.stack(np.broadcast_arrays(*parts), axis=-1)

    def velocity_increment_mp(self, t0, t1) -> tuple:
        """Exact accelerometer increment over ``[t0, t1]`` as three mpmath numbers."""
        t0 = MPMATH.num(t0)
        return self._dv(MPMATH, t0, MPMATH.num(t1) - t0)

    def velocity_increment_b0(self, t0, t1) -> np.ndarray:
        """The exact compensated velocity increment of an update ``[t0, t1]`` in the body
        frame at ``t0``: ``C_b_n(t0) f_n (t1 − t0)`` (m/s)."""
        t0, t1 = float(t0), float(t1)
        return self.specific_force(np.array([t0]))[0] * (t1 - t0)

    def velocity(self, t) -> np.ndarray:
        """``v_n(t) = f_n t`` (m/s), ``v_n(0) = 0``."""
        t = finite_array(t, "t")
        return t[..., None] * np.asarray(self.force, dtype=np.float64)

    def position(self, t) -> np.ndarray:
        """``p_n(t) = ½ f_n t²`` (m), ``p_n(0) = 0``."""
        t = finite_array(t, "t")
        return 0.5 * (t * t)[..., None] * np.asarray(self.force, dtype=np.float64)

    def velocity_mp(self, t) -> tuple:
        """``v_n(t)`` as three mpmath numbers."""
        t = MPMATH.num(t)
        return tuple(f * t for f in self._f(MPMATH))

    def position_mp(self, t) -> tuple:
        """``p_n(t)`` as three mpmath numbers."""
        t = MPMATH.num(t)
        return tuple(f * t * t / 2 for f in self._f(MPMATH))

    def axial_force(self) -> float:
        """The force along the cone axis, ``f_x`` (m/s²): the laws scale with it."""
        return float(self.force[0])

    def transverse_force(self) -> float:
        """``|(f_y, f_z)|`` (m/s²): the part the designed laws do not cover."""
        return math.hypot(float(self.force[1]), float(self.force[2]))


class ConedFlight:
    """A flight with a coning overlay: the body cones about its own z axis (half angle ``a``,
    cone rate ``Ω``) on top of an :class:`~strapdown.truth.trajectory.EarthFlight`.

    ``q_n_b(t) = q_n_f(t) ⊗ q_c(t)``, ``q_c`` the rotation by ``a`` about
    ``(cos Ωt, sin Ωt, 0)`` of the flight's body frame ``f``: classical coning with its cone
    axis along body z (vertical in level flight, so the specific force of gravity lies on
    it). Position and velocity are the flight's (the IMU turns about its own point); the
    body rate is ``ω_ib = C_c^T ω_if + ω_c``, ``ω_c = (−Ω sin a sin Ωt, Ω sin a cos Ωt,
    −2Ω sin²(a/2))``, the specific force ``f_b = C_c^T f_f``. Increments: 12-point
    Gauss–Legendre per interval of these closed forms, as the flight's own.
    """

    def __init__(self, flight, *, half_angle: float, cone_rate: float):
        self.flight = flight
        self.half_angle = float(finite_array(half_angle, "half_angle"))
        self.cone_rate = float(finite_array(cone_rate, "cone_rate"))

    @property
    def duration(self) -> float:
        return float(self.flight.duration)

    def _cone(self, t):
        a, om = self.half_angle, self.cone_rate
        s = math.sin(a / 2)
        one = np.ones_like(t)
        q = np.stack([math.cos(a / 2) * one, s * np.cos(om * t), s * np.sin(om * t), 0 * t],
                     axis=-1)
        w = np.stack([-om * math.sin(a) * np.sin(om * t), om * math.sin(a) * np.cos(om * t),
                      -2 * om * s * s * one], axis=-1)
        return q, w

    def sensed(self, t):
        """Ideal ``ω_ib`` (rad/s) and ``f_b`` (m/s²) at times ``t`` (any shape)."""
        t = np.asarray(t, dtype=np.float64)
        w_f, f_f = self.flight.sensed(t)
        q, w_c = self._cone(t)
        return _rotate_inv(q, w_f) + w_c, _rotate_inv(q, f_f)

    def increments(self, edges):
        """Ideal gyro (rad) and accelerometer (m/s) increments over consecutive ``edges``."""
        edges = as_times(edges, "edges", min_len=2)
        x, w = np.polynomial.legendre.leggauss(12)
        mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * (edges[1:] - edges[:-1])
        out_g, out_a = [], []
        for lo in range(0, mid.size, 20000):  # bounded memory
            sl = slice(lo, lo + 20000)
            wb, fb = self.sensed(mid[sl, None] + half[sl, None] * x[None, :])
            out_g.append(half[sl, None] * np.einsum("k,nkj->nj", w, wb))
            out_a.append(half[sl, None] * np.einsum("k,nkj->nj", w, fb))
        return np.concatenate(out_g), np.concatenate(out_a)

    def state(self, t):
        """The flight's truth at ``t`` with ``q`` the coned body's ``q_n_b``."""
        from dataclasses import replace

        from strapdown.rotation.quaternion import quat_multiply

        s = self.flight.state(t)
        return replace(s, q=quat_multiply(s.q, self._cone(np.asarray(t, float))[0]))


def _rotate_inv(q, x):
    """``C(q)^T x`` for unit quaternions ``q`` (scalar first), broadcasting."""
    w, v = q[..., :1], -q[..., 1:]
    tt = 2.0 * np.cross(v, x)
    return x + w * tt + np.cross(v, tt)
