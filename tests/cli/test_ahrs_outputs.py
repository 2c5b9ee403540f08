"""``strapdown ahrs`` writes the attitude and ``OUT.meta.json`` together (issue 16): when the
metadata cannot be written, neither file is left (nor a temporary one), and an earlier pair
is not replaced by half of a new one."""

from __future__ import annotations

import errno

import pytest

from strapdown._core.compile_notice import MESSAGE
from strapdown.cli import main


def _ahrs(tmp_path, capsys, out):
    from fuzz import corpus

    imu = tmp_path / "log.csv"
    imu.write_bytes(corpus.valid_seeds(tmp_path)["ahrs_csv"])
    try:
        code = main(["ahrs", "--imu", str(imu), "--gyro-units", "rad/s", "--acc-units",
                     "m/s2", "--out", str(out)])
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err  # without the one-off notice of a cold numba cache
    return code, "".join(ln for ln in err.splitlines(keepends=True) if ln.rstrip("\n") != MESSAGE)


def test_a_failed_metadata_write_leaves_neither_file(tmp_path, capsys, monkeypatch):
    from strapdown.apps import _logs

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    (tmp_path / "o").mkdir()
    monkeypatch.setattr(_logs.json, "dumps", full)  # the sidecar cannot be written
    code, err = _ahrs(tmp_path, capsys, tmp_path / "o" / "att.csv")
    assert code == 74 and "No space left on device" in err and err.count("\n") == 1
    assert list((tmp_path / "o").iterdir()) == []  # no attitude, no sidecar, no temp file


def test_a_failed_metadata_write_keeps_the_earlier_pair(tmp_path, capsys, monkeypatch):
    from strapdown.apps import _logs

    out = tmp_path / "o" / "att.csv"
    code, err = _ahrs(tmp_path, capsys, out)
    assert code == 0, err
    before = {p.name: p.read_bytes() for p in out.parent.iterdir()}
    assert sorted(before) == ["att.csv", "att.csv.meta.json"]

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(_logs.json, "dumps", full)
    assert _ahrs(tmp_path, capsys, out)[0] == 74
    assert {p.name: p.read_bytes() for p in out.parent.iterdir()} == before


def test_a_failed_sidecar_rename_removes_the_new_attitude(tmp_path, capsys, monkeypatch):
    """The attitude lands first; when the sidecar's own rename then fails, the attitude is
    removed again so no OUT stands without its OUT.meta.json."""
    import os

    from strapdown.io import files

    real = os.replace

    def replace(src, dst):
        if str(dst).endswith(".meta.json"):
            raise OSError(errno.EIO, "Input/output error", str(dst))
        return real(src, dst)

    (tmp_path / "o").mkdir()
    monkeypatch.setattr(files.os, "replace", replace)
    code, err = _ahrs(tmp_path, capsys, tmp_path / "o" / "att.csv")
    assert code == 74 and "Input/output error" in err and err.count("\n") == 1
    assert list((tmp_path / "o").iterdir()) == []


def test_a_start_in_motion_is_said_and_in_the_metadata(tmp_path, capsys):
    """A log whose first half second turns (1 rad/s about x) starts in motion: a note on
    stderr and ``start`` in the sidecar; a log that starts still says nothing of it."""
    import json

    import numpy as np

    from strapdown.rotation.dcm import dcm_from_quat
    from strapdown.rotation.quaternion import quat_from_rotvec

    n, h = 300, 0.01
    t = np.arange(n) * h
    for rate, still in ((1.0, False), (0.0, True)):
        w = np.tile([rate, 0.0, 0.0], (n, 1))
        c = dcm_from_quat(quat_from_rotvec(np.outer(rate * t, [1.0, 0.0, 0.0])))  # C_n_b
        a = np.einsum("nji,j->ni", c, [0.0, 0.0, 9.81])
        m = np.einsum("nji,j->ni", c, [0.0, 20.0, -40.0])
        rows = ["t,gx,gy,gz,ax,ay,az,mx,my,mz"]
        rows += [",".join(repr(float(v)) for v in (t[i], *w[i], *a[i], *m[i])) for i in range(n)]
        imu = tmp_path / f"log{rate}.csv"
        imu.write_text("\n".join(rows) + "\n")
        out = tmp_path / f"att{rate}.csv"
        assert main(["ahrs", "--imu", str(imu), "--gyro-units", "rad/s", "--acc-units", "m/s2",
                     "--out", str(out)]) == 0
        err = capsys.readouterr().err
        meta = json.loads(out.with_name(out.name + ".meta.json").read_text())
        assert ("starts in motion" in err) is not still
        assert meta["start"].startswith("still" if still else "in motion")


def test_an_unused_accelerometer_is_said_on_stderr_and_in_the_metadata(tmp_path, capsys):
    """A 6-axis log that starts spinning and never rests, its accelerometer 3.5 % low: the
    filter skips every accelerometer update (gravity's norm never measured), and the
    command says so — a ``warning:`` line naming the norm, the same text in
    ``OUT.meta.json``'s warnings, and "accelerometer used 0%" in its summary."""
    import json

    import numpy as np

    t = np.arange(2000) * 0.01
    rows = np.column_stack([t, np.zeros_like(t), np.zeros_like(t), np.full_like(t, 0.5),
                            np.zeros_like(t), np.zeros_like(t),
                            np.full_like(t, 0.965 * 9.80665)])
    imu = tmp_path / "spin.csv"
    imu.write_text("t,gx,gy,gz,ax,ay,az\n"
                   + "".join(",".join(f"{v:.6f}" for v in r) + "\n" for r in rows))
    out = tmp_path / "att.csv"
    code = main(["ahrs", "--imu", str(imu), "--gyro-units", "rad/s", "--acc-units", "m/s2",
                 "--out", str(out)])
    cap = capsys.readouterr()
    assert code in (0, None), cap.err
    said = [ln for ln in cap.err.splitlines() if ln.startswith("warning: ekf:")]
    assert len(said) == 1 and "-3.5 %" in said[0] and "AhrsConfig(gravity=" in said[0]
    meta = json.loads((tmp_path / "att.csv.meta.json").read_text())
    assert any("accelerometer updates were skipped" in w for w in meta["warnings"])
    assert meta["accelerometer_used"] == 0.0 and "accelerometer used 0%" in cap.out


def test_gyro_scale_sigma_reaches_the_filter_and_the_metadata(tmp_path, capsys):
    """``--gyro-scale-sigma``: a spinning log whose gyro reads 1.5 % high about the spin
    axis (a vertical spin at 3 rad/s): with the option the heading stays within a few
    degrees where without it the gyro drags it; the sidecar records the option; a value
    outside [0, 1) is refused, naming it."""
    import json

    import numpy as np

    from strapdown.rotation.dcm import dcm_from_quat
    from strapdown.rotation.quaternion import quat_from_rotvec

    n, h, rate = 6000, 0.01, 3.0
    t = np.arange(n) * h
    spin = np.where(t < 2.0, 0.0, rate)
    angle = np.cumsum(spin) * h
    c = dcm_from_quat(quat_from_rotvec(np.outer(angle, [0.0, 0.0, 1.0])))  # C_n_b
    a = np.einsum("nji,j->ni", c, [0.0, 0.0, 9.81])
    m = np.einsum("nji,j->ni", c, [0.0, 20.0, -40.0])
    w = np.column_stack([np.zeros(n), np.zeros(n), 1.015 * spin])
    rows = ["t,gx,gy,gz,ax,ay,az,mx,my,mz"]
    rows += [",".join(repr(float(v)) for v in (t[i], *w[i], *a[i], *m[i])) for i in range(n)]
    imu = tmp_path / "spin.csv"
    imu.write_text("\n".join(rows) + "\n")
    yaw_err = {}
    for sd in (0.0, 0.02):
        out = tmp_path / f"att{sd}.csv"
        assert main(["ahrs", "--imu", str(imu), "--gyro-units", "rad/s", "--acc-units", "m/s2",
                     "--gyro-scale-sigma", str(sd), "--out", str(out)]) == 0
        meta = json.loads(out.with_name(out.name + ".meta.json").read_text())
        assert meta["config"]["gyro_scale_sigma"] == sd
        q = np.loadtxt(out, delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
        yaw = 2.0 * np.arctan2(q[:, 3], q[:, 0])  # a rotation about the vertical only
        late = t > 40.0
        yaw_err[sd] = np.degrees(np.abs(np.angle(np.exp(1j * (yaw[late] - angle[late]))))).max()
    assert yaw_err[0.02] < 2.0 < yaw_err[0.0]
    capsys.readouterr()
    try:
        code = main(["ahrs", "--imu", str(imu), "--gyro-units", "rad/s", "--acc-units", "m/s2",
                     "--gyro-scale-sigma", "1.5", "--out", str(tmp_path / "x.csv")])
    except SystemExit as exc:
        code = exc.code
    assert code == 2
    assert "--gyro-scale-sigma" in capsys.readouterr().err


def test_gyro_range_reaches_the_filter_and_the_counts_the_metadata(tmp_path, capsys):
    """``--gyro-range-deg-s``: a body spun about its z axis at 6 rad/s (344 °/s) after 2 s,
    read by a gyro clipped at 5 rad/s. Given the range (5 rad/s = 286.5 °/s), it is the
    config's, and every clipped sample's rate is taken from the field: the note and the
    sidecar count them, and the yaw follows the spin within a degree (the clipped reading
    alone falls 1 rad/s behind). Without the option the range is found from the record (a
    flat top the field turns 1.2 times faster than), with the same counts. A range that is
    not positive and finite is refused, naming it."""
    import json
    import math

    import numpy as np

    from strapdown.rotation.dcm import dcm_from_quat
    from strapdown.rotation.quaternion import quat_from_rotvec

    n, h, rate, clip = 3000, 0.01, 6.0, 5.0
    t = np.arange(n) * h
    spin = np.where(t < 2.0, 0.0, rate)
    angle = np.concatenate([[0.0], np.cumsum(0.5 * h * (spin[1:] + spin[:-1]))])
    c = dcm_from_quat(quat_from_rotvec(np.outer(angle, [0.0, 0.0, 1.0])))  # C_n_b
    a = np.einsum("nji,j->ni", c, [0.0, 0.0, 9.81])
    m = np.einsum("nji,j->ni", c, [0.0, 20.0, -40.0])
    w = np.column_stack([np.zeros(n), np.zeros(n), np.minimum(spin, clip)])
    rows = ["t,gx,gy,gz,ax,ay,az,mx,my,mz"]
    rows += [",".join(repr(float(v)) for v in (t[i], *w[i], *a[i], *m[i])) for i in range(n)]
    imu = tmp_path / "spin.csv"
    imu.write_text("\n".join(rows) + "\n")
    out = tmp_path / "att.csv"
    assert main(["ahrs", "--imu", str(imu), "--gyro-units", "rad/s", "--acc-units", "m/s2",
                 "--gyro-range-deg-s", str(math.degrees(clip)), "--out", str(out)]) == 0
    cap = capsys.readouterr()
    at_range = int((t >= 2.0).sum()) - 1  # the first spinning sample's rate is an interval's
    assert f"at its range on {at_range + 1} samples" in cap.err
    meta = json.loads(out.with_name(out.name + ".meta.json").read_text())
    assert meta["gyro_at_range"]["samples"] == at_range + 1
    assert meta["gyro_at_range"]["recovered_from_field"] >= at_range
    assert meta["config"]["gyro_range"] == clip
    q = np.loadtxt(out, delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
    yaw = 2.0 * np.arctan2(q[:, 3], q[:, 0])
    late = t > 10.0
    err = np.degrees(np.abs(np.angle(np.exp(1j * (yaw[late] - angle[late])))))
    assert err.max() < 1.0
    found = tmp_path / "found.csv"
    assert main(["ahrs", "--imu", str(imu), "--gyro-units", "rad/s", "--acc-units", "m/s2",
                 "--out", str(found)]) == 0
    capsys.readouterr()
    meta_found = json.loads(found.with_name(found.name + ".meta.json").read_text())
    assert meta_found["gyro_at_range"] == meta["gyro_at_range"]
    assert meta_found["config"]["gyro_range"] == pytest.approx(clip, rel=1e-3)  # found
    for bad in ("0", "-5", "inf"):
        with pytest.raises(SystemExit) as exc:
            main(["ahrs", "--imu", str(imu), "--gyro-units", "rad/s", "--acc-units", "m/s2",
                  "--gyro-range-deg-s", bad, "--out", str(tmp_path / "x.csv")])
        assert exc.value.code == 2
        assert "--gyro-range-deg-s is the gyro's full scale" in capsys.readouterr().err
