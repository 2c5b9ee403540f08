"""Exact classical-coning frequency response of any attitude algorithm.

Under classical coning (Li & Zhang (2017) eq. 7: half angle ``a``, cone rate ``Ω``) every
update of a rotation-invariant algorithm sees the inputs of the first one turned about the
cone axis by ``ΩT`` (``T`` the update period), so its quaternion increment is
``E_k = r_k E r_k⁻¹`` with ``E`` the first one's and ``r_k = exp(x̂ kΩT/2)``. With the
initial tilt ``q_a`` the error after ``k`` updates is ``q_a (E ρ)^k q_a⁻¹ ρ^{−k}``,
``ρ = exp(x̂ ΩT/2)``; at whole cone periods (``ρ^k = ±1``) that is a rotation by ``kΔ``
about the axis ``n`` of ``A = q_a E ρ q_a⁻¹``, ``Δ = ψ − ΩT`` with ``ψ`` the rotation angle
of ``A``. The drift about the cone axis is therefore exactly

    drift = Δ n_x / T,

and the same holds with body spin ``ω_s`` about the body x axis
(:class:`~strapdown.truth.motions.SpinConing`): the body-frame inputs then turn by
``(Ω − ω_s) T`` per update, ``ρ = exp(x̂ (Ω − ω_s) T/2)`` in ``A``, and ``Δ = ψ − ΩT`` still.

an exact function of ``a`` and ``Ωh`` for any coefficients, structure or triple terms:
this module forms ``E`` from one update's exact inputs (the closed-form increments or
rates of :class:`~strapdown.truth.motions.ClassicalConing`) in arbitrary precision and
evaluates it, with no series truncation. The drift a simulation measures at whole cone
periods (:func:`strapdown.analysis.accuracy.chain_drift_rate`) is this value; a start-up
transient (real-time and single-chain structures, the sliding scheme) changes it by the
relative size of the start-up error only. Its double series in ``a`` and ``Ωh`` is
:func:`strapdown.design.finite_amplitude.drift_series`.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import mpmath

from strapdown._core.backend import MPMATH
from strapdown._core.validation import positive, positive_int
from strapdown.algorithms import _reference
from strapdown.algorithms.coning import WindowedAlgorithm
from strapdown.algorithms.errata import TABLE7
from strapdown.algorithms.finite_amplitude import triple_terms
from strapdown.algorithms.rate import Rk4, WindowedRateFamily
from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.algorithms.structures import single_chain_coefficients
from strapdown.truth.motions import ClassicalConing, SpinConing

__all__ = ["UpdateWindow", "classical_coning_drift", "table7_window", "update_window"]


@dataclass(frozen=True)
class UpdateWindow:
    """One update of an algorithm as data: what :func:`classical_coning_drift` evaluates.

    ``φ = s_α Σ w_n x_{o_n} + s_β Σ c x_{o_i} × x_{o_j} + Σ τ x_{o_m} × (x_{o_i} × x_{o_j})``
    over samples at offsets ``o`` from the update start (increments over
    ``[o h, (o+1) h]``, or rates at ``o h``), ``q ← q ⊗ exp(φ)`` every ``update`` samples;
    or, with ``rk4`` set, one normalised quaternion RK4 step (``"2td"``/``"td-interp"``).
    """

    input: str
    update: int
    offsets: tuple[int, ...]
    weights: tuple[Fraction | float, ...]
    pairs: tuple[tuple[int, int, Fraction | float], ...]
    triples: tuple[tuple[int, int, int, Fraction | float], ...] = ()
    rk4: str | None = None


def _from_windowed(alg: WindowedAlgorithm, triples=()) -> UpdateWindow:
    pairs = tuple((i, j, c) for (i, j), c in zip(alg.pairs, alg.pair_coefficients, strict=True))
    return UpdateWindow(alg.input, alg.update, tuple(alg.offsets), tuple(alg.weights), pairs,
                        tuple(triples))


def _rotvec_window(spec: AlgorithmSpec) -> UpdateWindow:
    cs = spec.family.coefficient_set(spec)  # type: ignore[attr-defined]
    st = spec.update_structure
    if st.own_startup:  # the single chain: its own coefficients, one increment per update
        n = st.chain_subsamples(cs)
        c = single_chain_coefficients(n)
        pairs = tuple((n - 1 - m, n - 1, v) for m, v in enumerate(c, start=1))
        tri = triple_terms("single-chain", n) if st.triple(cs) else ()
        return UpdateWindow("increment", 1, tuple(range(-(n - 1), 1)),
                            (Fraction(0),) * (n - 1) + (Fraction(1),), pairs, tri)
    n = cs.n
    k = cs.exact if cs.exact is not None else cs.matrix.tolist()
    pairs = tuple((i, j, k[i][j]) for i in range(n) for j in range(i + 1, n) if k[i][j] != 0)
    return UpdateWindow("increment", n, tuple(range(n)), (Fraction(1),) * n, pairs,
                        cs.triples)


def update_window(algorithm: AlgorithmSpec | WindowedAlgorithm | UpdateWindow,
                  triples=()) -> UpdateWindow:
    """The :class:`UpdateWindow` of an algorithm spec (``rotvec`` in every structure and
    coefficient set, the windowed rate families, ``rk4``), of a
    :class:`~strapdown.algorithms.coning.WindowedAlgorithm` (e.g. a designed one, with
    optional ``triples`` ``(m, i, j, τ)`` over its nodes) or itself."""
    if isinstance(algorithm, UpdateWindow):
        return algorithm
    if isinstance(algorithm, WindowedAlgorithm):
        return _from_windowed(algorithm, triples)
    if not isinstance(algorithm, AlgorithmSpec):
        raise ValueError("algorithm must be an AlgorithmSpec, a WindowedAlgorithm or an "
                         f"UpdateWindow, got {type(algorithm).__name__}")
    fam = algorithm.family
    if fam.coning_sets:
        return _rotvec_window(algorithm)
    if isinstance(fam, Rk4):
        step = algorithm.rk4_step
        return UpdateWindow("rate", 2 if step == "2td" else 1, (), (), (), (), step)
    if isinstance(fam, WindowedRateFamily):
        return _from_windowed(fam.windowed(algorithm))
    raise ValueError(f"no exact classical-coning response for {algorithm}: it is not a "
                     "rotation-invariant windowed algorithm")


def table7_window(*, triple: bool = True) -> UpdateWindow:
    """Zhang & Yu (2021) Table 7 (from Wang et al. (2015)) in the structure inferred by
    :func:`strapdown.algorithms.errata.triple_cross_rotation_vectors`:
    ``φ = Σθ + k11 θ1×θ3 + k12 θ2×(θ3 − θ1) + Σ k_mij θm × (θi × θj)``, three increments
    per update (``triple=False``: without the triple terms)."""
    k = TABLE7
    pairs = ((0, 2, k["k11"]), (1, 2, k["k12"]), (0, 1, k["k12"]))  # θ2×(−θ1) = θ1×θ2
    nodes = {"12": (0, 1), "23": (1, 2), "13": (0, 2)}
    tri = tuple((m, *nodes[ij], k[f"k{m + 1}{ij}"]) for ij in nodes for m in range(3)
                if k[f"k{m + 1}{ij}"] != 0.0) if triple else ()
    return UpdateWindow("increment", 3, (0, 1, 2), (1.0, 1.0, 1.0), pairs, tri)


def _num(v):
    if isinstance(v, Fraction):
        return mpmath.mpf(v.numerator) / v.denominator
    return mpmath.mpf(v)


def _increment_quaternion(w: UpdateWindow, motion: ClassicalConing | SpinConing, h):
    """``E`` of the update starting at t = 0 (exact inputs from the closed form)."""
    if w.rk4 is not None:
        stride = w.update
        omega = [motion.rate_mp(k * h) for k in range(stride + 1)]
        q = _reference.rk4(omega, h, (mpmath.mpf(1), 0, 0, 0), 0 if w.rk4 == "2td" else 1,
                           MPMATH)
        return q[1]
    if w.input == "increment":
        x = [motion.increment_mp(o * h, (o + 1) * h) for o in w.offsets]
        sa = sb = mpmath.mpf(1)
    else:
        x = [motion.rate_mp(o * h) for o in w.offsets]
        sa, sb = h, h * h
    pairs = [(i, j, sb * _num(c)) for i, j, c in w.pairs]
    phi = _reference.windowed_rotvec(x, [sa * _num(v) for v in w.weights], pairs,
                                     mpmath.mpf(0))
    phi = _reference.add_triples(x, 0, [(m, i, j, _num(c)) for m, i, j, c in w.triples], phi)
    return _reference.quat_exp(phi, MPMATH)


def classical_coning_drift(algorithm: AlgorithmSpec | WindowedAlgorithm | UpdateWindow,
                           half_angle: float, omega_h: float, *, cone_rate: float = 1.0,
                           digits: int = 50, triples=(), spin_ratio: float = 0.0) -> float:
    """Exact drift about the cone axis (rad/s) under classical coning: ``Δ n_x / T``.

    Parameters
    ----------
    algorithm : AlgorithmSpec, WindowedAlgorithm or UpdateWindow
        See :func:`update_window` (``triples`` go with a WindowedAlgorithm).
    half_angle : float
        Half-cone angle ``a`` (rad).
    omega_h : float
        ``Ωh``, cone rate times the sample interval; ``Ω T`` must not be a multiple of 2π.
    cone_rate : float
        ``Ω`` (rad/s); the drift scales with it at fixed ``Ωh``.
    digits : int
        Working precision (significant digits, ≥ 17).
    spin_ratio : float
        Body spin rate over cone rate, ``ω_s/Ω`` (0: classical coning; otherwise the motion
        of :class:`~strapdown.truth.motions.SpinConing`).

    Returns
    -------
    float
        The drift (negative when the computed attitude lags the cone, the sign of Li &
        Zhang (2017) Table 1's ``−c a²Ω(Ωh)^{2N}``).
    """
    w = update_window(algorithm, triples)
    positive(half_angle, "half_angle")
    positive(omega_h, "omega_h")
    cone_rate = positive(cone_rate, "cone_rate")
    if positive_int(digits, "digits") < 17:
        raise ValueError(f"digits must be at least 17, got {digits}")
    with mpmath.workdps(digits):
        x = mpmath.mpf(omega_h)
        half = w.update * x / 2
        sign = 1 if mpmath.sin(half) > 0 else -1
        if abs(mpmath.sin(half)) < 1e-12:  # (to the float64 resolution of omega_h)
            raise ValueError(f"Ω T = {float(2 * half):.6g} is a multiple of 2π: the cone "
                             "rotates whole turns per update and the drift is not defined")
        spin = float(spin_ratio)
        motion = (ClassicalConing(half_angle, 1.0) if spin == 0.0
                  else SpinConing(half_angle, 1.0, spin))
        e = _increment_quaternion(w, motion, x)
        qa = motion.attitude_mp(mpmath.mpf(0))
        turn = half * (1 - mpmath.mpf(spin))  # (Ω − ω_s) T / 2: the inputs' turn per update
        rho = (mpmath.cos(turn), mpmath.sin(turn), mpmath.mpf(0), mpmath.mpf(0))
        a = _reference.quat_mul(_reference.quat_mul(qa, _reference.quat_mul(e, rho)),
                                (qa[0], -qa[1], -qa[2], -qa[3]))
        v = mpmath.sqrt(a[1] ** 2 + a[2] ** 2 + a[3] ** 2)
        s, c = mpmath.sin(half), mpmath.cos(half)
        dev = mpmath.atan2(sign * v * c - a[0] * s, a[0] * c + sign * v * s)  # ψ/2 − ΩT/2
        nx = sign * a[1] / v
        return float(2 * dev * nx / (w.update * x) * cone_rate)
