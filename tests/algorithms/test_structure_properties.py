"""Properties of the coning corrections and the update structures, over drawn values.

* Frame equivariance (every named set × every N): ``φ(Rθ) = R φ(θ)`` for a proper
  rotation R, because ``Σθ`` is linear and ``Ra × Rb = R(a × b)`` (Li & Zhang (2017),
  eq. 6 in general pair form).
* Streaming: :class:`~strapdown.algorithms.streaming.RotvecStream` fed any chunking
  equals the one-shot run bit for bit (it calls the same kernels on the same numbers).
* Real-time structure (Li & Zhang (2017), eq. 15): chain k is a conventional run on the
  increments from sample k on, started from the chain's own start-up attitude.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from strapdown import rotation as R
from strapdown.algorithms.coning import (
    MAX_SUBSAMPLES,
    coefficient_set,
    coefficient_set_names,
    rotation_vectors,
)
from strapdown.algorithms.streaming import RotvecStream
from strapdown.algorithms.structures import conventional, realtime, run_structure
from strategies import (
    CONING_CHOICES,
    chunk_sizes,
    coning_sets,
    increments,
    rotation_matrices,
    split,
    unit_quaternions,
)

_F = {"allow_nan": False, "allow_infinity": False}
_EPS = np.finfo(np.float64).eps


def test_every_named_set_and_n_is_drawn():
    # the strategies below sample from CONING_CHOICES; it must hold every name × valid N
    assert {name for name, _ in CONING_CHOICES} == set(coefficient_set_names())
    assert ("miller", 3) in CONING_CHOICES and ("miller", 2) not in CONING_CHOICES
    assert {n for name, n in CONING_CHOICES if name == "table3"} == set(
        range(1, MAX_SUBSAMPLES + 1))


# ----------------------------------------------------------------- frame equivariance
def _equivariance_bound(theta, cs):
    """Round-off bound per group: 16 ε (Σ|θ_i| + Σ |k_ij| |θ_i| |θ_j|).

    A rotated vector ``fl(Rv)`` is off by at most ``γ₃ √3 |v| ≈ 5.2 ε |v|``, on both sides
    (``Rθ_i`` and ``Rφ``), plus ~ε|·| per sum and cross product; 22 500 draws over every
    set gave at most 5.4 ε(…)."""
    g = np.linalg.norm(theta, axis=-1).reshape(-1, cs.n)
    lin = g.sum(axis=1)
    quad = np.einsum("ij,gi,gj->g", np.abs(cs.matrix), g, g)
    cubic = sum(abs(float(c)) * g[:, m] * g[:, i] * g[:, j] for m, i, j, c in cs.triples)
    return 16 * _EPS * (lin + quad + cubic)


@pytest.mark.parametrize(("name", "n"), CONING_CHOICES, ids=[f"{a}-{b}" for a, b in CONING_CHOICES])
@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_rotation_vector_is_frame_equivariant(name, n, data):
    cs = coefficient_set(name, n)
    rot = data.draw(rotation_matrices(()), label="R")
    theta = data.draw(increments(st.integers(1, 4).map(lambda m: m * n), max_abs=1.0),
                      label="theta")
    lhs = rotation_vectors(theta @ rot.T, cs)
    rhs = rotation_vectors(theta, cs) @ rot.T
    assert np.all(np.linalg.norm(lhs - rhs, axis=-1) <= _equivariance_bound(theta, cs))


@settings(max_examples=25, deadline=None)
@given(coning_sets(), rotation_matrices(()), st.data())
def test_cross_terms_are_pseudovectors(cs, rot, data):
    # under the improper P = −R the sum flips and the pair terms do not:
    # φ(Pθ) = P Σθ − P Σ k θi×θj. This is what the proper-rotation test relies on to fail.
    theta = data.draw(increments(st.integers(1, 3).map(lambda m: m * cs.n), max_abs=1.0))
    s = theta.reshape(-1, cs.n, 3).sum(axis=1)
    cross = rotation_vectors(theta, cs) - s
    lhs = rotation_vectors(theta @ (-rot).T, cs)
    rhs = (s - cross) @ (-rot).T
    assert np.all(np.linalg.norm(lhs - rhs, axis=-1) <= _equivariance_bound(theta, cs))


# ----------------------------------------------------------------------- streaming
_SETS = {
    "conventional": coning_sets(),
    "realtime": coning_sets(),
    # the single chain takes Table 3's optimum (designed) or no correction
    "single-chain": st.sampled_from([(name, n) for name in ("table3", "none")
                                     for n in range(1, MAX_SUBSAMPLES + 1)]).map(
        lambda c: coefficient_set(*c)),
}


def _streamed(structure, cs, chunks, *, h, t0, q0):
    s = RotvecStream(structure, cs, h=h, t0=t0, q0=q0)
    parts = [s.feed(c) for c in chunks]
    return (np.concatenate([p.t for p in parts]), np.concatenate([p.q for p in parts]),
            np.concatenate([p.chain for p in parts]))


@pytest.mark.parametrize("structure", list(_SETS))
@settings(max_examples=50, deadline=None)
@given(data=st.data(), sizes=chunk_sizes(), q0=unit_quaternions(()),
       h=st.floats(1e-5, 0.1, **_F), t0=st.floats(-10.0, 10.0, **_F))
def test_streaming_is_chunk_invariant(structure, data, sizes, q0, h, t0):
    cs = data.draw(_SETS[structure], label="coefficients")
    theta = data.draw(increments(st.integers(cs.n, 60)), label="theta")
    one = run_structure(structure, theta, cs, h=h, t0=t0, q0=q0)
    t, q, chain = _streamed(structure, cs, split(theta, sizes), h=h, t0=t0, q0=q0)
    assert np.array_equal(q, one.q)
    assert np.array_equal(t, one.t)
    assert np.array_equal(chain, one.chain)


# ---------------------------------------------------------- real-time = N conventional chains
def _startup_attitude(q0, theta, cs, k):
    """``q(k) = q(0) ⊗ q(φ)``, φ from the k-subsample set of the same family on θ_1 … θ_k
    (Table 3 when the family has none), the start-up rule of the real-time structure."""
    try:
        sk = coefficient_set(cs.name, k)
    except ValueError:
        sk = coefficient_set("table3", k)
    return R.quat_multiply(q0, R.quat_from_rotvec(rotation_vectors(theta[:k], sk)[0]))


@settings(max_examples=40, deadline=None)
@given(coning_sets(), unit_quaternions(()), st.data())
def test_realtime_chain_k_is_conventional_from_sample_k(cs, q0, data):
    n = cs.n
    theta = data.draw(increments(st.integers(2 * n - 1, 6 * n)), label="theta")
    rt = realtime(theta, cs, h=1e-3, q0=q0)
    for k in range(n):
        start = rt.q[k]
        if k:
            assert R.attitude_error_angle(start, _startup_attitude(q0, theta, cs, k)) <= 1e-15
        conv = conventional(theta[k:], cs, h=1e-3, q0=start, tail="drop")
        chain = rt.q[k::n]
        assert np.array_equal(rt.chain[k::n], np.full(chain.shape[0], k))
        assert conv.q.shape == chain.shape
        if np.array_equal(conv.q[0], start):
            # the same kernel operations on the same numbers: exact
            assert np.array_equal(conv.q, chain)
        else:
            # conventional() renormalises its q0, which can move the last bit of an
            # already-unit start (about 1 start in 10); that ulp then rides along the
            # chain (at most 1.7 ε in 4000 chains)
            steps = np.arange(chain.shape[0])[:, None]
            assert np.all(np.abs(conv.q - chain) <= 4 * _EPS * (1 + steps))
