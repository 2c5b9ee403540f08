"""Plain-Python reference implementations, generic over the arithmetic.

The same code runs on Python floats (the oracle the compiled kernels are
tested against) and on mpmath numbers (arbitrary-precision analysis). It
mirrors :mod:`strapdown.algorithms._kernels` operation by operation, except that the
exponential map uses ``sin(|φ|/2)/|φ|`` directly (exact in mpmath).
"""

from __future__ import annotations

from strapdown._core.backend import Backend


def rotvec(theta, base, m, k, zero):
    """φ = Σθ + Σ_{i<j} k[i][j] θ_i × θ_j over theta[base : base + m]."""
    px = py = pz = zero
    for i in range(m):
        px += theta[base + i][0]
        py += theta[base + i][1]
        pz += theta[base + i][2]
    for i in range(m - 1):
        ax, ay, az = theta[base + i]
        for j in range(i + 1, m):
            c = k[i][j]
            if c != 0:
                bx, by, bz = theta[base + j]
                px += c * (ay * bz - az * by)
                py += c * (az * bx - ax * bz)
                pz += c * (ax * by - ay * bx)
    return px, py, pz


def quat_mul(p, q):
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    )


def quat_exp(phi, m: Backend):
    ang = m.sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2])
    if ang == 0:
        return (m.one, m.zero, m.zero, m.zero)
    s = m.sin(ang / 2) / ang
    return (m.cos(ang / 2), s * phi[0], s * phi[1], s * phi[2])


def update(qp, phi, m: Backend):
    w, x, y, z = quat_mul(qp, quat_exp(phi, m))
    inv = 1 / m.sqrt(w * w + x * x + y * y + z * z)
    return (w * inv, x * inv, y * inv, z * inv)


def conventional(theta, k, q0, m: Backend):
    """Conventional structure (see :func:`strapdown.algorithms._kernels.conventional_kernel`)."""
    n = len(k)
    out = [tuple(q0)]
    for u in range(len(theta) // n):
        out.append(update(out[-1], rotvec(theta, u * n, n, k, m.zero), m))
    return out


def realtime(theta, ks, q0, m: Backend):
    """Real-time structure (see :func:`strapdown.algorithms._kernels.realtime_kernel`)."""
    nsub = len(ks)
    out = [tuple(q0)]
    for j in range(1, len(theta) + 1):
        if j < nsub:
            out.append(update(out[0], rotvec(theta, 0, j, ks[j - 1], m.zero), m))
        else:
            phi = rotvec(theta, j - nsub, nsub, ks[nsub - 1], m.zero)
            out.append(update(out[j - nsub], phi, m))
    return out


def chain(phi, q0, stride, m: Backend):
    """Reference twin of :func:`strapdown.algorithms._kernels.chain_kernel` (q0: list of
    ``stride`` quats)."""
    out = [tuple(q) for q in q0]
    for k, p in enumerate(phi):
        out.append(update(out[k], p, m))
    return out


def windowed_rotvec(samples, weights, pairs, zero):
    """φ = Σ_n w_n s_n + Σ (i, j, k) k · s_i × s_j for one window of samples."""
    px = py = pz = zero
    for w, (sx, sy, sz) in zip(weights, samples, strict=True):
        if w != 0:
            px += w * sx
            py += w * sy
            pz += w * sz
    for i, j, c in pairs:
        ax, ay, az = samples[i]
        bx, by, bz = samples[j]
        px += c * (ay * bz - az * by)
        py += c * (az * bx - ax * bz)
        pz += c * (ax * by - ay * bx)
    return px, py, pz


def rk4(omega, h, q0, mode, m: Backend):
    """Reference twin of :func:`strapdown.algorithms._kernels.rk4_kernel` (mode 0: step 2h;
    1: step h)."""
    stride = 2 if mode == 0 else 1
    big_h = stride * h
    half = big_h / 2

    def f(q, w):
        return tuple(c / 2 for c in quat_mul(q, (m.zero, *w)))

    def axpy(q, s, k):
        return tuple(a + s * b for a, b in zip(q, k, strict=True))

    out = [tuple(q0)]
    for j in range((len(omega) - 1) // stride):
        b = j * stride
        q = out[-1]
        if mode == 0:
            mid = omega[b + 1]
        else:
            mid = tuple((u + v) / 2 for u, v in zip(omega[b], omega[b + 1], strict=True))
        k1 = f(q, omega[b])
        k2 = f(axpy(q, half, k1), mid)
        k3 = f(axpy(q, half, k2), mid)
        k4 = f(axpy(q, big_h, k3), omega[b + stride])
        new = tuple(qi + big_h / 6 * (a + 2 * b2 + 2 * c + d)
                    for qi, a, b2, c, d in zip(q, k1, k2, k3, k4, strict=True))
        inv = 1 / m.sqrt(sum(c * c for c in new))
        out.append(tuple(c * inv for c in new))
    return out


def quaternion_increment(theta, mode, alpha, beta, exact, q0, m: Backend):
    """Reference twin of :func:`strapdown.algorithms._kernels.quaternion_increment_kernel`."""

    def cross(u, v):
        return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])

    def trunc(p):
        th2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
        f = (1 - th2 / 24) / 2
        return (1 - th2 / 8 + th2 * th2 / 384, f * p[0], f * p[1], f * p[2])

    sub = 3 if mode == 1 else 2
    out = [tuple(q0)]
    for n in range(len(theta) // sub):
        t = theta[n * sub:(n + 1) * sub]
        s = tuple(sum(v[i] for v in t) for i in range(3))
        if mode == 1:
            c1 = cross(t[0], t[2])
            c2 = cross(t[1], tuple(t[2][i] - t[0][i] for i in range(3)))
            phi = tuple(s[i] + alpha * c1[i] + beta * c2[i] for i in range(3))
        else:
            c = cross(t[0], s)
            k = alpha if mode == 2 else 2 * alpha
            phi = tuple(s[i] + k * c[i] for i in range(3))
        if exact:
            d = quat_exp(phi, m)
        elif mode == 3:
            t0 = trunc(s)
            d = (t0[0], *(t0[1 + i] + alpha * c[i] for i in range(3)))
        else:
            d = trunc(phi)
        out.append(quat_mul(out[-1], d))
    return out


def windowed(x, offsets, weights, pairs, coefficients, sa, sb, starts, q0, stride, m: Backend):
    """Reference twin of :func:`strapdown.algorithms._kernels.windowed_kernel` and
    :func:`strapdown.algorithms._kernels.window4_kernel`.

    ``φ_b = sa Σ_n w_n x[b+o_n] + sb Σ_p c_p x[b+o_i] × x[b+o_j]`` for ``b`` in ``starts``,
    ``q[r + stride] = q[r] ⊗ q(φ_{starts[r]})``; ``q0`` lists the first ``stride`` attitudes.
    """
    sw = [sa * w for w in weights]
    sp = [(i, j, sb * c) for (i, j), c in zip(pairs, coefficients, strict=True)]
    phis = [windowed_rotvec([tuple(x[b + o]) for o in offsets], sw, sp, m.zero) for b in starts]
    return chain(phis, q0, stride, m)


def _cross(u, v):
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def add_triples(theta, base, triples, phi):
    """φ + Σ (m, i, j, c) c θ_m × (θ_i × θ_j) over theta[base + …] (finite-amplitude sets)."""
    px, py, pz = phi
    for m, i, j, c in triples:
        ux, uy, uz = _cross(theta[base + i], theta[base + j])
        ax, ay, az = theta[base + m]
        px += c * (ay * uz - az * uy)
        py += c * (az * ux - ax * uz)
        pz += c * (ax * uy - ay * ux)
    return px, py, pz


def conventional_triple(theta, k, triples, q0, m: Backend):
    """Reference twin of :func:`strapdown.algorithms._kernels.conventional_triple_kernel`."""
    n = len(k)
    out = [tuple(q0)]
    for u in range(len(theta) // n):
        phi = add_triples(theta, u * n, triples, rotvec(theta, u * n, n, k, m.zero))
        out.append(update(out[-1], phi, m))
    return out


def single_chain_triple(theta, c, triples, start, q0, m: Backend):
    """Reference twin of :func:`strapdown.algorithms._kernels.single_chain_triple_kernel`
    (``q0`` the attitude before ``theta[start]``)."""
    nm1 = len(c)
    out = [tuple(q0)]
    for i in range(start, len(theta)):
        bx, by, bz = theta[i]
        px, py, pz = bx, by, bz
        for p in range(1, nm1 + 1):
            if c[p - 1] != 0:
                ax, ay, az = theta[i - p]
                px += c[p - 1] * (ay * bz - az * by)
                py += c[p - 1] * (az * bx - ax * bz)
                pz += c[p - 1] * (ax * by - ay * bx)
        out.append(update(out[-1], add_triples(theta, i - nm1, triples, (px, py, pz)), m))
    return out
