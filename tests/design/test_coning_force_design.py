"""The designer's coning-force target: the tabulated sets and laws are its derivation, the
forms it cannot serve (cross-with-last, the single chain) stop at (Ωh)⁴, and the sets it
derives keep the classical-sculling law."""

from __future__ import annotations

from fractions import Fraction

import pytest

from strapdown.algorithms import tables
from strapdown.design import (
    derive,
    interval_structure,
    rate_structure,
    single_chain_structure,
    velocity_error_laws,
)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_tabulated_sets_are_the_designers(n):
    st = interval_structure(n, "all-pairs")
    d = derive(st, target="coning-force", rule="min-norm")
    assert d.coefficients == tables.SCULLING_CONING_FORCE[n]
    assert st.pairs == tuple((i, j) for i in range(n) for j in range(i + 1, n))
    laws = velocity_error_laws(st, d.coefficients)
    # both laws at the sculling order 2N, the sculling one unchanged
    assert laws["sculling"] == tables.SCULLING_DRIFT[n]
    assert laws["coning-force"] == tables.CONING_FORCE_DRIFT[("conventional", "coning-force")][n]
    assert (d.order, d.drift_constant) == laws["coning-force"]
    assert d.order == 2 * n


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6])
def test_classical_sets_stop_at_fourth_order(n):
    conv = velocity_error_laws(interval_structure(n), tables.SCULLING_CONVENTIONAL[n])
    chain = velocity_error_laws(single_chain_structure(n), tables.SCULLING_SINGLE_CHAIN[n])
    assert conv["coning-force"] == tables.CONING_FORCE_DRIFT[("conventional", "classical")][n]
    assert chain["coning-force"] == tables.CONING_FORCE_DRIFT[("single-chain", "classical")][n]
    assert conv["coning-force"][0] == chain["coning-force"][0] == min(2 * n, 4)
    # the classical conventional constant grows with N: N ≥ 3 worse than N = 2
    if n >= 3:
        assert abs(conv["coning-force"][1]) > abs(tables.CONING_FORCE_DRIFT[
            ("conventional", "classical")][n - 1][1])


@pytest.mark.parametrize("n", [3, 4, 5])
def test_forms_whose_pairs_sculling_fixes_cannot_meet_both(n):
    # N − 1 coefficients, all taken by the sculling conditions: the joint target stops where
    # the first force condition disagrees, and no choice reaches the sculling order on both
    for st in (interval_structure(n), single_chain_structure(n)):
        d = derive(st, target="coning-force")
        laws = velocity_error_laws(st, d.coefficients)
        assert min(laws["sculling"][0], laws["coning-force"][0]) < 2 * n, st.name
        assert laws["coning-force"][0] <= 2 * n - 2, st.name


def test_coning_force_record_and_bad_input():
    rec = derive(interval_structure(3, "all-pairs"), target="coning-force",
                 rule="min-norm").to_dict()
    assert rec["target"] == "coning-force" and "cone axis" in rec["drift_law"]
    assert rec["coefficients"] == ["31/20", "9/20", "-1/5"]
    with pytest.raises(ValueError, match="increment input only"):
        derive(rate_structure(2), target="coning-force")
    with pytest.raises(ValueError, match="one per pair"):
        velocity_error_laws(interval_structure(3), [Fraction(1)])


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6])
def test_a_single_chain_with_pairs_among_earlier_samples_reaches_both_orders(n):
    # the form extended (pairs among the window's earlier samples too, not only with the
    # current one): both laws at order 2N, the coning-force constant twice the sculling one
    from strapdown.design.designer import Structure

    nodes = tuple(Fraction(s) for s in range(-(n - 1), 1))
    pairs = tuple((i, j) for i in range(n) for j in range(i + 1, n))
    st = Structure(f"single chain, window pairs, N = {n}", "increment", 1, nodes,
                   tuple(Fraction(int(s == 0)) for s in nodes), pairs,
                   tuple(((k, Fraction(1)),) for k in range(len(pairs))), n)
    laws = velocity_error_laws(st, derive(st, target="coning-force", rule="min-norm")
                               .coefficients)
    assert laws["sculling"] == tables.SCULLING_DRIFT[n]
    assert laws["coning-force"] == (2 * n, 2 * tables.SCULLING_DRIFT[n][1])
