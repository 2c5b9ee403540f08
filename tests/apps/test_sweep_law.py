"""`strapdown sweep`: a table with the law's drift carries measured/law and its meaning."""

from __future__ import annotations

import csv
import textwrap

from strapdown.apps.sweep import load_scenario, sweep

SCENARIO = textwrap.dedent("""
    algorithms = ["rotvec:N=2", "rotvec:N=3:structure=realtime"]
    metrics = [{metrics}]
    seed = 5

    [motion]
    motion = "coning"
    half_angle_deg = 1.0

    [sensor]
    sample_rate_hz = 600.0
    duration = 20.0

    [grid]
    "gyro.white_noise" = [0.0, 1e-5]
""")


def test_law_columns_follow_the_prediction(tmp_path):
    p = tmp_path / "scn.toml"
    p.write_text(SCENARIO.format(metrics='"max_error_rad"'))
    assert load_scenario(p).metrics == ("max_error_rad",)  # no law, no law columns
    p.write_text(SCENARIO.format(metrics='"cone_axis_drift_rad_s", "predicted_drift_rad_s"'))
    assert load_scenario(p).metrics[-2:] == ("measured_over_law", "law_status")
    res = sweep(p, tmp_path / "out", workers=1, formats=("csv",))
    with open(res.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    got = [(r["algorithm"], r["gyro.white_noise"], r["law_status"]) for r in rows]
    assert got == [("rotvec:N=2", "0.0", "resolved"),
                   ("rotvec:N=3:structure=realtime", "0.0", "higher order in a dominates"),
                   ("rotvec:N=2", "1e-05", "gyro errors included"),
                   ("rotvec:N=3:structure=realtime", "1e-05", "gyro errors included")]
    r = rows[0]
    assert float(r["measured_over_law"]) == (float(r["cone_axis_drift_rad_s"])
                                             / float(r["predicted_drift_rad_s"]))
