"""Per-sample loops, compiled with numba (``cache=True``). Private.

The only loop-per-sample code of the library lives here, with explicit
output arrays. Every kernel is tested against the plain-Python reference in
:mod:`strapdown._reference`. Inputs are validated by the public wrappers in
:mod:`strapdown.structures`; the kernels trust them.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from strapdown.rotation._series import SMALL_ANGLE

_SMALL = SMALL_ANGLE


@njit(cache=True, inline="always")
def _rotvec(theta, base, m, k, phi):
    """φ = Σθ + Σ_{i<j} k_ij θ_i × θ_j over theta[base : base + m]; writes phi (3,)."""
    phi[0] = 0.0
    phi[1] = 0.0
    phi[2] = 0.0
    for i in range(m):
        phi[0] += theta[base + i, 0]
        phi[1] += theta[base + i, 1]
        phi[2] += theta[base + i, 2]
    for i in range(m - 1):
        ax = theta[base + i, 0]
        ay = theta[base + i, 1]
        az = theta[base + i, 2]
        for j in range(i + 1, m):
            c = k[i, j]
            if c != 0.0:
                bx = theta[base + j, 0]
                by = theta[base + j, 1]
                bz = theta[base + j, 2]
                phi[0] += c * (ay * bz - az * by)
                phi[1] += c * (az * bx - ax * bz)
                phi[2] += c * (ax * by - ay * bx)


@njit(cache=True, inline="always")
def _update(qp, phi, out):
    """out = normalise(qp ⊗ q(φ)) with the exact exponential map."""
    ang2 = phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]
    ang = np.sqrt(ang2)
    half = 0.5 * ang
    if half < _SMALL:
        x2 = half * half
        s = 0.5 * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0)))
    else:
        s = np.sin(half) / ang
    dw = np.cos(half)
    dx = s * phi[0]
    dy = s * phi[1]
    dz = s * phi[2]
    w = qp[0] * dw - qp[1] * dx - qp[2] * dy - qp[3] * dz
    x = qp[0] * dx + qp[1] * dw + qp[2] * dz - qp[3] * dy
    y = qp[0] * dy - qp[1] * dz + qp[2] * dw + qp[3] * dx
    z = qp[0] * dz + qp[1] * dy - qp[2] * dx + qp[3] * dw
    inv = 1.0 / np.sqrt(w * w + x * x + y * y + z * z)
    out[0] = w * inv
    out[1] = x * inv
    out[2] = y * inv
    out[3] = z * inv


@njit(cache=True)
def conventional_kernel(theta, k, q0, q_out):
    """Conventional structure: one update per N increments.

    theta (M·N, 3), k (N, N), q0 (4,), q_out (M + 1, 4); q_out[0] = q0.
    """
    n = k.shape[0]
    phi = np.empty(3)
    q_out[0, :] = q0
    for u in range(theta.shape[0] // n):
        _rotvec(theta, u * n, n, k, phi)
        _update(q_out[u], phi, q_out[u + 1])


@njit(cache=True)
def realtime_kernel(theta, ks, q0, q_out):
    """Li & Zhang 2017 real-time structure (eq. 15): an update every increment.

    ``q(k) = q(k−N) ⊗ q(φ_k)`` with φ_k from increments k−N+1 … k. Start-up
    (k < N): ``q(k) = q(0) ⊗ q(φ)`` with the k-subsample set on increments 1 … k.
    theta (n, 3); ks (N, N, N) with ks[m−1, :m, :m] the m-subsample matrix;
    q_out (n + 1, 4).
    """
    nsub = ks.shape[0]
    phi = np.empty(3)
    q_out[0, :] = q0
    for j in range(1, theta.shape[0] + 1):
        if j < nsub:
            _rotvec(theta, 0, j, ks[j - 1], phi)
            _update(q_out[0], phi, q_out[j])
        else:
            _rotvec(theta, j - nsub, nsub, ks[nsub - 1], phi)
            _update(q_out[j - nsub], phi, q_out[j])


@njit(cache=True)
def chain_kernel(phi, q0, stride, q_out):
    """Chain rotation vectors: ``q[k] = q[k − stride] ⊗ q(φ_k)`` for k ≥ stride.

    phi (n, 3) holds φ_1 … φ_n; q0 (stride, 4) the first ``stride`` attitudes;
    q_out (n + stride, 4) with q_out[:stride] = q0. Stride 1 is a single chain.
    """
    for s in range(stride):
        q_out[s, :] = q0[s]
    for k in range(phi.shape[0]):
        _update(q_out[k], phi[k], q_out[k + stride])


@njit(cache=True, inline="always")
def _mul_pure(q, wx, wy, wz, out):
    """out = ½ q ⊗ [0, w]."""
    out[0] = 0.5 * (-q[1] * wx - q[2] * wy - q[3] * wz)
    out[1] = 0.5 * (q[0] * wx + q[2] * wz - q[3] * wy)
    out[2] = 0.5 * (q[0] * wy - q[1] * wz + q[3] * wx)
    out[3] = 0.5 * (q[0] * wz + q[1] * wy - q[2] * wx)


@njit(cache=True)
def rk4_kernel(omega, h, q0, mode, q_out):
    """Quaternion RK4 on rate samples, normalised after each step.

    mode 0: step 2h, rates at the step's start, middle and end (samples k, k+1, k+2);
    q_out has (n − 1)//2 + 1 rows. mode 1: step h, middle rate = mean of the two
    end samples; q_out has n rows.
    """
    k1 = np.empty(4)
    k2 = np.empty(4)
    k3 = np.empty(4)
    k4 = np.empty(4)
    tmp = np.empty(4)
    q_out[0, :] = q0
    stride = 2 if mode == 0 else 1
    big_h = stride * h
    for j in range(q_out.shape[0] - 1):
        b = j * stride
        q = q_out[j]
        if mode == 0:
            m0, m1, m2 = omega[b + 1, 0], omega[b + 1, 1], omega[b + 1, 2]
        else:
            m0 = 0.5 * (omega[b, 0] + omega[b + 1, 0])
            m1 = 0.5 * (omega[b, 1] + omega[b + 1, 1])
            m2 = 0.5 * (omega[b, 2] + omega[b + 1, 2])
        e = b + stride
        _mul_pure(q, omega[b, 0], omega[b, 1], omega[b, 2], k1)
        for i in range(4):
            tmp[i] = q[i] + 0.5 * big_h * k1[i]
        _mul_pure(tmp, m0, m1, m2, k2)
        for i in range(4):
            tmp[i] = q[i] + 0.5 * big_h * k2[i]
        _mul_pure(tmp, m0, m1, m2, k3)
        for i in range(4):
            tmp[i] = q[i] + big_h * k3[i]
        _mul_pure(tmp, omega[e, 0], omega[e, 1], omega[e, 2], k4)
        s = 0.0
        for i in range(4):
            tmp[i] = q[i] + big_h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            s += tmp[i] * tmp[i]
        inv = 1.0 / np.sqrt(s)
        for i in range(4):
            q_out[j + 1, i] = tmp[i] * inv
