"""One error type for bad input (strapdown.InputError), bounded messages that name the file,
and the CSV dialects read as plainly as commas: a UTF-8 BOM, CRLF, ``;``, tab and ``|``."""

from __future__ import annotations

import math

import numpy as np
import pytest

import strapdown
from strapdown import InputError
from strapdown._core.errors import MAX_MESSAGE, bounded, shown
from strapdown.apps.ahrs_log import read_ahrs_log
from strapdown.cli import main
from strapdown.io import read_imu
from strapdown.io.containers import read_mat
from strapdown.truth.motions import SpinConing

T = np.arange(50) / 1000.0
W = SpinConing(0.05, 2 * math.pi, 20.0).rate(T)


def _text(t, g, header="t,gx,gy,gz", sep=",", newline="\n", bom=False):
    lines = [header.replace(",", sep)]
    lines += [sep.join(repr(float(v)) for v in (ti, *gi)) for ti, gi in zip(t, g, strict=True)]
    return ("\ufeff" if bom else "") + newline.join(lines) + newline


def test_input_error_is_a_value_error_exported_from_the_package():
    assert issubclass(InputError, ValueError)
    assert strapdown.InputError is InputError and "InputError" in dir(strapdown)


def test_messages_are_bounded_and_keep_both_ends():
    text = "/data/log.csv: " + "x" * 100_000 + " expected numbers"
    b = bounded(text)
    assert len(b) == MAX_MESSAGE and b.startswith("/data/log.csv: ")
    assert b.endswith("expected numbers") and " … " in b
    assert len(str(InputError(text))) <= MAX_MESSAGE
    assert len(shown("y" * 1000, 60)) == 60


def test_a_huge_header_cell_gives_a_short_error_naming_the_file(tmp_path):
    path = tmp_path / "wide.csv"
    path.write_text("t," + "g" * 200_000 + ",gy,gz\n0,1,2,3\n")  # over csv's 131072 limit
    with pytest.raises(InputError) as exc:
        read_imu(path, kind="rate", units="rad/s")
    msg = str(exc.value)
    assert str(path) in msg and "header row is longer than" in msg and len(msg) <= MAX_MESSAGE
    path.write_text("t," + "g" * 60_000 + ",gy,gz\n0,1,2,3\n")  # a header row, no gyro axes
    with pytest.raises(InputError, match="no gyro columns") as exc:
        read_imu(path, kind="rate", units="rad/s")
    assert len(str(exc.value)) <= MAX_MESSAGE


@pytest.mark.parametrize(("sep", "newline", "bom"), [
    (",", "\r\n", False), (",", "\n", True), (",", "\r\n", True), (";", "\n", False),
    ("\t", "\r\n", True), ("|", "\n", False),
])
def test_csv_dialects_read_like_plain_commas(tmp_path, sep, newline, bom):
    plain = tmp_path / "plain.csv"
    plain.write_text(_text(T, W), newline="")
    other = tmp_path / "other.csv"
    other.write_text(_text(T, W, sep=sep, newline=newline, bom=bom), encoding="utf-8",
                     newline="")
    a = read_imu(plain, kind="rate", units="rad/s")
    b = read_imu(other, kind="rate", units="rad/s")
    assert np.array_equal(a.t, b.t) and np.array_equal(a.data, b.data)
    assert np.array_equal(b.data, W)


def test_the_delimiter_can_be_given(tmp_path):
    path = tmp_path / "semi.csv"
    path.write_text(_text(T, W, header="t,gx[rad/s],gy[rad/s],gz[rad/s]", sep=";"))
    log = read_imu(path, kind="rate", units=None, delimiter=";")
    assert np.array_equal(log.data, W)
    with pytest.raises(InputError, match="no time column"):  # read with commas: one column
        read_imu(path, kind="rate", units=None, delimiter=",")
    with pytest.raises(InputError, match="--delimiter must be one of"):
        read_imu(path, kind="rate", units=None, delimiter="x")
    out = tmp_path / "a.csv"
    assert main(["run", "--imu", str(path), "--rates", "--delimiter", ";", "--angles", "none",
                 "--out", str(out)]) == 0
    assert out.read_text().startswith("t,qw,qx,qy,qz\n")


def test_ahrs_reads_a_tab_separated_log_with_a_bom(tmp_path):
    n = 400
    t = np.arange(n) * 0.01
    cols = [t, *np.zeros((3, n)), np.zeros(n), np.zeros(n), np.full(n, 9.81), np.full(n, 20.0),
            np.zeros(n), np.full(n, -40.0)]
    body = "\r\n".join("\t".join(repr(float(c[i])) for c in cols) for i in range(n))
    path = tmp_path / "ahrs.tsv.csv"
    path.write_text("\ufefft\tgx\tgy\tgz\tax\tay\taz\tmx\tmy\tmz\r\n" + body + "\r\n",
                    encoding="utf-8", newline="")
    log = read_ahrs_log(path, gyro_units="rad/s", acc_units="m/s2")
    assert log.t.size == n and np.array_equal(log.acc[:, 2], np.full(n, 9.81))
    assert log.mag is not None and np.array_equal(log.mag[:, 2], np.full(n, -40.0))


def _v73(path, variables):
    """A MATLAB v7.3 file: HDF5 with a 512-byte user block, variables transposed."""
    h5py = pytest.importorskip("h5py")
    with h5py.File(path, "w", userblock_size=512) as f:
        for k, v in variables.items():
            ds = f.create_dataset(k, data=np.asarray(v).T)
            ds.attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as f:
        f.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(116) + b"\0" * 8 + b"\x00\x02IM")
    return path


def test_matlab_v73_is_read_through_hdf5(tmp_path):
    g = W.copy()
    path = _v73(tmp_path / "broad73.mat", {"imu_gyr": g, "sampling_rate": [[1000.0]]})
    assert read_mat(path, ["imu_gyr"]).arrays["imu_gyr"].shape == (50, 3)
    log = read_imu(path, kind="rate", units=None)
    assert log.units == "rad/s" and np.array_equal(log.data, g)
    assert log.h == pytest.approx(1e-3, rel=1e-12)


def test_matlab_v4_is_refused_with_how_to_convert(tmp_path):
    from scipy.io import savemat

    path = tmp_path / "old.mat"
    savemat(path, {"imu_gyr": W}, format="4")
    with pytest.raises(InputError, match=r"MAT v4 file; re-save it in MATLAB with "
                                         r"save\(file, '-v7'\)"):
        read_imu(path, kind="rate", units="rad/s", sample_rate_hz=1000.0)
