"""Every crash family of issue 16, reproduced by a corpus file (tests/fuzz/corpus.py, made at
test time) and now refused with a clear InputError that names the file — or read, where
reading is right (v7.3, BOM and CRLF, ``;`` and tab)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from fuzz import corpus
from fuzz.targets import API
from strapdown import InputError

#: What each corpus file's error says (a regex), or None where the file is read.
EXPECTED = {
    "npy_valid": None, "npy_fortran": None, "npy_bigendian": None,
    "npy_empty": "an empty file .* expected an array saved by numpy.save",
    "npy_negative_shape": r"shape \(-5, 4\) has a negative dimension",
    "npy_empty_but_unrepresentable": r"shape \(0, 312, 3695261232714254\) of float64 is "
                                     "larger than any array can be",
    "npy_unclosed_header": "unreadable .npy header",
    "npy_structured": "structured dtype .* expected a plain numeric array",
    "npy_0d": r"must be \(n, 4\) \[t, gx, gy, gz\], got shape \(\)",
    "npy_1d": r"got shape \(8,\)",
    "npy_object": "holds objects; expected numbers",
    "npy_complex": "complex numbers; a log holds real numbers",
    "npy_strings": "expected numbers",
    "npy_7tib": r"truncated .npy: the header declares \(274877906944, 4\)",
    "npy_truncated": r"truncated .npy: .*\(2048 bytes\), the file holds 1948",
    "npy_bad_version": "format version 9.0 is not known",
    "npy_huge_header_len": "header of 2147483647 bytes",
    "npy_header_not_dict": "must be a dict of descr, fortran_order and shape",
    "npy_header_code": "unreadable .npy header",
    "npy_bool_shape": "is not a tuple of integers",
    "npy_nan": "NaN or infinity in data row 4",
    "npy_one_row": "1 samples; at least 2 are needed",
    "npy_1e308": r"turns the body by 1e\+305 rad in one sample \(at most π\)",
    "npz_valid": None,
    "npz_empty": "an empty file; expected a .npz archive",
    "npz_empty_but_unrepresentable": r"array 't'\): the .npy shape \(0, 312, 3695261232714254\) "
                                     "of float64 is larger than any array can be",
    "npz_broken_zip": "not a readable .npz archive",
    "npz_not_zip": "not a readable .npz archive",
    "npz_encrypted": "is encrypted; numpy archives are not",
    "npz_unknown_compression": "compression method 99; numpy archives are stored or deflated",
    "npz_time_column": r"times of shape \(n,\) .* got \(64, 1\)",
    "npz_missing_gyro": r"need arrays 't' and 'gyro'; found \['t'\]",
    "npz_structured": "array 'gyro' has a structured dtype",
    "npz_object": "array 'gyro' holds objects",
    "npz_complex": "array 'gyro' holds complex numbers",
    "npz_bomb": "would inflate .* a compression bomb",
    "npz_crc": "Bad CRC-32",
    "npz_lengths_differ": r"got \(10,\) and \(64, 3\)",
    "mat_valid": None, "mat_valid_compressed": None, "mat_v73_valid": None,
    "mat_empty": "an empty file; expected a MATLAB .mat file",
    "mat_text": "too short for a MATLAB .mat file",
    "mat_header_only": r"no 'imu_gyr' \(BROAD\) .* found \[\]",
    "mat_corrupt_zlib": "a compressed variable is corrupt",
    "mat_truncated": "truncated: a variable of 1592 bytes",
    "mat_truncated_z": "truncated: a variable of",
    "mat_vector_rate": r"sampling_rate must be one number, got float64 of shape \(1, 2\)",
    "mat_huge_rate": "sampling_rate must be positive and finite, between",
    "mat_struct": "variable 'imu_gyr' is a struct; expected a numeric matrix",
    "mat_complex": "variable 'imu_gyr' holds complex numbers",
    "mat_char": "variable 'imu_gyr' is a char array",
    "mat_dims_lie": "declares 64000x3 values, its data holds 192: the file is corrupt",
    "mat_negative_dims": "negative dimensions",
    "mat_empty_but_unrepresentable": r"variable 'imu_gyr' has dimensions \(0, 2147483647, "
                                     r"2147483647, 2147483647\), larger than any array can be",
    "mat_v4": r"MAT v4 file; re-save it in MATLAB with save\(file, '-v7'\)",
    "mat_v73_char": "variable 'imu_gyr' is a MATLAB char",
    "mat_bomb": "a compressed variable would inflate .* a compression bomb",
    "mat_big_endian_garbage": "no 'imu_gyr'",
    "h5_valid": None,
    "h5_not_hdf5": "not an HDF5 file", "h5_empty": "not an HDF5 file",
    "h5_strings": "dataset 'gyro' holds variable-length data",
    "h5_vlen": "dataset 'gyro' holds variable-length data",
    "h5_reference": "dataset 'gyro' holds references",
    "h5_null": "dataset 'gyro' has a null dataspace",
    "h5_dangling": "'gyro' is a broken link",
    "h5_compound": "compound dtype",
    "h5_group": "'gyro' is a group, not an array",
    "h5_bomb": r"dataset 'gyro' \(200000000, 3\) would take .* over the memory budget",
    "h5_truncated": "not a readable HDF5 file",
    "csv_valid": None, "ahrs_csv_valid": None, "csv_bom_crlf": None, "csv_semicolon": None,
    "csv_tab": None,
    "csv_huge_header_cell": "header row is longer than 65536 characters",
    "csv_1e308": r"turns the body by 1e\+305 rad in one sample",
    "csv_5e-324_step": "time step of 5e-324 s before data row 2; steps must be finite and at "
                       "least 1e-09 s",
    "ahrs_csv_5e-324_step": "time step of 5e-324 s before data row 2",
    "ahrs_csv_1e300_apart": "a sample period of 1e[+]300 s",
    "ahrs_csv_1e300_acc": "accelerometer in data row 10 has norm 1.732e[+]300",
    "csv_nan": "NaN or infinity in data row 4",
    "csv_binary": "not UTF-8 text",
    "csv_one_row": "1 samples; at least 2 are needed",
    "csv_header_only": "no data rows",
    "csv_empty": "empty file; expected a CSV with a header row",
    "csv_ragged": "expected 4 numbers separated by ',' in every data row",
    "csv_words": "could not convert string 'one'",
    "csv_complex": "could not convert string '1[+]2j'",
    "csv_nul": "no gyro columns",
    "csv_backwards": "non-monotonic time stamp in data row 2",
    "csv_huge_times": "sample period of",
    "csv_overflow_step": "time step of inf s before data row 2",
    "csv_latin1": "not UTF-8 text",
    "csv_quotes": "no time column",
}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("corpus")
    return {e.name: e for e in corpus.build(d) if e.fmt != "toml"}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_corpus_file_is_read_or_refused_clearly(files, name, tmp_path):
    e = files[name]
    call = dict(API[e.fmt])[e.target]
    msg = EXPECTED[name]
    if msg is None:
        call(e.path, tmp_path)
        return
    with pytest.raises(InputError) as exc:
        call(e.path, tmp_path)
    text = str(exc.value)
    assert re.search(msg, text), text
    assert str(e.path) in text and len(text) <= 500
    assert "np.float64" not in text and "allow_pickle" not in text


def test_every_corpus_file_has_an_expectation(files):
    assert set(files) - set(EXPECTED) <= {"npy_increments_valid", "npy_int", "npz_nav_valid"}


def test_a_bit_flipped_uncompressed_mat_never_takes_the_process_down(files, tmp_path):
    """The SIGSEGV of issue 16: one byte flipped in an uncompressed BROAD .mat crashed scipy's
    reader. Each flip at every 8th byte of the variables is now read or refused, in-process
    (the MAT v5 structure is validated before anything is decoded)."""
    from strapdown.io.broad import read_broad

    data = files["mat_valid"].path.read_bytes()
    path = tmp_path / "flip.mat"
    outcomes = {"read": 0, "refused": 0}
    for i in range(128, len(data), 8):
        for bit in (0, 7):
            b = bytearray(data)
            b[i] ^= 1 << bit
            path.write_bytes(bytes(b))
            try:
                read_broad(path)
                outcomes["read"] += 1
            except InputError:
                outcomes["refused"] += 1
    assert outcomes["refused"] > 0 and outcomes["read"] > 0  # flips in values stay readable


def test_declared_size_is_checked_against_the_memory_budget(files, monkeypatch):
    from strapdown._core.limits import memory_budget
    from strapdown.io.containers import read_npz

    z = files["npz_valid"].path
    with memory_budget(1000):  # t (64 floats) fits, gyro (64 × 3) does not
        with pytest.raises(InputError, match="over the memory budget of 1000 bytes; raise it "
                                             "with --max-memory or STRAPDOWN_MAX_BYTES"):
            read_npz(z, ["t", "gyro"])
    monkeypatch.setenv("STRAPDOWN_MAX_BYTES", "1k")
    with pytest.raises(InputError, match="over the memory budget of 1 kiB"):
        read_npz(z, ["t", "gyro"])
    monkeypatch.setenv("STRAPDOWN_MAX_BYTES", "lots")
    with pytest.raises(InputError, match="STRAPDOWN_MAX_BYTES: 'lots' is not a size"):
        read_npz(z, ["t"])


def test_max_memory_option_applies_to_a_command(files, tmp_path, capsys):
    from strapdown.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["run", "--imu", str(files["npz_valid"].path), "--rates", "--units", "rad/s",
              "--max-memory", "1k", "--out", str(tmp_path / "a.csv")])
    assert exc.value.code == 2
    assert "over the memory budget of 1 kiB" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())
    assert main(["run", "--imu", str(files["npz_valid"].path), "--rates", "--units", "rad/s",
                 "--max-memory", "64M", "--out", str(tmp_path / "a.csv")]) == 0


def test_streamed_npy_follows_the_same_rules_as_every_route(tmp_path, capsys):
    """The streamed .npy path used to accept --increments --units deg/s (57x angle error),
    --gap-tolerance -1, --saturation -1 or nan and a one-row log, all refused on CSV."""
    from strapdown.cli import main

    t = np.arange(100) * 1e-3
    path = tmp_path / "inc.npy"
    np.save(path, np.column_stack([t, np.full((100, 3), 1e-4)]))
    base = ["run", "--imu", str(path), "--increments", "--out", str(tmp_path / "a.csv")]
    for extra, msg in [(["--units", "deg/s"], "increment units must be one of ('rad', 'deg')"),
                       (["--units", "rad", "--gap-tolerance", "-1"], "gap_tolerance"),
                       (["--units", "rad", "--saturation", "-1"], "saturation must be positive"),
                       (["--units", "rad", "--saturation", "nan"], "saturation must be positive")]:
        with pytest.raises(SystemExit) as exc:
            main(base + extra)
        assert exc.value.code == 2
        assert msg in capsys.readouterr().err
    from strapdown.apps.run import run_log

    with pytest.raises(InputError, match=r"increment units must be one of \('rad', 'deg'\)"):
        run_log(path, tmp_path / "a.csv", kind="increment", units="deg/s")
    np.save(path, np.column_stack([t, np.full((100, 3), 1e-4)])[:1])
    with pytest.raises(InputError, match="1 samples; at least 2 are needed"):
        run_log(path, tmp_path / "a.csv", kind="increment", units="rad")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["inc.npy"]


def test_realtime_with_fewer_samples_than_n_is_an_error_not_an_empty_file(tmp_path):
    from strapdown.apps.run import run_log

    t = np.arange(2) * 1e-3
    path = tmp_path / "inc.csv"
    path.write_text("t,gx,gy,gz\n" + "".join(f"{float(ti)!r},1e-4,0,0\n" for ti in t))
    with pytest.raises(InputError, match="give no attitude update"):
        run_log(path, tmp_path / "a.csv", kind="increment", units="rad", subsamples=3,
                structure="realtime")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["inc.csv"]


def test_an_overflowing_increment_log_is_one_line_from_compare(files, tmp_path, capsys):
    """1e308-rad increments made ``g / h`` overflow in the unit check: a RuntimeWarning and its
    source line printed before the error (found by the fuzz campaign)."""
    import warnings

    from strapdown.cli import main

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(SystemExit) as exc:
            main(["compare", "--imu", str(files["npy_1e308"].path), "--increments", "--units",
                  "rad", "--algorithms", "rotvec:N=2", "--out", str(tmp_path / "cmp")])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "turns the body by 1e+308 rad" in err
