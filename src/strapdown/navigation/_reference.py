"""Plain-Python twins of :mod:`strapdown.navigation._kernels`, generic over the arithmetic.

The same code runs on Python floats (the oracle the compiled kernels are tested against)
and on mpmath numbers (the arbitrary-precision analysis of the sculling error law). It
mirrors the kernels operation by operation; the body increments' twins come from
:mod:`strapdown.algorithms._velocity_reference`, quaternion helpers from
:mod:`strapdown.algorithms._reference`.
"""

from __future__ import annotations

from strapdown._core.backend import Backend
from strapdown.algorithms._reference import update
from strapdown.algorithms._velocity_reference import axpy, cross


def rotate(q, x):
    """C(q) x (same operations as the kernel)."""
    w, a, b, c = q
    tx = 2 * (b * x[2] - c * x[1])
    ty = 2 * (c * x[0] - a * x[2])
    tz = 2 * (a * x[1] - b * x[0])
    return (x[0] + w * tx + (b * tz - c * ty), x[1] + w * ty + (c * tx - a * tz),
            x[2] + w * tz + (a * ty - b * tx))


def inertial(body, period, q0, v0, p0, m: Backend):
    """Twin of :func:`strapdown.navigation._kernels.inertial_kernel`: lists of q, v, p."""
    qs, vs, ps = [tuple(q0)], [tuple(v0)], [tuple(p0)]
    for phi, dvb, drb in body:
        q, v, p = qs[-1], vs[-1], ps[-1]
        vs.append(axpy(1, rotate(q, dvb), v))
        ps.append(tuple(pi + vi * period + ri
                        for pi, vi, ri in zip(p, v, rotate(q, drb), strict=True)))
        qs.append(update(q, phi, m))
    return qs, vs, ps


# ---------------------------------------------------------------------- WGS-84 navigation
def earth_rates(lat, hgt, v, m: Backend, quad=1):
    """Twin of :func:`strapdown.navigation._kernels._rates`: ω_in, gravity and
    Coriolis, (L̇, λ̇, ḣ) as one 9-tuple (``quad = 0``: linear height correction)."""
    from strapdown.truth import earth

    s, cl = m.sin(lat), m.cos(lat)
    s2 = s * s
    d = 1 - earth.E2 * s2
    sq = m.sqrt(d)
    e0 = earth.A * (1 - earth.E2) / (d * sq) + hgt
    e1 = earth.A / sq + hgt
    g0 = earth.GE * (1 + earth.GK * s2) / sq
    gam = g0 * (1 - 2 / earth.A * (1 + earth.F + earth.GM_RATIO - 2 * earth.F * s2) * hgt
                + quad * (3 * hgt * hgt / (earth.A * earth.A)))
    wie0, wie2 = earth.OMEGA * cl, -earth.OMEGA * s
    win = (wie0 + v[1] / e1, -v[0] / e0, wie2 - v[1] * (s / cl) / e1)
    w = (wie0 + win[0], win[1], wie2 + win[2])
    return (*win, -(w[1] * v[2] - w[2] * v[1]), -(w[2] * v[0] - w[0] * v[2]),
            gam - (w[0] * v[1] - w[1] * v[0]), v[0] / e0, v[1] / (e1 * cl), -v[2])


def _am(k, a, b, c, d):
    if k == 2:
        return 0.5 * (a + b)
    if k == 3:
        return (5 * a + 8 * b - c) / 12
    return (9 * a + 19 * b - 5 * c + d) / 24


def _extrap(k, b, c, d):
    return b if k == 2 else (2 * b - c if k == 3 else 3 * b - 3 * c + d)


def left_update(zeta, q, m: Backend):
    """normalise(q(ζ) ⊗ q) by the exact exponential."""
    ang = m.sqrt(zeta[0] * zeta[0] + zeta[1] * zeta[1] + zeta[2] * zeta[2])
    s = m.sin(ang / 2) / ang if ang != 0 else 0.5 + 0 * ang
    d = (m.cos(ang / 2), s * zeta[0], s * zeta[1], s * zeta[2])
    out = (d[0] * q[0] - d[1] * q[1] - d[2] * q[2] - d[3] * q[3],
           d[0] * q[1] + d[1] * q[0] + d[2] * q[3] - d[3] * q[2],
           d[0] * q[2] - d[1] * q[3] + d[2] * q[0] + d[3] * q[1],
           d[0] * q[3] + d[1] * q[2] - d[2] * q[1] + d[3] * q[0])
    inv = 1 / m.sqrt(sum(x * x for x in out))
    return tuple(x * inv for x in out)


def earth_nav(body, period, pos0, v0, q0, m: Backend, quad=1):
    """Twin of :func:`strapdown.navigation._kernels.earth_nav_kernel` on a list of
    ``(φ, Δv_b)``: lists of positions, velocities and ``q_n_b`` (row 0 the initial state).
    The same equations; the navigation-frame rotation by its exponential (the kernel takes
    a series below |ζ|/2 = 1e-2, equal to rounding)."""
    ps, vs, qs = [tuple(pos0)], [tuple(v0)], [tuple(q0)]
    hist = [earth_rates(pos0[0], pos0[2], v0, m, quad) + (0 * period,) * 3]
    for phi, dvb in body:
        p, v, q = ps[-1], vs[-1], qs[-1]
        k = len(hist) + 1
        h3 = hist + [(0 * period,) * 12] * (3 - len(hist))
        col = [(h3[0][c], h3[1][c], h3[2][c]) for c in range(12)]
        pred = [_extrap(k, *col[c]) for c in range(9)]
        zeta = tuple(period * _am(k, pred[c], *col[c]) for c in range(3))
        x, an = rotate(q, dvb), rotate(q, phi)
        t1 = cross(zeta, x)
        t3 = cross(zeta, cross(an, x))
        t4 = cross(zeta, t1)
        db = tuple(dvb[c] - h3[0][9 + c] if len(hist) > 1 else 0 * period for c in range(3))
        t5 = cross(zeta, rotate(q, db))
        t6 = cross(tuple(period * (pred[c] - h3[0][c]) for c in range(3)), x)
        vp = [v[c] + (x[c] - 0.5 * t1[c] - t3[c] / 12 + t4[c] / 6 - (t5[c] - t6[c]) / 12)
              + period * _am(k, pred[3 + c], *col[3 + c]) for c in range(3)]
        pp = [p[c] + period * _am(k, pred[6 + c], *col[6 + c]) for c in range(3)]
        end = earth_rates(pp[0], pp[2], vp, m, quad)
        w = 0.5 if k == 2 else (5 / 12 if k == 3 else 0.375)
        vn = tuple(vp[c] + period * w * (end[3 + c] - pred[3 + c]) for c in range(3))
        ps.append(tuple(p[c] + period * _am(k, end[6 + c], *col[6 + c]) for c in range(3)))
        vs.append(vn)
        cz = cross(h3[0][:3], end[:3])
        zeta = tuple(period * (_am(k, end[c], *col[c]) + period / 12 * cz[c]) for c in range(3))
        hist = [tuple(end) + tuple(dvb), *hist[:2]]
        qs.append(left_update(tuple(-z for z in zeta), update(q, phi, m), m))
    return ps, vs, qs
