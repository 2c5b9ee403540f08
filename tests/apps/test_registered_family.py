"""A family registered from outside appears everywhere with no other edit (issue 26).

A throw-away rate family — the one-sample rectangle rule ``ΔΦ = td ω_k``, nothing but a
:class:`~strapdown.algorithms.rate.WindowedRateFamily` with its window — is registered by a
plug-in script (:func:`strapdown.algorithms.spec.register`) before the command line runs, in
a subprocess so the registry of this test session stays as shipped. Each command must then
list it, run it and write its result: ``evaluate``, ``run``, ``compare``, ``sweep``,
``advise``, the AHRS's propagation (``ahrs``), ``export-c`` and the navigation (``nav
--algorithm``, through the family's velocity counterpart).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

NAME = "rect-test"
PLUGIN = textwrap.dedent(f'''
    import sys
    from fractions import Fraction

    from strapdown.algorithms import spec
    from strapdown.algorithms.coning import WindowedAlgorithm
    from strapdown.algorithms.rate import WindowedRateFamily


    class Rectangle(WindowedRateFamily):
        """The rectangle rule over [t_k, t_k+1]: no quadrature beyond ω_k, no coning term."""

        name = "{NAME}"
        reference = "throw-away test family"

        def coefficient_names(self):
            return ("derived",)

        def windowed(self, s):
            return WindowedAlgorithm("rate", 1, (0, 1), (Fraction(1), Fraction(0)), (), (),
                                     "{NAME}")


    spec.register(Rectangle())
    from strapdown.cli import main

    sys.exit(main(sys.argv[1:]))
''')


@pytest.fixture(scope="module")
def plugin(tmp_path_factory) -> tuple[Path, Path]:
    """The plug-in script and a directory with a 2 s, 200 Hz rate log of coning."""
    d = tmp_path_factory.mktemp("plugin")
    script = d / "plugin.py"
    script.write_text(PLUGIN)
    t = np.arange(401) / 200.0
    w = np.column_stack([0.2 * np.cos(2 * np.pi * t), 0.2 * np.sin(2 * np.pi * t),
                         np.full_like(t, 0.05)])
    acc = np.tile([0.0, 0.0, 9.81], (t.size, 1))
    mag = np.tile([20.0, 0.0, -40.0], (t.size, 1))
    rows = np.column_stack([t, w])
    np.savetxt(d / "rates.csv", rows, delimiter=",", header="t,gx[rad/s],gy[rad/s],gz[rad/s]",
               comments="", fmt="%.17g")
    np.savetxt(d / "imu9.csv", np.column_stack([t, w, acc, mag]), delimiter=",",
               header="t,gx,gy,gz,ax,ay,az,mx,my,mz", comments="", fmt="%.17g")
    return script, d


def _cli(plugin: tuple[Path, Path], *args: str) -> subprocess.CompletedProcess[str]:
    script, d = plugin
    res = subprocess.run([sys.executable, str(script), *args], cwd=d, capture_output=True,
                         text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    return res


def test_evaluate_lists_and_runs_it(plugin):
    d = json.loads(_cli(plugin, "evaluate", "--algorithm", NAME, "--sample-rate-hz", "500",
                        "--duration", "1", "--json").stdout)
    assert d["algorithm"] == NAME
    assert d["update_period_s"] == pytest.approx(1 / 500)
    assert d["max_error_rad"] > 0  # a rectangle rule drifts under coning
    assert NAME in _cli(plugin, "evaluate", "--help").stdout


def test_run_writes_its_attitude(plugin):
    _, d = plugin
    _cli(plugin, "run", "--imu", "rates.csv", "--algorithm", NAME, "--out", "att.csv",
         "--no-progress")
    meta = json.loads((d / "att.csv.meta.json").read_text())
    assert NAME in json.dumps(meta)
    assert len((d / "att.csv").read_text().splitlines()) == 402  # header + 401 attitudes


def test_compare_and_sweep_tabulate_it(plugin):
    _, d = plugin
    _cli(plugin, "compare", "--algorithms", NAME, "rate-single", "--sample-rate-hz", "400",
         "--duration", "1", "--out", "cmp")
    assert (d / "cmp" / "summary.csv").read_text().splitlines()[1].startswith(NAME + ",")
    (d / "scn.toml").write_text(f'algorithms = ["{NAME}", "rate-single"]\n'
                                "[sensor]\nsample_rate_hz = 400.0\nduration = 1.0\n")
    _cli(plugin, "sweep", "scn.toml", "--out", "sw", "--workers", "1", "--format", "csv",
         "--no-progress")
    assert (d / "sw" / "results.csv").read_text().splitlines()[1].startswith(f"0,{NAME},")


def test_advise_ranks_it(plugin):
    out = json.loads(_cli(plugin, "advise", "--imu", "rates.csv", "--json", "--no-verify",
                          "--no-progress").stdout)
    assert NAME in [c["spec"] for c in out["candidates"]]


def test_ahrs_propagates_with_it(plugin):
    _, d = plugin
    for alg in (NAME, "rate-single"):
        _cli(plugin, "ahrs", "--imu", "imu9.csv", "--algorithm", alg, "--gyro-units", "rad/s",
             "--acc-units", "m/s2", "--out", f"ahrs-{alg}.csv")
    assert json.loads((d / f"ahrs-{NAME}.csv.meta.json").read_text())["algorithm"] == NAME
    # its own propagation, not another family's under its name
    assert (d / f"ahrs-{NAME}.csv").read_text() != (d / "ahrs-rate-single.csv").read_text()


def test_export_c_generates_it(plugin):
    _, d = plugin
    _cli(plugin, "export-c", "--algorithm", NAME, "--sample-rate-hz", "200", "--out", "c")
    source = (d / "c" / "sd_rect_test_conventional.c").read_text()
    assert "rect" in source and "sd_rect_test_conventional_update" in source


def test_nav_navigates_with_it(plugin):
    """Its velocity counterpart (the windowed dual, asked of the family) navigates a rate log:
    listed by nav --algorithm, one update per sample, its own increments."""
    _, d = plugin
    assert NAME in _cli(plugin, "nav", "--help").stdout
    t = np.arange(401) / 200.0
    w = np.column_stack([0.2 * np.cos(2 * np.pi * t), 0.2 * np.sin(2 * np.pi * t),
                         np.full_like(t, 0.05)])
    f = np.tile([0.0, 0.0, -9.81], (t.size, 1))
    np.savetxt(d / "nav.csv", np.column_stack([t, w, f]), delimiter=",", comments="",
               header="t,gx[rad/s],gy[rad/s],gz[rad/s],ax[m/s^2],ay[m/s^2],az[m/s^2]",
               fmt="%.17g")
    for alg in (NAME, "rate-single"):
        _cli(plugin, "nav", "--imu", "nav.csv", "--algorithm", alg, "--init-lat", "45",
             "--init-lon", "7", "--init-height", "300", "--no-progress", "--out",
             f"nav-{alg}.csv")
    meta = json.loads((d / f"nav-{NAME}.csv.meta.json").read_text())
    assert meta["algorithm"] == NAME and meta["outputs"] == 400  # an update every sample
    rows = np.loadtxt(d / f"nav-{NAME}.csv", delimiter=",", skiprows=1)
    assert rows.shape[0] == 401 and np.all(np.isfinite(rows))
    assert (d / f"nav-{NAME}.csv").read_text() != (d / "nav-rate-single.csv").read_text()
