"""The papers' printed variants (strapdown.algorithms.errata) against exact truth and the
corrected forms they sit beside."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.coning import MAX_SUBSAMPLES, TABLE3, coefficient_set
from strapdown.algorithms.errata import eq6_printed_matrix, printed_cone_rates
from strapdown.truth.cone_motions import spin_coning


@pytest.mark.parametrize("n", range(1, MAX_SUBSAMPLES + 1))
def test_eq6_printed_set_is_built_from_errata(n):
    cs = coefficient_set("eq6-printed", n)
    assert [list(r) for r in cs.exact] == eq6_printed_matrix(TABLE3[n])
    # every pair (i, j > i) carries ς_i: row i of the upper triangle is constant
    for i, s in enumerate(TABLE3[n]):
        assert all(cs.exact[i][j] == s for j in range(i + 1, n))


@pytest.mark.parametrize("n", [1, 2])
def test_eq6_printed_equals_table3_for_n_up_to_two(n):
    assert np.array_equal(coefficient_set("eq6-printed", n).matrix,
                          coefficient_set("table3", n).matrix)


def test_eq6_printed_differs_from_table3_for_n3():
    assert not np.array_equal(coefficient_set("eq6-printed", 3).matrix,
                              coefficient_set("table3", 3).matrix)


def test_printed_cone_rates_have_row_one_sign_inverted():
    # spin + coning: δ̇ = (Ω, 0, ω_s) exactly; the printed eq. 7 gets −Ω in row 1 only
    cone, spin = 360.0, 3600.0
    m = spin_coning(5.0, cone, spin)
    for t in (0.013, 0.25, 0.61):
        rates = printed_cone_rates(m.angles(t), m.rate(t))
        assert rates[0] == pytest.approx(-math.radians(cone), rel=1e-12)
        assert rates[1] == pytest.approx(0.0, abs=1e-12)
        assert rates[2] == pytest.approx(math.radians(spin), rel=1e-12)
