"""``strapdown evaluate --motion coning-force``: a body coning in a constant specific force,
the rectified velocity-error rate against the coning-in-force law (arbitrary precision and
float64), the JSON record and text, bad input."""

from __future__ import annotations

import json
import math

import pytest

from strapdown import InputError
from strapdown.analysis.evaluate import MOTIONS, EvaluationConfig, run_evaluation
from strapdown.cli import main

SMALL = dict(motion="coning-force", half_angle_deg=1e-8, cone_rate_hz=1.0, accel_amplitude=9.8,
             sample_rate_hz=60.0, duration=3.0, precision=40)


@pytest.mark.parametrize(("n", "structure", "order", "c"),
                         [(3, "conventional", 6, -29 / 840), (3, "single-chain", 4, 1 / 120)])
def test_law_against_measurement_in_mpmath(n, structure, order, c):
    # the law −c a² f (Ωh)^order along the cone axis (navigation x), c from the designer's
    # derivation (tests/design), measured on exact increments in 40 digits
    ev = run_evaluation(EvaluationConfig.of(subsamples=n, structure=structure, **SMALL))
    d = ev.to_dict()
    law = -c * math.radians(1e-8) ** 2 * 9.8 * (2 * math.pi / 60) ** order
    assert d["predicted_velocity_error_rate_m_s2"][0] == pytest.approx(law, rel=1e-12)
    assert d["velocity_error_rate_m_s2"][0] / law == pytest.approx(1.0, abs=0.02)
    assert d["velocity_rate_over_law"] == pytest.approx(1.0, abs=0.02)
    assert d["velocity_set"] == ("coning-force" if structure == "conventional" else "classical")


def test_float64_at_two_degrees_beats_the_two_sample_set():
    kw = dict(SMALL, half_angle_deg=2.0, cone_rate_hz=5.0, sample_rate_hz=100.0,
              duration=20.0, precision=None)
    rate = {n: run_evaluation(EvaluationConfig.of(subsamples=n, **kw)).to_dict()[
        "velocity_error_rate_m_s2"][0] for n in (2, 3)}
    assert "coning-force" in MOTIONS
    assert abs(rate[3]) < 0.1 * abs(rate[2])


def test_cli_json_and_text(capsys):
    args = ["evaluate", "--motion", "coning-force", "--half-angle-deg", "2", "--cone-rate-hz",
            "5", "--accel-amplitude", "9.8", "--sample-rate-hz", "100", "--duration", "4",
            "--subsamples", "3"]
    assert main([*args, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["motion"] == "coning-force" and d["half_angle_deg"] == 2.0
    assert d["force_along_cone_axis_m_s2"] == 9.8 and d["samples"] == 399
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "coning in a force: a = 2°, 5 Hz, f = 9.8 m/s² along the cone axis" in out
    assert "(cone axis, navigation x)" in out and "velocity set coning-force" in out


@pytest.mark.parametrize(("change", "message"), [
    ({"algorithm": "rk4"}, "increment velocity algorithms"),
    ({"half_angle_deg": 95.0}, "within ±90°"),
    ({"cone_rate_hz": 0.0}, "non-zero"),
    ({"accel_amplitude": math.inf}, "must be finite"),
    ({"cone_rate_hz": 40.0}, "Nyquist"),
    ({"precision": 10}, "at least 17 digits"),
])
def test_bad_input_is_refused(change, message):
    with pytest.raises((InputError, ValueError), match=message):
        run_evaluation(EvaluationConfig.of(**dict(SMALL, **change)))
