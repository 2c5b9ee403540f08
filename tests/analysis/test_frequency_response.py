"""Exact classical-coning frequency response against arbitrary-precision simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.coning import TABLE3
from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.analysis.accuracy import chain_drift_rate
from strapdown.analysis.frequency_response import (
    UpdateWindow,
    classical_coning_drift,
    update_window,
)
from strapdown.truth.motions import ClassicalConing

OMEGA = 2 * math.pi
SPECS = ["rotvec:N=1", "rotvec:N=3", "rotvec:N=5", "rotvec:N=2:structure=realtime",
         "rotvec:N=4:coefficients=lag", "rotvec:N=3:coefficients=eq6-printed",
         "rotvec:N=3:coefficients=miller", "rotvec:N=4:coefficients=finite-amplitude",
         "rotvec:N=3:structure=single-chain",
         "rotvec:N=5:structure=single-chain:coefficients=finite-amplitude",
         "rate-single", "rate-three", "rate-two", "rk4", "rk4:rk4_step=td-interp"]


def _simulated(spec, a, spp, digits=40):
    motion = ClassicalConing(a, OMEGA)
    s = spec.run_mp(motion, h=motion.period / spp, samples=2 * spp + spec.min_samples,
                    digits=digits)
    k = s.startup
    chains = chain_drift_rate(s.t[k:], s.err[k:, 0], s.chain[k:], period=motion.period)
    assert all(c.method == "whole-periods" for c in chains)
    return float(np.mean([c.rate for c in chains]))


def _points():
    rng = np.random.default_rng(19)
    out = []
    for k in range(20):
        spec = AlgorithmSpec.parse(SPECS[k % len(SPECS)])
        u = update_window(spec).update
        # Ωh = 2π/spp with whole periods on every update; the first five reach Ωh ≥ 0.45
        mult = int(rng.integers(2, 5)) if k < 5 else int(rng.integers(2, 60 // u + 2))
        spp = u * mult if u > 1 else int(rng.integers(7, 14 if k < 5 else 80))
        a = math.radians(float(rng.uniform(0.2, 8.0)))
        out.append((spec, a, spp))
    return out


@pytest.mark.parametrize(("spec", "a", "spp"), _points(), ids=lambda v: str(v)[:40])
def test_exact_response_is_the_simulated_drift(spec, a, spp):
    exact = classical_coning_drift(spec, a, 2 * math.pi / spp, cone_rate=OMEGA)
    assert exact == pytest.approx(_simulated(spec, a, spp), rel=1e-6)


def test_points_reach_omega_h_near_one():
    assert max(2 * math.pi / spp for _, _, spp in _points()) > 0.85


def test_small_angle_limit_is_table1():
    spec = AlgorithmSpec.parse("rotvec:N=3")
    a, x = 1e-5, 0.02
    exact = classical_coning_drift(spec, a, x, cone_rate=OMEGA)
    law = spec.drift_law().predict(a, OMEGA, x / OMEGA)
    assert exact / law == pytest.approx(1, abs=2 * x * x)  # next term 1/1440 / (1/280) x²


def test_window_forms_and_errors():
    w = update_window(AlgorithmSpec.parse("rotvec:N=3"))
    assert w.update == 3 and [c for _, _, c in w.pairs] == list(TABLE3[3])[::-1]
    assert update_window(w) is w
    alg = update_window(AlgorithmSpec.parse("rate-three")).pairs
    assert len(alg) == 6
    assert isinstance(w, UpdateWindow)
    with pytest.raises(ValueError, match="not a rotation-invariant"):
        update_window(AlgorithmSpec.parse("miller:step=0.01"))
    with pytest.raises(ValueError, match="multiple of 2π"):
        classical_coning_drift(AlgorithmSpec.parse("rotvec:N=2"), 0.01, math.pi)
    with pytest.raises(ValueError, match="AlgorithmSpec"):
        update_window("rotvec:N=3")


@pytest.mark.parametrize(("text", "ratio"), [("rotvec:N=3", 3), ("rk4", 2),
                                             ("rotvec:N=4:coefficients=finite-amplitude", 10),
                                             ("rotvec:N=2:structure=single-chain", 5)])
def test_spin_coning_response_is_the_simulated_drift(text, ratio):
    from strapdown.truth.motions import SpinConing

    spec = AlgorithmSpec.parse(text)
    a, spp = math.radians(2.0), 120
    motion = SpinConing(a, OMEGA, OMEGA * ratio)
    s = spec.run_mp(motion, h=1.0 / spp, samples=2 * spp + spec.min_samples, digits=40)
    k = s.startup
    chains = chain_drift_rate(s.t[k:], s.err[k:, 0], s.chain[k:], period=1.0)
    assert all(c.method == "whole-periods" for c in chains)
    exact = classical_coning_drift(spec, a, 2 * math.pi / spp, cone_rate=OMEGA,
                                   spin_ratio=ratio)
    assert exact == pytest.approx(float(np.mean([c.rate for c in chains])), rel=1e-8)


def test_table7_window_is_the_errata_rotation_vector():
    from strapdown.algorithms import _reference
    from strapdown.algorithms.errata import triple_cross_rotation_vectors
    from strapdown.analysis.frequency_response import table7_window

    theta = np.random.default_rng(7).normal(size=(3, 3)) * 0.1
    for triple in (True, False):
        w = table7_window(triple=triple)
        x = [tuple(r) for r in theta]
        phi = _reference.windowed_rotvec(x, list(w.weights), list(w.pairs), 0.0)
        phi = _reference.add_triples(x, 0, list(w.triples), phi)
        assert np.allclose(phi, triple_cross_rotation_vectors(theta, triple=triple)[0],
                           rtol=0, atol=1e-15)
