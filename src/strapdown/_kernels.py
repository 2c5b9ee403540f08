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
