"""Per-update loops of the navigation: body increments chained in a non-rotating frame
(:func:`inertial_kernel`) and on the WGS-84 Earth (:func:`earth_nav_kernel`,
:func:`earth_nav_chunk_kernel`), compiled with numba (``cache=True``). Private.

Tested against the plain-Python twin :mod:`strapdown.navigation._reference`, which mirrors
them operation by operation. Inputs are validated by the public wrappers in
:mod:`strapdown.navigation.earth` and :mod:`strapdown.navigation.inertial`; the kernels
trust them. The body increments come from :mod:`strapdown.algorithms.velocity`; the
Earth navigation's equations are documented in :mod:`strapdown.navigation.earth`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from strapdown.algorithms._kernels import _update


@njit(cache=True, inline="always")
def _rotate(q, x, out):
    """out = C(q) x for a unit quaternion q (scalar first)."""
    w, a, b, c = q[0], q[1], q[2], q[3]
    # t = 2 vec × x ; out = x + w t + vec × t
    tx = 2.0 * (b * x[2] - c * x[1])
    ty = 2.0 * (c * x[0] - a * x[2])
    tz = 2.0 * (a * x[1] - b * x[0])
    out[0] = x[0] + w * tx + (b * tz - c * ty)
    out[1] = x[1] + w * ty + (c * tx - a * tz)
    out[2] = x[2] + w * tz + (a * ty - b * tx)


@njit(cache=True)
def inertial_kernel(phi, dvb, drb, period, q0, v0, p0, q_out, v_out, p_out):
    """Chain body increments in a non-rotating frame without gravity.

    ``v_m = v_{m−1} + C_{m−1} Δv_b``, ``p_m = p_{m−1} + v_{m−1} T + C_{m−1} ΔR_b``,
    ``q_m = q_{m−1} ⊗ q(φ_m)``; outputs (M + 1, ·) with row 0 the initial state.
    """
    tmp = np.empty(3)
    q_out[0, :] = q0
    v_out[0, :] = v0
    p_out[0, :] = p0
    for m in range(phi.shape[0]):
        q = q_out[m]
        _rotate(q, dvb[m], tmp)
        for c in range(3):
            v_out[m + 1, c] = v_out[m, c] + tmp[c]
        _rotate(q, drb[m], tmp)
        for c in range(3):
            p_out[m + 1, c] = p_out[m, c] + v_out[m, c] * period + tmp[c]
        _update(q, phi[m], q_out[m + 1])


# ---------------------------------------------------------------------- WGS-84 navigation
_A = 6378137.0
_F = 1.0 / 298.257223563
_E2 = _F * (2.0 - _F)
_OMEGA = 7.292115e-5
_GE = 9.7803253359
_GK = 0.00193185265241
_GM_RATIO = 0.00344978650684  # m = ω² a² b / GM


@njit(cache=True, inline="always")
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, inline="always")
def _rates(lat, hgt, v, out, quad):
    """out[0:3] = ω_in, out[3:6] = γ − (ω_ie + ω_in) × v (gravity and Coriolis),
    out[6:9] = (L̇, λ̇, ḣ) at the state (lat, hgt, v); ``quad`` 1.0 keeps normal gravity's
    second-order height term, 0.0 drops it (the linear height correction)."""
    s = np.sin(lat)
    cl = np.cos(lat)
    s2 = s * s
    d = 1.0 - _E2 * s2
    sq = np.sqrt(d)
    e0 = _A * (1.0 - _E2) / (d * sq) + hgt
    e1 = _A / sq + hgt
    g0 = _GE * (1.0 + _GK * s2) / sq
    gam = g0 * (1.0 - 2.0 / _A * (1.0 + _F + _GM_RATIO - 2.0 * _F * s2) * hgt
                + quad * (3.0 * hgt * hgt / (_A * _A)))
    wie0 = _OMEGA * cl
    wie2 = -_OMEGA * s
    out[0] = wie0 + v[1] / e1
    out[1] = -v[0] / e0
    out[2] = wie2 - v[1] * (s / cl) / e1
    w0 = wie0 + out[0]
    w1 = out[1]
    w2 = wie2 + out[2]
    out[3] = -(w1 * v[2] - w2 * v[1])
    out[4] = -(w2 * v[0] - w0 * v[2])
    out[5] = gam - (w0 * v[1] - w1 * v[0])
    out[6] = v[0] / e0
    out[7] = v[1] / (e1 * cl)
    out[8] = -v[2]


@njit(cache=True, inline="always")
def _am(k, a, b, c, d):
    """Adams–Moulton mean over an update from the values at its end (a) and at the k − 1
    updates before (b, c, d): k = 2 trapezoid, 3 and 4 the three- and four-point rules."""
    if k == 2:
        return 0.5 * (a + b)
    if k == 3:
        return (5.0 * a + 8.0 * b - c) / 12.0
    return (9.0 * a + 19.0 * b - 5.0 * c + d) / 24.0


@njit(cache=True, inline="always")
def _extrap(k, b, c, d):
    """The value at the update's end extrapolated from the k − 1 before (b, c, d)."""
    if k == 2:
        return b
    if k == 3:
        return 2.0 * b - c
    return 3.0 * b - 3.0 * c + d


@njit(cache=True)
def earth_nav_kernel(phi, dvb, period, lat0, lon0, h0, v0, q0, pos_out, v_out, q_out, quad):
    """NED navigation on the WGS-84 Earth from body increments (see
    :mod:`strapdown.navigation.earth` for the equations).

    pos_out (M + 1, 3) latitude, longitude (rad), height (m); v_out (M + 1, 3) NED m/s;
    q_out (M + 1, 4) q_n_b. Row 0 is the initial state. ``quad``: 1.0 normal gravity with
    the second-order height correction, 0.0 with the linear one (:func:`_rates`).
    """
    pos_out[0, 0] = lat0
    pos_out[0, 1] = lon0
    pos_out[0, 2] = h0
    v_out[0, :] = v0
    q_out[0, :] = q0
    hist = np.zeros((3, 12))
    earth_nav_chunk_kernel(phi, dvb, period, hist, 0, pos_out, v_out, q_out, quad)


@njit(cache=True)
def earth_nav_chunk_kernel(phi, dvb, period, hist, nh, pos_out, v_out, q_out, quad):
    """:func:`earth_nav_kernel` continuing a run: rows 0 of the outputs hold the state the
    chunk starts from (filled by the caller); ``hist`` (3, 12) the Earth rates
    (:func:`_rates`, columns 0–8) and the body-frame velocity increment ``Δv_b``
    (columns 9–11) at the last ``nh`` updates, newest first, updated in place (``nh = 0``:
    a run's start). Returns the new ``nh``."""
    zeta = np.empty(3)
    x = np.empty(3)
    an = np.empty(3)
    t1 = np.empty(3)
    t2 = np.empty(3)
    t3 = np.empty(3)
    t4 = np.empty(3)
    t5 = np.empty(3)
    t6 = np.empty(3)
    db = np.empty(3)
    dx = np.empty(3)
    dz = np.empty(3)
    pred = np.empty(9)
    end = np.empty(9)
    pp = np.empty(3)
    qb = np.empty(4)
    if nh == 0:
        _rates(pos_out[0, 0], pos_out[0, 2], v_out[0], hist[0], quad)
        nh = 1
    for m in range(phi.shape[0]):
        p = pos_out[m]
        v = v_out[m]
        k = nh + 1  # points of the quadrature: this update's end and nh before
        for c in range(9):
            pred[c] = _extrap(k, hist[0, c], hist[1, c], hist[2, c])
        # navigation-frame rotation over the update, ζ = ∫ ω_in dt, predicted
        for c in range(3):
            zeta[c] = period * _am(k, pred[c], hist[0, c], hist[1, c], hist[2, c])
        # specific-force increment: body part rotated to n(m−1), then the frame rotation
        q = q_out[m]
        _rotate(q, dvb[m], x)
        _rotate(q, phi[m], an)
        # the body's rotation, q_{m−1} ⊗ q(φ), here rather than beside the frame's at the
        # end: it needs only q_{m−1}, and started early it overlaps the Earth rates below
        # (same operations, about 4 % faster)
        _update(q, phi[m], qb)
        _cross(zeta, x, t1)  # ζ × X
        _cross(an, x, t2)  # α × X
        _cross(zeta, t2, t3)  # ζ × (α × X)
        _cross(zeta, t1, t4)  # ζ × (ζ × X)
        # the specific force's change in the body, C (Δv_b,m − Δv_b,m−1) (the body's
        # rotation is in α × X), and the frame rotation's, Δζ = T (ω_in,m − ω_in,m−1)
        for c in range(3):
            db[c] = dvb[m, c] - hist[0, 9 + c] if nh > 1 else 0.0
            dz[c] = period * (pred[c] - hist[0, c])
        _rotate(q, db, dx)
        _cross(zeta, dx, t5)  # ζ × ΔX
        _cross(dz, x, t6)  # Δζ × X
        vn = v_out[m + 1]
        for c in range(3):
            vn[c] = (v[c] + (x[c] - 0.5 * t1[c] - t3[c] / 12.0 + t4[c] / 6.0
                             - (t5[c] - t6[c]) / 12.0)
                     + period * _am(k, pred[3 + c], hist[0, 3 + c], hist[1, 3 + c],
                                    hist[2, 3 + c]))
        # predicted position, the rates at the update's end, then the correction
        for c in range(3):
            pp[c] = p[c] + period * _am(k, pred[6 + c], hist[0, 6 + c], hist[1, 6 + c],
                                        hist[2, 6 + c])
        _rates(pp[0], pp[2], vn, end, quad)
        w = 0.5 if k == 2 else (5.0 / 12.0 if k == 3 else 0.375)
        for c in range(3):
            vn[c] += period * w * (end[3 + c] - pred[3 + c])
        pn = pos_out[m + 1]
        for c in range(3):
            pn[c] = p[c] + period * _am(k, end[6 + c], hist[0, 6 + c], hist[1, 6 + c],
                                        hist[2, 6 + c])
        # ζ again from the corrected end rates, with the frame's own coning
        # (T²/12) ω_in,m−1 × ω_in,m, for the attitude
        _cross(hist[0, :3], end[:3], dz)
        for c in range(3):
            zeta[c] = period * (_am(k, end[c], hist[0, c], hist[1, c], hist[2, c])
                                + period / 12.0 * dz[c])
        hist[2, :] = hist[1, :]
        hist[1, :] = hist[0, :]
        hist[0, :9] = end
        hist[0, 9:] = dvb[m]
        nh = min(nh + 1, 3)
        # attitude: q_m = q(ζ)* ⊗ q_{m−1} ⊗ q(φ)
        for c in range(3):
            zeta[c] = -zeta[c]
        _left_update(zeta, qb, q_out[m + 1])
    return nh


@njit(cache=True, inline="always")
def _left_update(zeta, q, out):
    """out = normalise(q(ζ) ⊗ q) (exact exponential)."""
    ang = np.sqrt(zeta[0] * zeta[0] + zeta[1] * zeta[1] + zeta[2] * zeta[2])
    half = 0.5 * ang
    if half < 1e-2:
        x2 = half * half
        s = 0.5 * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0)))
        dw = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0)))
    else:
        s = np.sin(half) / ang
        dw = np.cos(half)
    dx = s * zeta[0]
    dy = s * zeta[1]
    dz = s * zeta[2]
    w = dw * q[0] - dx * q[1] - dy * q[2] - dz * q[3]
    x = dw * q[1] + dx * q[0] + dy * q[3] - dz * q[2]
    y = dw * q[2] - dx * q[3] + dy * q[0] + dz * q[1]
    z = dw * q[3] + dx * q[2] - dy * q[1] + dz * q[0]
    inv = 1.0 / np.sqrt(w * w + x * x + y * y + z * z)
    out[0] = w * inv
    out[1] = x * inv
    out[2] = y * inv
    out[3] = z * inv
