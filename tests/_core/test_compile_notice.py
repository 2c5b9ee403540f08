"""The first-use compile notice: said once when numba compiles our kernels, never when its
cache is warm. Each run is a fresh process with its own NUMBA_CACHE_DIR, so "cold" is real."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

from strapdown._core.compile_notice import MESSAGE

PROBE = textwrap.dedent("""
    from numba import njit

    @njit(cache=True)
    def inc(x):
        return x + 1.0

    @njit(cache=True)
    def twice(x):
        return inc(inc(x))
""")

DRIVER = textwrap.dedent("""
    import sys
    sys.path.insert(0, sys.argv[1])
    from strapdown._core.compile_notice import notice
    said = []
    with notice(said.append, package=sys.argv[2]):
        import probe_kernels
        probe_kernels.twice(1.0)
        probe_kernels.inc(2.0)
    probe_kernels.twice(3)  # a new signature, compiled outside the block: not announced
    print(len(said), *said, sep="|")
""")


def _env(cache) -> dict:
    return {**os.environ, "NUMBA_CACHE_DIR": str(cache)}


def _probe(tmp_path, package="probe_kernels") -> list[str]:
    (tmp_path / "probe_kernels.py").write_text(PROBE)
    out = subprocess.run([sys.executable, "-c", DRIVER, str(tmp_path), package],
                         env=_env(tmp_path / "cache"), capture_output=True, text=True,
                         check=True).stdout
    return out.strip().split("|")


def test_notice_once_on_a_cold_cache_and_never_when_warm(tmp_path):
    assert _probe(tmp_path) == ["1", MESSAGE]  # two kernels compiled, one line
    assert _probe(tmp_path) == ["0"]  # loaded from numba's cache: silent


def test_notice_ignores_other_packages(tmp_path):
    assert _probe(tmp_path, package="strapdown") == ["0"]  # cold, but not ours


def _strapdown(args, cache):
    return subprocess.run([sys.executable, "-m", "strapdown.cli", *args], env=_env(cache),
                          capture_output=True, text=True, timeout=600)


def test_cli_says_it_compiles_on_first_use_only(tmp_path):
    args = ["evaluate", "--duration", "0.2", "--sample-rate-hz", "600"]
    cold = _strapdown(args, tmp_path / "cache")
    assert cold.returncode == 0 and cold.stderr == MESSAGE + "\n"
    warm = _strapdown(args, tmp_path / "cache")
    assert warm.returncode == 0 and warm.stderr == "" and warm.stdout == cold.stdout


def test_sweep_workers_say_it_once_for_the_pool(tmp_path):
    # Four cases of the rotation-vector family: both workers start on one at once and both
    # compile its kernels cold. rk4 and rate-three cost seconds of compiling and made the
    # check no stricter: with a flag per worker planted, this scenario printed the line
    # twice in 3 runs of 3, the four-family one in 2 of 3.
    scn = tmp_path / "scn.toml"
    scn.write_text('algorithms = ["rotvec:N=2", "rotvec:N=3"]\n'
                   '[sensor]\nsample_rate_hz = 600.0\nduration = 0.5\n'
                   '[grid]\ncone_rate_hz = [1.0, 2.0]\n')
    res = _strapdown(["sweep", str(scn), "--out", str(tmp_path / "out"), "--workers", "2",
                      "--format", "csv", "--no-progress"], tmp_path / "cache")
    assert res.returncode == 0, res.stderr
    assert res.stderr.count(MESSAGE) == 1
