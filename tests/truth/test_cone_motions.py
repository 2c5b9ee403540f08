"""Zhang & Yu (2021) cone-angle motions (strapdown.truth.cone_motions)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.truth.cone_motions import spin_coning, zhang_yu_simulation


def test_simulations_follow_tables_5_and_6():
    t = np.array([0.0, 1.0, 2.0])
    d = math.radians
    for number in (1, 3):
        a = zhang_yu_simulation(number).angles(t)
        assert np.allclose(a, np.outer(t, [d(360), d(1.146), d(360)]), rtol=0, atol=1e-14)
    for number in (2, 4):
        a = zhang_yu_simulation(number).angles(t)
        expect = np.outer(t, [d(360), d(1.146), d(360)]) + 0.5 * np.outer(t * t,
                                                                           [d(24), 0, d(24)])
        assert np.allclose(a, expect, rtol=0, atol=1e-13)


@pytest.mark.parametrize("number", [0, 5, 1.5])
def test_unknown_simulation_is_refused(number):
    with pytest.raises(ValueError, match="simulations 1–4"):
        zhang_yu_simulation(number)


def test_spin_coning_angles():
    m = spin_coning(2.0, 90.0, 720.0)
    a = m.angles(np.array([0.0, 0.5]))
    d = math.radians
    assert np.allclose(a[0], [-math.pi / 2, d(2.0), 0.0], rtol=0, atol=1e-15)
    assert np.allclose(a[1], [-math.pi / 2 + d(45.0), d(2.0), d(360.0)], rtol=0, atol=1e-14)
