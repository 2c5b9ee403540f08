"""Reading logs, validation with row numbers, unit plausibility, `strapdown run`."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.io import savemat

from conftest import BROAD
from strapdown import InputError
from strapdown.algorithms.coning import coefficient_set
from strapdown.algorithms.structures import conventional, realtime
from strapdown.apps.run import run_log
from strapdown.cli import main
from strapdown.io import UnitWarning, read_imu
from strapdown.truth.motions import PureSpin, SpinConing


def _csv(path, t, g, names=("t", "gx", "gy", "gz")):
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for ti, gi in zip(t, g, strict=True):
            f.write(",".join(repr(float(v)) for v in (ti, *gi)) + "\n")


def test_deg_per_s_declared_as_rad_per_s_warns(tmp_path):
    t = np.arange(200) / 1000.0
    w = PureSpin(math.radians(1080.0)).rate(t)
    _csv(tmp_path / "log.csv", t, np.degrees(w))
    with pytest.warns(UnitWarning, match="more likely in degrees"):
        read_imu(tmp_path / "log.csv", kind="rate", units="rad/s")
    log = read_imu(tmp_path / "log.csv", kind="rate", units="deg/s")
    assert np.allclose(log.data, w, rtol=1e-14)


def test_duplicated_timestamp_fails_with_row_and_writes_nothing(tmp_path, capsys):
    """A duplicated stamp with different values is an error naming both rows and the option
    that resolves it (one with identical values is dropped: tests/io/test_timing.py)."""
    t = np.arange(10) / 100.0
    t[6] = t[5]
    w = np.zeros((10, 3))
    w[:, 0] = np.arange(10) * 0.01
    _csv(tmp_path / "log.csv", t, w)
    out = tmp_path / "att.csv"
    with pytest.raises(SystemExit) as exc:
        main(["run", "--imu", str(tmp_path / "log.csv"), "--rates", "--units", "rad/s",
              "--algorithm", "rk4", "--out", str(out)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "duplicated time stamp in data rows 6 and 7" in err
    assert "--duplicate-stamps first" in err
    assert not out.exists() and list(tmp_path.iterdir()) == [tmp_path / "log.csv"]


@pytest.mark.parametrize(("mutate", "msg"), [
    (lambda t, g: g.__setitem__((3, 1), np.nan), "NaN or infinity in data row 4"),
    (lambda t, g: t.__setitem__(5, 0.001), "non-monotonic time stamp in data row 6"),
])
def test_validation_rows(tmp_path, mutate, msg):
    t = np.arange(10) / 100.0
    g = np.zeros((10, 3))
    mutate(t, g)
    _csv(tmp_path / "log.csv", t, g)
    with pytest.raises(ValueError, match=msg):
        read_imu(tmp_path / "log.csv", kind="rate", units="rad/s")


def test_gaps_and_columns(tmp_path):
    t = np.r_[np.arange(10), np.arange(20, 30)] / 100.0
    _csv(tmp_path / "log.csv", t, np.zeros((20, 3)), names=("time", "a", "b", "c"))
    with pytest.raises(ValueError, match=r"no gyro columns in the header \['time', 'a'"):
        read_imu(tmp_path / "log.csv", kind="rate", units="rad/s")
    with pytest.raises(ValueError, match="not in the header"):
        read_imu(tmp_path / "log.csv", kind="rate", units="rad/s", columns=("t", "a", "b", "c"))
    log = read_imu(tmp_path / "log.csv", kind="rate", units="rad/s",
                   columns=("time", "a", "b", "c"))
    assert log.gaps == [11]


@pytest.mark.parametrize("structure", ["conventional", "realtime", "single-chain"])
def test_run_npy_streams_and_matches_one_shot(tmp_path, structure, monkeypatch):
    import strapdown.apps.run as run_mod

    monkeypatch.setattr(run_mod, "CHUNK", 777)  # many chunks
    m = SpinConing(0.05, 2 * math.pi, 20.0)
    h = 1e-3
    n = 3000
    edges = np.arange(n + 1) * h
    th = m.increments(edges)
    np.save(tmp_path / "log.npy", np.column_stack([edges[1:], th]))
    main(["run", "--imu", str(tmp_path / "log.npy"), "--increments", "--units", "rad",
          "--structure", structure, "--angles", "none", "--out", str(tmp_path / "a.csv")])
    got = np.loadtxt(tmp_path / "a.csv", delimiter=",", skiprows=1)
    cs = coefficient_set("table3", 3)
    if structure == "conventional":
        ref = conventional(th, cs, h=h)
    elif structure == "realtime":
        ref = realtime(th, cs, h=h)
    else:
        from strapdown.algorithms.structures import single_chain

        ref = single_chain(th, 3, h=h)
    assert np.array_equal(got[:, 1:5], ref.q)
    assert np.allclose(got[:, 0], ref.t, atol=1e-12)


def test_run_refuses_to_overwrite_input(tmp_path, capsys):
    np.save(tmp_path / "log.npy", np.zeros((5, 4)))
    with pytest.raises(SystemExit):
        main(["run", "--imu", str(tmp_path / "log.npy"), "--increments", "--units", "rad",
              "--out", str(tmp_path / "log.npy")])
    assert "must not be the input" in capsys.readouterr().err


def test_psins_mat_layout(tmp_path):
    n = 50
    t = np.arange(1, n + 1) * 0.01
    wm = np.tile([1e-4, 0, 0], (n, 1))
    savemat(tmp_path / "imu.mat", {"imu": np.column_stack([wm, np.zeros((n, 3)), t])})
    log = read_imu(tmp_path / "imu.mat", kind="increment", units="rad")
    assert np.allclose(log.data, wm) and log.h == pytest.approx(0.01)


@pytest.mark.skipif(BROAD is None, reason="BROAD data not found (set STRAPDOWN_BROAD)")
def test_broad_recording_reads_and_runs(tmp_path):
    path = BROAD / "07_undisturbed_fast_rotation_B.mat"
    log = read_imu(path, kind="rate", units="rad/s")
    assert log.h == pytest.approx(1 / 285.714, rel=1e-3)
    assert 5 < np.abs(log.data).max() < 40  # fast rotations, up to ~25 rad/s
    main(["run", "--imu", str(path), "--rates", "--units", "rad/s", "--algorithm", "rk4",
          "--angles", "none", "--out", str(tmp_path / "broad.npz")])
    with np.load(tmp_path / "broad.npz") as z:
        q = np.column_stack([z["qw"], z["qx"], z["qy"], z["qz"]])
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
    # the same recording in deg/s, declared as rad/s: the unit warning, then an error since
    # a sample turns the body by more than π (the log cannot be integrated)
    with pytest.warns(UnitWarning), pytest.raises(InputError, match="turns the body by"):
        read_imu(_as_degrees(path, tmp_path), kind="rate", units="rad/s")


def _as_degrees(path, tmp_path):
    from scipy.io import loadmat

    m = loadmat(path)
    out = tmp_path / "deg.mat"
    savemat(out, {"imu_gyr": np.degrees(m["imu_gyr"]), "sampling_rate": m["sampling_rate"]})
    return out


def test_header_declares_units_and_contradiction_fails(tmp_path):
    t = np.arange(50) / 100.0
    w = np.tile([0.5, -0.25, 0.125], (50, 1))
    _csv(tmp_path / "log.csv", t, np.degrees(w),
         names=("t[s]", "gx[deg/s]", "gy[deg/s]", "gz[deg/s]"))
    log = read_imu(tmp_path / "log.csv", kind="rate", units=None)
    assert np.allclose(log.data, w, rtol=1e-14)
    with pytest.raises(ValueError, match="contradict the header's 'deg/s'"):
        read_imu(tmp_path / "log.csv", kind="rate", units="rad/s")
    with pytest.raises(ValueError, match="a increment log needs one of"):
        read_imu(tmp_path / "log.csv", kind="increment", units=None)
    _csv(tmp_path / "plain.csv", t, w)
    with pytest.raises(ValueError, match="no units declared"):
        read_imu(tmp_path / "plain.csv", kind="rate", units=None)


def test_gap_policy_and_segments(tmp_path):
    t = np.r_[np.arange(10), np.arange(20, 30)] / 100.0
    _csv(tmp_path / "log.csv", t, np.zeros((20, 3)))
    with pytest.raises(ValueError, match=r"gap of 0\.11 s .* before data row 11"):
        read_imu(tmp_path / "log.csv", kind="rate", units="rad/s", on_gap="error")
    log = read_imu(tmp_path / "log.csv", kind="rate", units="rad/s")
    assert [(s.start, s.stop) for s in log.segments()] == [(0, 10), (10, 20)]


def test_run_split_at_gap_restarts_integration(tmp_path):
    # constant rate about x, 1 rad/s; a 0.1 s gap in the log. Split: each segment integrates
    # only its own samples, so the angle at the end is 18 samples × 0.01 s (not 0.29 s).
    t = np.r_[np.arange(10), np.arange(20, 30)] / 100.0
    _csv(tmp_path / "log.csv", t, np.tile([1.0, 0, 0], (20, 1)))
    out = tmp_path / "att.csv"
    main(["run", "--imu", str(tmp_path / "log.csv"), "--rates", "--units", "rad/s",
          "--algorithm", "rate-single", "--on-gap", "split", "--angles", "none",
          "--out", str(out)])
    a = np.genfromtxt(out, delimiter=",", names=True)
    assert set(a["segment"]) == {0.0, 1.0}
    angle = 2 * np.arctan2(a["qx"][-1], a["qw"][-1])
    assert angle == pytest.approx(0.18, rel=1e-12)
    # without splitting, rate algorithms refuse the gap and write nothing
    with pytest.raises(ValueError, match=r"1 gap\(s\) \(10 sample\(s\) missing on the fitted "
                       r"100 Hz clock\), the first of 0\.11 s before data row 11; "
                       "rate algorithms cannot bridge a gap: pass --on-gap split"):
        run_log(tmp_path / "log.csv", tmp_path / "b.csv", kind="rate", units="rad/s",
                algorithm="rate-single")
    assert not (tmp_path / "b.csv").exists() and not (tmp_path / "b.csv.meta.json").exists()


def test_saturation_is_reported(tmp_path, capsys):
    t = np.arange(30) / 100.0
    g = np.zeros((30, 3))
    g[[4, 17], 2] = 2000.0
    _csv(tmp_path / "log.csv", t, g)
    log = read_imu(tmp_path / "log.csv", kind="rate", units="deg/s", saturation=2000.0)
    assert log.saturated == [5, 18]
    main(["run", "--imu", str(tmp_path / "log.csv"), "--rates", "--units", "deg/s",
          "--algorithm", "rk4", "--saturation", "2000", "--out", str(tmp_path / "o.csv")])
    assert "2 saturated row(s), first at data row 5" in capsys.readouterr().err


def test_hdf5_log(tmp_path):
    h5py = pytest.importorskip("h5py")
    t = np.arange(100) / 200.0
    w = SpinConing(0.05, 2 * math.pi, 20.0).rate(t)
    with h5py.File(tmp_path / "log.h5", "w") as f:
        f["t"] = t
        f["gyro"] = w
    log = read_imu(tmp_path / "log.h5", kind="rate", units="rad/s")
    assert np.array_equal(log.data, w) and np.array_equal(log.t, t)
    with h5py.File(tmp_path / "bad.h5", "w") as f:
        f["acc"] = w
    with pytest.raises(ValueError, match="datasets 't' and 'gyro'"):
        read_imu(tmp_path / "bad.h5", kind="rate", units="rad/s")


def test_run_progress_bar_goes_to_stderr(tmp_path, capsys):
    np.save(tmp_path / "log.npy", np.column_stack([np.arange(1, 301) * 1e-3,
                                                   np.full((300, 3), 1e-4)]))
    main(["run", "--imu", str(tmp_path / "log.npy"), "--increments", "--units", "rad",
          "--progress", "--out", str(tmp_path / "a.csv")])
    cap = capsys.readouterr()
    assert "300/300" in cap.err and "wrote" in cap.out


def test_streamed_npy_reports_gaps_and_saturation(tmp_path, monkeypatch):
    import strapdown.apps.run as run_mod

    monkeypatch.setattr(run_mod, "CHUNK", 64)  # the gap and a saturated row in later chunks
    t = np.r_[np.arange(1, 101), np.arange(111, 201)] * 1e-3
    th = np.full((t.size, 3), 1e-5)
    th[150, 0] = 0.01
    np.save(tmp_path / "log.npy", np.column_stack([t, th]))
    res = run_log(tmp_path / "log.npy", tmp_path / "a.csv", kind="increment", units="rad",
                  saturation=0.01)
    assert res["gaps"] == {"count": 1, "first_rows": [101]}
    assert res["saturated"] == {"count": 1, "first_rows": [151]}
    with pytest.raises(ValueError, match=r"gap of 0\.011 s .* before data row 101"):
        run_log(tmp_path / "log.npy", tmp_path / "b.csv", kind="increment", units="rad",
                on_gap="error")
    assert not (tmp_path / "b.csv").exists()
