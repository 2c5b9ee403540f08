"""The sculling target of the designer: its own error series, Ignagni's duality with coning."""

from __future__ import annotations

from fractions import Fraction

import pytest
import sympy as sp

from strapdown.design import (
    derive,
    interval_structure,
    rate_structure,
    single_chain_structure,
    uncompressed_structure,
)
from strapdown.design.designer import Structure, _coning_series, _sculling_series


def _structures(n):
    return [interval_structure(n), interval_structure(n, "lag"), interval_structure(n, "all-pairs"),
            single_chain_structure(n), uncompressed_structure(n, 2)]


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_sculling_coefficients_equal_coning_coefficients(n):
    for st in _structures(n):
        c, s = derive(st), derive(st, target="sculling")
        assert s.coefficients == c.coefficients, st.name
        assert (s.order, s.drift_constant) == (c.order, c.drift_constant), st.name
    assert derive(interval_structure(n), target="sculling").order == 2 * n


def test_sculling_series_is_its_own_derivation():
    # independent sympy check of the first-order rectified error of ½α×υ + k(θ1×v2 + v1×θ2)
    # for N = 2 against the exact ∫(α − α0)×f, averaged over the start phase (cos ψ part)
    x, k = sp.symbols("x k")
    d = [sp.exp(sp.I * s * x) * (sp.exp(sp.I * x) - 1) for s in (0, 1)]
    pair = -sp.im(sp.expand_complex(d[0] * sp.conjugate(d[1])))
    e = k * pair - sp.Rational(1, 2) * (2 * x - sp.sin(2 * x))
    ser = sp.expand(sp.series(sp.simplify(e.subs(x, x)), x, 0, 8).removeO())
    e0, pairs = _sculling_series(interval_structure(2, "all-pairs"), 7)
    kk = sp.Symbol("k")
    mine = sum((sp.Rational(e0[p].numerator, e0[p].denominator)
                + kk * sp.Rational(pairs[0][p].numerator, pairs[0][p].denominator)) * x**p
               for p in range(8))
    assert sp.expand(mine.subs(kk, k) - ser) == 0
    # and (the duality) term for term equal to the coning series of the designer
    assert _sculling_series(interval_structure(4), 20) == _coning_series(interval_structure(4), 20)


def test_sculling_target_refuses_rate_input_and_untiled_weights():
    with pytest.raises(ValueError, match="increment input only"):
        derive(rate_structure(2), target="sculling")
    st = interval_structure(2)
    bad = Structure("half weights", "increment", 2, st.nodes, (Fraction(1, 2),) * 2, st.pairs,
                    st.groups, 2)
    with pytest.raises(ValueError, match="tile"):
        derive(bad, target="sculling")


def test_sculling_record_states_its_law():
    rec = derive(interval_structure(3), target="sculling").to_dict()
    assert rec["target"] == "sculling" and "θ0 A cos ψ" in rec["drift_law"]
    assert rec["drift_constant"] == "1/280" and rec["order"] == 6
