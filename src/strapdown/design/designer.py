"""Coning coefficient design: exact derivation for any algorithm structure.

A :class:`Structure` says, as data, which terms a rotation-vector algorithm
may use: its input (angular increments or rate samples), its sample nodes
(inside the update interval or from earlier intervals), the α weights, and
the cross products ``s_i × s_j`` whose coefficients are free — possibly tied
together in groups (cross-with-last, lag form). :func:`derive` finds the
coefficients exactly (rational arithmetic; sympy for the linear algebra).

Targets
-------
``coning``
    Cancel the classical-coning drift series in ``x = Ωh`` to the highest
    order the structure allows (Ignagni 1996; Li & Zhang 2017 Table 3).
``polynomial``
    Match the second-order Bortz term ``½∫α×ω`` exactly for angular rates
    that are polynomials in time of degree < number of nodes (Miller 1983).
``sculling``
    Cancel the rectified velocity error of classical sculling (angular oscillation
    ``θ0 sin Ωt`` about one body axis, linear ``A sin(Ωt + ψ)`` along another) in the
    velocity update ``Δv = υ + ½ α × υ + Σ_{i<j} k_ij (θ_i × v_j + v_i × θ_j)``
    (Savage (1998b); Ignagni (1998)); increment input only. Its error series is derived
    on its own (:func:`_sculling_series`) and turns out equal, term for term, to the
    classical-coning series: the designed sculling coefficients are the coning ones
    (Ignagni's duality), with the law
    ``rectified velocity error rate = −c · θ0 A cos ψ (Ωh)^order`` along the axis normal
    to both vibrations, ``c`` and ``order`` those of the coning drift.
``coning-force``
    The sculling conditions *and* those of a body coning (half angle ``a``, cone rate
    ``Ω``) in a constant specific force ``f`` along the cone axis
    (:class:`strapdown.truth.coning_force.ConingInForce`), interleaved by power of ``x``
    (:func:`_coning_force_series`): the sculling target has no coning × constant-force term,
    and the whole-update ``⅙ α × (α × υ)`` is exact for a constant rate only. Law (leading
    order in ``a``): rectified velocity error rate along the cone axis
    ``= −c · a² f (Ωh)^order``; ``order``/``drift_constant`` of the design are this law's
    (:func:`velocity_error_laws` gives both). A pair sum whose coefficients the sculling
    conditions fix (cross-with-last, the single chain) cannot meet these conditions beyond
    ``(Ωh)⁴``; all pairs of the N subsamples can, to the sculling order ``2N``.

Classical-coning analysis (leading order in the half-cone angle ``a``)
---------------------------------------------------------------------
Write body-frame y–z components as complex numbers. With ``ε = φ_alg − φ_true``
for one update ending at ``t_k``, the reference-frame error grows by
``C_n_b(t_k) J_r(φ) ε`` (``J_r`` the right Jacobian of the exponential
map), whose cone-axis component to order ``a²`` is

    D = ε_x + Im(conj(r_c) ε_c) − ½ Im(conj(φ_c) ε_c),

``r_c`` the true attitude's rotation vector at ``t_k``. Under coning every
y–z quantity is ``a F(x) e^{iΩt}``, so ``D`` does not depend on the phase
and is a power series in ``x`` with rational coefficients. For increment
input the increments tile the update exactly, ``ε_c = 0`` and ``D`` is the
familiar lag-sum series; for rate input the quadrature error of ``α`` enters
through ``ε_c`` at the same order as the coning term, which is why a
derivation that ignores it overstates the order (as Wang, Wang & Wang's three-period
derivation does; see docs/reproductions.md).

The drift about the cone axis is ``D / T_update``; we report it in the sign
convention of Li & Zhang Table 1: drift = −c · a²Ω(Ωh)^order, so that a
positive ``c`` means the computed attitude lags the cone.

When the target leaves coefficients free (e.g. all pairs under classical
coning, where only lag sums matter), a documented rule settles them:
``"polynomial"`` (satisfy as many polynomial-rate conditions as possible,
lowest degrees first, then minimum norm) or ``"min-norm"``.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from itertools import pairwise
from math import factorial
from typing import Any, Literal, get_args

import numpy as np
import sympy as sp

from strapdown._core.kinds import INPUT_KINDS, InputKind
from strapdown._core.validation import positive_int
from strapdown.algorithms.coning import CoefficientSet, WindowedAlgorithm
from strapdown.algorithms.family import Rk4Step

__all__ = [
    "FORMS",
    "LAYOUTS",
    "RULES",
    "TARGETS",
    "Design",
    "DesignRule",
    "DesignTarget",
    "Form",
    "Layout",
    "Structure",
    "classical_coning_drift",
    "derive",
    "interval_structure",
    "newton_cotes_weights",
    "rate_structure",
    "rk4_classical_coning_drift",
    "single_chain_structure",
    "structure_by_name",
    "three_period_structure",
    "uncompressed_structure",
    "velocity_error_laws",
]

F = Fraction
#: What a derivation cancels (see the module docstring).
DesignTarget = Literal["coning", "polynomial", "sculling", "coning-force"]
TARGETS: tuple[DesignTarget, ...] = get_args(DesignTarget)
#: How coefficients the target leaves free are settled.
DesignRule = Literal["polynomial", "min-norm"]
RULES: tuple[DesignRule, ...] = get_args(DesignRule)
#: Which cross products of an update's nodes are free, and how they are tied: one per
#: lag m with the last node (Li & Zhang Table 3), lag sums spread evenly, or every pair.
Layout = Literal["cross-with-last", "lag", "all-pairs"]
LAYOUTS: tuple[Layout, ...] = get_args(Layout)
#: The structures ``strapdown coefficients --form`` names (:func:`structure_by_name`).
Form = Literal[Layout, "single-chain", "uncompressed", "rate", "rate-three"]


# --------------------------------------------------------------------------- structures
@dataclass(frozen=True)
class Structure:
    """Which terms a rotation-vector algorithm may use.

    Attributes
    ----------
    name : str
        Human-readable name.
    input : {"increment", "rate"}
        Increment nodes ``s`` stand for ``θ`` over ``[s h, (s+1) h]`` from the
        update start; rate nodes ``τ`` for ``ω(τ h)``.
    update : int
        Samples per attitude update ``U`` (N for the conventional structure,
        1 for the single chain).
    nodes : tuple of Fraction
        Node positions (units of h); negative ones lie in earlier intervals.
    weights : tuple of Fraction
        ``α = Σ w_n s_n`` (increments: 1 on current nodes, 0 on earlier ones;
        rates: quadrature weights in units of h).
    pairs : tuple of (int, int)
        Node indices ``(i, j)``, ``i`` earlier than ``j``: the cross products
        ``s_i × s_j`` the correction may use, in the documented term order.
    groups : tuple of tuple of (int, Fraction)
        The unknowns: each is a list of (pair index, multiplier).
    n : int
        The N the structure is named after.
    triples : tuple of (int, int, int)
        Node indices ``(m, i, j)``, ``i`` earlier than ``j``: the triple cross products
        ``s_m × (s_i × s_j)`` the correction may use (increment input; designed by
        :func:`strapdown.design.finite_amplitude.derive_triple`). Empty by default.
    """

    name: str
    input: InputKind
    update: int
    nodes: tuple[Fraction, ...]
    weights: tuple[Fraction, ...]
    pairs: tuple[tuple[int, int], ...]
    groups: tuple[tuple[tuple[int, Fraction], ...], ...]
    n: int
    triples: tuple[tuple[int, int, int], ...] = ()

    def __post_init__(self):
        if self.input not in INPUT_KINDS:
            raise ValueError(f"input must be 'increment' or 'rate', got {self.input!r}")
        if len(self.weights) != len(self.nodes):
            raise ValueError("weights and nodes must have the same length")
        for i, j in self.pairs:
            if not (0 <= i < len(self.nodes) and 0 <= j < len(self.nodes)):
                raise ValueError(f"pair {(i, j)} indexes outside the {len(self.nodes)} nodes")
            if not self.nodes[i] < self.nodes[j]:
                raise ValueError(f"pair {(i, j)}: the first node must be the earlier one")
        for m, i, j in self.triples:
            if self.input != "increment":
                raise ValueError("triple cross products are defined for increment input only")
            if not all(0 <= k < len(self.nodes) for k in (m, i, j)) or not i < j:
                raise ValueError(f"triple {(m, i, j)}: indices must lie among the "
                                 f"{len(self.nodes)} nodes with i < j")

    def term_names(self) -> tuple[str, ...]:
        """``"θ1×θ3"``-style names of the cross products, in pair order."""
        return tuple(f"{self._node_name(i)}×{self._node_name(j)}" for i, j in self.pairs)

    def triple_names(self) -> tuple[str, ...]:
        """``"θ3×(θ1×θ3)"``-style names of the triple cross products, in order."""
        nm = self._node_name
        return tuple(f"{nm(m)}×({nm(i)}×{nm(j)})" for m, i, j in self.triples)

    def _node_name(self, i: int) -> str:
        s = self.nodes[i]
        sym = "θ" if self.input == "increment" else "ω"
        if self.update == 1 and self.input == "increment":  # single chain: relative to k
            m = -int(s)
            return f"{sym}[k]" if m == 0 else f"{sym}[k−{m}]"
        idx = int(s) + 1
        return f"{sym}{idx}" if s == int(s) else f"{sym}({s})"


def _nodes(lo: int, hi: int) -> tuple[Fraction, ...]:
    return tuple(F(s) for s in range(lo, hi))


def _each_pair(nodes, pairs):
    """One free coefficient per pair."""
    return [((k, F(1)),) for k in range(len(pairs))]


def _lag_sums(nodes, pairs):
    """One free coefficient per lag, spread evenly over the pairs of that lag."""
    groups = []
    for lag in sorted({nodes[j] - nodes[i] for i, j in pairs}):
        members = [k for k, (i, j) in enumerate(pairs) if nodes[j] - nodes[i] == lag]
        groups.append(tuple((k, F(1, len(members))) for k in members))
    return groups


@dataclass(frozen=True)
class _LayoutRule:
    """What a :data:`Layout` answers: whether its pairs are the lags with the last node
    (ordered by lag m = 1, 2, …: ς_m multiplies s_{last−m} × s_last, Li & Zhang Table 3)
    rather than every pair with a current node, and how it groups them."""

    with_last: bool
    groups: Callable[[Sequence[Fraction], list[tuple[int, int]]], list]


_LAYOUT_RULES: dict[str, _LayoutRule] = {
    "cross-with-last": _LayoutRule(True, _each_pair),
    "lag": _LayoutRule(False, _lag_sums),
    "all-pairs": _LayoutRule(False, _each_pair),
}


def _pairs_and_groups(nodes, layout, current_from, last):
    """Pairs whose later node is current; grouped by layout."""
    rule = _LAYOUT_RULES.get(layout) if isinstance(layout, str) else None
    if rule is None:
        raise ValueError(f"unknown layout {layout!r}; choose one of {', '.join(LAYOUTS)}")
    idx = range(len(nodes))
    if rule.with_last:
        pairs = [(last - m, last) for m in range(1, last + 1)]
    else:
        pairs = [(i, j) for j in idx for i in idx if i < j and j >= current_from]
        pairs.sort(key=lambda p: (p[0], p[1]))
    return tuple(pairs), tuple(rule.groups(nodes, pairs))


def interval_structure(n: int, layout: Layout = "cross-with-last") -> Structure:
    """N increments inside one update interval (the conventional structure)."""
    n = positive_int(n, "N (subsamples)")
    nodes = _nodes(0, n)
    pairs, groups = _pairs_and_groups(nodes, layout, 0, n - 1)
    return Structure(f"{layout}, N = {n}", "increment", n, nodes, (F(1),) * n, pairs, groups, n)


def uncompressed_structure(n: int, previous: int, layout: Layout = "cross-with-last"
                           ) -> Structure:
    """N current increments plus ``previous`` increments of earlier intervals ("uncompressed").

    Cross products pair a current increment with any earlier one (current or
    previous); products among previous increments belong to earlier updates.
    """
    n = positive_int(n, "N (subsamples)")
    if isinstance(previous, bool) or not isinstance(previous, int) or previous < 0:
        raise ValueError(f"previous must be a non-negative integer, got {previous!r}")
    nodes = _nodes(-previous, n)
    pairs, groups = _pairs_and_groups(nodes, layout, previous, len(nodes) - 1)
    w = tuple(F(0) if s < 0 else F(1) for s in nodes)
    return Structure(f"uncompressed {layout}, N = {n}, {previous} previous", "increment", n,
                     nodes, w, pairs, groups, n)


def single_chain_structure(n: int) -> Structure:
    """One increment per update, corrected with the previous N−1 increments.

    ``φ_k = θ_k + Σ_{m=1}^{N−1} c_m θ_{k−m} × θ_k`` and ``q_k = q_{k−1} ⊗ q(φ_k)``:
    an attitude every h from a single chain.
    """
    n = positive_int(n, "N (subsamples)")
    nodes = _nodes(-(n - 1), 1)
    last = n - 1
    pairs = tuple((last - m, last) for m in range(1, n))
    groups = tuple(((k, F(1)),) for k in range(len(pairs)))
    w = tuple(F(1) if s == 0 else F(0) for s in nodes)
    return Structure(f"single chain, N = {n}", "increment", 1, nodes, w, pairs, groups, n)


def newton_cotes_weights(nodes, update: int) -> tuple[Fraction, ...]:
    """Quadrature weights over ``[0, update]`` exact for polynomials of degree < len(nodes)."""
    nodes = [F(s) for s in nodes]
    k = len(nodes)
    a = sp.Matrix(k, k, lambda p, i: sp.Rational(nodes[i]) ** p)
    b = sp.Matrix(k, 1, lambda p, _: sp.Rational(update) ** (p + 1) / (p + 1))
    sol = a.LUsolve(b)
    return tuple(F(int(sp.fraction(v)[0]), int(sp.fraction(v)[1])) for v in sol)


def rate_structure(n: int, layout: Layout = "all-pairs",
                   weights: Sequence[Fraction | int | float | str] | None = None,
                   nodes: Sequence[Fraction | int | float | str] | None = None) -> Structure:
    """Rate samples at nodes of an update of N sample intervals (default 0, 1, …, N).

    ``α = h Σ w_n ω_n`` (Newton–Cotes on the nodes by default: exact for
    polynomial rates of degree < number of nodes), ``β = h² Σ k_ij ω_i × ω_j``.
    ``nodes`` may be any increasing rationals in units of h (e.g. ``[0, 1/2,
    2]``); negative ones lie in the previous interval.
    """
    n = positive_int(n, "N (sample intervals)")
    if nodes is None:
        nodes = _nodes(0, n + 1)
    else:
        nodes = tuple(F(x) for x in nodes)
        if len(nodes) < 2 or any(b <= a for a, b in pairwise(nodes)):
            raise ValueError(f"nodes must be at least two increasing values, got {nodes}")
    w = newton_cotes_weights(nodes, n) if weights is None else tuple(F(x) for x in weights)
    pairs, groups = _pairs_and_groups(nodes, layout, 0, n)
    return Structure(f"rate input {layout}, {n} intervals", "rate", n, nodes, w, pairs, groups, n)


def three_period_structure() -> Structure:
    """Wang, Wang & Wang's three-period rate algorithm: ω1…ω4 at 0, T/3, 2T/3, T, Simpson 3/8
    α, lag sums."""
    s = rate_structure(3, "lag", weights=[F(3, 8), F(9, 8), F(9, 8), F(3, 8)])
    return Structure("rate three-period (Wang et al.), lag sums", s.input, s.update, s.nodes,
                     s.weights, s.pairs, s.groups, 3)


FORMS: tuple[Form, ...] = get_args(Form)


def _interval_form(layout: Layout) -> Callable[[int, int | None], Structure]:
    return lambda n, previous: interval_structure(n, layout)


#: How each :data:`Form` builds its structure from N and ``previous`` (a layout: N
#: increments in one interval, :func:`interval_structure`).
_FORM_BUILDERS: dict[str, Callable[[int, int | None], Structure]] = {
    **{layout: _interval_form(layout) for layout in LAYOUTS},
    "single-chain": lambda n, previous: single_chain_structure(n),
    "uncompressed": lambda n, previous: uncompressed_structure(
        n, n if previous is None else previous),
    "rate": lambda n, previous: rate_structure(n),
    "rate-three": lambda n, previous: three_period_structure(),
}


def structure_by_name(form: Form, n: int, *, previous: int | None = None) -> Structure:
    """The structure a CLI ``--form`` names (``uncompressed`` defaults to N previous increments)."""
    build = _FORM_BUILDERS.get(form) if isinstance(form, str) else None
    if build is None:
        raise ValueError(f"unknown form {form!r}; choose one of {', '.join(FORMS)}")
    return build(n, previous)


# ------------------------------------------------------------------ exact power series
def _sin(c: Fraction, m: int) -> list[Fraction]:
    out = [F(0)] * (m + 1)
    for k in range(0, m + 1):
        if k % 2 == 1:
            out[k] = F((-1) ** (k // 2)) * c**k / factorial(k)
    return out


def _cos(c: Fraction, m: int) -> list[Fraction]:
    out = [F(0)] * (m + 1)
    for k in range(0, m + 1, 2):
        out[k] = F((-1) ** (k // 2)) * c**k / factorial(k)
    return out


def _mul(a, b, m):
    out = [F(0)] * (m + 1)
    for i, ai in enumerate(a):
        if ai:
            for j in range(0, m + 1 - i):
                if b[j]:
                    out[i + j] += ai * b[j]
    return out


def _add(*terms):
    return [sum(c) for c in zip(*terms, strict=True)]


def _scale(a, s):
    return [s * v for v in a]


def _shift(a, k):
    """Multiply by x^k (truncating)."""
    return ([F(0)] * k + a)[: len(a)]


def _coning_series(st: Structure, m: int, *, quadrature: bool = True):
    """Cone-axis error per update over a² as series in x: fixed part and one per pair."""
    one = [F(1)] + [F(0)] * m
    u = F(st.update)
    if st.input == "increment":
        two_sin2 = _scale(_add(one, _scale(_cos(F(1), m), -1)), 2)  # 4 sin²(x/2)
        pair = [_mul(two_sin2, _sin(st.nodes[j] - st.nodes[i], m), m) for i, j in st.pairs]
        e0 = _add(_shift(_scale(one, -u / 2), 1), _scale(_sin(u, m), F(1, 2)))
        return e0, pair
    pair = [_shift(_sin(st.nodes[j] - st.nodes[i], m), 2) for i, j in st.pairs]
    wsum = sum(st.weights)
    e0 = _add(_shift(_scale(one, -wsum / 2), 1), _scale(_sin(u, m), F(1, 2)))
    if quadrature:
        # e_c = x Σ w_n i e^{i t_n} − (1 − e^{−iUx}),  t_n = (τ_n − U) x
        e_re = [F(0)] * (m + 1)
        e_im = [F(0)] * (m + 1)
        for w, tau in zip(st.weights, st.nodes, strict=True):
            e_re = _add(e_re, _shift(_scale(_sin(tau - u, m), -w), 1))
            e_im = _add(e_im, _shift(_scale(_cos(tau - u, m), w), 1))
        p_re = _add(one, _scale(_cos(u, m), -1))
        p_im = _sin(u, m)  # 1 − e^{−iUx}: Im = sin(Ux)
        e_re = _add(e_re, _scale(p_re, -1))
        e_im = _add(e_im, _scale(p_im, -1))
        # Im(e_c) − ½ Im(conj(p) e_c) = e_im − ½ (p_re e_im − p_im e_re)
        corr = _add(e_im, _scale(_add(_mul(p_re, e_im, m), _scale(_mul(p_im, e_re, m), -1)),
                                 F(-1, 2)))
        # The periodic part of the accumulated error, δ_c = a e_c e^{iΩt}/(1 − e^{−iΩT}),
        # crosses each new error in the composition: ½ (δ × g)_x = ¼ |e_c|² cot(ΩT/2).
        # cot(Ux/2) = (2/(U x)) · Σ_n (−1)^n 2^{2n} B_{2n} (Ux/2)^{2n}/(2n)!.
        e2 = _add(_mul(e_re, e_re, m), _mul(e_im, e_im, m))
        tcot = [F(0)] * (m + 1)
        for k in range(0, m + 1, 2):
            b = sp.bernoulli(k)
            bk = F(int(sp.fraction(b)[0]), int(sp.fraction(b)[1]))
            tcot[k] = F((-1) ** (k // 2)) * 2**k * bk * (u / 2) ** k / factorial(k)
        # e_c = O(x), so |e_c|² starts at x²: dividing by x leaves a power series.
        accum = _scale(_mul([*e2[1:], F(0)], tcot, m), F(2) / u / 4)
        e0 = _add(e0, corr, accum)
    return e0, pair


def _sculling_series(st: Structure, m: int):
    """Rectified sculling velocity error per update over ``θ0 A cos ψ / Ω``, as series in x.

    Classical sculling, first order in θ0 (Savage (1998b); Ignagni (1998)): with
    ``d_n = e^{i s_n x}(e^{ix} − 1)`` the gyro and accelerometer increments of node ``n``
    are ``θ_n = θ0 Im(e^{iφ} d_n)`` and ``v_n = (A/Ω) Im(−i e^{iψ} e^{iφ} d_n)`` (φ the
    phase at the update start). Averaged over φ, a pair term ``k (θ_i × v_j + v_i × θ_j)``
    contributes ``−k Im(d_i conj(d_j))`` along the normal axis, the rotation compensation
    ``½ α × υ`` contributes ``¼ |D|² sin ψ`` (``D = Σ w_n d_n``) and the exact
    ``∫ (α(t) − α_0) × f`` contributes ``½ [cos ψ (Ux − sin Ux) + sin ψ (1 − cos Ux)]``:
    the sin ψ parts cancel when the weighted increments tile the update
    (``½|D|² = 1 − cos Ux``), which is checked, and what remains is
    ``e0 = −½ (Ux − sin Ux)`` and one series per pair.
    """
    if st.input != "increment":
        raise ValueError("the sculling target is derived for increment input only; "
                         f"{st.name!r} takes rate samples")
    u = F(st.update)
    re, im = [], []
    for s in st.nodes:
        re.append(_add(_cos(s + 1, m), _scale(_cos(s, m), -1)))
        im.append(_add(_sin(s + 1, m), _scale(_sin(s, m), -1)))
    pair = [_add(_mul(re[i], im[j], m), _scale(_mul(im[i], re[j], m), -1))
            for i, j in st.pairs]  # −Im(d_i conj d_j) = Re d_i Im d_j − Im d_i Re d_j
    d_re = _add(*[_scale(r, w) for r, w in zip(re, st.weights, strict=True)])
    d_im = _add(*[_scale(r, w) for r, w in zip(im, st.weights, strict=True)])
    half_d2 = _scale(_add(_mul(d_re, d_re, m), _mul(d_im, d_im, m)), F(1, 2))
    if half_d2 != _add([F(1)] + [F(0)] * m, _scale(_cos(u, m), -1)):
        raise ValueError(f"{st.name!r}: the weighted increments do not tile the update, "
                         "so the sculling series has no closed form here")
    e0 = _scale(_add(_shift(_scale([F(1)] + [F(0)] * m, u), 1), _scale(_sin(u, m), -1)),
                F(-1, 2))
    return e0, pair


def _coning_force_series(st: Structure, m: int):
    """Rectified cone-axis velocity error per update of a body coning in a constant specific
    force ``f`` along the cone axis, over ``a² f / Ω``, as series in x (leading order in a).

    Increments of node ``n``: ``θ_c = sin a e^{iφ} d_n``, ``v_c = f θ_c`` (body y + iz; the
    transverse rate and force are parallel), ``θ_x = −2 sin²(a/2) x``, ``v_x = f cos a x``.
    The update's ``Δv_b`` is rotated to the navigation frame by ``C_n_b(t0)``, whose cone-axis
    row is ``(cos a, sin a Im(e^{−iφ} ·))``: the O(a) transverse error counts through the
    tilt. Exactly, ``½ α × υ`` has no cone-axis part and ``(α × υ)_c = −i f U x α_c``;
    ``⅙ α × (α × υ)`` gives ``−(1/6) f U x |α_c|²``; a pair ``k (θ_i × v_j + v_i × θ_j)``
    gives ``2 Im(conj(d_i) d_j)`` along the axis and ``i f x (θ_{c,j} − θ_{c,i})`` across it.
    Against the exact ``f U x``:
    ``e0 = −(Ux − sin Ux) + (1/6) Ux (1 − cos Ux)``, pair ``(i, j)``:
    ``2 Im(conj(d_i) d_j) + x Re(d_j − d_i)`` — the first part is twice the sculling pair
    series (a lag function), the second depends on where the pair sits in the update.
    """
    _, p_s = _sculling_series(st, m)  # checks increment input and tiling
    u = F(st.update)
    one = [F(1)] + [F(0)] * m
    re = [_add(_cos(s + 1, m), _scale(_cos(s, m), -1)) for s in st.nodes]
    pair = [_add(_scale(p, 2), _shift(_add(re[j], _scale(re[i], -1)), 1))
            for p, (i, j) in zip(p_s, st.pairs, strict=True)]
    ux = _shift(_scale(one, u), 1)
    e0 = _add(_scale(_add(ux, _scale(_sin(u, m), -1)), -1),
              _scale(_mul(ux, _add(one, _scale(_cos(u, m), -1)), m), F(1, 6)))
    return e0, pair


def velocity_error_laws(structure: Structure, coefficients, *, terms: int = 30
                        ) -> dict[str, tuple[int | None, Fraction | None]]:
    """Leading classical-sculling and coning-in-force laws ``(order, constant)`` of any
    velocity pair coefficients on an increment structure (one per pair, converted exactly):
    ``{"sculling": …, "coning-force": …}``, the laws of the module docstring; ``(None,
    None)`` when a series vanishes up to ``x^terms``."""
    coeffs = tuple(F(c) for c in coefficients)
    if len(coeffs) != len(structure.pairs):
        raise ValueError(f"{len(structure.pairs)} coefficients expected (one per pair), got "
                         f"{len(coeffs)}")
    out = {}
    for name, fn in (("sculling", _sculling_series), ("coning-force", _coning_force_series)):
        e0, ps = fn(structure, terms)
        out[name] = _leading(structure, coeffs, e0, ps, terms)
    return out


def _poly_conditions(st: Structure):
    """Rows (per pair) and targets of the polynomial-rate conditions, lowest degree first."""
    k = len(st.nodes)
    u = F(st.update)
    rows, rhs, labels = [], [], []
    degs = sorted(((p, q) for p in range(k) for q in range(p + 1, k)), key=lambda d: (sum(d), d))
    for p, q in degs:
        row = []
        for i, j in st.pairs:
            if st.input == "increment":
                a_ip = _mono_int(st.nodes[i], p)
                a_iq = _mono_int(st.nodes[i], q)
                a_jp = _mono_int(st.nodes[j], p)
                a_jq = _mono_int(st.nodes[j], q)
            else:
                a_ip, a_iq = st.nodes[i] ** p, st.nodes[i] ** q
                a_jp, a_jq = st.nodes[j] ** p, st.nodes[j] ** q
            row.append(a_ip * a_jq - a_iq * a_jp)
        exact = F(1, 2) * u ** (p + q + 2) / (p + q + 2) * (F(1, p + 1) - F(1, q + 1))
        rows.append(row)
        rhs.append(exact)
        labels.append((p, q))
    return rows, rhs, labels


def _mono_int(s: Fraction, p: int) -> Fraction:
    """∫_s^{s+1} t^p dt."""
    return ((s + 1) ** (p + 1) - s ** (p + 1)) / (p + 1)


# ------------------------------------------------------------------------ linear algebra
def _to_sp(rows):
    return sp.Matrix([[sp.Rational(v.numerator, v.denominator) for v in r] for r in rows])


def _consistent(a: sp.Matrix, b: sp.Matrix) -> bool:
    if a.rows == 0:
        return True
    return a.rank() == a.row_join(b).rank()


def _prefix_solve(rows, rhs, base_rows=(), base_rhs=(), *, skip: bool = False):
    """Add conditions in order while the system stays consistent; return (A rows, b).

    ``skip=False`` stops at the first condition that cannot be met (the
    coning series: that power is the order); ``skip=True`` passes over it and
    tries the next (polynomial conditions: meet as many as possible).
    """
    a_rows, b_rows = list(base_rows), list(base_rhs)
    for r, v in zip(rows, rhs, strict=True):
        if all(x == 0 for x in r):
            if v != 0 and not skip:
                break  # a condition no coefficient can touch: the order is reached
            continue
        trial_a = _to_sp([*a_rows, r])
        trial_b = _to_sp([[x] for x in [*b_rows, v]])
        if not _consistent(trial_a, trial_b):
            if skip:
                continue
            break
        a_rows.append(r)
        b_rows.append(v)
    return a_rows, b_rows


def _min_norm(a_rows, b_rows, nvar):
    if not a_rows:
        return sp.zeros(nvar, 1)
    a = _to_sp(a_rows)
    b = _to_sp([[x] for x in b_rows])
    # reduce to independent rows, then u = Aᵀ (A Aᵀ)⁻¹ b (exact minimum-norm solution)
    _, piv = a.T.rref()
    a = a.extract(list(piv), list(range(nvar)))
    b = b.extract(list(piv), [0])
    return a.T * (a * a.T).LUsolve(b)


# ------------------------------------------------------------------------------ result
@dataclass(frozen=True)
class Design:
    """An exactly derived coefficient set.

    Attributes
    ----------
    structure : Structure
    target : {"coning", "polynomial", "sculling", "coning-force"}
    rule : str
        How remaining freedom was settled.
    coefficients : tuple of Fraction
        One per pair of ``structure.pairs`` (rate input: in units of h²).
    order : int or None
        Classical-coning drift order in Ωh (None if no drift up to the
        series length examined).
    drift_constant : Fraction or None
        ``c`` with drift about the cone axis = −c · a²Ω(Ωh)^order.
    quadrature_included : bool
        Whether the rate-input α quadrature error was part of the derivation.
    conditions : int
        Number of independent conditions the target imposed and met.
    triple_coefficients : tuple of Fraction
        One per ``structure.triples`` (empty without triple terms).
    amplitude_law : tuple of (int, int, Fraction)
        Finite-amplitude designs only: ``(p, q, c)`` per power of ``a``, the leading terms of
        drift ``= −Σ c a^p Ω (Ωh)^q`` (:func:`strapdown.design.finite_amplitude.drift_series`).
    """

    structure: Structure
    target: DesignTarget
    rule: DesignRule
    coefficients: tuple[Fraction, ...]
    order: int | None
    drift_constant: Fraction | None
    quadrature_included: bool
    conditions: int
    triple_coefficients: tuple[Fraction, ...] = ()
    amplitude_law: tuple[tuple[int, int, Fraction], ...] = ()

    @property
    def terms(self) -> tuple[str, ...]:
        return self.structure.term_names()

    def predicted_drift(self, half_angle: float, cone_rate: float, h: float) -> float:
        """Leading-order drift about the cone axis (rad/s)."""
        if self.order is None or self.drift_constant is None:  # both None together
            return 0.0
        return -float(self.drift_constant) * half_angle**2 * cone_rate * (cone_rate * h) ** (
            self.order)

    def coefficient_set(self, name: str | None = None) -> CoefficientSet:
        """As a :class:`~strapdown.algorithms.coning.CoefficientSet` (interval increment
        structures only)."""
        st = self.structure
        if st.input != "increment" or st.update != len(st.nodes) or st.nodes[0] != 0:
            raise ValueError(
                f"{st.name!r} is not a within-interval increment structure; use windowed()"
            )
        n = len(st.nodes)
        k = [[F(0)] * n for _ in range(n)]
        for (i, j), c in zip(st.pairs, self.coefficients, strict=True):
            k[i][j] += c
        mat = np.array([[float(v) for v in r] for r in k])
        triples = tuple((m, i, j, c) for (m, i, j), c in zip(st.triples, self.triple_coefficients,
                                                             strict=True))
        return CoefficientSet(name or f"designed-{self.target}", n, mat,
                              tuple(tuple(r) for r in k), f"derived: {st.name}, {self.target}",
                              _TARGET_RULES[self.target].classical_coning
                              and self.order == 2 * n, triples)

    def algorithm(self) -> WindowedAlgorithm:
        """The derived algorithm in general windowed form (any structure; pair terms only:
        a design with triple terms runs through :meth:`coefficient_set`)."""
        st = self.structure
        if st.triples:
            raise ValueError("the windowed form has no triple terms; use coefficient_set() "
                             "(conventional) or the finite-amplitude sets")
        if any(s != int(s) for s in st.nodes):
            raise ValueError("nodes off the sample grid cannot run on a sample stream")
        return WindowedAlgorithm(st.input, st.update, tuple(int(s) for s in st.nodes),
                                 st.weights, st.pairs, self.coefficients,
                                 f"{st.name} ({self.target})")

    def to_dict(self) -> dict[str, Any]:
        """The documented JSON record of ``strapdown coefficients`` (with triple terms: also
        ``triple_terms``, ``triple_coefficients``, ``triple_decimals`` and ``amplitude_law``,
        a list of {``a_power``, ``order``, ``constant``})."""
        rec: dict[str, Any] = {
            "form": self.structure.name,
            "input": self.structure.input,
            "target": self.target,
            "rule": self.rule,
            "coefficients": [_fs(c) for c in self.coefficients],
            "decimals": [float(c) for c in self.coefficients],
            "terms": list(self.terms),
            "drift_constant": None if self.drift_constant is None else _fs(self.drift_constant),
            "order": self.order,
            "drift_law": _LAWS.get(self.target,
                                   "drift about the cone axis = −drift_constant · a²Ω(Ωh)^order"),
            "quadrature_included": self.quadrature_included,
        }
        if self.structure.triples:
            rec["triple_terms"] = list(self.structure.triple_names())
            rec["triple_coefficients"] = [_fs(c) for c in self.triple_coefficients]
            rec["triple_decimals"] = [float(c) for c in self.triple_coefficients]
            rec["amplitude_law"] = [{"a_power": p, "order": q, "constant": _fs(c)}
                                    for p, q, c in self.amplitude_law]
            rec["drift_law"] = ("drift about the cone axis = −Σ constant · a^a_power Ω "
                                "(Ωh)^order (amplitude_law)")
        return rec


_SCULLING_LAW = ("rectified velocity error rate along the axis normal to both vibrations = "
                 "−drift_constant · θ0 A cos ψ (Ωh)^order")
_FORCE_LAW = ("rectified velocity error rate along the cone axis of a body coning in a "
              "constant specific force f along that axis = −drift_constant · a² f (Ωh)^order")
_LAWS = {"sculling": _SCULLING_LAW, "coning-force": _FORCE_LAW}


def _leading(st, coeffs, e0, pair_series, m):
    resid = [e0[p] + sum(pair_series[k][p] * coeffs[k] for k in range(len(coeffs)))
             for p in range(m + 1)]
    lead = next((p for p in range(m + 1) if resid[p] != 0), None)
    if lead is None:
        return None, None
    return lead - 1, -resid[lead] / st.update


def classical_coning_drift(structure: Structure, coefficients, *, quadrature: bool = True,
                           terms: int = 40) -> tuple[int | None, Fraction | None]:
    """Leading classical-coning drift (order, constant) of any coefficients on a structure.

    ``coefficients`` are per pair (exact rationals or numbers, converted
    exactly). Drift about the cone axis = −constant · a²Ω(Ωh)^order; ``(None,
    None)`` when the series vanishes up to ``x^terms``.
    """
    coeffs = tuple(F(c) for c in coefficients)
    if len(coeffs) != len(structure.pairs):
        raise ValueError(
            f"{len(structure.pairs)} coefficients expected (one per pair), got {len(coeffs)}"
        )
    e0, pair_series = _coning_series(structure, terms, quadrature=quadrature)
    return _leading(structure, coeffs, e0, pair_series, terms)


def rk4_classical_coning_drift(step: Rk4Step = "2td", terms: int = 12) -> tuple[int, Fraction]:
    """Classical-coning drift ``(order, c)`` of quaternion RK4 on rate samples (sympy).

    One normalised RK4 step on ``q̇ = ½ q ⊗ ω`` is ``q ⊗ P/|P|`` with ``P`` a
    quaternion polynomial in the rate samples, i.e. a rotation-vector
    algorithm with ``φ = 2 vec(P)`` to the orders that matter; its error
    enters the same cone-axis drift formula as every other algorithm here.
    ``step="2td"``: step 2 td with the middle sample; ``"td-interp"``: step td,
    middle rate = mean of the ends. Takes a few seconds; the results are
    tabulated in :data:`strapdown.algorithms.rate.RK4_DRIFT`.
    """
    a, x = sp.symbols("a x", positive=True)

    def qmul(p, q):
        pw, px, py, pz = p
        qw, qx, qy, qz = q
        return (pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
                pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw)

    def trunc(e):
        e = sp.expand(e)
        return sum(e.coeff(a, k) * a**k for k in range(3))

    def omega(t):  # classical coning to O(a²) with Ω = 1
        return (0, -(a**2) / 2, -a * sp.sin(t), a * sp.cos(t))

    def comb(*terms_):
        return tuple(sp.Add(*(c * q[i] for c, q in terms_)) for i in range(4))

    if step == "2td":
        big_h, w1, wm, w4 = 2 * x, omega(-2 * x), omega(-x), omega(0)
    elif step == "td-interp":
        big_h, w1, w4 = x, omega(-x), omega(0)
        wm = tuple((p + q) / 2 for p, q in zip(w1, w4, strict=True))
    else:
        raise ValueError(f"step must be '2td' or 'td-interp', got {step!r}")
    one = (1, 0, 0, 0)
    half = sp.Rational(1, 2)
    k1 = comb((half, qmul(one, w1)))
    k2 = comb((half, qmul(comb((1, one), (big_h / 2, k1)), wm)))
    k3 = comb((half, qmul(comb((1, one), (big_h / 2, k2)), wm)))
    k4 = comb((half, qmul(comb((1, one), (big_h, k3)), w4)))
    p = comb((1, one), (big_h / 6, k1), (big_h / 3, k2), (big_h / 3, k3), (big_h / 6, k4))
    ph = [trunc(2 * c) for c in p[1:]]
    tx, ty, tz = -(a**2) / 2 * sp.sin(big_h), a * (1 - sp.cos(big_h)), a * sp.sin(big_h)
    ex, ey, ez = ph[0] - tx, ph[1] - ty, ph[2] - tz
    d = (ex + a * ez - half * (ty * ez - tz * ey)
         + sp.Rational(1, 4) * (ey**2 + ez**2) * sp.cot(big_h / 2))
    d = sp.expand(sp.expand(d).coeff(a, 2))
    ser = sp.expand(sp.series(d, x, 0, terms).removeO())
    lead = min(sp.Poly(ser, x).monoms())[0]
    units = 2 if step == "2td" else 1  # update period in td
    c = -sp.Rational(ser.coeff(x, lead)) / units
    return lead - 1, F(int(sp.fraction(c)[0]), int(sp.fraction(c)[1]))


def _fs(f: Fraction) -> str:
    return f"{f.numerator}/{f.denominator}"


def _frac(v) -> Fraction:
    v = sp.nsimplify(v) if not isinstance(v, sp.Rational) else v
    n, d = sp.fraction(v)
    return F(int(n), int(d))


@dataclass(frozen=True)
class _TargetRule:
    """What a :data:`DesignTarget` answers: the error series it is measured on
    (``series(structure, m, quadrature)`` → the uncorrected series and one per pair, powers
    of Ωh up to ``m``), whether the coefficients are fitted to it (``fits_series``; else the
    polynomial conditions alone, the series only measured), whether the classical-sculling
    conditions are met with it power by power (``with_sculling``) and whether its order is
    the classical-coning drift order (``classical_coning``: a set at order 2N is the
    classical optimum)."""

    series: Callable[[Structure, int, bool], tuple[list, list]]
    fits_series: bool = True
    with_sculling: bool = False
    classical_coning: bool = False


def _coning_target_series(st: Structure, m: int, quadrature: bool):
    return _coning_series(st, m, quadrature=quadrature)


_TARGET_RULES: dict[str, _TargetRule] = {
    "coning": _TargetRule(_coning_target_series, classical_coning=True),
    "polynomial": _TargetRule(_coning_target_series, fits_series=False),
    "sculling": _TargetRule(lambda st, m, quadrature: _sculling_series(st, m)),
    "coning-force": _TargetRule(lambda st, m, quadrature: _coning_force_series(st, m),
                                with_sculling=True),
}


def derive(structure: Structure, *, target: DesignTarget = "coning",
           rule: DesignRule = "polynomial",
           quadrature: bool = True) -> Design:
    """Derive a structure's coefficients exactly.

    Parameters
    ----------
    structure : Structure
    target : {"coning", "polynomial", "sculling", "coning-force"}
        ``sculling``: increment structures only (ValueError for rate input).
    rule : {"polynomial", "min-norm"}
        How to settle coefficients the target leaves free.
    quadrature : bool
        Rate input only: include the α quadrature error in the coning series
        (True, correct) or ignore it as a derivation that fits only β does
        (False, kept to show what that overstates).

    Notes
    -----
    Results are cached per argument set (structures are immutable).
    """
    if target not in TARGETS:
        raise ValueError(f"unknown target {target!r}; choose one of {', '.join(TARGETS)}")
    if rule not in RULES:
        raise ValueError(f"unknown rule {rule!r}; choose one of {', '.join(RULES)}")
    if not isinstance(structure, Structure):
        raise ValueError(f"structure must be a Structure, got {type(structure).__name__}")
    return _derive(structure, target, rule, bool(quadrature) or structure.input == "increment")


@functools.lru_cache(maxsize=256)
def _derive(st: Structure, target: DesignTarget, rule: DesignRule, quadrature: bool) -> Design:
    ng = len(st.groups)
    npair = len(st.pairs)
    # group → pair expansion matrix G (npair × ng)
    g = [[F(0)] * ng for _ in range(npair)]
    for col, members in enumerate(st.groups):
        for k, mult in members:
            g[k][col] += mult
    m = 2 * ng + 2 * max(len(st.nodes), 2) + 9
    aim = _TARGET_RULES[target]
    e0, pair_series = aim.series(st, m, quadrature)
    grp_series = [[sum(g[k][col] * pair_series[k][p] for k in range(npair)) for p in range(m + 1)]
                  for col in range(ng)]
    con_rows = [[grp_series[c][p] for c in range(ng)] for p in range(m + 1)]
    con_rhs = [-e0[p] for p in range(m + 1)]
    poly_rows_p, poly_rhs, _ = _poly_conditions(st)
    poly_rows = [[sum(r[k] * g[k][c] for k in range(npair)) for c in range(ng)]
                 for r in poly_rows_p]
    if aim.with_sculling:  # sculling and force conditions, power by power
        e_s, p_s = _sculling_series(st, m)
        rows_s = [[sum(g[k][c] * p_s[k][p] for k in range(npair)) for c in range(ng)]
                  for p in range(m + 1)]
        con_rows = [r for p in range(m + 1) for r in (rows_s[p], con_rows[p])]
        con_rhs = [v for p in range(m + 1) for v in (-e_s[p], con_rhs[p])]
    if aim.fits_series:
        a, b = _prefix_solve(con_rows, con_rhs)
        conditions = len(a)
        if rule == "polynomial":
            a, b = _prefix_solve(poly_rows, poly_rhs, a, b, skip=True)
    else:
        a, b = _prefix_solve(poly_rows, poly_rhs, skip=True)
        conditions = len(a)
    u = _min_norm(a, b, ng)
    ug = [_frac(v) for v in u]
    coeffs = tuple(sum((g[k][c] * ug[c] for c in range(ng)), F(0)) for k in range(npair))
    order, const = _leading(st, coeffs, e0, pair_series, m)
    rule_used = rule if aim.fits_series else "min-norm"
    return Design(st, target, rule_used, coeffs, order, const, quadrature, conditions)
