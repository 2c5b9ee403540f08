"""Coning coefficients that keep their order at finite cone amplitude: triple cross products.

The classical-coning drift of a rotation-vector algorithm is a function of two small
parameters, the half-cone angle ``a`` and ``x = Ωh``. Li & Zhang (2017) Table 3 (and every
published set) cancel only its ``a²`` part; at ``a = 1°`` the ``a⁴`` part, which comes from
the Bortz terms the pair form neglects, dominates for N ≥ 3 (``strapdown reproduce li2017``).
Triple cross products ``θ_m × (θ_i × θ_j)`` are ``O(a³)`` in the rotation vector, so they
leave the ``a²`` drift unchanged and shift the ``a⁴`` drift linearly: with the pair
coefficients of the ``a²`` design fixed, the ``a⁴`` conditions, order by order in ``x``,
are a linear system for the triple coefficients.

The drift series
----------------
Under classical coning every update's rotation vector is the first one's turned about the
cone axis by ``ΩT`` (``T`` the update period), so the error after ``k`` updates is
``q_a (E ρ)^k q_a⁻¹ ρ^{−k}`` with ``E = exp(φ_0)``, ``ρ = exp(x̂ ΩT/2)``, ``q_a`` the
initial tilt. At whole cone periods that is a rotation by ``k Δ`` about the axis ``n`` of
``q_a E ρ q_a⁻¹``, ``Δ = ψ − ΩT`` with ``ψ`` the rotation angle of ``E ρ``: the drift about
the cone axis is exactly ``Δ n_x / T`` (the exact response, evaluated in arbitrary precision
by :mod:`strapdown.analysis.frequency_response`). :func:`drift_series` expands it as a
double power series in ``a`` and ``x`` with exact rational coefficients (gmpy2 ``mpq``):
increments from the closed form of the classical-coning motion (Li & Zhang (2017) eq. 7),
``φ`` with its pair and triple terms, the exponential map, ``E ρ`` and
``2 atan(tan(ψ/2 − ΩT/2))``, every step a truncated bivariate series.

Result (N = 3 … 6, both structures; :func:`derive_triple`): with the triple terms
``τ_m θ_N × (θ_{N−m} × θ_N)`` (single chain: ``θ_k × (θ_{k−m} × θ_k)``), m = 1 … N−1, the
``a⁴`` drift is cancelled through the order of the ``a²`` law, ``x^{2N}``, so the drift is
``−c₂ a²Ω x^{2N} − c₄ a⁴Ω x^{2N+2} − c₆ a⁶Ω x^6 − …`` (constants in
:attr:`strapdown.design.Design.amplitude_law`). The ``a⁶ x⁴`` term vanishes with the
``a⁴ x⁴`` term; the ``a⁶ x⁶`` term remains (it is quadratic in the triple coefficients, so
this linear design cannot remove it) and dominates the conventional N = 5, 6 sets at small
``x``, where the drift is far below the float64 floor.

:func:`derive_triple_a6` removes it too: with the extra terms ``θ_{N−1} × (θ_{N−m} × θ_N)``
(:func:`with_a6_triples`) the ``a⁴`` conditions through ``x^{2N+2}`` leave N − 3 free
directions, and the ``a⁶ x⁶, x⁸, …`` coefficients, quadratic in them, are zeroed by Newton's
method (an algebraic root, rounded to rationals). Conventional N = 6 at ``a = 1°``: 1.23–1.26×
the ``a²`` law over Ωh 0.05–0.2 (the linear set: 2.79× at 0.2, and the ``a⁶`` term below);
N = 5: 0.98–1.00× over 0.005–0.2. For the single chain no real root is found with these terms.
The shipped conventional N = 4, 5, 6 ``finite-amplitude`` sets are these designs (N = 5
with ``through_law``; :data:`strapdown.algorithms.finite_amplitude.A6_DESIGN`).

Spin plus coning (``spin_ratio`` σ = ω_s/Ω, :func:`derive_spin_robust`): with body spin the
axial increment is ``O(1)``, the ``a²`` drift of Table 3 drops to ``(Ωh)⁴`` (e.g.
``−12/5 a²Ω(Ωh)⁴`` for N = 3 at σ = 3), and triple terms enter it. Its ``(Ωh)⁴``
coefficient is affine in them and polynomial in σ, so a few triple terms cancel it for every
ratio at once — N = 3: ``+51/40 θ3×(θ2×θ3) − 39/40 θ3×(θ1×θ3)``.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import replace
from fractions import Fraction
from math import factorial

import sympy as sp
from gmpy2 import mpq

from strapdown.design.designer import Design, Structure, derive

__all__ = ["A_ORDER", "derive_spin_robust", "derive_triple", "derive_triple_a6", "drift_series",
           "leading_terms", "with_a6_triples",
           "with_last_triples", "with_triples_to_last"]

#: Highest power of ``a`` carried by :func:`drift_series`.
A_ORDER = 6

_Series = list[list[mpq]]  # s[p][q]: coefficient of a^p x^q


class _Bivariate:
    """Truncated bivariate power series in ``a`` (degree ≤ pa) and ``x`` (degree ≤ qx)."""

    def __init__(self, pa: int, qx: int):
        self.pa, self.qx = pa, qx

    def zero(self) -> _Series:
        return [[mpq(0)] * (self.qx + 1) for _ in range(self.pa + 1)]

    def const(self, c) -> _Series:
        z = self.zero()
        z[0][0] = mpq(c)
        return z

    def add(self, *ss: _Series) -> _Series:
        z = self.zero()
        for s in ss:
            for p in range(self.pa + 1):
                zp, sp_ = z[p], s[p]
                for q in range(self.qx + 1):
                    zp[q] += sp_[q]
        return z

    def scale(self, s: _Series, c) -> _Series:
        c = mpq(c)
        return [[c * v for v in row] for row in s]

    def mul(self, s: _Series, t: _Series) -> _Series:
        z = self.zero()
        for p1 in range(self.pa + 1):
            for q1, v1 in enumerate(s[p1]):
                if not v1:
                    continue
                for p2 in range(self.pa + 1 - p1):
                    r2, zr = t[p2], z[p1 + p2]
                    for q2 in range(self.qx + 1 - q1):
                        if r2[q2]:
                            zr[q1 + q2] += v1 * r2[q2]
        return z

    def xshift(self, s: _Series, k: int) -> _Series:
        """Multiply by ``x^k``; a negative ``k`` divides exactly (checked)."""
        z = self.zero()
        for p in range(self.pa + 1):
            for q, v in enumerate(s[p]):
                if v:
                    if q + k < 0:
                        raise ArithmeticError("series not divisible by the power of x")
                    if q + k <= self.qx:
                        z[p][q + k] = v
        return z

    def _graded(self):
        return sorted(((p, q) for p in range(self.pa + 1) for q in range(self.qx + 1)),
                      key=lambda t: (t[0] + t[1], t))

    def inv(self, s: _Series) -> _Series:
        """``1/s`` (``s`` with a non-zero constant term)."""
        y = self.zero()
        nz = [(p, q) for p in range(self.pa + 1) for q in range(self.qx + 1)
              if s[p][q] and (p, q) != (0, 0)]
        for p, q in self._graded():
            if (p, q) == (0, 0):
                y[0][0] = 1 / s[0][0]
                continue
            acc = sum((s[p1][q1] * y[p - p1][q - q1] for p1, q1 in nz if p1 <= p and q1 <= q),
                      mpq(0))
            y[p][q] = -acc / s[0][0]
        return y

    def sqrt(self, s: _Series, root: mpq) -> _Series:
        """``√s`` with constant term ``root`` (``root² = s₀₀``)."""
        if root * root != s[0][0]:
            raise ArithmeticError("the constant term is not the square of the given root")
        y = self.zero()
        y[0][0] = root
        for p, q in self._graded():
            if (p, q) == (0, 0):
                continue
            acc = mpq(0)
            for p1 in range(p + 1):
                for q1 in range(q + 1):
                    if (p1, q1) not in ((0, 0), (p, q)) and y[p1][q1]:
                        acc += y[p1][q1] * y[p - p1][q - q1]
            y[p][q] = (s[p][q] - acc) / (2 * root)
        return y

    def trig_a(self, cosine: bool) -> _Series:
        z = self.zero()
        for k in range(0 if cosine else 1, self.pa + 1, 2):
            z[k][0] = mpq((-1) ** (k // 2), factorial(k))
        return z

    def trig_x(self, c, cosine: bool) -> _Series:
        z = self.zero()
        c = mpq(c)
        for k in range(0 if cosine else 1, self.qx + 1, 2):
            z[0][k] = mpq((-1) ** (k // 2)) * c**k / factorial(k)
        return z

    def trig_diff_x(self, nu, n, cosine: bool) -> _Series:
        """``(cos ν(n+1)x − cos νnx)/ν`` (or the sines), a polynomial in ν: finite at ν = 0."""
        z = self.zero()
        nu, n = mpq(nu), mpq(n)
        for k in range(2 if cosine else 1, self.qx + 1, 2):
            sign = (-1) ** (k // 2)
            z[0][k] = mpq(sign) * nu ** (k - 1) * ((n + 1) ** k - n**k) / factorial(k)
        return z

    def cross(self, u, v):
        m, a = self.mul, self.add
        return (a(m(u[1], v[2]), self.scale(m(u[2], v[1]), -1)),
                a(m(u[2], v[0]), self.scale(m(u[0], v[2]), -1)),
                a(m(u[0], v[1]), self.scale(m(u[1], v[0]), -1)))

    def power_series(self, coeffs: Sequence[mpq], s: _Series) -> _Series:
        """``Σ_k coeffs[k] s^k`` (``s`` is ``O(a²)``: powers beyond ``pa/2`` vanish)."""
        out = self.const(coeffs[0])
        pw = self.const(1)
        for c in coeffs[1:]:
            pw = self.mul(pw, s)
            out = self.add(out, self.scale(pw, c))
        return out


def _q(v) -> mpq:
    f = Fraction(v)
    return mpq(f.numerator, f.denominator)


def _rotation_vector(b: _Bivariate, st: Structure, pairs, triples, spin=0):
    """φ of the update starting at t = 0, per component, from the closed-form increments.

    ``θ_n = (−(1 − cos a) x, sin a (cos(s+1)x − cos sx), sin a (sin(s+1)x − sin sx))`` for
    node ``s`` (Li & Zhang (2017) eq. 7, increments over ``[s h, (s+1) h]``, ``Ω = 1``);
    with body spin ``σ = ω_s/Ω`` (:class:`~strapdown.truth.motions.SpinConing`) the axial
    increment gains ``σ x`` and the transverse ones turn at ``ν = 1 − σ``:
    ``sin a (cos ν(s+1)x − cos νsx)/ν`` and likewise with sines.
    """
    sa, ca = b.trig_a(False), b.trig_a(True)
    minus_g_x = b.xshift(b.add(ca, b.const(mpq(spin) - 1)), 1)
    nu = 1 - mpq(spin)
    th = []
    for s in st.nodes:
        re, im = b.trig_diff_x(nu, s, True), b.trig_diff_x(nu, s, False)
        th.append((minus_g_x, b.mul(sa, re), b.mul(sa, im)))
    phi = [b.zero(), b.zero(), b.zero()]
    terms: list[tuple[tuple, mpq]] = [(t, _q(w)) for t, w in zip(th, st.weights, strict=True)]
    crosses: dict[tuple[int, int], tuple] = {}
    for (i, j), c in pairs:
        if c:
            crosses[i, j] = crosses.get((i, j)) or b.cross(th[i], th[j])
            terms.append((crosses[i, j], _q(c)))
    for (m, i, j), c in triples:
        if c:
            crosses[i, j] = crosses.get((i, j)) or b.cross(th[i], th[j])
            terms.append((b.cross(th[m], crosses[i, j]), _q(c)))
    for vec, c in terms:
        if c:
            for k in range(3):
                phi[k] = b.add(phi[k], b.scale(vec[k], c))
    return phi, sa, ca


def _drift(b: _Bivariate, st: Structure, pairs, triples, spin=0) -> _Series:
    """Drift about the cone axis over Ω, ``Δ n_x / (Ω T)``, as a bivariate series (body spin
    ``σ``: ``ρ = exp(x̂ (1 − σ)ΩT/2)``, see :mod:`strapdown.analysis.frequency_response`)."""
    phi, sa, ca = _rotation_vector(b, st, pairs, triples, spin)
    s2 = b.add(*(b.mul(p, p) for p in phi))
    kmax = b.pa // 2 + 1 if not spin else b.qx // 2 + 2  # with spin |φ|² is O(x²) only
    ew = b.power_series([mpq((-1) ** k, 4**k * factorial(2 * k)) for k in range(kmax)], s2)
    sv = b.power_series([mpq((-1) ** k, 2 * 4**k * factorial(2 * k + 1)) for k in range(kmax)],
                        s2)
    ev = [b.mul(sv, p) for p in phi]
    u = mpq(st.update)
    cr, sr = b.trig_x(u / 2, True), b.trig_x(u / 2, False)
    nu = 1 - mpq(spin)
    rc, rs = (cr, sr) if not spin else (b.trig_x(u * nu / 2, True), b.trig_x(u * nu / 2, False))
    neg = functools.partial(b.scale, c=-1)
    aw = b.add(b.mul(ew, rc), neg(b.mul(ev[0], rs)))  # E ⊗ ρ, ρ = (cos νΩT/2, sin νΩT/2, 0, 0)
    ax = b.add(b.mul(ew, rs), b.mul(ev[0], rc))
    ay = b.add(b.mul(ev[1], rc), b.mul(ev[2], rs))
    az = b.add(b.mul(ev[2], rc), neg(b.mul(ev[1], rs)))
    y = b.sqrt(b.xshift(b.add(b.mul(ax, ax), b.mul(ay, ay), b.mul(az, az)), -2), u / 2)
    vabs = b.xshift(y, 1)  # |vec(E ρ)| = sin(ψ/2)
    num = b.add(b.mul(vabs, cr), neg(b.mul(aw, sr)))  # tan(ψ/2 − ΩT/2) = num/den
    den = b.add(b.mul(aw, cr), b.mul(vabs, sr))
    z = b.mul(num, b.inv(den))
    z2 = b.mul(z, z)
    at = b.add(z, b.scale(b.mul(z, z2), mpq(-1, 3)), b.scale(b.mul(b.mul(z, z2), z2), mpq(1, 5)))
    # n_x of the axis turned by the initial tilt q_a (about y by a): cos a v_x + sin a v_z
    nx = b.mul(b.add(b.mul(ca, b.xshift(ax, -1)), b.mul(sa, b.xshift(az, -1))), b.inv(y))
    return b.xshift(b.scale(b.mul(at, nx), 2 / u), -1)


def drift_series(structure: Structure, coefficients: Sequence, triple_coefficients: Sequence = (),
                 *, x_order: int | None = None, spin_ratio=0, a_order: int = A_ORDER
                 ) -> dict[int, tuple[Fraction, ...]]:
    """Exact double series of the classical-coning drift about the cone axis.

    ``drift = Ω Σ_{p, q} d[p][q] a^p (Ωh)^q`` (rad/s, the sign of Li & Zhang (2017) Table 1
    reversed: ``d = −c``), for the increment ``structure`` with pair ``coefficients`` and
    ``triple_coefficients`` (one per ``structure.triples``), to ``a^{A_ORDER}`` and
    ``x^{x_order}`` (default ``2N + 6``). Returns ``{p: (d[p][0], …, d[p][x_order])}`` for
    even ``p``; odd powers of ``a`` vanish. ``spin_ratio``: body spin over cone rate,
    ``ω_s/Ω`` (exact rational; the motion of :class:`~strapdown.truth.motions.SpinConing`);
    ``a_order``: the highest power of ``a`` carried (a smaller one is faster).
    """
    if structure.input != "increment":
        raise ValueError("the finite-amplitude series is derived for increment input only; "
                         f"{structure.name!r} takes rate samples")
    if len(coefficients) != len(structure.pairs):
        raise ValueError(f"{len(structure.pairs)} pair coefficients expected, "
                         f"got {len(coefficients)}")
    if len(triple_coefficients) != len(structure.triples):
        raise ValueError(f"{len(structure.triples)} triple coefficients expected, "
                         f"got {len(triple_coefficients)}")
    x_order = 2 * structure.n + 6 if x_order is None else int(x_order)
    b = _Bivariate(int(a_order), x_order + 3)  # the divisions by x lose three orders
    d = _drift(b, structure, list(zip(structure.pairs, coefficients, strict=True)),
               list(zip(structure.triples, triple_coefficients, strict=True)), _q(spin_ratio))
    return {p: tuple(Fraction(int(v.numerator), int(v.denominator)) for v in d[p][:x_order + 1])
            for p in range(0, int(a_order) + 1, 2)}


def leading_terms(series: dict[int, tuple[Fraction, ...]]
                  ) -> tuple[tuple[int, int, Fraction], ...]:
    """``(a power, x power, c)`` of each power of ``a``'s leading term, drift ``= −c a^p Ω x^q``
    (powers whose series vanishes to the length examined are left out)."""
    out = []
    for p, row in sorted(series.items()):
        q = next((k for k, v in enumerate(row) if v), None)
        if q is not None:
            out.append((p, q, -row[q]))
    return tuple(out)


def with_last_triples(structure: Structure) -> Structure:
    """``structure`` with the triple terms ``θ_L × (θ_{L−m} × θ_L)``, m = 1 … L, ``θ_L`` its
    last node (conventional: θ_N; single chain: θ_k)."""
    last = len(structure.nodes) - 1
    triples = tuple((last, last - m, last) for m in range(1, last + 1))
    return replace(structure, name=f"{structure.name}, triple θ_L×(θ_(L−m)×θ_L)",
                   triples=triples)


def _to_sp(v: Fraction) -> sp.Rational:
    return sp.Rational(v.numerator, v.denominator)


@functools.lru_cache(maxsize=64)
def derive_triple(structure: Structure) -> Design:
    """Pair coefficients of the ``a²`` (coning) design plus triple coefficients cancelling the
    ``a⁴`` drift order by order in ``Ωh`` through the order of the ``a²`` law.

    ``structure`` must list its triple terms (e.g. :func:`with_last_triples`). The ``a⁴``
    drift is affine in the triple coefficients (checked): one :func:`drift_series` per term
    gives its column; conditions are taken lowest order first while the system stays
    consistent, and free coefficients are settled by minimum norm (exact).
    """
    if not structure.triples:
        raise ValueError(f"{structure.name!r} has no triple terms; add them with "
                         "with_last_triples()")
    plain = derive(replace(structure, triples=()))
    top = plain.order if plain.order is not None else 2 * structure.n
    zeros = (Fraction(0),) * len(structure.triples)
    base = drift_series(structure, plain.coefficients, zeros)[4]
    cols = []
    for k in range(len(structure.triples)):
        unit = tuple(Fraction(int(i == k)) for i in range(len(zeros)))
        cols.append([v - w for v, w in zip(drift_series(structure, plain.coefficients, unit)[4],
                                           base, strict=True)])
    rows: list[list[sp.Rational]] = []
    rhs: list[sp.Rational] = []
    for q in range(top + 1):
        trial_a = sp.Matrix([*rows, [_to_sp(c[q]) for c in cols]])
        trial_b = sp.Matrix([*rhs, -_to_sp(base[q])])
        if trial_a.rank() != trial_a.row_join(trial_b).rank():
            break
        rows.append([_to_sp(c[q]) for c in cols])
        rhs.append(-_to_sp(base[q]))
    a, bvec = sp.Matrix(rows), sp.Matrix(rhs)
    _, piv = a.T.rref()
    a, bvec = a.extract(list(piv), list(range(a.cols))), bvec.extract(list(piv), [0])
    sol = a.T * (a * a.T).LUsolve(bvec) if a.rows else sp.zeros(len(cols), 1)
    tri = tuple(Fraction(int(sp.fraction(v)[0]), int(sp.fraction(v)[1])) for v in sol)
    series = drift_series(structure, plain.coefficients, tri)
    c2 = plain.drift_constant or Fraction(0)
    if any(series[2][q] != -c2 * (q == plain.order)
           for q in range(min(len(series[2]), (plain.order or 0) + 1))):
        raise ArithmeticError("the triple terms changed the a² drift; the design is wrong")
    return replace(plain, structure=structure, triple_coefficients=tri,
                   amplitude_law=leading_terms(series), conditions=plain.conditions + len(rows))


def with_triples_to_last(structure: Structure) -> Structure:
    """``structure`` with every triple term ``θ_m × (θ_i × θ_L)`` (``θ_L`` the last node,
    ``i < L``, any ``m``): the candidates of :func:`derive_spin_robust`."""
    last = len(structure.nodes) - 1
    triples = tuple((m, i, last) for i in range(last - 1, -1, -1) for m in range(last, -1, -1))
    return replace(structure, name=f"{structure.name}, triple θ_m×(θ_i×θ_L)", triples=triples)


def _spin_x4_rows(structure: Structure, pairs: Sequence[Fraction]):
    """The a² (Ωh)⁴ drift coefficient under spin as a polynomial in the spin ratio σ: its
    σ-coefficients for the base (no triple terms) and per triple term (affine, checked)."""
    k = len(structure.triples)
    deg = 2 * structure.n + 4  # the polynomial's degree is below this (checked at deg + 1)
    ss = [Fraction(v) for v in range(deg + 2)]

    def x4(t, s):
        return drift_series(structure, pairs, t, spin_ratio=s, x_order=4, a_order=2)[2][4]

    zero = (Fraction(0),) * k
    base = [x4(zero, s) for s in ss]
    cols = []
    for j in range(k):
        e = tuple(Fraction(int(i == j)) for i in range(k))
        cols.append([x4(e, s) - b for s, b in zip(ss, base, strict=True)])
    e2 = tuple(Fraction(2 * int(i == 0)) for i in range(k))
    if k and x4(e2, ss[3]) - base[3] != 2 * cols[0][3]:
        raise ArithmeticError("the a² (Ωh)⁴ spin term is not affine in the triple terms")
    sym = sp.Symbol("s")

    def coeffs(vals):
        poly = sp.Poly(sp.interpolate([(int(s), _to_sp(v)) for s, v in zip(ss, vals,
                                                                         strict=True)], sym),
                       sym)
        c = [sp.Rational(x) for x in reversed(poly.all_coeffs())]
        if len(c) > deg + 1:
            raise ArithmeticError("the spin polynomial's degree exceeds the bound")
        return c + [sp.Rational(0)] * (deg + 1 - len(c))

    return coeffs(base), [coeffs(c) for c in cols]


@functools.lru_cache(maxsize=32)
def derive_spin_robust(structure: Structure, *, amplitude: bool = True) -> Design:
    """Triple coefficients that cancel the ``a² (Ωh)⁴`` drift for every spin/cone ratio at
    once (spin plus coning, :class:`~strapdown.truth.motions.SpinConing`), and with
    ``amplitude`` also the classical-coning ``a⁴`` drift through the ``a²`` law's order.

    The pair coefficients are the classical ``a²`` design's. Under spin the axial increment
    is ``O(1)``, so triple terms enter the ``a²`` drift; its ``(Ωh)⁴`` coefficient is affine
    in them and a polynomial in the ratio ``σ = ω_s/Ω`` (exact interpolation over
    ``σ = 0, 1, …``): every ``σ``-coefficient is a linear condition. Higher powers of ``Ωh``
    are quadratic in the triple terms and stay. The conditions must all be met (an error
    otherwise); free coefficients are settled by minimum norm (exact).
    """
    if not structure.triples:
        raise ValueError(f"{structure.name!r} has no triple terms; add them with "
                         "with_triples_to_last()")
    plain = derive(replace(structure, triples=()))
    base, cols = _spin_x4_rows(structure, plain.coefficients)
    rows = [[c[d] for c in cols] for d in range(len(base))]
    rhs = [-b for b in base]
    if amplitude:
        top = plain.order if plain.order is not None else 2 * structure.n
        zeros = (Fraction(0),) * len(structure.triples)
        b4 = drift_series(structure, plain.coefficients, zeros)[4]
        c4 = []
        for k in range(len(structure.triples)):
            unit = tuple(Fraction(int(i == k)) for i in range(len(zeros)))
            c4.append([v - w for v, w in zip(drift_series(structure, plain.coefficients,
                                                          unit)[4], b4, strict=True)])
        rows += [[_to_sp(c[q]) for c in c4] for q in range(top + 1)]
        rhs += [-_to_sp(b4[q]) for q in range(top + 1)]
    a, bvec = sp.Matrix(rows), sp.Matrix(rhs)
    if a.rank() != a.row_join(bvec).rank():
        raise ValueError(f"{structure.name!r}: its triple terms cannot meet every condition; "
                         "give more (with_triples_to_last)")
    _, piv = a.T.rref()
    a, bvec = a.extract(list(piv), list(range(a.cols))), bvec.extract(list(piv), [0])
    sol = a.T * (a * a.T).LUsolve(bvec)
    tri = tuple(Fraction(int(sp.fraction(v)[0]), int(sp.fraction(v)[1])) for v in sol)
    series = drift_series(structure, plain.coefficients, tri)
    return replace(plain, structure=structure, triple_coefficients=tri,
                   amplitude_law=leading_terms(series), conditions=plain.conditions + a.rows)


def with_a6_triples(structure: Structure, *, through_law: bool = False) -> Structure:
    """``structure`` with the triple terms of :func:`with_last_triples` plus
    ``θ_{L−1} × (θ_{L−m} × θ_L)``, m = 2 … L: the candidates of :func:`derive_triple_a6`
    (N − 3 more free coefficients than the ``a⁴`` conditions through ``x^{2N+2}`` use, so the
    ``a⁶`` terms ``x⁶ … x^{2N−2}`` can be cancelled). ``through_law`` adds
    ``θ_{L−2} × (θ_{L−3} × θ_L)`` (N ≥ 4): one more, so ``a⁶`` goes through ``x^{2N}``,
    the order of the ``a²`` law (at the price of larger coefficients for N = 6)."""
    last = len(structure.nodes) - 1
    extra = tuple((last - 1, last - m, last) for m in range(2, last + 1))
    name = f"{structure.name}, triple θ_L×(θ_(L−m)×θ_L), θ_(L−1)×(θ_(L−m)×θ_L)"
    if through_law:
        if last < 3:
            raise ValueError("through_law needs N ≥ 4 nodes (the term θ_(L−2)×(θ_(L−3)×θ_L))")
        extra += ((last - 2, last - 3, last),)
        name += ", θ_(L−2)×(θ_(L−3)×θ_L)"
    st = with_last_triples(structure)
    return replace(st, name=name, triples=st.triples + extra)


def _a4_affine_space(structure: Structure, pairs, top: int):
    """Triple coefficients meeting every ``a⁴ x^q`` condition, q ≤ ``top``, exactly: a
    particular solution and a basis of the free directions (sympy, exact)."""
    k = len(structure.triples)
    zeros = (Fraction(0),) * k
    base = drift_series(structure, pairs, zeros, x_order=top, a_order=4)[4]
    cols = []
    for j in range(k):
        unit = tuple(Fraction(int(i == j)) for i in range(k))
        cols.append(drift_series(structure, pairs, unit, x_order=top, a_order=4)[4])
    a = sp.Matrix([[_to_sp(c[q] - base[q]) for c in cols] for q in range(top + 1)])
    rhs = sp.Matrix([-_to_sp(base[q]) for q in range(top + 1)])
    if a.rank() != a.row_join(rhs).rank():
        raise ValueError(f"{structure.name!r}: its triple terms cannot cancel the a⁴ drift "
                         f"through (Ωh)^{top}")
    sol, params = a.gauss_jordan_solve(rhs)
    tau0 = sol.subs({p: 0 for p in params})
    return tau0, [sol.diff(p) for p in params]


def _a6_quadratics(structure: Structure, pairs, tau0, basis, qs):
    """The ``a⁶ x^q`` drift coefficients (q in ``qs``) on the affine space ``tau0 + Σ p_i
    basis_i`` as exact quadratic polynomials in the ``p_i`` (``a⁶`` is quadratic in the
    triple coefficients: triple terms are ``O(a³)``), by interpolation at the points
    ``0, e_i, 2e_i, e_i + e_j``."""
    d, k = len(basis), len(structure.triples)
    ps = sp.symbols(f"p0:{d}")
    pts = [(0,) * d]
    for i in range(d):
        pts += [tuple(s * int(j == i) for j in range(d)) for s in (1, 2)]
    pts += [tuple(int(j in (i1, i2)) for j in range(d)) for i1 in range(d)
            for i2 in range(i1 + 1, d)]
    mons = [sp.Integer(1), *ps, *(ps[i] * ps[j] for i in range(d) for j in range(i, d))]
    vals = []
    for pt in pts:
        tau = tau0 + sum((basis[i] * pt[i] for i in range(d)), sp.zeros(k, 1))
        vals.append(drift_series(structure, pairs, tuple(Fraction(int(sp.fraction(v)[0]),
                                                                  int(sp.fraction(v)[1]))
                                                         for v in tau),
                                 x_order=max(qs), a_order=6)[6])
    m_inv = sp.Matrix([[m.subs(dict(zip(ps, pt, strict=True))) for m in mons]
                       for pt in pts]).inv()
    out = []
    for q in qs:
        c = m_inv * sp.Matrix([_to_sp(v[q]) for v in vals])
        out.append(sum((ci * m for ci, m in zip(c, mons, strict=True)), sp.Integer(0)))
    return ps, out


@functools.lru_cache(maxsize=16)
def derive_triple_a6(structure: Structure, *, digits: int = 50, starts: int = 40,
                     seed: int = 0) -> Design:
    """Like :func:`derive_triple`, and the leading ``a⁶`` drift cancelled too.

    ``structure`` lists its triple terms (e.g. :func:`with_a6_triples`). The ``a⁴`` drift is
    affine in the triple coefficients: its conditions through ``x^{2N+2}`` are solved
    exactly, leaving ``d`` free directions; the ``a⁶`` drift is quadratic in them, and its
    ``x^6, x^8, …`` coefficients (``d`` of them) are set to zero by Newton's method
    (``mpmath.findroot`` at ``digits`` digits, ``starts`` seeded starting points; the root
    with the smallest largest coefficient is kept). The root is algebraic, not rational: the
    free parameters are rounded to rationals with denominators below 10^24, so the ``a²``
    and ``a⁴`` conditions hold exactly and the cancelled ``a⁶`` coefficients are below
    1e-20 (checked).
    """
    import mpmath
    import numpy as np

    if not structure.triples:
        raise ValueError(f"{structure.name!r} has no triple terms; add them with "
                         "with_a6_triples()")
    plain = derive(replace(structure, triples=()))
    top = (plain.order if plain.order is not None else 2 * structure.n) + 2
    tau0, basis = _a4_affine_space(structure, plain.coefficients, top)
    if not basis:
        raise ValueError(f"{structure.name!r}: no freedom left for the a⁶ terms after the a⁴ "
                         "conditions; give more triple terms (with_a6_triples)")
    qs = tuple(range(6, 6 + 2 * len(basis), 2))
    ps, polys = _a6_quadratics(structure, plain.coefficients, tau0, basis, qs)
    rng = np.random.default_rng(seed)
    best = None
    with mpmath.workdps(digits):
        fs = [sp.lambdify(ps, f, "mpmath") for f in polys]
        for _ in range(starts):
            x0 = [mpmath.mpf(float(v)) for v in rng.normal(scale=3.0, size=len(ps))]
            try:
                r = mpmath.findroot(lambda *p: [f(*p) for f in fs], x0)
            except (ValueError, ZeroDivisionError):
                continue
            r = [r[i] for i in range(len(ps))] if hasattr(r, "rows") else [r]
            tau = [tau0[i] + sum(basis[j][i] * r[j] for j in range(len(ps)))
                   for i in range(len(tau0))]
            size = max(abs(mpmath.mpf(sp.N(v, digits))) for v in tau)
            if best is None or size < best[0]:
                best = (size, [Fraction(mpmath.nstr(v, digits)).limit_denominator(10**24)
                               for v in r])
    if best is None:
        raise ArithmeticError(f"{structure.name!r}: no real root of the a⁶ conditions found")
    p = best[1]
    tau = tau0 + sum((basis[j] * _to_sp(p[j]) for j in range(len(p))),
                     sp.zeros(len(tau0), 1))
    tri = tuple(Fraction(int(sp.fraction(v)[0]), int(sp.fraction(v)[1])) for v in tau)
    series = drift_series(structure, plain.coefficients, tri)
    if series[2] != drift_series(structure, plain.coefficients, (Fraction(0),) * len(tri))[2]:
        raise ArithmeticError("the triple terms changed the a² drift; the design is wrong")
    if any(series[4][:top + 1]) or any(abs(series[6][q]) > 1e-20 for q in qs):
        raise ArithmeticError("the a⁴/a⁶ conditions are not met; the design is wrong")
    law = leading_terms({pw: tuple(v if pw != 6 or q not in qs else Fraction(0)
                                   for q, v in enumerate(row)) for pw, row in series.items()})
    return replace(plain, structure=structure, triple_coefficients=tri, amplitude_law=law,
                   conditions=plain.conditions + top // 2 - 1 + len(qs))
