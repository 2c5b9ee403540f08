"""Scenario files that used to crash, pass validation and fail at run time, or grow without
bound (issue 16) — each an InputError naming the file and the key — and sweeps whose grid
points share a configuration: computed once, every row labelled with its own grid point,
results.csv byte-identical with one worker, the pool and Dask."""

from __future__ import annotations

import csv
import re
import textwrap

import pytest

from fuzz import corpus
from strapdown import InputError
from strapdown.apps.sweep import cases, load_scenario, sweep

EXPECTED = {
    "toml_gyro_5": r"\[gyro\] must be a table, got 5",
    "toml_grid_float": r"\[grid\] must be a table, got 1.0",
    "toml_string_angle": r"\[motion\]: half_angle_deg must be a finite number, got '1.0'",
    "toml_list_noise": r"white_noise must be a finite number, got \[1e-06\]",
    "toml_nan_noise": "white_noise must be a finite number, got nan",
    "toml_rate_1e308": "gives 5e[+]307 samples; at most 1e[+]08 per evaluation",
    "toml_nested": "nested too deeply to be a scenario",
    "toml_coefficients_table": r"coefficients must be a string, got \{'a': 1\}",
    "toml_half_angle_1e308": "half angle must be within ±180°",
    "toml_grid_1e12": "the grid has more than 100000 cases",
    "toml_grid_bad_value": "spin_rate_dps must be a finite number, got 'fast'",
    "toml_bad_utf8": "not UTF-8 text",
    "toml_not_toml": "not valid TOML",
    "toml_seed_float": "seed must be a non-negative integer, got 1.5",
    "toml_misalignment": "misalignment must be a 3×3 list of lists, got 3",
    "toml_duration_huge": "gives 2e[+]14 samples",
    "toml_krylov_string": "krylov_rates must be a list of three finite numbers",
    "toml_cone_rate_huge": r"the cone rate turns .* rad in one sample at 200 Hz; at most π",
}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("corpus")
    return {e.name: e for e in corpus.build(d) if e.fmt == "toml"}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_bad_scenarios_are_refused_before_anything_runs(files, name, tmp_path):
    path = files[name].path
    with pytest.raises(InputError) as exc:
        load_scenario(path)
    text = str(exc.value)
    assert re.search(EXPECTED[name], text), text
    assert str(path) in text and len(text) <= 500
    with pytest.raises(InputError):
        sweep(path, tmp_path / "out", workers=1, formats=["csv"])
    assert not (tmp_path / "out").exists()  # refused before the output directory


def test_valid_scenarios_load(files):
    assert len(cases(load_scenario(files["toml_valid"].path))) == 1
    assert load_scenario(files["toml_bias_list"].path).gyro["bias"] == [1e-6, 0.0, 0.0]


def test_the_cli_gives_one_line_and_exit_2(files, tmp_path, capsys):
    from strapdown.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["sweep", str(files["toml_nested"].path), "--out", str(tmp_path / "o")])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "nested too deeply" in err


DUPLICATES = textwrap.dedent("""
    algorithms = ["rotvec:N=3", "rate-three"]
    metrics = ["max_error_rad", "samples"]

    [motion]
    motion = "coning"
    half_angle_deg = 1.0

    [sensor]
    sample_rate_hz = 400.0
    duration = 1.0

    [grid]
    subsamples = [2, 3, 4]          # rotvec:N=3 sets N itself; rate-three has none
    cone_rate_hz = [2.0, 2.0, 5.0]  # a repeated value
""")


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_duplicate_configurations_are_computed_once_and_labelled_for_every_point(tmp_path):
    scn = tmp_path / "dup.toml"
    scn.write_text(DUPLICATES)
    cs = cases(load_scenario(scn))
    # rotvec:N=3: one configuration per distinct cone rate; rate-three keeps the grid's
    # subsamples in its (otherwise equal) configuration: 2 × (1 + 3) results for 18 cases
    assert len(cs) == 3 * 3 * 2 and len({c.key for c in cs}) == 8
    res = sweep(scn, tmp_path / "one", workers=1, formats=["csv"])
    assert (res.total, res.computed) == (18, 8)
    rows = _rows(res.csv)
    assert [int(r["case"]) for r in rows] == list(range(18))
    grid = [(s, c) for s in ("2", "3", "4") for c in ("2.0", "2.0", "5.0")]
    assert [(r["subsamples"], r["cone_rate_hz"]) for r in rows[::2]] == grid
    assert [r["algorithm"] for r in rows] == ["rotvec:N=3", "rate-three"] * 9
    by_config = {}
    for c, r in zip(cs, rows, strict=True):  # the same configuration, the same numbers
        metrics = (r["max_error_rad"], r["samples"])
        assert by_config.setdefault(c.key, metrics) == metrics
    assert rows[0]["max_error_rad"] != rows[4]["max_error_rad"]  # 2 Hz and 5 Hz differ
    again = sweep(scn, tmp_path / "one", workers=1, formats=["csv"])
    assert (again.skipped, again.computed) == (18, 0)
    assert again.csv.read_bytes() == res.csv.read_bytes()


def test_duplicate_sweeps_are_identical_with_one_worker_the_pool_and_dask(tmp_path):
    distributed = pytest.importorskip("distributed")
    scn = tmp_path / "dup.toml"
    scn.write_text(DUPLICATES)
    one = sweep(scn, tmp_path / "one", workers=1, formats=["csv"])
    pool = sweep(scn, tmp_path / "pool", workers=2, formats=["csv"])
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=":0") as cluster:
        address = cluster.scheduler_address.removeprefix("tcp://")
        dask = sweep(scn, tmp_path / "dask", scheduler=f"dask://{address}", formats=["csv"])
    assert one.csv.read_bytes() == pool.csv.read_bytes() == dask.csv.read_bytes()
    assert pool.computed == dask.computed == 8


def test_a_grid_mixing_kinds_is_refused_before_any_case_runs(tmp_path):
    # a scalar and a list in one grid column: Parquet refused it after results.csv was written
    scn = tmp_path / "s.toml"
    scn.write_text(textwrap.dedent("""
        algorithms = ["rotvec:N=2"]
        metrics = ["max_error_rad"]
        seed = 3
        [sensor]
        sample_rate_hz = 200.0
        duration = 0.5
        [grid]
        "gyro.bias" = [1e-6, [1e-6, 0.0, 0.0]]
        spin_rate_dps = [0, 1.5]
    """))
    with pytest.raises(InputError, match=r"grid 'gyro\.bias' mixes list and number values"):
        sweep(scn, tmp_path / "o", workers=1)
    assert not (tmp_path / "o").exists()
    scn.write_text(scn.read_text().replace("[1e-6, [1e-6, 0.0, 0.0]]", "[1e-6, 2e-6]"))
    pytest.importorskip("pyarrow")
    res = sweep(scn, tmp_path / "o", workers=1)  # ints and floats in one column are numbers
    assert res.parquet is not None and len(_rows(res.csv)) == 4
