"""The fuzz suite in ``make test``: hypothesis-generated hostile files through every reader
(only success or an InputError, bounded and naming the file), and the quick profile of the
campaign (tests/fuzz/campaign.py: the corpus and mutations through the API in worker
processes and through ``python -m strapdown.cli``, under the memory cap and time limit).

``STRAPDOWN_FUZZ_EXAMPLES`` sets the examples per strategy (``make fuzz``: 2000).
"""

from __future__ import annotations

import os
import warnings

import pytest
from hypothesis import HealthCheck, given, settings

from fuzz import file_strategies as fs
from fuzz.targets import API
from strapdown import InputError

EXAMPLES = int(os.environ.get("STRAPDOWN_FUZZ_EXAMPLES", "40"))
_SETTINGS = settings(max_examples=EXAMPLES, deadline=None, database=None,
                     suppress_health_check=[HealthCheck.function_scoped_fixture,
                                            HealthCheck.too_slow, HealthCheck.data_too_large])


def _through(fmt: str, data: bytes, tmp_path, names=None) -> None:
    """``data`` as a file through every API target of ``fmt``: success or an InputError."""
    path = tmp_path / f"input.{fmt}"
    path.write_bytes(data)
    for name, call in API[fmt]:
        if names is not None and name not in names:
            continue
        scratch = tmp_path / "scratch"
        scratch.mkdir(exist_ok=True)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                call(path, scratch)
            except InputError as exc:
                assert len(str(exc)) <= 500 and str(path) in str(exc), (name, str(exc))
                assert not any(scratch.rglob("*")), name  # nothing written on an error
        assert not [p for p in scratch.rglob(".*")], name  # never a temporary file left
        for p in sorted(scratch.rglob("*"), reverse=True):
            p.rmdir() if p.is_dir() else p.unlink()


@_SETTINGS
@given(data=fs.csv_files())
def test_csv(tmp_path, data):
    _through("csv", data, tmp_path, {"read_imu rate", "read_imu increment", "read_ahrs_log",
                                     "truth", "run rate"})


@_SETTINGS
@given(data=fs.npy_files())
def test_npy(tmp_path, data):
    _through("npy", data, tmp_path)


@_SETTINGS
@given(data=fs.npz_files())
def test_npz(tmp_path, data):
    _through("npz", data, tmp_path, {"read_imu rate", "truth", "nav"})


@_SETTINGS
@given(data=fs.mat_files())
def test_mat(tmp_path, data):
    _through("mat", data, tmp_path, {"read_imu rate", "read_broad", "read_ahrs_log"})


@_SETTINGS
@given(data=fs.toml_scenarios())
def test_toml(tmp_path, data):
    _through("toml", data, tmp_path, {"load_scenario"})


@pytest.mark.slow
def test_quick_campaign_has_no_failure():
    from fuzz.campaign import campaign, report

    tallies = campaign("quick", say=lambda _m: None)
    text = report(tallies)
    assert not any(t.failures for t in tallies.values()), text
    assert sum(t.cli_runs for t in tallies.values()) >= 6


def test_a_command_lines_peak_is_its_own_not_the_parents(tmp_path):
    """ru_maxrss of a child includes its parent's RSS at fork (Linux keeps it across exec):
    under a test session of ~750 MB every run seemed to peak there. The campaign measures
    the command's own VmHWM: a run started by a process holding 512 MB stays well below."""
    import numpy as np

    from fuzz import corpus
    from fuzz.campaign import PEAK_LIMIT_MB, run_cli
    from fuzz.targets import CLI

    imu = tmp_path / "log.csv"
    imu.write_bytes(corpus.valid_seeds(tmp_path)["csv"])
    (tmp_path / "out").mkdir()
    ballast = np.ones(512 * 2**20 // 8)  # resident: every page written
    rec = run_cli(CLI["csv"][0], imu, tmp_path / "out")
    assert ballast.sum() == ballast.size and rec["ok"] and rec["code"] == 0, rec
    assert 20.0 < rec["peak_mb"] < PEAK_LIMIT_MB, rec
