"""Arbitrary-precision evaluation of the rotation-vector algorithms (mpmath).

The drifts of Li & Zhang 2017 Table 1 at small cone angles are far below
float64 round-off (1e-16 rad per update). Here the same algorithms
(:mod:`strapdown.algorithms._reference`) run on the same motion with every quantity —
exact increments, coefficients (exact rationals), exponential map, truth
attitude and error — carried at ``digits`` significant digits. Only the final
error vectors are converted to float64 (their relative precision is what
matters, not their size).

Cost is roughly 20 µs per arithmetic operation: about 10⁴ updates per second
for N = 3. :data:`MAX_MP_SAMPLES` bounds a run so that a typo cannot start an
hour-long computation silently.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import get_args

import mpmath
import numpy as np
from numpy.typing import NDArray

from strapdown._core.backend import MPMATH
from strapdown._core.validation import positive, positive_int
from strapdown.algorithms import _reference
from strapdown.algorithms.coning import CoefficientSet, WindowedAlgorithm
from strapdown.algorithms.family import IncrementStructure, Rk4Step
from strapdown.algorithms.structures import UpdateStructure, increment_structure, startup_sets
from strapdown.truth.motions import Motion

__all__ = ["MAX_MP_SAMPLES", "MpSolution", "run_mp", "run_rk4_mp", "run_windowed_mp"]

#: Largest number of increments one arbitrary-precision run accepts.
MAX_MP_SAMPLES = 2_000_000


@dataclass(frozen=True)
class MpSolution:
    """Result of an arbitrary-precision run, errors already formed in high precision.

    Attributes
    ----------
    t : ndarray (m,)
        Output times (s, float64).
    err : ndarray (m, 3)
        Reference-frame error vectors (rad), converted to float64.
    angle : ndarray (m,)
        Error angles (rad).
    chain : ndarray (m,)
        Interleaved chain index of each output.
    digits : int
        Working precision (significant decimal digits).
    startup : int
        First steady-state output (see :class:`strapdown.algorithms.structures.AttitudeSolution`).
    """

    t: NDArray[np.float64]
    err: NDArray[np.float64]
    angle: NDArray[np.float64]
    chain: NDArray[np.int_]
    digits: int
    startup: int = 0


def _single_chain_phis(theta, coefficients: CoefficientSet, chain):
    """Single-chain rotation vectors in mpmath, with the same start-up as the float64 path
    (``chain``: the single-chain structure, which says what the set runs)."""
    from strapdown.algorithms.finite_amplitude import triple_terms
    from strapdown.algorithms.structures import single_chain_coefficients

    n = chain.chain_subsamples(coefficients)
    sets = {m: [_mpf(c) for c in single_chain_coefficients(m)] for m in range(1, n + 1)}
    triples = ([(m, i, j, _mpf(c)) for m, i, j, c in triple_terms("single-chain", n)]
               if chain.triple(coefficients) else [])
    zero = mpmath.mpf(0)
    phis = []
    for k in range(len(theta)):
        cs = sets[min(k + 1, n)]
        window = [theta[k - m] for m in range(len(cs), -1, -1)]  # θ_{k−M} … θ_k
        last = len(window) - 1
        pairs = [(last - m, last, c) for m, c in enumerate(cs, start=1)]
        w = [zero] * last + [mpmath.mpf(1)]
        phi = _reference.windowed_rotvec(window, w, pairs, zero)
        if k >= n - 1:  # steady state: the finite-amplitude triple terms
            phi = _reference.add_triples(window, 0, triples, phi)
        phis.append(phi)
    return phis


def _mp_matrix(cs: CoefficientSet):
    if cs.exact is not None:
        return [[mpmath.mpf(v.numerator) / v.denominator for v in row] for row in cs.exact]
    return [[mpmath.mpf(float(v)) for v in row] for row in cs.matrix]


def _mpf(v):
    from fractions import Fraction

    if isinstance(v, Fraction):
        return mpmath.mpf(v.numerator) / v.denominator
    return mpmath.mpf(float(v))


def _errors(motion, q, t_out, chain, digits, startup=0):
    err = np.empty((len(q), 3))
    ang = np.empty(len(q))
    for i, (qe, tt) in enumerate(zip(q, t_out, strict=True)):
        qt = motion.attitude_mp(tt)
        v, a = _log(_reference.quat_mul(qe, (qt[0], -qt[1], -qt[2], -qt[3])))
        err[i] = [float(c) for c in v]
        ang[i] = float(a)
    return MpSolution(np.array([float(x) for x in t_out]), err, ang, chain, digits, startup)


def _check_run(motion, h, samples, digits):
    if not motion.has_closed_form:
        raise ValueError(
            f"{type(motion).__name__} has no closed form; arbitrary precision needs one"
        )
    h = positive(h, "h (sample interval)")
    samples = positive_int(samples, "samples")
    digits = positive_int(digits, "digits")
    if digits < 17:
        raise ValueError(f"digits must be at least 17 (float64 is ~16), got {digits}")
    if samples > MAX_MP_SAMPLES:
        raise ValueError(
            f"{samples} samples exceed the arbitrary-precision limit of {MAX_MP_SAMPLES}; "
            "shorten the duration or lower the sample rate"
        )
    return h, samples, digits


def run_windowed_mp(motion: Motion, algorithm: WindowedAlgorithm, *, h: float, updates: int,
                    digits: int = 50, t0: float = 0.0, sliding: bool = False,
                    startup: WindowedAlgorithm | None = None) -> MpSolution:
    """Run a windowed (designed) algorithm on a closed-form motion in arbitrary precision.

    History samples before ``t0`` come from the motion itself, so the first
    update at ``t0`` already has its full window; outputs are at
    ``t0 + j·update·h``, ``j = 0 … updates``. With ``sliding=True`` the same
    runs every sample as in :func:`strapdown.algorithms.structures.windowed` (``updates``
    then counts outputs after the start-up).
    """
    if not isinstance(algorithm, WindowedAlgorithm):
        raise ValueError(f"algorithm must be a WindowedAlgorithm, got {type(algorithm).__name__}")
    h, updates, digits = _check_run(motion, h, updates, digits)
    u = algorithm.update
    with mpmath.workdps(digits):
        hm = mpmath.mpf(h)
        tm0 = mpmath.mpf(t0)
        lo = min(0, min(algorithm.offsets))
        hi = (updates - 1) * u + algorithm.span
        if algorithm.input == "increment":
            samples = {k: motion.increment_mp(tm0 + k * hm, tm0 + (k + 1) * hm)
                       for k in range(lo, hi + 1)}
            sa, sb = mpmath.mpf(1), mpmath.mpf(1)
        else:
            samples = {k: motion.rate_mp(tm0 + k * hm) for k in range(lo, hi + 1)}
            sa, sb = hm, hm * hm
        def phi_of(alg, start):
            w = [sa * _mpf(x) for x in alg.weights]
            pairs = [(i, j, sb * _mpf(c)) for (i, j), c in
                     zip(alg.pairs, alg.pair_coefficients, strict=True) if c != 0]
            window = [samples[start + o] for o in alg.offsets]
            return _reference.windowed_rotvec(window, w, pairs, mpmath.mpf(0))

        q0 = motion.attitude_mp(tm0)
        if not sliding:
            phis = [phi_of(algorithm, j * u) for j in range(updates)]
            q = _reference.chain(phis, [q0], 1, MPMATH)
            t_out = [tm0 + j * u * hm for j in range(updates + 1)]
            return _errors(motion, q, t_out, np.zeros(len(q), int), digits)
        if startup is None or startup.update != 1:
            raise ValueError("the sliding scheme needs a one-sample startup algorithm")
        first = _reference.chain([phi_of(startup, k) for k in range(u - 1)], [q0], 1, MPMATH)
        total = updates + u - 1
        need = total - u + algorithm.span
        for k in range(hi + 1, need + 1):
            samples[k] = (motion.increment_mp(tm0 + k * hm, tm0 + (k + 1) * hm)
                          if algorithm.input == "increment" else motion.rate_mp(tm0 + k * hm))
        phis = [phi_of(algorithm, k) for k in range(total - u + 1)]
        q = _reference.chain(phis, first, u, MPMATH)
        t_out = [tm0 + k * hm for k in range(len(q))]
        return _errors(motion, q, t_out, np.arange(len(q)) % u, digits)


def _log(dq):
    w, x, y, z = dq
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    s = mpmath.sqrt(x * x + y * y + z * z)
    ang = 2 * mpmath.atan2(s, w)
    scale = 2 / w if s == 0 else ang / s
    return (scale * x, scale * y, scale * z), ang


def run_mp(
    motion: Motion,
    coefficients: CoefficientSet,
    *,
    structure: IncrementStructure | UpdateStructure,
    h: float,
    samples: int,
    digits: int = 50,
    t0: float = 0.0,
) -> MpSolution:
    """Run a structure on a closed-form motion in arbitrary precision.

    Parameters
    ----------
    motion : Motion
        Must have closed forms (``motion.has_closed_form``).
    coefficients : CoefficientSet
        Coning correction (exact rationals are used when available).
    structure : {"conventional", "realtime", "single-chain"}
    h : float
        Increment interval (s); taken exactly as the float64 value given.
    samples : int
        Number of increments (the conventional structure drops a tail that
        does not fill an update).
    digits : int
        Significant decimal digits (≥ 17).
    t0 : float
        Start time (s).
    """
    st = increment_structure(structure)  # the registered object answers the facts
    h, samples, digits = _check_run(motion, h, samples, digits)
    n = coefficients.n
    if samples < n:
        raise ValueError(f"N = {n} subsamples need at least {n} increments, got {samples}")
    with mpmath.workdps(digits):
        hm = mpmath.mpf(h)
        tm0 = mpmath.mpf(t0)
        samples = st.usable_samples(samples, n)
        edges = [tm0 + k * hm for k in range(samples + 1)]
        theta = [motion.increment_mp(edges[k], edges[k + 1]) for k in range(samples)]
        q0 = motion.attitude_mp(tm0)
        if st.whole_updates and coefficients.triples:
            triples = [(m, i, j, _mpf(c)) for m, i, j, c in coefficients.triples]
            q = _reference.conventional_triple(theta, _mp_matrix(coefficients), triples, q0,
                                               MPMATH)
            t_out = edges[::n]
            chain = np.zeros(len(q), int)
        elif st.whole_updates:
            q = _reference.conventional(theta, _mp_matrix(coefficients), q0, MPMATH)
            t_out = edges[::n]
            chain = np.zeros(len(q), int)
        elif st.interleaved:
            st.check_set(coefficients)
            ks = [_mp_matrix(s) for s in startup_sets(coefficients)]
            q = _reference.realtime(theta, ks, q0, MPMATH)
            t_out = edges
            chain = np.arange(len(q)) % n
        else:
            q = _reference.chain(_single_chain_phis(theta, coefficients, st), [q0], 1,
                                 MPMATH)
            t_out = edges
            chain = np.zeros(len(q), int)
            n_sc = st.chain_subsamples(coefficients)
            return _errors(motion, q, t_out, chain, digits, min(n_sc - 1, len(q) - 1))
        return _errors(motion, q, t_out, chain, digits)


def run_rk4_mp(motion: Motion, *, h: float, samples: int, step: Rk4Step = "2td",
               digits: int = 50, t0: float = 0.0) -> MpSolution:
    """Quaternion RK4 on exact rate samples in arbitrary precision (see
    :mod:`strapdown.algorithms.rate`)."""
    if step not in get_args(Rk4Step):
        raise ValueError(f"step must be '2td' or 'td-interp', got {step!r}")
    h, samples, digits = _check_run(motion, h, samples, digits)
    mode = 0 if step == "2td" else 1
    stride = 2 if mode == 0 else 1
    if samples < stride + 1:
        raise ValueError(f"RK4 with step {step} needs at least {stride + 1} samples")
    with mpmath.workdps(digits):
        hm = mpmath.mpf(h)
        tm0 = mpmath.mpf(t0)
        omega = [motion.rate_mp(tm0 + k * hm) for k in range(samples)]
        q = _reference.rk4(omega, hm, motion.attitude_mp(tm0), mode, MPMATH)
        t_out = [tm0 + j * stride * hm for j in range(len(q))]
        return _errors(motion, q, t_out, np.zeros(len(q), int), digits)
