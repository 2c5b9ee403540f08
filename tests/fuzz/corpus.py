"""Hand-made corrupt (and a few valid) input files, generated at test time — no binary blobs
in git. Each entry is one file with the format it claims and what a reader must do with
it: ``"error"`` (an :class:`strapdown.InputError`), ``"ok"`` (read), or ``"any"`` (either,
but nothing else: no other exception, no crash, no hang, no memory blow-up).

The families are the ones issue 16 found, each reproduced here: ``.npy``/``.npz`` (empty,
negative shape, unclosed header, broken zip, encrypted flag, unknown compression, structured
dtype, 0-d array, a time column of shape (n, 1), a zip bomb, a 7 TiB header), ``.mat`` (empty,
text, v7.3, corrupt zlib, truncated, vector ``sampling_rate``, struct, complex, char, v4,
bit flips in an uncompressed file, an inflation bomb), HDF5 (not HDF5, string, vlen,
reference, null, compound and group datasets, a dangling link, a chunked bomb), CSV (a
131 073-character header cell, a 1e308 rate, a 5e-324 s time step, NaN, binary, one row)
and TOML scenarios (wrong types, 1e308 rates, 100 000 nested arrays, NaN noise, a grid of
10¹² points, values that used to pass validation and fail at run time).
"""

from __future__ import annotations

import io
import struct
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["FORMATS", "Entry", "build", "mat_v5", "npy_bytes", "valid_seeds"]

FORMATS = ("csv", "npy", "npz", "mat", "h5", "toml")


@dataclass(frozen=True)
class Entry:
    """One corpus file."""

    name: str
    fmt: str
    path: Path
    expect: str  # "error", "ok" or "any", of ``target``
    target: str  # the API target (fuzz.targets.API) the expectation is about


def _log(n: int = 64, h: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
    """A smooth, valid rate log: spin plus coning, rad/s."""
    t = np.arange(n) * h
    w = np.column_stack([20.0 + 0 * t, 0.5 * np.cos(6.0 * t), 0.5 * np.sin(6.0 * t)])
    return t, w


def npy_bytes(arr: np.ndarray) -> bytes:
    b = io.BytesIO()
    np.save(b, arr, allow_pickle=False)
    return b.getvalue()


def _npy_raw(header: str, data: bytes = b"", version: int = 1) -> bytes:
    h = header.encode("latin-1" if version < 3 else "utf-8", "replace")
    if version == 1:
        return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(h)) + h + data
    return b"\x93NUMPY" + bytes([version, 0]) + struct.pack("<I", len(h)) + h + data


def _npz(members: dict[str, bytes], compression: int = zipfile.ZIP_DEFLATED) -> bytes:
    b = io.BytesIO()
    with zipfile.ZipFile(b, "w", compression) as z:
        for k, v in members.items():
            z.writestr(k + ".npy", v)
    return b.getvalue()


def _set_local_flag(data: bytes, flag: int = 0, method: int | None = None) -> bytes:
    """Set bits in every local and central header's flag (and the method)."""
    out = bytearray(data)
    for sig, off_flag in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        i = out.find(sig)
        while i >= 0:
            f = struct.unpack_from("<H", out, i + off_flag)[0] | flag
            struct.pack_into("<H", out, i + off_flag, f)
            if method is not None:
                struct.pack_into("<H", out, i + off_flag + 2, method)
            i = out.find(sig, i + 4)
    return bytes(out)


def _deflate_zeros(prefix: bytes, zeros: int, raw: bool) -> tuple[bytes, int]:
    """``prefix`` + ``zeros`` zero bytes deflated in chunks; ``(stream, crc32)``."""
    import zlib

    co = zlib.compressobj(9, zlib.DEFLATED, -15 if raw else 15)
    parts, crc = [co.compress(prefix)], zlib.crc32(prefix)
    chunk = bytes(1 << 22)
    while zeros:
        k = min(zeros, len(chunk))
        parts.append(co.compress(chunk[:k]))
        crc = zlib.crc32(chunk[:k], crc)
        zeros -= k
    parts.append(co.flush())
    return b"".join(parts), crc


def _zip_bomb(declared: int) -> bytes:
    """A .npz whose gyro member inflates ~1000 times (zeros), declaring ``declared`` bytes."""
    t, _ = _log()
    rows = declared // 24
    hdr = _npy_raw(f"{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, 3), }}"
                   ).ljust(128, b" ")
    data, crc = _deflate_zeros(hdr, declared // 24 * 24, raw=True)
    size = len(hdr) + declared // 24 * 24
    b = io.BytesIO()
    with zipfile.ZipFile(b, "w") as z:
        z.writestr("t.npy", npy_bytes(t))
    out = b.getvalue()
    cd = out.find(b"PK\x01\x02")
    local, central = out[:cd], out[cd:out.find(b"PK\x05\x06")]
    name = b"gyro.npy"
    lh = struct.pack("<4sHHHHHIIIHH", b"PK\x03\x04", 20, 0, 8, 0, 0, crc, len(data), size,
                     len(name), 0) + name
    ch = struct.pack("<4sHHHHHHIIIHHHHHII", b"PK\x01\x02", 20, 20, 0, 8, 0, 0, crc, len(data),
                     size, len(name), 0, 0, 0, 0, 0, len(local)) + name
    eocd = struct.pack("<4sHHHHIIH", b"PK\x05\x06", 0, 0, 2, 2, len(central) + len(ch),
                       len(local) + len(lh) + len(data), 0)
    return local + lh + data + central + ch + eocd


# ------------------------------------------------------------------------------ MAT v5
def _mat_elem(t: int, payload: bytes) -> bytes:
    return struct.pack("<II", t, len(payload)) + payload + b"\0" * ((-len(payload)) % 8)


def _mat_matrix(name: str, arr: np.ndarray | None = None, *, cls: int = 6, dims=None,
                data: bytes | None = None, dtype_code: int = 9, flags: int = 0) -> bytes:
    a = None if arr is None else np.asarray(arr, float)
    dims = dims if dims is not None else (a.shape if a is not None else (1, 1))
    if data is None:
        data = (a if a is not None else np.zeros(1)).astype("<f8").tobytes(order="F")
    body = _mat_elem(6, struct.pack("<II", cls | flags, 0))
    body += _mat_elem(5, struct.pack(f"<{len(dims)}i", *dims))
    body += _mat_elem(1, name.encode())
    body += _mat_elem(dtype_code, data)
    return _mat_elem(14, body)


def mat_v5(variables: list[bytes], *, compress: bool = False) -> bytes:
    """A MATLAB v5 file from miMATRIX elements (:func:`_mat_matrix`), optionally each in a
    miCOMPRESSED element."""
    import zlib

    head = b"MATLAB 5.0 MAT-file, corpus".ljust(116, b" ") + b"\0" * 8 + b"\x00\x01IM"
    body = b""
    for v in variables:
        if compress:
            c = zlib.compress(v)
            body += struct.pack("<II", 15, len(c)) + c
        else:
            body += v
    return head + body


def _broad_vars(n: int = 64, fs=100.0) -> list[bytes]:
    _t, w = _log(n, 1.0 / 100.0)
    acc = np.tile([0.0, 0.0, 9.81], (n, 1))
    mag = np.tile([20.0, 0.0, -40.0], (n, 1))
    return [_mat_matrix("imu_gyr", w), _mat_matrix("imu_acc", acc), _mat_matrix("imu_mag", mag),
            _mat_matrix("opt_quat", np.tile([1.0, 0, 0, 0], (n, 1))),
            _mat_matrix("movement", np.ones((n, 1))),
            _mat_matrix("sampling_rate", np.atleast_2d(fs))]


def _v73(path: Path, variables: dict[str, object], classes: dict[str, str] | None = None):
    import h5py

    with h5py.File(path, "w", userblock_size=512) as f:
        for k, v in variables.items():
            ds = f.create_dataset(k, data=v)
            ds.attrs["MATLAB_class"] = np.bytes_((classes or {}).get(k, "double"))
    with open(path, "r+b") as f:
        f.write(b"MATLAB 7.3 MAT-file, corpus".ljust(116) + b"\0" * 8 + b"\x00\x02IM")


# ------------------------------------------------------------------------------ HDF5
def _h5(path: Path, build: Callable) -> None:
    import h5py

    with h5py.File(path, "w") as f:
        build(f)


def _h5_log(f) -> None:
    t, w = _log()
    f["t"] = t
    f["gyro"] = w


def _h5_bomb(f) -> None:
    t, _ = _log()
    f["t"] = t
    f.create_dataset("gyro", shape=(200_000_000, 3), dtype="f8", chunks=(100_000, 3),
                     compression="gzip")  # 4.8 GB declared, nothing stored


def _h5_strings(f) -> None:
    import h5py

    f["t"] = np.array([b"a", b"b"])
    f.create_dataset("gyro", data=["x", "y"], dtype=h5py.string_dtype())


def _h5_vlen(f) -> None:
    import h5py

    f["t"] = np.arange(3.0)
    ds = f.create_dataset("gyro", (3,), dtype=h5py.vlen_dtype(np.float64))
    ds[0] = [1.0, 2.0]


def _h5_ref(f) -> None:
    import h5py

    f["t"] = np.arange(3.0)
    ds = f.create_dataset("gyro", (3,), dtype=h5py.ref_dtype)
    ds[0] = f["t"].ref


def _h5_null(f) -> None:
    import h5py

    f["t"] = h5py.Empty("f8")
    f["gyro"] = h5py.Empty("f8")


def _h5_dangling(f) -> None:
    import h5py

    f["t"] = np.arange(3.0)
    f["gyro"] = h5py.SoftLink("/nowhere")


def _h5_compound(f) -> None:
    f["t"] = np.arange(3.0)
    f["gyro"] = np.zeros(3, dtype=[("re", "f8"), ("im", "f8")])


def _h5_group(f) -> None:
    f["t"] = np.arange(3.0)
    f.create_group("gyro")


# ------------------------------------------------------------------------------ CSV
def _csv(t, w, header="t,gx,gy,gz") -> bytes:
    rows = [header] + [",".join(repr(float(v)) for v in (ti, *wi))
                       for ti, wi in zip(t, w, strict=False)]
    return ("\n".join(rows) + "\n").encode()


def _ahrs_csv(n=64, h=0.01, t=None, acc=None) -> bytes:
    t = np.arange(n) * h if t is None else t
    g = np.zeros((n, 3))
    a = np.tile([0.0, 0.0, 9.81], (n, 1)) if acc is None else acc
    m = np.tile([20.0, 0.0, -40.0], (n, 1))
    rows = ["t,gx,gy,gz,ax,ay,az,mx,my,mz"]
    rows += [",".join(repr(float(v)) for v in (t[i], *g[i], *a[i], *m[i])) for i in range(n)]
    return ("\n".join(rows) + "\n").encode()


# ------------------------------------------------------------------------------ TOML
_SCENARIO = """algorithms = ["rotvec:N=2"]
metrics = ["max_error_rad"]
seed = 1
[motion]
motion = "coning"
half_angle_deg = 1.0
[sensor]
sample_rate_hz = 200.0
duration = 0.5
"""


def _toml(extra: str = "", base: str = _SCENARIO) -> bytes:
    return (base + extra).encode()


def valid_seeds(d: Path) -> dict[str, bytes]:
    """A valid file of every format (the mutation fuzzer's seeds), as bytes."""
    t, w = _log()
    seeds = {"csv": _csv(t, w, "t,gx[rad/s],gy[rad/s],gz[rad/s]"),
             "npy": npy_bytes(np.column_stack([t, w])),
             "npz": _npz({"t": npy_bytes(t), "gyro": npy_bytes(w)}),
             "npz_stored": _npz({"t": npy_bytes(t), "gyro": npy_bytes(w)}, zipfile.ZIP_STORED),
             "mat": mat_v5(_broad_vars()),
             "mat_z": mat_v5(_broad_vars(), compress=True),
             "toml": _toml('[grid]\ncone_rate_hz = [1.0, 2.0]\n"gyro.white_noise" = [0.0, 1e-6]\n'),
             "ahrs_csv": _ahrs_csv()}
    h5 = d / "_seed.h5"
    _h5(h5, _h5_log)
    seeds["h5"] = h5.read_bytes()
    v73 = d / "_seed73.mat"
    _v73(v73, {"imu_gyr": w.T, "sampling_rate": np.array([[1000.0]])})
    seeds["mat73"] = v73.read_bytes()
    h5.unlink()
    v73.unlink()
    return seeds


def _entries() -> list[tuple[str, str, str, Callable[[Path], bytes | None]]]:
    """``(name, format, expect, make)``; ``make(path)`` returns the bytes or writes the file
    itself (returning None)."""
    t, w = _log()
    log = np.column_stack([t, w])
    big_hdr = f"{{'descr': '<f8', 'fortran_order': False, 'shape': ({2**40 // 4}, 4), }}"
    e: list[tuple[str, str, str, Callable[[Path], bytes | None]]] = [
        # .npy
        ("npy_valid", "npy", "ok", lambda p: npy_bytes(log)),
        ("npy_increments_valid", "npy", "any", lambda p: npy_bytes(
            np.column_stack([t, w * 1e-3]))),
        ("npy_empty", "npy", "error", lambda p: b""),
        ("npy_negative_shape", "npy", "error", lambda p: _npy_raw(
            "{'descr': '<f8', 'fortran_order': False, 'shape': (-5, 4), }", bytes(160))),
        ("npy_unclosed_header", "npy", "error", lambda p: _npy_raw(
            "{'descr': '<f8', 'fortran_order': False, 'shape': (5, 4", bytes(160))),
        ("npy_structured", "npy", "error", lambda p: npy_bytes(
            np.zeros(5, dtype=[("t", "f8"), ("g", "f8", 3)]))),
        ("npy_0d", "npy", "error", lambda p: npy_bytes(np.array(1.0))),
        ("npy_1d", "npy", "error", lambda p: npy_bytes(np.arange(8.0))),
        ("npy_object", "npy", "error", lambda p: _npy_raw(
            "{'descr': '|O', 'fortran_order': False, 'shape': (2, 4), }", b"\x80\x04N.")),
        ("npy_complex", "npy", "error", lambda p: npy_bytes(log.astype(complex))),
        ("npy_strings", "npy", "error", lambda p: npy_bytes(np.array([["a"] * 4] * 3))),
        ("npy_7tib", "npy", "error", lambda p: _npy_raw(big_hdr, bytes(64))),
        ("npy_empty_but_unrepresentable", "npy", "error", lambda p: _npy_raw(
            "{'descr': '<f8', 'fortran_order': False, 'shape': (0, 312, 3695261232714254), }")),
        ("npy_truncated", "npy", "error", lambda p: npy_bytes(log)[:-100]),
        ("npy_bad_version", "npy", "error", lambda p: b"\x93NUMPY\x09\x00" + bytes(64)),
        ("npy_huge_header_len", "npy", "error", lambda p: b"\x93NUMPY\x02\x00\xff\xff\xff\x7f"),
        ("npy_header_not_dict", "npy", "error", lambda p: _npy_raw("[1, 2, 3]")),
        ("npy_header_code", "npy", "error", lambda p: _npy_raw("__import__('os').system('x')")),
        ("npy_bool_shape", "npy", "error", lambda p: _npy_raw(
            "{'descr': '<f8', 'fortran_order': False, 'shape': (True, 4), }", bytes(64))),
        ("npy_nan", "npy", "error", lambda p: npy_bytes(np.where(log == log[3, 2], np.nan, log))),
        ("npy_one_row", "npy", "error", lambda p: npy_bytes(log[:1])),
        ("npy_int", "npy", "any", lambda p: npy_bytes((log * 1000).astype(np.int64))),
        ("npy_fortran", "npy", "ok", lambda p: npy_bytes(np.asfortranarray(log))),
        ("npy_bigendian", "npy", "ok", lambda p: npy_bytes(log.astype(">f8"))),
        ("npy_1e308", "npy", "error", lambda p: npy_bytes(np.where(log == log[5, 1], 1e308, log))),
        # .npz
        ("npz_valid", "npz", "ok", lambda p: _npz({"t": npy_bytes(t), "gyro": npy_bytes(w)})),
        ("npz_nav_valid", "npz", "any", lambda p: _npz(
            {"t": npy_bytes(t), "gyro": npy_bytes(w * 1e-3),
             "accel": npy_bytes(np.tile([0.0, 0.0, -9.81], (t.size, 1)))})),
        ("npz_empty", "npz", "error", lambda p: b""),
        ("npz_empty_but_unrepresentable", "npz", "error", lambda p: _npz(
            {"t": _npy_raw("{'descr': '<f8', 'fortran_order': False, "
                           "'shape': (0, 312, 3695261232714254), }"),
             "gyro": npy_bytes(w)}, zipfile.ZIP_STORED)),
        ("npz_broken_zip", "npz", "error", lambda p: _npz(
            {"t": npy_bytes(t), "gyro": npy_bytes(w)})[:-30]),
        ("npz_not_zip", "npz", "error", lambda p: b"PK\x03\x04 not really a zip" * 4),
        ("npz_encrypted", "npz", "error", lambda p: _set_local_flag(
            _npz({"t": npy_bytes(t), "gyro": npy_bytes(w)}), flag=1)),
        ("npz_unknown_compression", "npz", "error", lambda p: _set_local_flag(
            _npz({"t": npy_bytes(t), "gyro": npy_bytes(w)}), method=99)),
        ("npz_time_column", "npz", "error", lambda p: _npz(
            {"t": npy_bytes(t[:, None]), "gyro": npy_bytes(w)})),
        ("npz_missing_gyro", "npz", "error", lambda p: _npz({"t": npy_bytes(t)})),
        ("npz_structured", "npz", "error", lambda p: _npz(
            {"t": npy_bytes(t), "gyro": npy_bytes(np.zeros(3, dtype=[("x", "f8")]))})),
        ("npz_object", "npz", "error", lambda p: _npz({"t": npy_bytes(t), "gyro": _npy_raw(
            "{'descr': '|O', 'fortran_order': False, 'shape': (3,), }", b"\x80\x04N.")})),
        ("npz_complex", "npz", "error", lambda p: _npz(
            {"t": npy_bytes(t), "gyro": npy_bytes(w.astype(complex))})),
        ("npz_bomb", "npz", "error", lambda p: _zip_bomb(300_000_000)),
        ("npz_crc", "npz", "error", lambda p: _flip_in_member(
            _npz({"t": npy_bytes(t), "gyro": npy_bytes(w)}, zipfile.ZIP_STORED))),
        ("npz_lengths_differ", "npz", "error", lambda p: _npz(
            {"t": npy_bytes(t[:10]), "gyro": npy_bytes(w)})),
        # .mat
        ("mat_valid", "mat", "ok", lambda p: mat_v5(_broad_vars())),
        ("mat_valid_compressed", "mat", "ok", lambda p: mat_v5(_broad_vars(), compress=True)),
        ("mat_empty", "mat", "error", lambda p: b""),
        ("mat_text", "mat", "error", lambda p: b"imu_gyr = [1 2 3];\n"),
        ("mat_header_only", "mat", "error", lambda p: mat_v5([])),
        ("mat_corrupt_zlib", "mat", "error", lambda p: _corrupt_zlib(
            mat_v5(_broad_vars(), compress=True))),
        ("mat_truncated", "mat", "error", lambda p: mat_v5(_broad_vars())[:700]),
        ("mat_truncated_z", "mat", "error", lambda p: mat_v5(_broad_vars(), compress=True)[:300]),
        ("mat_vector_rate", "mat", "error", lambda p: mat_v5(
            [*_broad_vars()[:-1], _mat_matrix("sampling_rate", np.array([[100.0, 200.0]]))])),
        ("mat_huge_rate", "mat", "error", lambda p: mat_v5(
            [*_broad_vars()[:-1], _mat_matrix("sampling_rate", np.array([[1e+308]]))])),
        ("mat_struct", "mat", "error", lambda p: mat_v5(
            [_mat_matrix("imu_gyr", cls=2, dims=(1, 1), data=b""), *_broad_vars()[1:]])),
        ("mat_complex", "mat", "error", lambda p: mat_v5(
            [_mat_matrix("imu_gyr", w, flags=2048), *_broad_vars()[1:]])),
        ("mat_char", "mat", "error", lambda p: mat_v5(
            [_mat_matrix("imu_gyr", cls=4, dims=(1, 3), data=b"a\x00b\x00c\x00", dtype_code=4),
             *_broad_vars()[1:]])),
        ("mat_dims_lie", "mat", "error", lambda p: mat_v5(
            [_mat_matrix("imu_gyr", w, dims=(64000, 3)), *_broad_vars()[1:]])),
        ("mat_negative_dims", "mat", "error", lambda p: mat_v5(
            [_mat_matrix("imu_gyr", w, dims=(-64, 3)), *_broad_vars()[1:]])),
        ("mat_empty_but_unrepresentable", "mat", "error", lambda p: mat_v5(
            [_mat_matrix("imu_gyr", dims=(0, 2**31 - 1, 2**31 - 1, 2**31 - 1), data=b""),
             *_broad_vars()[1:]])),
        ("mat_v4", "mat", "error", _v4),
        ("mat_v73_valid", "mat", "ok", lambda p: _v73(
            p, {"imu_gyr": w.T, "sampling_rate": np.array([[1000.0]])})),
        ("mat_v73_char", "mat", "error", lambda p: _v73(
            p, {"imu_gyr": np.zeros((3, 4), np.uint16), "sampling_rate": np.array([[1.0]])},
            {"imu_gyr": "char"})),
        ("mat_bomb", "mat", "error", lambda p: _mat_bomb()),
        ("mat_big_endian_garbage", "mat", "error", lambda p: b"MATLAB".ljust(124) + b"\x01\x00MI"
         + bytes(64)),
        # HDF5
        ("h5_valid", "h5", "ok", lambda p: _h5(p, _h5_log)),
        ("h5_not_hdf5", "h5", "error", lambda p: b"this is not an HDF5 file\n" * 10),
        ("h5_empty", "h5", "error", lambda p: b""),
        ("h5_strings", "h5", "error", lambda p: _h5(p, _h5_strings)),
        ("h5_vlen", "h5", "error", lambda p: _h5(p, _h5_vlen)),
        ("h5_reference", "h5", "error", lambda p: _h5(p, _h5_ref)),
        ("h5_null", "h5", "error", lambda p: _h5(p, _h5_null)),
        ("h5_dangling", "h5", "error", lambda p: _h5(p, _h5_dangling)),
        ("h5_compound", "h5", "error", lambda p: _h5(p, _h5_compound)),
        ("h5_group", "h5", "error", lambda p: _h5(p, _h5_group)),
        ("h5_bomb", "h5", "error", lambda p: _h5(p, _h5_bomb)),
        ("h5_truncated", "h5", "error", lambda p: _h5_then(p, _h5_log, lambda b: b[:600])),
        # CSV
        ("csv_valid", "csv", "ok", lambda p: _csv(t, w, "t,gx[rad/s],gy[rad/s],gz[rad/s]")),
        ("ahrs_csv_valid", "csv", "ok", lambda p: _ahrs_csv()),
        ("csv_huge_header_cell", "csv", "error", lambda p: ("t," + "g" * 131_073 + ",gy,gz\n"
                                                             "0,1,2,3\n").encode()),
        ("csv_1e308", "csv", "error", lambda p: _csv(t, np.where(w == w[7, 0], 1e308, w))),
        ("csv_5e-324_step", "csv", "error", lambda p: _csv(np.array([0.0, 5e-324, 1e-323,
                                                                     1.5e-323]), w[:4])),
        ("ahrs_csv_5e-324_step", "csv", "error", lambda p: _ahrs_csv(
            4, t=np.array([0.0, 5e-324, 1e-323, 1.5e-323]))),
        ("ahrs_csv_1e300_apart", "csv", "error", lambda p: _ahrs_csv(8, h=1e300)),
        ("ahrs_csv_1e300_acc", "csv", "error", lambda p: _ahrs_csv(
            64, acc=np.where(np.arange(64)[:, None] == 9, 1e300, np.tile([0, 0, 9.81], (64, 1))))),
        ("csv_nan", "csv", "error", lambda p: _csv(t, np.where(w == w[3, 1], np.nan, w))),
        ("csv_binary", "csv", "error", lambda p: b"\x93NUMPY\x01\x00\xff\xfe binary\x00\x01"),
        ("csv_one_row", "csv", "error", lambda p: _csv(t[:1], w[:1])),
        ("csv_header_only", "csv", "error", lambda p: b"t,gx,gy,gz\n"),
        ("csv_empty", "csv", "error", lambda p: b""),
        ("csv_ragged", "csv", "error", lambda p: b"t,gx,gy,gz\n0,1,2,3\n0.001,1,2\n"),
        ("csv_words", "csv", "error", lambda p: b"t,gx,gy,gz\n0,one,2,3\n0.001,1,2,3\n"),
        ("csv_complex", "csv", "error", lambda p: b"t,gx,gy,gz\n0,1+2j,2,3\n0.001,1,2,3\n"),
        ("csv_nul", "csv", "error", lambda p: b"t,g\x00x,gy,gz\n0,1,2,3\n0.001,1,2,3\n"),
        ("csv_backwards", "csv", "error", lambda p: _csv(t[::-1], w)),
        ("csv_huge_times", "csv", "error", lambda p: _csv(t * 1e308, w)),
        ("csv_overflow_step", "csv", "error", lambda p: _csv(np.array([-1.7e308, 1.7e308]),
                                                             w[:2])),
        ("csv_bom_crlf", "csv", "ok", lambda p: b"\xef\xbb\xbf" + _csv(
            t, w, "t,gx[rad/s],gy[rad/s],gz[rad/s]").replace(b"\n", b"\r\n")),
        ("csv_semicolon", "csv", "ok", lambda p: _csv(
            t, w, "t,gx[rad/s],gy[rad/s],gz[rad/s]").replace(b",", b";")),
        ("csv_tab", "csv", "ok", lambda p: _csv(
            t, w, "t,gx[rad/s],gy[rad/s],gz[rad/s]").replace(b",", b"\t")),
        ("csv_latin1", "csv", "error", lambda p: "t,gx[°/s],gy,gz\n0,1,2,3\n".encode("latin-1")),
        ("csv_quotes", "csv", "error", lambda p: b'"t,gx,gy,gz\n0,1,2,3\n'),
        # TOML scenarios
        ("toml_valid", "toml", "ok", lambda p: _toml()),
        ("toml_gyro_5", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            "seed = 1", "seed = 1\ngyro = 5"))),
        ("toml_grid_float", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            "seed = 1", "seed = 1\ngrid = 1.0"))),
        ("toml_string_angle", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            "half_angle_deg = 1.0", 'half_angle_deg = "1.0"'))),
        ("toml_list_noise", "toml", "error", lambda p: _toml("[gyro]\nwhite_noise = [1e-6]\n")),
        ("toml_nan_noise", "toml", "error", lambda p: _toml("[gyro]\nwhite_noise = nan\n")),
        ("toml_rate_1e308", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            "sample_rate_hz = 200.0", "sample_rate_hz = 1e308"))),
        ("toml_nested", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            'algorithms = ["rotvec:N=2"]', "algorithms = " + "[" * 100_000 + "]" * 100_000))),
        ("toml_coefficients_table", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            'algorithms = ["rotvec:N=2"]', 'algorithms = ["rotvec:N=2"]\n').replace(
            "[sensor]", "[run]\ncoefficients = {a = 1}\n[sensor]"))),
        ("toml_half_angle_1e308", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            "half_angle_deg = 1.0", "half_angle_deg = 1e308"))),
        ("toml_grid_1e12", "toml", "error", lambda p: _toml(
            "[grid]\n" + "".join(f"{k} = [{', '.join(str(1.0 + i) for i in range(1000))}]\n"
                                 for k in ("cone_rate_hz", "half_angle_deg", "duration",
                                           "spin_rate_dps")))),
        ("toml_grid_bad_value", "toml", "error", lambda p: _toml(
            '[grid]\nspin_rate_dps = [0.0, "fast"]\n')),
        ("toml_bad_utf8", "toml", "error", lambda p: _toml().replace(b"coning", b"con\xffing")),
        ("toml_not_toml", "toml", "error", lambda p: b"algorithms = [\n"),
        ("toml_seed_float", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            "seed = 1", "seed = 1.5"))),
        ("toml_misalignment", "toml", "error", lambda p: _toml("[gyro]\nmisalignment = 3\n")),
        ("toml_bias_list", "toml", "ok", lambda p: _toml("[gyro]\nbias = [1e-6, 0.0, 0.0]\n")),
        ("toml_duration_huge", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            "duration = 0.5", "duration = 1e12"))),
        ("toml_krylov_string", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            'motion = "coning"', 'motion = "krylov"\nkrylov_rates = ["a", 1, 2]'))),
        ("toml_cone_rate_huge", "toml", "error", lambda p: _toml("", _SCENARIO.replace(
            "half_angle_deg = 1.0", "half_angle_deg = 1.0\ncone_rate_hz = 1e300"))),
    ]
    return e


def _flip_in_member(data: bytes) -> bytes:
    b = bytearray(data)
    i = b.find(b"gyro.npy")
    b[i + 200] ^= 0xFF
    return bytes(b)


def _corrupt_zlib(data: bytes) -> bytes:
    b = bytearray(data)
    for i in range(140, min(len(b), 400), 37):
        b[i] ^= 0x5A
    return bytes(b)


def _mat_bomb() -> bytes:
    """A compressed variable of 300 MB of zeros (deflate ~1000:1, ~300 kB on disk)."""
    n = 12_500_000
    head = _mat_elem(6, struct.pack("<II", 6, 0)) + _mat_elem(5, struct.pack("<2i", n, 3))
    head += _mat_elem(1, b"imu_gyr")
    prefix = struct.pack("<II", 14, len(head) + 8 + n * 24) + head + struct.pack("<II", 9, n * 24)
    c, _ = _deflate_zeros(prefix, n * 24, raw=False)
    return (b"MATLAB 5.0 MAT-file, bomb".ljust(116) + b"\0" * 8 + b"\x00\x01IM"
            + struct.pack("<II", 15, len(c)) + c)


def _v4(p: Path) -> None:
    from scipy.io import savemat

    _t, w = _log()
    savemat(p, {"imu_gyr": w}, format="4")


def _h5_then(p: Path, build: Callable, cut: Callable[[bytes], bytes]) -> bytes:
    _h5(p, build)
    return cut(p.read_bytes())


_SUFFIX = {"csv": ".csv", "npy": ".npy", "npz": ".npz", "mat": ".mat", "h5": ".h5",
           "toml": ".toml"}


def build(d: Path) -> list[Entry]:
    """Write every corpus file into ``d``; returns the entries."""
    d.mkdir(parents=True, exist_ok=True)
    out = []
    for name, fmt, expect, make in _entries():
        path = d / (name + _SUFFIX[fmt])
        data = make(path)
        if data is not None:
            path.write_bytes(data)
        target = {"csv": "read_imu rate", "npy": "read_imu rate", "npz": "read_imu rate",
                  "mat": "read_imu rate", "h5": "read_imu rate", "toml": "load_scenario"}[fmt]
        if name.startswith("ahrs_"):
            target = "read_ahrs_log"
        out.append(Entry(name, fmt, path, expect, target))
    return out
