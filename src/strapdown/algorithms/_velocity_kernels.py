"""Per-sample loops of the velocity update (body-frame rotation, velocity and position
increments of the conventional structure and the single chain), compiled with numba
(``cache=True``). Private.

Tested against the plain-Python twin :mod:`strapdown.algorithms._velocity_reference`, which
mirrors them operation by operation. Inputs are validated by the public wrappers in
:mod:`strapdown.algorithms.velocity`; the kernels trust them. The formulas are documented
there. The navigation kernels that integrate these increments (in a non-rotating frame, on
the WGS-84 Earth) are :mod:`strapdown.navigation._kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from strapdown._core.compile_notice import python_notice

python_notice()

_TWELFTH = 1.0 / 12.0


@njit(cache=True, inline="always")
def _cross_acc(c, a, b, out):
    """out += c · a × b (a, b, out of length 3)."""
    out[0] += c * (a[1] * b[2] - a[2] * b[1])
    out[1] += c * (a[2] * b[0] - a[0] * b[2])
    out[2] += c * (a[0] * b[1] - a[1] * b[0])


@njit(cache=True, inline="always")
def _rotation_comp(alpha, ups, out):
    """out = υ + ½ α × υ + ⅙ α × (α × υ) (rotation compensation to second order)."""
    cx = alpha[1] * ups[2] - alpha[2] * ups[1]
    cy = alpha[2] * ups[0] - alpha[0] * ups[2]
    cz = alpha[0] * ups[1] - alpha[1] * ups[0]
    out[0] = ups[0] + 0.5 * cx + (alpha[1] * cz - alpha[2] * cy) / 6.0
    out[1] = ups[1] + 0.5 * cy + (alpha[2] * cx - alpha[0] * cz) / 6.0
    out[2] = ups[2] + 0.5 * cz + (alpha[0] * cy - alpha[1] * cx) / 6.0


@njit(cache=True)
def conventional_body_kernel(theta, dv, kc, ks, h, phi_out, dv_out, dr_out):
    """Body-frame increments of the conventional structure, one row per N samples.

    theta, dv (M·N, 3) gyro and accelerometer increments; kc, ks (N, N) coning and
    sculling matrices (upper triangular); h sample interval; phi_out, dv_out, dr_out
    (M, 3): rotation vector, compensated velocity increment and position increment in
    the body frame at the update start.
    """
    n = kc.shape[0]
    alpha = np.empty(3)
    ups = np.empty(3)
    run = np.empty(3)
    scul = np.zeros(3)
    prev_t = np.zeros(3)
    prev_v = np.zeros(3)
    dr = np.empty(3)
    for u in range(theta.shape[0] // n):
        b = u * n
        alpha[:] = 0.0
        ups[:] = 0.0
        scul[:] = 0.0
        dr[:] = 0.0
        for j in range(n):
            # running two-sample sculling (Savage's recursive form) for the position
            _cross_acc(_TWELFTH, prev_t, dv[b + j], scul)
            _cross_acc(_TWELFTH, prev_v, theta[b + j], scul)
            for c in range(3):
                alpha[c] += theta[b + j, c]
                ups[c] += dv[b + j, c]
                prev_t[c] = theta[b + j, c]
                prev_v[c] = dv[b + j, c]
            if j < n - 1:
                _rotation_comp(alpha, ups, run)
                for c in range(3):
                    dr[c] += h * (run[c] + scul[c])
        phi = phi_out[u]
        out = dv_out[u]
        for c in range(3):
            phi[c] = alpha[c]
        _rotation_comp(alpha, ups, out)
        for i in range(n - 1):
            for j in range(i + 1, n):
                if kc[i, j] != 0.0:
                    _cross_acc(kc[i, j], theta[b + i], theta[b + j], phi)
                if ks[i, j] != 0.0:
                    _cross_acc(ks[i, j], theta[b + i], dv[b + j], out)
                    _cross_acc(ks[i, j], dv[b + i], theta[b + j], out)
        for c in range(3):
            dr_out[u, c] = dr[c] + 0.5 * h * out[c]


@njit(cache=True)
def single_chain_body_kernel(theta, dv, tab_c, tab_s, h, phi_out, dv_out, dr_out):
    """Body-frame increments of the single chain, one row per sample.

    tab_c, tab_s (N, N − 1): row m holds c_1 … c_m of the (m+1)-sample coning and sculling
    sets (start-up rows, then the steady row N − 1), as
    :func:`strapdown.algorithms.structures.single_chain_table`.
    """
    n = tab_c.shape[0]
    for k in range(theta.shape[0]):
        row = min(k, n - 1)
        phi = phi_out[k]
        out = dv_out[k]
        for c in range(3):
            phi[c] = theta[k, c]
        _rotation_comp(theta[k], dv[k], out)
        for m in range(1, row + 1):
            cc = tab_c[row, m - 1]
            cs = tab_s[row, m - 1]
            if cc != 0.0:
                _cross_acc(cc, theta[k - m], theta[k], phi)
            if cs != 0.0:
                _cross_acc(cs, theta[k - m], dv[k], out)
                _cross_acc(cs, dv[k - m], theta[k], out)
        for c in range(3):
            dr_out[k, c] = 0.5 * h * out[c]
