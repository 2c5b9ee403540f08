"""Coefficient sets: Table 3 against an independent sympy derivation; layouts; validation."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from strapdown.algorithms import coning as C


def _derive_optimum(n):
    """Independent derivation: lag sums cancelling the classical-coning error series.

    Per-update cone-axis error / sin²a = Σ K_m 4 sin²(x/2) sin(m x) − ½ (N x − sin N x),
    x = Ωh (the exact increments' cross products and the exact coning term).
    """
    x = sp.symbols("x")
    k = sp.symbols(f"K1:{n + 1}")[: n - 1]
    e = sum(k[m - 1] * 4 * sp.sin(x / 2) ** 2 * sp.sin(m * x) for m in range(1, n))
    e -= sp.Rational(1, 2) * (n * x - sp.sin(n * x))
    ser = sp.expand(sp.series(e, x, 0, 2 * n + 3).removeO())
    sol = sp.solve([ser.coeff(x, 2 * j + 1) for j in range(1, n)], k, dict=True)
    sol = sol[0] if sol else {}
    lead = sp.expand(ser.subs(sol)).coeff(x, 2 * n + 1) / n
    return [Fraction(int(sp.fraction(sol[s])[0]), int(sp.fraction(sol[s])[1])) for s in k], lead


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_table3_is_the_classical_coning_optimum(n):
    lags, lead = _derive_optimum(n)
    assert list(C.TABLE3[n]) == lags
    assert -lead == sp.Rational(C.table1_drift_constant(n).numerator,
                                C.table1_drift_constant(n).denominator)


def test_table1_constants():
    assert [C.table1_drift_constant(n) for n in range(1, 6)] == [
        Fraction(1, 12), Fraction(1, 60), Fraction(1, 280), Fraction(1, 1260), Fraction(1, 5544)]


def test_cross_with_last_layout():
    cs = C.coefficient_set("table3", 4)
    k = cs.matrix
    assert k[2, 3] == pytest.approx(214 / 105) and k[1, 3] == pytest.approx(92 / 105)
    assert k[0, 3] == pytest.approx(54 / 105)
    assert np.count_nonzero(k) == 3
    assert cs.exact[0][3] == Fraction(54, 105)


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6])
def test_lag_form_has_same_lag_sums(n):
    assert np.allclose(C.coefficient_set("lag", n).lag_sums(),
                       C.coefficient_set("table3", n).lag_sums(), rtol=1e-15)


def test_eq6_printed_layout():
    k = C.coefficient_set("eq6-printed", 3).matrix
    assert k[0, 1] == k[0, 2] == pytest.approx(27 / 20)
    assert k[1, 2] == pytest.approx(9 / 20)


def test_miller_set():
    cs = C.coefficient_set("miller", 3)
    theta = np.array([[0.1, 0.2, -0.3], [0.05, -0.1, 0.2], [0.3, 0.1, 0.0]])
    t1, t2, t3 = theta
    expected = theta.sum(0) + 33 / 80 * np.cross(t1, t3) + 57 / 80 * np.cross(t2, t3 - t1)
    assert np.allclose(C.rotation_vectors(theta, cs)[0], expected, atol=1e-16)
    with pytest.raises(ValueError, match="N = 3 only"):
        C.coefficient_set("miller", 2)


def test_rotation_vectors_general_form():
    rng = np.random.default_rng(0)
    theta = rng.normal(size=(8, 3)) * 1e-2
    k = np.triu(rng.normal(size=(4, 4)), 1)
    phi = C.rotation_vectors(theta, C.user_coefficients(k))
    g = theta.reshape(2, 4, 3)
    ref = g.sum(1) + sum(k[i, j] * np.cross(g[:, i], g[:, j])
                         for i in range(4) for j in range(i + 1, 4))
    assert np.allclose(phi, ref, atol=1e-18)


@pytest.mark.parametrize(
    ("call", "msg"),
    [
        (lambda: C.coefficient_set("nope", 2), "unknown coefficient set"),
        (lambda: C.coefficient_set("table3", 0), "positive integer"),
        (lambda: C.coefficient_set("table3", 7), "N = 1 … 6"),
        (lambda: C.user_coefficients(np.ones((3, 3))), "strictly upper triangular"),
        (lambda: C.user_coefficients(np.zeros((2, 3))), r"shape \(N, N\)"),
        (lambda: C.user_coefficients([[0, np.nan], [0, 0]]), "NaN"),
        (lambda: C.rotation_vectors(np.zeros((5, 3)), C.coefficient_set("table3", 2)),
         "whole number of groups"),
        (lambda: C.rotation_vectors(np.zeros((4, 2)), C.coefficient_set("table3", 2)),
         r"shape \(\.\.\., 3\)"),
    ],
)
def test_bad_input(call, msg):
    with pytest.raises(ValueError, match=msg):
        call()
