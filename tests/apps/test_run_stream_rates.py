"""`strapdown run` on a .npy rate log with uniform stamps streams (RateStream, the file read
in blocks): the same bytes and sidecar as the whole-record route for every rate algorithm,
O(1) memory, and the whole-record route for every log it cannot vouch for. Also
--init-attitude and the summary's peak rate and total rotation."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import strapdown.apps.run as run_mod
from strapdown.algorithms.spec import AlgorithmSpec
from strapdown.apps.run import initial_attitude, run_log
from strapdown.cli import main
from strapdown.rotation.quaternion import quat_multiply

RATE_ALGORITHMS = [("rate-single", "conventional"), ("rate-three", "conventional"),
                   ("rate-three", "sliding"), ("rate-two", "conventional"),
                   ("rk4", "conventional")]


def _log(n, t0=3.5, td=2.5e-3, seed=0):
    rng = np.random.default_rng(seed)
    t = t0 + np.arange(n) * td
    w = np.column_stack([2 * np.sin(9 * t), np.cos(5 * t), np.full(n, 0.7)])
    return np.column_stack([t, w + rng.normal(size=(n, 3)) * 0.05])


def _both(tmp_path, monkeypatch, data, out="a.csv", **kw):
    """The streamed run and the whole-record run of the same .npy log: (files, sidecars)."""
    np.save(tmp_path / "log.npy", data)
    kw = {"kind": "rate", "units": "rad/s", **kw}
    streamed = run_log(tmp_path / "log.npy", tmp_path / f"s_{out}", **kw)
    with monkeypatch.context() as m:
        m.setattr(run_mod, "_rate_scan", lambda *a: None)
        whole = run_log(tmp_path / "log.npy", tmp_path / f"w_{out}", **kw)
    return ((tmp_path / f"s_{out}").read_bytes(), (tmp_path / f"w_{out}").read_bytes(),
            streamed, whole)


def _same_meta(a, b):
    # the whole-record route reports the sensor clock fitted to every stamp
    # (strapdown.io.timing); the streamed one the period the algorithm ran on and the
    # stamps' deviation from that grid
    drop = ("streamed", "time_base", "jitter_periods", "sample_period_s", "update_period_s",
            "timing")
    assert a["sample_period_s"] == pytest.approx(b["sample_period_s"], rel=1e-9)
    assert {k: v for k, v in a.items() if k not in drop} == {
        k: v for k, v in b.items() if k not in drop}


@pytest.mark.parametrize(("algorithm", "structure"), RATE_ALGORITHMS)
@pytest.mark.parametrize("chunk", [997, 4096])
def test_streamed_is_bit_identical_to_the_whole_record_run(tmp_path, monkeypatch, algorithm,
                                                           structure, chunk):
    monkeypatch.setattr(run_mod, "CHUNK", chunk)  # many chunk boundaries in a short log
    s, w, ms, mw = _both(tmp_path, monkeypatch, _log(10_007), algorithm=algorithm,
                         structure=structure, q0=[0.9, 0.1, -0.3, 0.2])
    assert ms["streamed"] and not mw["streamed"]
    assert s == w
    _same_meta(ms, mw)


@pytest.mark.parametrize(("extra", "out"), [
    ({"algorithm": "rk4", "on_gap": "split", "angles": "cone"}, "a.csv"),
    ({"units": "deg/s", "saturation": 140.0}, "a.csv"),
    ({"structure": "sliding"}, "a.npz"),
])
def test_options_streamed_the_same(tmp_path, monkeypatch, extra, out):
    monkeypatch.setattr(run_mod, "CHUNK", 1000)
    data = _log(5003)
    if extra.get("units") == "deg/s":
        data[:, 1:] = np.degrees(data[:, 1:])
        data[[10, 4000], 1] = 150.0  # saturated rows 11 and 4001
    s, w, ms, mw = _both(tmp_path, monkeypatch, data, out=out, **extra)
    assert ms["streamed"] and s == w
    _same_meta(ms, mw)
    if "saturation" in extra:
        assert ms["saturated"]["first_rows"] == [11, 4001]


@pytest.mark.parametrize("layout", ["fortran", "float32", "big-endian"])
def test_any_npy_layout_streams_the_same(tmp_path, monkeypatch, layout):
    monkeypatch.setattr(run_mod, "CHUNK", 777)
    data = _log(3001, t0=0.0, td=2.0**-9)  # stamps exact in float32 too
    data = {"fortran": np.asfortranarray(data), "float32": data.astype(np.float32),
            "big-endian": data.astype(">f8")}[layout]
    s, w, ms, _ = _both(tmp_path, monkeypatch, data)
    assert ms["streamed"] and s == w


@pytest.mark.parametrize(("change", "extra"), [
    ("jitter", {}), ("none", {"sample_rate_hz": 400.0}), ("jitter", {"resample": True}),
    ("held", {}), ("epoch", {}), ("none", {"units": "deg/s", "accept_unit_warning": True}),
    ("nan", {}),
])
def test_logs_it_cannot_vouch_for_go_whole(tmp_path, monkeypatch, change, extra):
    data = _log(3000)
    if change == "jitter":
        data[:, 0] += np.random.default_rng(1).uniform(-1, 1, 3000) * 2.5e-4
    elif change == "held":
        data[1::2, 1:] = data[0::2, 1:]  # a logger at twice the sensor's rate
    elif change == "epoch":
        data[:, 0] += 1.7e9
    elif change == "nan":
        data[1500, 2] = np.nan
    if extra.get("units") == "deg/s":  # tiny rates in deg/s: the unit warning
        data[:, 1:] *= 1e-6
    np.save(tmp_path / "log.npy", data)
    kw = {"kind": "rate", "units": "rad/s", **extra}
    if change == "nan":
        with pytest.raises(run_mod.InputError, match="NaN or infinity in data row 1501"):
            run_log(tmp_path / "log.npy", tmp_path / "a.csv", **kw)
        return
    meta = run_log(tmp_path / "log.npy", tmp_path / "a.csv", **kw)
    assert not meta["streamed"]


def test_streamed_equals_run_rates(tmp_path):
    data = _log(2000)
    np.save(tmp_path / "log.npy", data)
    meta = run_log(tmp_path / "log.npy", tmp_path / "a.csv", kind="rate", units="rad/s",
                   algorithm="rk4", angles="none")
    got = np.loadtxt(tmp_path / "a.csv", delimiter=",", skiprows=1)
    one = AlgorithmSpec("rk4").run_rates(data[:, 0], data[:, 1:])
    assert meta["streamed"] and np.array_equal(got[:, 1:], one.q)
    assert np.array_equal(got[:, 0], one.t)


_PEAK = """
import sys
def peak():
    with open("/proc/self/status") as f:
        return next(int(x.split()[1]) for x in f if x.startswith("VmHWM")) / 1024.0
from strapdown.cli import main
assert main(sys.argv[1:]) == 0
print("PEAK", peak())
"""


def _peak_mb(*args):
    # VmHWM: the child's own peak (ru_maxrss of a child includes its parent's RSS at fork)
    out = subprocess.run([sys.executable, "-c", _PEAK, *args], capture_output=True,
                         text=True, check=True).stdout
    return float(out.split("PEAK")[-1])


# One rate algorithm and the increment route: RateStream runs rk4 and rate-three through
# the same chunk loop (buffer, carried attitude, per-chunk output), only the kernel it calls
# per chunk differs, and both are checked bit-identical to the whole-record run above; rk4
# here cost 5 s (20 s on a loaded machine) for no other line of the stream.
@pytest.mark.parametrize(("kind", "units", "algorithm"), [
    ("--rates", "rad/s", "rate-three"), ("--increments", "rad", "rotvec")])
def test_a_long_npy_log_streams_in_constant_memory(tmp_path, kind, units, algorithm):
    n = 2_000_000  # 64 MB of log; the acceptance's 2e7 (640 MB) was measured by hand
    t = np.arange(n) * 1e-3
    data = np.empty((n, 4))
    data[:, 0] = t
    data[:, 1] = 0.3 * np.sin(t)
    data[:, 2] = 0.2
    data[:, 3] = -0.1
    if kind == "--increments":
        data[:, 1:] *= 1e-3
    np.save(tmp_path / "log.npy", data)
    np.save(tmp_path / "short.npy", data[:1000])
    del data, t

    def peak(log):
        return _peak_mb("run", "--imu", str(tmp_path / log), kind, "--units", units,
                        "--algorithm", algorithm, "--angles", "none", "--out",
                        str(tmp_path / f"{log}.csv"))

    # the baseline: the same command on a short log (imports and compiled kernels loaded)
    base, run = peak("short.npy"), peak("log.npy")
    meta = json.loads((tmp_path / "log.npy.csv.meta.json").read_text())
    assert meta["samples"] == n and meta["streamed"]
    assert run - base < 32.0, (run, base)  # the whole log would be 64 MB, its result 80


def test_init_attitude_yaw_pitch_roll_or_quaternion(tmp_path, capsys):
    np.save(tmp_path / "log.npy", _log(601))
    args = ["run", "--imu", str(tmp_path / "log.npy"), "--rates", "--units", "rad/s",
            "--angles", "ypr"]
    assert main([*args, "--out", str(tmp_path / "i.csv")]) == 0
    assert main([*args, "--init-attitude", "30", "-10", "5", "--out",
                 str(tmp_path / "y.csv")]) == 0
    assert main([*args, "--init-attitude", "2", "0", "0", "2", "--out",
                 str(tmp_path / "q.csv")]) == 0
    ident = np.loadtxt(tmp_path / "i.csv", delimiter=",", skiprows=1)
    ypr = np.loadtxt(tmp_path / "y.csv", delimiter=",", skiprows=1)
    quat = np.loadtxt(tmp_path / "q.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(ypr[0, 5:8], [30, -10, 5], atol=1e-12)
    q0 = initial_attitude([30, -10, 5])
    np.testing.assert_allclose(ypr[:, 1:5], quat_multiply(q0, ident[:, 1:5]), atol=1e-12)
    np.testing.assert_allclose(quat[0, 1:5], [math.sqrt(0.5), 0, 0, math.sqrt(0.5)],
                               atol=1e-15)
    meta = json.loads((tmp_path / "y.csv.meta.json").read_text())
    assert meta["initial_attitude"]["given"]
    np.testing.assert_allclose(meta["initial_attitude"]["ypr_deg"], [30, -10, 5], atol=1e-9)
    assert not json.loads((tmp_path / "i.csv.meta.json").read_text())[
        "initial_attitude"]["given"]
    assert "n: the frame of the initial attitude" in meta["frame"]


@pytest.mark.parametrize(("values", "message"), [
    (["1", "2"], "takes 3 numbers"), (["400", "0", "0"], "within ±360"),
    (["0", "0", "0", "0"], "non-zero norm"), (["nan", "0", "0"], "finite")])
def test_bad_init_attitude_is_refused(tmp_path, capsys, values, message):
    np.save(tmp_path / "log.npy", _log(100))
    with pytest.raises(SystemExit) as exc:
        main(["run", "--imu", str(tmp_path / "log.npy"), "--rates", "--units", "rad/s",
              "--init-attitude", *values, "--out", str(tmp_path / "a.csv")])
    assert exc.value.code == 2 and message in capsys.readouterr().err
    assert not (tmp_path / "a.csv").exists()


def test_summary_shows_peak_rate_and_total_rotation(tmp_path, capsys):
    """A rad/s log declared as deg/s: the summary says 'max 0.5 deg/s' (57x too slow)."""
    n = 2101  # 2.1 s, 700 rate-three updates
    t = np.arange(n) * 1e-3
    data = np.column_stack([t, np.full(n, 0.5), np.zeros(n), np.zeros(n)])  # 0.5 rad/s
    np.save(tmp_path / "log.npy", data)
    for units, peak, total in (("deg/s", 0.5, 1.05), ("rad/s", math.degrees(0.5),
                                                      math.degrees(1.05))):
        assert main(["run", "--imu", str(tmp_path / "log.npy"), "--rates", "--units", units,
                     "--out", str(tmp_path / "a.csv")]) == 0
        out = capsys.readouterr().out
        assert f"max {peak:.3g} deg/s, total rotation {total:.4g} deg" in out
        meta = json.loads((tmp_path / "a.csv.meta.json").read_text())
        assert meta["peak_rate_deg_s"] == pytest.approx(peak, rel=1e-12)
        assert meta["total_rotation_deg"] == pytest.approx(total, rel=1e-9)


def test_increment_log_summary(tmp_path):
    h, n = 1e-3, 3000
    data = np.column_stack([np.arange(1, n + 1) * h, np.full(n, 0.2 * h), np.zeros(n),
                            np.zeros(n)])
    np.save(tmp_path / "inc.npy", data)
    meta = run_log(tmp_path / "inc.npy", tmp_path / "a.csv", kind="increment", units="rad")
    assert meta["peak_rate_deg_s"] == pytest.approx(math.degrees(0.2), rel=1e-9)
    assert meta["total_rotation_deg"] == pytest.approx(math.degrees(0.2 * n * h), rel=1e-9)
