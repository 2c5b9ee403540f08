"""Plain-Python twins of :mod:`strapdown.algorithms._velocity_kernels`, generic over the
arithmetic.

The same code runs on Python floats (the oracle the compiled kernels are tested against)
and on mpmath numbers (the arbitrary-precision analysis of the sculling error law). It
mirrors the kernels operation by operation. The navigation's twins, which chain these
increments, are :mod:`strapdown.navigation._reference`.
"""

from __future__ import annotations


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def axpy(c, x, y):
    """y + c·x."""
    return tuple(yi + c * xi for xi, yi in zip(x, y, strict=True))


def rotation_comp(alpha, ups):
    """υ + ½ α × υ + ⅙ α × (α × υ)."""
    c = cross(alpha, ups)
    cc = cross(alpha, c)
    return tuple(u + 0.5 * a + b / 6 for u, a, b in zip(ups, c, cc, strict=True))


def conventional_body(theta, dv, kc, ks, h, zero):
    """Twin of :func:`strapdown.algorithms._velocity_kernels.conventional_body_kernel`:
    lists of (φ, Δv_b, ΔR_b) per update; ``kc``, ``ks`` nested lists (N × N)."""
    n = len(kc)
    z3 = (zero, zero, zero)
    twelfth = (zero + 1) / 12
    prev_t, prev_v = z3, z3
    out = []
    for u in range(len(theta) // n):
        b = u * n
        alpha, ups, scul, dr = z3, z3, z3, z3
        for j in range(n):
            scul = axpy(twelfth, cross(prev_t, dv[b + j]), scul)
            scul = axpy(twelfth, cross(prev_v, theta[b + j]), scul)
            alpha = axpy(1, theta[b + j], alpha)
            ups = axpy(1, dv[b + j], ups)
            prev_t, prev_v = tuple(theta[b + j]), tuple(dv[b + j])
            if j < n - 1:
                run = rotation_comp(alpha, ups)
                dr = tuple(d + h * (r + s) for d, r, s in zip(dr, run, scul, strict=True))
        phi, vel = alpha, rotation_comp(alpha, ups)
        for i in range(n - 1):
            for j in range(i + 1, n):
                if kc[i][j] != 0:
                    phi = axpy(kc[i][j], cross(theta[b + i], theta[b + j]), phi)
                if ks[i][j] != 0:
                    vel = axpy(ks[i][j], cross(theta[b + i], dv[b + j]), vel)
                    vel = axpy(ks[i][j], cross(dv[b + i], theta[b + j]), vel)
        out.append((phi, vel, tuple(d + h / 2 * v for d, v in zip(dr, vel, strict=True))))
    return out


def single_chain_body(theta, dv, tab_c, tab_s, h):
    """Twin of :func:`strapdown.algorithms._velocity_kernels.single_chain_body_kernel`."""
    n = len(tab_c)
    out = []
    for k in range(len(theta)):
        row = min(k, n - 1)
        phi, vel = tuple(theta[k]), rotation_comp(theta[k], dv[k])
        for m in range(1, row + 1):
            cc, cs = tab_c[row][m - 1], tab_s[row][m - 1]
            if cc != 0:
                phi = axpy(cc, cross(theta[k - m], theta[k]), phi)
            if cs != 0:
                vel = axpy(cs, cross(theta[k - m], dv[k]), vel)
                vel = axpy(cs, cross(dv[k - m], theta[k]), vel)
        out.append((phi, vel, tuple(h / 2 * v for v in vel)))
    return out
