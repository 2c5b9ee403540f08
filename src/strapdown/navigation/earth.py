"""Strapdown navigation on the WGS-84 Earth (NED): attitude, velocity and position at the
update structure's rate with the coning and sculling corrections of
:mod:`strapdown.algorithms.velocity` (Savage (1998b)).

Per update of period ``T`` with body increments ``φ``, ``Δv_b`` (:func:`body_increments`)
and the state at ``t_{m−1}``:

* the Earth rates ``r = (ω_in, γ − (ω_ie + ω_in) × v, L̇, λ̇, ḣ)`` (WGS-84 radii, normal
  gravity by Somigliana with the second-order or the linear height correction,
  :mod:`strapdown.truth.earth`) are kept at the last three updates; their value at ``t_m``
  is extrapolated (quadratically), and every Earth term is integrated over the update by
  the Adams–Moulton rule of the four points ``t_{m−3} … t_m``,
  ``T (9 r_m + 19 r_{m−1} − 5 r_{m−2} + r_{m−3})/24`` (the two- and three-point rules at a
  run's first two updates): the predicted ``ζ = ∫ ω_in dt``;
* specific-force increment ``X = C_{m−1} Δv_b``, ``α = C_{m−1} φ``,
  ``Δv_SF = X − ½ ζ × X − (1/12) ζ × (α × X) + ⅙ ζ × (ζ × X) − (1/12)(ζ × ΔX − Δζ × X)``
  with ``ΔX = C_{m−1}(Δv_b,m − Δv_b,m−1)`` (the specific force's change in the body; its
  rotation is the ``α × X`` term) and ``Δζ = T (ω_in,m − ω_in,m−1)``: Savage (1998b)'s
  velocity rotation integral for a specific force and a frame rate varying linearly over
  the update, to second order in the frame rotation, exact for a vehicle at rest on the
  Earth (``α = ζ``); ``ΔX`` and ``Δζ`` are zero at a run's first update;
* ``v_m = v_{m−1} + Δv_SF + ∫ [γ − (2 ω_ie + ω_en) × v] dt``, the latitude, longitude and
  height predicted with the extrapolated rates, the rates evaluated at the predicted
  ``t_m`` state, the gravity–Coriolis integral corrected with them (predictor–corrector),
  and the position integrated by the same rule with them;
* ``ζ`` again by the same rule from those corrected rates, plus the frame's own coning
  ``(T²/12) ω_in,m−1 × ω_in,m`` (Bortz (1971)), and ``q_m = q(−ζ) ⊗ q_{m−1} ⊗ q(φ)``.

The Earth terms are thus integrated to fourth order, from the first update on; the
navigation's order is that of the body increments (on a smooth manoeuvre: second for
N = 1, third for N ≥ 2, see ``strapdown reproduce sculling``), also on a manoeuvre that
accelerates from its first update (``tests/navigation/test_navigation_startup.py``: the
first update's ζ used to come from the start rates alone, a one-off ``½ T² |ω̇_in|`` tilt,
and the velocity update counted the body's rotation twice).

Conventions: each increment covers the interval that ends at its stamp, so the initial
state is at ``t0`` = the first stamp − ``h`` (the start of the first interval); the
solution's row 0 is that state and row ``m`` the state at ``t0 + m T``. Increments short
of a whole conventional update at the end (fewer than N) are dropped with a
:class:`TrailingSamplesWarning` (``trailing="drop"``) or refused (``"error"``).

:class:`NavStream` runs the same update over a log fed in chunks, equal to
:func:`navigate` bit for bit whatever the chunking.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.errors import InputError
from strapdown._core.validation import as_quaternions, as_vectors, finite_array
from strapdown.algorithms.velocity import (
    DEFAULT_VELOCITY_SET,
    BodyIncrements,
    NavStructure,
    VelocitySet,
    body_increments,
)
from strapdown.navigation import _kernels
from strapdown.truth.earth import GRAVITY_MODELS, GravityModel, gravity_quadratic

__all__ = ["GRAVITY_MODELS", "POLE_LIMIT_DEG", "TRAILING_POLICIES", "GravityModel",
           "NavSolution", "NavStream", "TrailingPolicy", "TrailingSamplesWarning", "navigate",
           "navigate_rates"]

#: What :func:`navigate` does with fewer than N increments left after the last whole
#: conventional update: navigate without them and warn (``"drop"``), or refuse (``"error"``).
TrailingPolicy = Literal["drop", "error"]
TRAILING_POLICIES: tuple[TrailingPolicy, ...] = get_args(TrailingPolicy)


class TrailingSamplesWarning(UserWarning):
    """Increments short of a whole update at the end of a record were not navigated."""

#: Largest latitude magnitude (deg) navigated: the mechanisation runs in the local-level,
#: north-pointing NED frame, whose transport rate (``v_E tan φ / R``) and longitude rate
#: (``v_E / (R cos φ)``) are singular at the poles. Beyond 89.9° (about 11 km from a pole)
#: a flight is refused, at the start or at the first update that reaches it, naming the
#: time; crossing a pole needs a wander-azimuth mechanisation (not implemented).
POLE_LIMIT_DEG = 89.9


@dataclass(frozen=True)
class NavSolution:
    """Navigation output, one row per update (row 0 the initial state).

    ``t`` (m,) s; ``lat``, ``lon`` (m,) rad; ``height`` (m,) m; ``v`` (m, 3) NED m/s;
    ``q`` (m, 4) ``q_n_b``.
    """

    t: NDArray[np.float64]
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    height: NDArray[np.float64]
    v: NDArray[np.float64]
    q: NDArray[np.float64]
    structure: NavStructure
    n: int
    update_period: float


def _initial(lat, lon, height, v0, q0):
    lat = float(finite_array(lat, "initial latitude"))
    if not abs(lat) < math.pi / 2:
        raise ValueError(f"initial latitude must lie within ±90°, got {math.degrees(lat)}°")
    if abs(lat) > math.radians(POLE_LIMIT_DEG):
        raise ValueError(f"initial latitude {math.degrees(lat):.9g}° lies within "
                         f"{90 - POLE_LIMIT_DEG:g}° of a pole, where the north-pointing NED "
                         f"mechanisation is singular; |latitude| must not exceed "
                         f"{POLE_LIMIT_DEG:g}°")
    lon = float(finite_array(lon, "initial longitude"))
    height = float(finite_array(height, "initial height"))
    v = np.zeros(3) if v0 is None else as_vectors(v0, "initial velocity")
    q = np.array([1.0, 0.0, 0.0, 0.0]) if q0 is None else as_quaternions(q0, "initial attitude")
    if v.shape != (3,) or q.shape != (4,):
        raise ValueError(f"initial velocity must have shape (3,) and attitude (4,), got "
                         f"{v.shape} and {q.shape}")
    return lat, lon, height, v, q / np.linalg.norm(q)


def navigate(gyro: ArrayLike, accel: ArrayLike, n: int, *, h: float, lat: float, lon: float,
             height: float, v0: ArrayLike | None = None, q0: ArrayLike | None = None,
             structure: NavStructure = "conventional", t0: float = 0.0,
             sculling: bool = True, velocity_set: VelocitySet = DEFAULT_VELOCITY_SET,
             gravity: GravityModel = "wgs84", trailing: TrailingPolicy = "drop"
             ) -> NavSolution:
    """Navigate from gyro (rad) and accelerometer (m/s) increments every ``h`` seconds
    (the equations and conventions: module docstring).

    Increment ``i`` (row ``i`` of ``gyro`` and ``accel``, from 0) covers the interval
    ``[t0 + i h, t0 + (i + 1) h]``: a log whose increments are stamped at the ends of their
    intervals, ``t_1, t_2, …``, starts at ``t0 = t_1 − h``, where the initial state is.

    Parameters
    ----------
    gyro, accel : array_like of shape (k, 3)
    n : int
        Subsamples N of the coning and sculling corrections.
    h : float
        Sample interval (s).
    lat, lon, height : float
        Initial position (rad, rad, m).
    v0 : array_like of shape (3,), optional
        Initial NED velocity (m/s); zero by default.
    q0 : array_like of shape (4,), optional
        Initial ``q_n_b`` (NED); identity by default.
    structure : {"conventional", "single-chain"}
    sculling : bool
        False drops the sculling terms (rotation compensation only).
    velocity_set : {"coning-force", "classical"}
        The conventional structure's sculling pairs
        (:func:`strapdown.algorithms.velocity.body_increments`).
    t0 : float
        Time of the initial state (s): the start of the first increment's interval.
    gravity : {"wgs84", "linear"}
        Normal gravity's height correction: the WGS-84 formula's second-order one (default)
        or its linear term (:func:`strapdown.truth.earth.gravity`).
    trailing : {"drop", "error"}
        Fewer than N increments left after the last whole conventional update: navigated
        without, with a :class:`TrailingSamplesWarning` (default, as ``strapdown nav``), or
        an :class:`~strapdown._core.errors.InputError` naming them.

    Returns
    -------
    NavSolution
        Row 0 the initial state at ``t0``, row ``m`` the state at ``t0 + m T`` (``T = N h``
        for the conventional structure, ``h`` for the single chain).
    """
    lat, lon, height, v0, q0 = _initial(lat, lon, height, v0, q0)
    quad = gravity_quadratic(gravity)
    b = body_increments(gyro, accel, n, h=h, structure=structure, sculling=sculling,
                        velocity_set=velocity_set)
    m = b.phi.shape[0]
    _trailing(np.shape(gyro)[0] - m * round(b.update_period / h), b.n, h, trailing)
    pos = np.empty((m + 1, 3))
    v = np.empty((m + 1, 3))
    q = np.empty((m + 1, 4))
    _kernels.earth_nav_kernel(b.phi, b.dv, b.update_period, lat, lon, height, v0, q0,
                                  pos, v, q, quad)
    t = float(finite_array(t0, "t0")) + np.arange(m + 1) * b.update_period
    _check_pole(t, pos[:, 0])
    return NavSolution(t, pos[:, 0], pos[:, 1], pos[:, 2], v, q, structure, b.n,
                       b.update_period)


def navigate_rates(omega: ArrayLike, force: ArrayLike, *, td: float, lat: float, lon: float,
                   height: float, algorithm: str = "rate-single",
                   coefficients: str | None = None, v0: ArrayLike | None = None,
                   q0: ArrayLike | None = None, t0: float = 0.0, sculling: bool = True,
                   gravity: GravityModel = "wgs84") -> NavSolution:
    """Navigate from rate (rad/s) and specific-force (m/s²) samples every ``td`` with the
    velocity counterpart of a rate-input family (:meth:`strapdown.algorithms.family.Family.
    velocity`; :func:`strapdown.algorithms.velocity.rate_velocity_algorithms` lists them).

    Sample ``k`` is taken at ``t0 + k td``; the family's window turns them into rotation,
    velocity and position increments per update (the dual of its coning update), which the
    Earth navigation of :func:`navigate` integrates. Row 0 is the initial state at the first
    update's start (``t0`` plus the window's history); a tail too short for one more update is
    not used.

    Parameters
    ----------
    omega, force : array_like of shape (k, 3)
    td : float
        Sample interval (s).
    lat, lon, height, v0, q0, t0, sculling, gravity
        As :func:`navigate`.
    algorithm : str
        A registered rate-input family with a velocity counterpart.
    coefficients : str, optional
        Its coefficient set (default: the family's).
    """
    from strapdown.algorithms.velocity import _inputs, _rate_spec

    spec = _rate_spec(coefficients, algorithm)
    vel = spec.family.velocity(spec, sculling=sculling)
    assert vel is not None  # _rate_spec: a rate-input velocity counterpart
    w, f = _inputs(omega, force)
    if w.shape[0] < vel.min_samples:
        raise ValueError(f"{algorithm} needs at least {vel.min_samples} samples, got "
                         f"{w.shape[0]}")
    lat, lon, height, v0, q0 = _initial(lat, lon, height, v0, q0)
    b = vel.body(w, f, float(finite_array(td, "td (sample interval)")))
    return _earth(b, lat, lon, height, v0, q0,
                  float(finite_array(t0, "t0")) + vel.start * b.h, gravity)


def _earth(b: BodyIncrements, lat: float, lon: float, height: float, v0, q0, t0: float,
           gravity: GravityModel) -> NavSolution:
    """The Earth navigation of body increments from validated initial state at ``t0``."""
    m = b.phi.shape[0]
    pos, v, q = np.empty((m + 1, 3)), np.empty((m + 1, 3)), np.empty((m + 1, 4))
    _kernels.earth_nav_kernel(b.phi, b.dv, b.update_period, lat, lon, height, v0, q0,
                                  pos, v, q, gravity_quadratic(gravity))
    t = t0 + np.arange(m + 1) * b.update_period
    _check_pole(t, pos[:, 0])
    return NavSolution(t, pos[:, 0], pos[:, 1], pos[:, 2], v, q, b.structure, b.n,
                       b.update_period)


def _trailing(left: int, n: int, h: float, policy: TrailingPolicy) -> None:
    """Warn about, or refuse (``policy == "error"``), ``left`` increments short of a whole
    update of N = ``n`` at the end of a record."""
    if policy not in TRAILING_POLICIES:
        raise ValueError(f"trailing must be one of {', '.join(TRAILING_POLICIES)}, got "
                         f"{policy!r}")
    if not left:
        return
    what = (f"{left} increment(s) after the last whole update of N = {n} "
            f"({left * h:.6g} s at the end of the record)")
    if policy == "error":
        raise InputError(f"{what}: not a whole update (trailing='error'); trailing='drop' "
                         "navigates without them, the single chain updates every sample")
    warnings.warn(f"{what} not navigated (trailing='drop')", TrailingSamplesWarning,
                  stacklevel=3)


def _check_pole(t: NDArray[np.float64], lat: NDArray[np.float64]) -> None:
    """Raise at the first update whose latitude passes :data:`POLE_LIMIT_DEG` (or is not
    finite: past the pole the solution is garbage), naming its time."""
    bad = ~(np.abs(lat) <= math.radians(POLE_LIMIT_DEG))
    if np.any(bad):
        i = int(np.argmax(bad))
        raise ValueError(f"the flight reaches latitude {math.degrees(lat[i]):.9g}° at t = "
                         f"{t[i]:.6g} s, within {90 - POLE_LIMIT_DEG:g}° of a pole, where the "
                         "north-pointing NED mechanisation is singular (|latitude| at most "
                         f"{POLE_LIMIT_DEG:g}°); nothing navigated past it")


_Z3 = np.zeros((0, 3))


class NavStream:
    """:func:`navigate` over increments fed in chunks (a log streamed from a file).

    Each :meth:`feed` returns the updates its samples complete, one row per update (no
    initial row), bit for bit the rows :func:`navigate` gives on the whole record: the
    conventional structure keeps a tail of fewer than N samples for the next chunk and
    the previous update's samples for the running two-sample sculling; the single chain
    keeps the last N − 1 samples (its pair terms reach N − 1 back); the navigation state
    keeps the Earth rates of the last three updates.

    Parameters are those of :func:`navigate` (``trailing`` aside: a stream does not know
    where it ends; :attr:`pending` holds the samples short of an update); ``t0`` is the
    time of the initial state.
    """

    def __init__(self, n: int, *, h: float, lat: float, lon: float, height: float,
                 v0: ArrayLike | None = None, q0: ArrayLike | None = None,
                 structure: NavStructure = "conventional", t0: float = 0.0,
                 sculling: bool = True, velocity_set: VelocitySet = DEFAULT_VELOCITY_SET,
                 gravity: GravityModel = "wgs84"):
        from strapdown._core.validation import positive
        from strapdown.algorithms.velocity import _n, _structure, _velocity_set

        self.velocity_set = _velocity_set(velocity_set)
        self.gravity, self._quad = gravity, gravity_quadratic(gravity)
        lat, lon, height, v, q = _initial(lat, lon, height, v0, q0)
        self.n, self.h = _n(n), positive(h, "h (sample interval)")
        self.structure, self.sculling = _structure(structure), bool(sculling)
        self.update_period = self.structure.update_period(self.n, self.h)
        self._pos = np.array([lat, lon, height])
        self._v, self._q = v, q
        self._hist = np.zeros((3, 12))  # Earth rates of the last updates (the kernel's)
        self._nh = 0
        self._ctx = (_Z3, _Z3)  # samples before the chunk the next one needs as context
        self._pending = (_Z3, _Z3)  # conventional: samples short of a whole update
        self._t0 = float(finite_array(t0, "t0"))
        self._updates = 0

    def _body(self, g: NDArray[np.float64], a: NDArray[np.float64]):
        """Body increments of the new samples, computed with their context."""
        n = self.n
        g = np.concatenate([self._pending[0], g])
        a = np.concatenate([self._pending[1], a])
        if self.structure.whole_updates:  # the conventional structure: whole updates
            m = g.shape[0] // n
            self._pending = (g[m * n:], a[m * n:])
            g, a = g[: m * n], a[: m * n]
            keep = n
        else:
            keep = n - 1
        if g.shape[0] == 0:
            return None
        cg, ca = self._ctx
        b = body_increments(np.concatenate([cg, g]), np.concatenate([ca, a]), n, h=self.h,
                            structure=self.structure.name,  # type: ignore[arg-type]
                            sculling=self.sculling, velocity_set=self.velocity_set)
        skip = cg.shape[0] // (n if self.structure.whole_updates else 1)
        both_g, both_a = np.concatenate([cg, g]), np.concatenate([ca, a])
        start = max(both_g.shape[0] - keep, 0)
        self._ctx = (both_g[start:], both_a[start:]) if keep else (_Z3, _Z3)
        return b.phi[skip:], b.dv[skip:]

    @property
    def pending(self) -> int:
        """Samples fed but short of a whole conventional update (always 0 for the single
        chain): what :func:`navigate` would drop or refuse were the record to end here."""
        return int(self._pending[0].shape[0])

    def feed(self, gyro: ArrayLike, accel: ArrayLike) -> NavSolution:
        """Advance by gyro (rad) and accelerometer (m/s) increments ``(k, 3)``; returns the
        updates completed (possibly none)."""
        from strapdown.algorithms.velocity import _inputs

        g, a = _inputs(gyro, accel) if np.size(gyro) else (_Z3, _Z3)
        body = self._body(g, a)
        m = 0 if body is None else body[0].shape[0]
        pos = np.empty((m + 1, 3))
        v = np.empty((m + 1, 3))
        q = np.empty((m + 1, 4))
        pos[0], v[0], q[0] = self._pos, self._v, self._q
        if m:
            assert body is not None
            self._nh = _kernels.earth_nav_chunk_kernel(
                np.ascontiguousarray(body[0]), np.ascontiguousarray(body[1]),
                self.update_period, self._hist, self._nh, pos, v, q, self._quad)
            self._pos, self._v, self._q = pos[-1].copy(), v[-1].copy(), q[-1].copy()
        t = self._t0 + (self._updates + 1 + np.arange(m)) * self.update_period
        _check_pole(t, pos[1:, 0])
        self._updates += m
        return NavSolution(t, pos[1:, 0], pos[1:, 1], pos[1:, 2], v[1:], q[1:],
                           self.structure.name,  # type: ignore[arg-type]
                           self.n, self.update_period)
