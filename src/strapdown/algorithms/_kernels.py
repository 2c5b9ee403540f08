"""Per-sample loops, compiled with numba (``cache=True``). Private.

The only loop-per-sample code of the library lives here, with explicit
output arrays. Every kernel is tested against the plain-Python reference in
:mod:`strapdown.algorithms._reference`. Inputs are validated by the public wrappers in
:mod:`strapdown.algorithms.structures`; the kernels trust them.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from strapdown._core.compile_notice import python_notice
from strapdown._core.series import SMALL_ANGLE

_SMALL = SMALL_ANGLE
# every kernel module imports this one: a Python call that compiles kernels says so (logged;
# the commands print their own line)
python_notice()


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
def _mul_exp(q0, q1, q2, q3, px, py, pz):
    """normalise(q ⊗ q(φ)) on scalars, with the exact exponential map (series below
    :data:`SMALL_ANGLE`); returns (w, x, y, z)."""
    ang2 = px * px + py * py + pz * pz
    ang = np.sqrt(ang2)
    half = 0.5 * ang
    if half < _SMALL:
        x2 = half * half
        s = 0.5 * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0)))
        dw = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0)))
    else:
        s = np.sin(half) / ang
        dw = np.cos(half)
    dx = s * px
    dy = s * py
    dz = s * pz
    w = q0 * dw - q1 * dx - q2 * dy - q3 * dz
    x = q0 * dx + q1 * dw + q2 * dz - q3 * dy
    y = q0 * dy - q1 * dz + q2 * dw + q3 * dx
    z = q0 * dz + q1 * dy - q2 * dx + q3 * dw
    inv = 1.0 / np.sqrt(w * w + x * x + y * y + z * z)
    return w * inv, x * inv, y * inv, z * inv


@njit(cache=True, inline="always")
def _update(qp, phi, out):
    """out = normalise(qp ⊗ q(φ)) with the exact exponential map."""
    w, x, y, z = _mul_exp(qp[0], qp[1], qp[2], qp[3], phi[0], phi[1], phi[2])
    out[0] = w
    out[1] = x
    out[2] = y
    out[3] = z


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
    first = min(nsub - 1, theta.shape[0])
    for j in range(1, first + 1):  # start-up
        _rotvec(theta, 0, j, ks[j - 1], phi)
        _update(q_out[0], phi, q_out[j])
    kmain = ks[nsub - 1]
    for j in range(nsub, theta.shape[0] + 1):  # steady: as realtime_steady_kernel
        _rotvec(theta, j - nsub, nsub, kmain, phi)
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


@njit(cache=True)
def quaternion_increment_kernel(theta, mode, alpha, beta, exact, q0, q_out):
    """Plaksiy's algorithms A1 (mode 1, thirds), A2 (mode 2, halves), A3 (mode 3, halves).

    A1: φ = θ* + α θ⁽¹⁾×θ⁽³⁾ + β θ⁽²⁾×(θ⁽³⁾ − θ⁽¹⁾);  A2: φ = θ* + α θ⁽⁴⁾×θ*;
    increment ΔΛ from φ by the truncated series (eq. 7) or, with ``exact``, the
    exponential map. A3 (eq. 8): ΔΛ = [1 − θ*²/8 + θ*⁴/384,
    ½θ*(1 − θ*²/24) + α θ⁽⁴⁾×θ*]; with ``exact``: exp(θ* + 2α θ⁽⁴⁾×θ*).
    Λ_n = Λ_{n−1} ∘ ΔΛ_n without renormalisation, as the paper states.
    """
    sub = 3 if mode == 1 else 2
    phi = np.empty(3)
    d = np.empty(4)
    q_out[0, :] = q0
    for n in range(q_out.shape[0] - 1):
        b = n * sub
        sx = 0.0
        sy = 0.0
        sz = 0.0
        for i in range(sub):
            sx += theta[b + i, 0]
            sy += theta[b + i, 1]
            sz += theta[b + i, 2]
        if mode == 1:
            ax, ay, az = theta[b, 0], theta[b, 1], theta[b, 2]
            bx, by, bz = theta[b + 1, 0], theta[b + 1, 1], theta[b + 1, 2]
            cx, cy, cz = theta[b + 2, 0], theta[b + 2, 1], theta[b + 2, 2]
            ex, ey, ez = cx - ax, cy - ay, cz - az
            phi[0] = sx + alpha * (ay * cz - az * cy) + beta * (by * ez - bz * ey)
            phi[1] = sy + alpha * (az * cx - ax * cz) + beta * (bz * ex - bx * ez)
            phi[2] = sz + alpha * (ax * cy - ay * cx) + beta * (bx * ey - by * ex)
        else:
            ax, ay, az = theta[b, 0], theta[b, 1], theta[b, 2]
            cx = ay * sz - az * sy
            cy = az * sx - ax * sz
            cz = ax * sy - ay * sx
            k = alpha if mode == 2 else 2.0 * alpha
            if mode == 3 and not exact:
                th2 = sx * sx + sy * sy + sz * sz
                d[0] = 1.0 - th2 / 8.0 + th2 * th2 / 384.0
                f = 0.5 * (1.0 - th2 / 24.0)
                d[1] = f * sx + alpha * cx
                d[2] = f * sy + alpha * cy
                d[3] = f * sz + alpha * cz
            phi[0] = sx + k * cx
            phi[1] = sy + k * cy
            phi[2] = sz + k * cz
        if exact:
            ang = np.sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2])
            half = 0.5 * ang
            if half < _SMALL:
                x2 = half * half
                s = 0.5 * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0)))
                d[0] = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0)))
            else:
                s = np.sin(half) / ang
                d[0] = np.cos(half)
            d[1] = s * phi[0]
            d[2] = s * phi[1]
            d[3] = s * phi[2]
        elif mode != 3:
            th2 = phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]
            d[0] = 1.0 - th2 / 8.0 + th2 * th2 / 384.0
            f = 0.5 * (1.0 - th2 / 24.0)
            d[1] = f * phi[0]
            d[2] = f * phi[1]
            d[3] = f * phi[2]
        qp = q_out[n]
        q_out[n + 1, 0] = qp[0] * d[0] - qp[1] * d[1] - qp[2] * d[2] - qp[3] * d[3]
        q_out[n + 1, 1] = qp[0] * d[1] + qp[1] * d[0] + qp[2] * d[3] - qp[3] * d[2]
        q_out[n + 1, 2] = qp[0] * d[2] - qp[1] * d[3] + qp[2] * d[0] + qp[3] * d[1]
        q_out[n + 1, 3] = qp[0] * d[3] + qp[1] * d[2] - qp[2] * d[1] + qp[3] * d[0]


@njit(cache=True)
def _cone_deriv(method, y, wx, wy, wz, out):
    """Right-hand sides of the cone-angle ODEs (see strapdown.algorithms.cone_kinematics)."""
    if method <= 1:  # eq. 7 corrected (0) or as printed (1); y = (δ1, δ2, δ3)
        e = y[0] - y[2]
        a = np.cos(e) * wy + np.sin(e) * wz
        out[0] = (-a if method == 0 else a) / np.sin(y[1])
        out[1] = -np.sin(e) * wy + np.cos(e) * wz
        out[2] = wx - np.tan(0.5 * y[1]) * a
    elif method == 2:  # nutation form; y = (ν_y, ν_z, δ3)
        ny, nz = y[0], y[1]
        ang2 = ny * ny + nz * nz
        ang = np.sqrt(ang2)
        if ang < 1e-4:
            c1 = 0.5 - ang2 / 24.0
            c2 = 1.0 / 6.0 - ang2 / 120.0
        else:
            c1 = (1.0 - np.cos(ang)) / ang2
            c2 = (ang - np.sin(ang)) / (ang2 * ang)
        # J_r = I − c1 K + c2 K², K = [ν×] with ν = (0, ny, nz); columns 2 and 3 of J_r
        # K = [[0,-nz,ny],[nz,0,0],[-ny,0,0]]
        # K² = [[-(ny²+nz²),0,0],[0,-nz²,ny nz],[0,ny nz,-ny²]]
        j12 = c1 * nz
        j22 = 1.0 - c2 * nz * nz
        j32 = c2 * ny * nz
        j13 = -c1 * ny
        j23 = c2 * ny * nz
        j33 = 1.0 - c2 * ny * ny
        c3, s3 = np.cos(y[2]), np.sin(y[2])
        rx = wx
        ry = c3 * wy - s3 * wz
        rz = s3 * wy + c3 * wz
        det = j22 * j33 - j23 * j32
        nyd = (ry * j33 - j23 * rz) / det
        nzd = (j22 * rz - j32 * ry) / det
        out[0] = nyd
        out[1] = nzd
        out[2] = rx - j12 * nyd - j13 * nzd
    else:  # z-y-x Euler; y = (yaw, pitch, roll)
        s, c = np.sin(y[2]), np.cos(y[2])
        q = wy * s + wz * c
        out[0] = q / np.cos(y[1])
        out[1] = wy * c - wz * s
        out[2] = wx + q * np.tan(y[1])


@njit(cache=True)
def cone_ode_kernel(omega, h, y0, method, switch, out, mode):
    """RK4 (step 2h, middle = middle sample) for the cone-angle ODEs.

    method 0/1 (eq. 7 corrected/printed) hand over to the nutation form (2)
    while sin δ2 < switch; ``mode`` receives 1 where the nutation form carried
    the state. ``out`` rows are (δ1, δ2, δ3) for methods 0–2 and (yaw, pitch,
    roll) for method 3. Returns the number of hand-overs.
    """
    k1 = np.empty(3)
    k2 = np.empty(3)
    k3 = np.empty(3)
    k4 = np.empty(3)
    tmp = np.empty(3)
    y = np.empty(3)
    eq7 = method <= 1
    sing = False
    if method == 2 or (eq7 and np.sin(y0[1]) < switch):
        y[0] = -y0[1] * np.sin(y0[0])
        y[1] = y0[1] * np.cos(y0[0])
        y[2] = y0[2]
        sing = True
    else:
        y[:] = y0
    out[0, :] = y0
    mode[0] = 1 if (sing and eq7) else 0
    switches = 0
    for k in range(out.shape[0] - 1):
        m = 2 if sing else method
        b = 2 * k
        _cone_deriv(m, y, omega[b, 0], omega[b, 1], omega[b, 2], k1)
        for i in range(3):
            tmp[i] = y[i] + h * k1[i]
        _cone_deriv(m, tmp, omega[b + 1, 0], omega[b + 1, 1], omega[b + 1, 2], k2)
        for i in range(3):
            tmp[i] = y[i] + h * k2[i]
        _cone_deriv(m, tmp, omega[b + 1, 0], omega[b + 1, 1], omega[b + 1, 2], k3)
        for i in range(3):
            tmp[i] = y[i] + 2.0 * h * k3[i]
        _cone_deriv(m, tmp, omega[b + 2, 0], omega[b + 2, 1], omega[b + 2, 2], k4)
        for i in range(3):
            y[i] = y[i] + (2.0 * h) / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        if sing:
            d2 = np.sqrt(y[0] * y[0] + y[1] * y[1])
            d1 = np.arctan2(-y[0], y[1]) if d2 > 0.0 else 0.0
            out[k + 1, 0] = d1
            out[k + 1, 1] = d2
            out[k + 1, 2] = y[2]
            if eq7 and np.sin(d2) >= switch:
                sing = False
                switches += 1
                y[0] = d1
                y[1] = d2
        else:
            out[k + 1, :] = y
            if eq7 and np.sin(y[1]) < switch:
                sing = True
                switches += 1
                d1, d2 = y[0], y[1]
                y[0] = -d2 * np.sin(d1)
                y[1] = d2 * np.cos(d1)
        mode[k + 1] = 1 if (sing and eq7) else 0
    return switches


@njit(cache=True)
def single_chain_kernel(theta, csets, start, g0, q_out):
    """Single chain: ``φ_i = θ_i + Σ_{p=1}^{m} c[m, p−1] θ_{i−p} × θ_i``, ``q ← q ⊗ q(φ)``.

    ``theta[:start]`` is history (the previous ``start`` increments), new
    increments follow; ``g0`` is the global index of ``theta[start]``;
    ``m = min(g, N − 1)`` previous increments are used (start-up rows of
    ``csets``, shape (N, N − 1)). ``q_out[0]`` holds the attitude before the
    first new increment; one row is written per new increment.
    """
    nm1 = csets.shape[0] - 1
    phi = np.empty(3)
    for i in range(start, theta.shape[0]):
        g = g0 + i - start
        m = g if g < nm1 else nm1
        bx, by, bz = theta[i, 0], theta[i, 1], theta[i, 2]
        phi[0] = bx
        phi[1] = by
        phi[2] = bz
        for p in range(1, m + 1):
            c = csets[m, p - 1]
            if c != 0.0:
                ax, ay, az = theta[i - p, 0], theta[i - p, 1], theta[i - p, 2]
                phi[0] += c * (ay * bz - az * by)
                phi[1] += c * (az * bx - ax * bz)
                phi[2] += c * (ax * by - ay * bx)
        k = i - start
        _update(q_out[k], phi, q_out[k + 1])


@njit(cache=True)
def realtime_steady_kernel(theta, k, q_out):
    """Steady state of the real-time structure, resumable.

    theta = the last N − 1 increments followed by new ones; q_out[:N] = the last N
    attitudes; writes q_out[N:] — the same operations as the main branch of
    :func:`realtime_kernel`.
    """
    n = k.shape[0]
    phi = np.empty(3)
    for j in range(theta.shape[0] - n + 1):
        _rotvec(theta, j, n, k, phi)
        _update(q_out[j], phi, q_out[j + n])


@njit(cache=True)
def windowed_kernel(x, offsets, weights, pi, pj, pc, sa, sb, starts, stride, q_out):
    """Fused windowed algorithm: φ_b = sa Σ w_n x[b+o_n] + sb Σ_p c_p x[b+o_i] × x[b+o_j];
    ``q_out[r + stride] = q_out[r] ⊗ q(φ_{starts[r]})`` (q_out[:stride] given)."""
    phi = np.empty(3)
    nn = offsets.shape[0]
    win = np.empty((nn, 3))
    sw = sa * weights
    sc = sb * pc
    for r in range(starts.shape[0]):
        b = starts[r]
        phi[0] = 0.0
        phi[1] = 0.0
        phi[2] = 0.0
        for n in range(nn):  # the window, loaded once
            o = b + offsets[n]
            win[n, 0] = x[o, 0]
            win[n, 1] = x[o, 1]
            win[n, 2] = x[o, 2]
            w = sw[n]
            phi[0] += w * win[n, 0]
            phi[1] += w * win[n, 1]
            phi[2] += w * win[n, 2]
        for p in range(sc.shape[0]):
            c = sc[p]
            i = pi[p]
            j = pj[p]
            ax, ay, az = win[i, 0], win[i, 1], win[i, 2]
            bx, by, bz = win[j, 0], win[j, 1], win[j, 2]
            phi[0] += c * (ay * bz - az * by)
            phi[1] += c * (az * bx - ax * bz)
            phi[2] += c * (ax * by - ay * bx)
        _update(q_out[r], phi, q_out[r + stride])


@njit(cache=True, inline="always")
def _update_rows(q, src, px, py, pz, dst):
    """q[dst] = normalise(q[src] ⊗ q(φ)), φ = (px, py, pz): :func:`_update` on scalars."""
    w, x, y, z = _mul_exp(q[src, 0], q[src, 1], q[src, 2], q[src, 3], px, py, pz)
    q[dst, 0] = w
    q[dst, 1] = x
    q[dst, 2] = y
    q[dst, 3] = z


@njit(cache=True)
def window4_kernel(x, weights, pc, sa, sb, b0, step, stride, q_out):
    """Fused four-sample window (offsets 0 … 3, all six pairs), e.g. the three-period rate
    algorithm, conventional (step 3, stride 1) or sliding (step 1, stride 3).

    ``φ_b = sa Σ_n w_n x[b+n] + sb Σ_p c_p x[b+i_p] × x[b+j_p]`` with the pairs in the
    order (0,1), (0,2), (0,3), (1,2), (1,3), (2,3); ``q_out[r + stride] = q_out[r] ⊗ q(φ_b)``
    with ``b = b0 + r·step`` for every row after the given ``q_out[:stride]``. The same
    floating-point operations in the same order as :func:`windowed_kernel` with those
    offsets and pairs (bit-identical), the window in registers. With ``step == 1`` the
    cross products of consecutive windows overlap: the three that involve the window's
    first three samples are the previous window's last three, carried instead of
    recomputed (the same products of the same operands, so the same values).
    """
    w0, w1, w2, w3 = sa * weights[0], sa * weights[1], sa * weights[2], sa * weights[3]
    c01, c02, c03 = sb * pc[0], sb * pc[1], sb * pc[2]
    c12, c13, c23 = sb * pc[3], sb * pc[4], sb * pc[5]
    # samples 1 … 3 and cross products 12, 13, 23 "before" window b0: shifted into 0 … 2
    # and 01, 02, 12 at the top of the loop (unused unless step == 1)
    a1x, a1y, a1z = x[b0, 0], x[b0, 1], x[b0, 2]
    a2x, a2y, a2z = x[b0 + 1, 0], x[b0 + 1, 1], x[b0 + 1, 2]
    a3x, a3y, a3z = x[b0 + 2, 0], x[b0 + 2, 1], x[b0 + 2, 2]
    e12x, e12y, e12z = a1y * a2z - a1z * a2y, a1z * a2x - a1x * a2z, a1x * a2y - a1y * a2x
    e13x, e13y, e13z = a1y * a3z - a1z * a3y, a1z * a3x - a1x * a3z, a1x * a3y - a1y * a3x
    e23x, e23y, e23z = a2y * a3z - a2z * a3y, a2z * a3x - a2x * a3z, a2x * a3y - a2y * a3x
    for r in range(q_out.shape[0] - stride):
        b = b0 + r * step
        if step == 1:  # slide by one sample
            a0x, a0y, a0z = a1x, a1y, a1z
            a1x, a1y, a1z = a2x, a2y, a2z
            a2x, a2y, a2z = a3x, a3y, a3z
            e01x, e01y, e01z = e12x, e12y, e12z
            e02x, e02y, e02z = e13x, e13y, e13z
            e12x, e12y, e12z = e23x, e23y, e23z
        else:
            a0x, a0y, a0z = x[b, 0], x[b, 1], x[b, 2]
            a1x, a1y, a1z = x[b + 1, 0], x[b + 1, 1], x[b + 1, 2]
            a2x, a2y, a2z = x[b + 2, 0], x[b + 2, 1], x[b + 2, 2]
            e01x, e01y, e01z = a0y * a1z - a0z * a1y, a0z * a1x - a0x * a1z, a0x * a1y - a0y * a1x
            e02x, e02y, e02z = a0y * a2z - a0z * a2y, a0z * a2x - a0x * a2z, a0x * a2y - a0y * a2x
            e12x, e12y, e12z = a1y * a2z - a1z * a2y, a1z * a2x - a1x * a2z, a1x * a2y - a1y * a2x
        a3x, a3y, a3z = x[b + 3, 0], x[b + 3, 1], x[b + 3, 2]
        e03x, e03y, e03z = a0y * a3z - a0z * a3y, a0z * a3x - a0x * a3z, a0x * a3y - a0y * a3x
        e13x, e13y, e13z = a1y * a3z - a1z * a3y, a1z * a3x - a1x * a3z, a1x * a3y - a1y * a3x
        e23x, e23y, e23z = a2y * a3z - a2z * a3y, a2z * a3x - a2x * a3z, a2x * a3y - a2y * a3x
        px = 0.0 + w0 * a0x + w1 * a1x + w2 * a2x + w3 * a3x
        py = 0.0 + w0 * a0y + w1 * a1y + w2 * a2y + w3 * a3y
        pz = 0.0 + w0 * a0z + w1 * a1z + w2 * a2z + w3 * a3z
        px += c01 * e01x
        py += c01 * e01y
        pz += c01 * e01z
        px += c02 * e02x
        py += c02 * e02y
        pz += c02 * e02z
        px += c03 * e03x
        py += c03 * e03y
        pz += c03 * e03z
        px += c12 * e12x
        py += c12 * e12y
        pz += c12 * e12z
        px += c13 * e13x
        py += c13 * e13y
        pz += c13 * e13z
        px += c23 * e23x
        py += c23 * e23y
        pz += c23 * e23z
        _update_rows(q_out, r, px, py, pz, r + stride)


@njit(cache=True, inline="always")
def _add_triples(theta, base, tm, ti, tj, tc, phi):
    """φ += Σ_p tc[p] θ_m × (θ_i × θ_j) over theta[base + …] (finite-amplitude sets)."""
    for p in range(tc.shape[0]):
        c = tc[p]
        m = base + tm[p]
        i = base + ti[p]
        j = base + tj[p]
        ux = theta[i, 1] * theta[j, 2] - theta[i, 2] * theta[j, 1]
        uy = theta[i, 2] * theta[j, 0] - theta[i, 0] * theta[j, 2]
        uz = theta[i, 0] * theta[j, 1] - theta[i, 1] * theta[j, 0]
        ax, ay, az = theta[m, 0], theta[m, 1], theta[m, 2]
        phi[0] += c * (ay * uz - az * uy)
        phi[1] += c * (az * ux - ax * uz)
        phi[2] += c * (ax * uy - ay * ux)


@njit(cache=True)
def conventional_triple_kernel(theta, k, tm, ti, tj, tc, q0, q_out):
    """Conventional structure with triple cross products: :func:`conventional_kernel`'s φ
    (the same operations) plus ``Σ_p tc[p] θ_m × (θ_i × θ_j)`` over each update's N
    increments (tm, ti, tj int64 node indices, tc float64)."""
    n = k.shape[0]
    phi = np.empty(3)
    q_out[0, :] = q0
    for u in range(theta.shape[0] // n):
        _rotvec(theta, u * n, n, k, phi)
        _add_triples(theta, u * n, tm, ti, tj, tc, phi)
        _update(q_out[u], phi, q_out[u + 1])


@njit(cache=True)
def single_chain_triple_kernel(theta, c, tm, ti, tj, tc, start, q_out):
    """Single chain in steady state with triple terms: ``φ_i = θ_i + Σ_{p=1}^{N−1} c[p−1]
    θ_{i−p} × θ_i + Σ_p tc[p] θ_m × (θ_i' × θ_j')`` over the window θ_{i−N+1} … θ_i (node
    indices 0 … N−1), ``q ← q ⊗ q(φ)``. ``theta[:start]`` is history (start ≥ N − 1);
    ``q_out[0]`` holds the attitude before ``theta[start]``; one row per new increment."""
    nm1 = c.shape[0]
    phi = np.empty(3)
    for i in range(start, theta.shape[0]):
        bx, by, bz = theta[i, 0], theta[i, 1], theta[i, 2]
        phi[0] = bx
        phi[1] = by
        phi[2] = bz
        for p in range(1, nm1 + 1):
            cp = c[p - 1]
            if cp != 0.0:
                ax, ay, az = theta[i - p, 0], theta[i - p, 1], theta[i - p, 2]
                phi[0] += cp * (ay * bz - az * by)
                phi[1] += cp * (az * bx - ax * bz)
                phi[2] += cp * (ax * by - ay * bx)
        _add_triples(theta, i - nm1, tm, ti, tj, tc, phi)
        k = i - start
        _update(q_out[k], phi, q_out[k + 1])
