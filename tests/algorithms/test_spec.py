"""The algorithm model: grammar round trip, registry facts, validation, runs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strapdown.algorithms.coning import coefficient_set_names
from strapdown.algorithms.spec import (
    ALGORITHMS,
    REGISTRY,
    STRUCTURES,
    AlgorithmSpec,
    algorithms_taking,
    parse_spec,
)
from strapdown.truth import sensors
from strapdown.truth.motions import ClassicalConing


def _every_spec():
    """One spec per family × structure × coefficient choice (N = 3 where it applies)."""
    for name, fam in REGISTRY.items():
        for structure in fam.structures:
            for coeffs in (None, *fam.coefficient_names()):
                if coeffs == "miller" or (structure == "single-chain" and coeffs not in (
                        None, "table3", "none", "finite-amplitude")) or (
                        structure == "realtime" and coeffs == "finite-amplitude"):
                    continue
                extra = {"step": 0.01} if fam.stepped else {}
                yield AlgorithmSpec(name, structure=structure, coefficients=coeffs, **extra)


SPECS = list(_every_spec())


@pytest.mark.parametrize("spec", SPECS, ids=str)
def test_print_then_parse_is_the_identity(spec):
    assert AlgorithmSpec.parse(str(spec)) == spec


def test_grammar_examples():
    s = AlgorithmSpec.parse("rotvec:N=3:structure=realtime")
    assert (s.algorithm, s.subsamples, s.structure) == ("rotvec", 3, "realtime")
    assert str(AlgorithmSpec.parse("rate-three:structure=sliding")) == (
        "rate-three:structure=sliding")
    assert AlgorithmSpec.parse("miller:step=0.01:exact_exp=true").exact_exp is True
    assert parse_spec("rotvec:N=3:structure=realtime") == {
        "algorithm": "rotvec", "subsamples": 3, "structure": "realtime"}
    # defaults fill what the string leaves out; the string wins
    assert AlgorithmSpec.parse("rotvec", subsamples=5).subsamples == 5
    assert AlgorithmSpec.parse("rotvec:N=2", subsamples=5).subsamples == 2


@pytest.mark.parametrize(("text", "msg"), [
    ("rotvek:N=3", "unknown algorithm 'rotvek'"),
    ("rotvec:subsample=3", "not key=value"),
    ("rotvec:N=three", "bad value 'three' for subsamples"),
    ("rotvec:N=7", "at most 6"),
    ("rotvec:N=0", "positive"),
    ("rotvec:structure=sliding", "supports the structures"),
    ("rotvec:coefficients=derived", "takes coefficients table3 or lag"),
    ("rotvec:N=4:coefficients=miller", "N = 3 only"),
    ("rate-three:coefficients=table3", "derived or paper"),
    ("rate-single:structure=sliding", "supports the structures"),
    ("rk4:coefficients=paper", "rk4 has no coefficients"),
    ("rk4:rk4_step=3td", "rk4_step must be one of"),
    ("miller", "needs --step"),
    ("panov:step=0.01:beta=0.2", "one coefficient"),
    ("miller:step=0.01:coefficients=table3", "alpha/--beta, not --coefficients"),
    ("rotvec:alpha=0.5", "rotvec takes no alpha"),
    ("rate-three:N=3", r"rate-three takes no N \(subsamples\)"),
    ("rk4:exact_exp=true", "rk4 takes no exact_exp"),
    ("miller:step=0.01:rk4_step=2td", "miller takes no rk4_step"),
    ("rate-single:step=0.01", "rate-single takes no step"),
    ("miller:step=-1", "positive"),
])
def test_invalid_specs_name_the_problem(text, msg):
    with pytest.raises(ValueError, match=msg):
        AlgorithmSpec.parse(text)


def test_registry_facts():
    assert ALGORITHMS == ("rotvec", "rate-single", "rate-three", "rk4", "rate-two", "miller",
                          "panov", "power")
    assert set(STRUCTURES) == {"conventional", "realtime", "single-chain", "sliding"}
    assert algorithms_taking("rate") == ("rate-single", "rate-three", "rk4", "rate-two")
    assert REGISTRY["rotvec"].coefficient_names() == coefficient_set_names()
    h = 1e-3
    facts = {  # spec: (input kind, minimum samples, update period / h, drift order)
        "rotvec:N=3": ("increment", 3, 3, 6),
        "rotvec:N=3:structure=realtime": ("increment", 3, 1, 6),
        "rotvec:N=4:structure=single-chain": ("increment", 1, 1, 8),
        "rotvec:N=3:coefficients=miller": ("increment", 3, 3, None),
        "rate-single": ("rate", 2, 1, 4),
        "rate-single:coefficients=paper": ("rate", 2, 1, 2),
        "rate-three": ("rate", 4, 3, 8),
        "rate-three:structure=sliding": ("rate", 4, 1, 8),
        "rate-three:coefficients=paper": ("rate", 4, 3, 4),
        "rk4": ("rate", 3, 2, 4),
        "rk4:rk4_step=td-interp": ("rate", 2, 1, 2),
        "miller:step=0.03": ("increment", 3, 30, None),
        "panov:step=0.02": ("increment", 2, 20, None),
    }
    for text, (kind, need, period, order) in facts.items():
        s = AlgorithmSpec.parse(text)
        law = s.drift_law()
        assert (s.input_kind, s.min_samples, (law.order if law else None)) == (
            kind, need, order), text
        assert s.update_period(h) == pytest.approx(period * h, rel=1e-15), text


def test_drift_law_is_table1_for_the_optimal_sets():
    from strapdown.analysis import table1_prediction

    for n in range(1, 7):
        law = AlgorithmSpec("rotvec", subsamples=n).drift_law()
        assert law.predict(0.01, 2.0, 1e-3) == table1_prediction(0.01, 2.0, 1e-3, n)


def test_run_dispatches_on_the_record_kind():
    motion = ClassicalConing(math.radians(1.0), 2 * math.pi)
    h = 1e-3
    inc = sensors.increments(motion, h, 300)
    rates = sensors.rate_samples(motion, h, 301)
    q0 = motion.attitude(0.0)
    sol = AlgorithmSpec.parse("rotvec:N=3").run(inc, q0=q0)
    assert sol.q.shape == (101, 4) and sol.t[0] == 0.0
    sol = AlgorithmSpec.parse("rate-three:structure=sliding").run(rates, q0=q0)
    assert sol.q.shape[0] == 301
    with pytest.raises(ValueError, match="rotvec takes increments; this log holds rates"):
        AlgorithmSpec.parse("rotvec").run(rates)
    with pytest.raises(ValueError, match="rk4 takes rate samples; this log holds increments"):
        AlgorithmSpec.parse("rk4").run(inc)
    # the explicit entry points agree with run(record)
    np.testing.assert_array_equal(
        AlgorithmSpec.parse("rk4").run_rates(rates.t, rates.data, q0=q0).q,
        AlgorithmSpec.parse("rk4").run(rates, q0=q0).q)
    with pytest.raises(ValueError, match="takes increments"):
        AlgorithmSpec.parse("rotvec").run_rates(rates.t, rates.data)


def test_specs_are_frozen_and_hashable():
    s = AlgorithmSpec.parse("rotvec:N=2")
    with pytest.raises(AttributeError):
        s.subsamples = 3  # type: ignore[misc]
    assert len({s, AlgorithmSpec.parse("rotvec:N=2")}) == 1


@pytest.mark.parametrize("text", ["rate-single", "rate-three", "rate-three:structure=sliding",
                                  "rk4", "rotvec:N=3"])
def test_every_filter_propagation_is_described(text):
    p = AlgorithmSpec.parse(text).propagation()
    assert {"is_rate", "offsets", "weights", "pi", "pj", "pc", "stride", "span", "end_off",
            "lag", "start_c", "rk4"} == set(p)


@pytest.mark.parametrize("text", ["rotvec:N=3:structure=realtime", "rk4:rk4_step=td-interp",
                                  "miller:step=0.01"])
def test_filter_refuses_what_it_cannot_propagate(text):
    with pytest.raises(ValueError):
        AlgorithmSpec.parse(text).propagation()
