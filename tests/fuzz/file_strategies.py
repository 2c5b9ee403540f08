"""Hypothesis strategies for hostile input files: CSV text, ``.npy`` headers, ``.npz``
archives, MATLAB v5 variables and TOML scenarios — built from values, so a failing example
shrinks to a small, readable file."""

from __future__ import annotations

import io
import zipfile

import numpy as np
from hypothesis import strategies as st

from fuzz.corpus import _mat_matrix, _npy_raw, mat_v5, npy_bytes

__all__ = ["csv_files", "mat_files", "npy_files", "npz_files", "toml_scenarios"]

_SPECIAL = ["nan", "inf", "-inf", "1e308", "-1e308", "5e-324", "1e999", "0", "-0", "", " ",
            "x", "1e", "0x1p3", "1_000", "١", "NaN", "+1", "1.5.2", "'1'", '"1"']
_HEADER = ["t", "time", "t[ms]", "time_us", "gx", "gy", "gz", "wx", "gx[deg/s]", "gy[rad/s]",
           "gz[°/s]", "ax", "ay", "az", "ax[g]", "mx", "my", "mz", "qw", "qx", "qy", "qz", "",
           "gx[", "gx]", "t[furlong]", "g x", "\ufeff", "é"]


def _cell() -> st.SearchStrategy[str]:
    return st.one_of(
        st.floats(allow_nan=True, allow_infinity=True).map(repr),
        st.integers(-(10**30), 10**30).map(str),
        st.sampled_from(_SPECIAL),
        st.text(st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=8),
    )


@st.composite
def csv_files(draw) -> bytes:
    """A CSV log: a header of known and odd names, rows of numbers and junk, any delimiter,
    line end and an optional BOM (occasionally undecodable bytes)."""
    sep = draw(st.sampled_from([",", ";", "\t", "|", " "]))
    ncol = draw(st.integers(1, 11))
    header = draw(st.lists(st.sampled_from(_HEADER) | st.text(max_size=6), min_size=ncol,
                           max_size=ncol))
    if draw(st.booleans()):
        header[:4] = ["t", "gx", "gy", "gz"][:len(header)]
    rows = draw(st.lists(st.lists(_cell(), min_size=0, max_size=ncol + 1), max_size=12))
    if draw(st.booleans()):  # a well-formed numeric body the header may or may not fit
        n = draw(st.integers(0, 40))
        h = draw(st.sampled_from([1e-3, 1e-2, 5e-324, 1e300, 0.0, -1e-3]))
        rate = draw(st.sampled_from([0.0, 1.0, 20.0, 1e3, 1e308]))
        rows = [[repr(i * h)] + [repr(rate)] * (ncol - 1) for i in range(n)]
    newline = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    text = newline.join([sep.join(header)] + [sep.join(r) for r in rows]) + newline
    data = ("\ufeff" if draw(st.booleans()) else "") + text
    raw = data.encode("utf-8", "surrogatepass")
    if draw(st.integers(0, 9)) == 0:
        raw += draw(st.binary(max_size=16))
    return raw


_DESCR = ["<f8", ">f8", "<f4", "<i8", "|u1", "|b1", "<c16", "|O", "<U3", "|S4", "<M8[s]",
          "V8", "<f16", "f8,f8", "(2,)f8", "bogus", "<m8[ns]"]


@st.composite
def npy_files(draw) -> bytes:
    """A ``.npy`` file with a header of any dtype, order and shape (negative, huge, bool,
    ragged) and a body that may or may not fit it."""
    if draw(st.booleans()):
        shape = draw(st.tuples(st.integers(0, 50), st.integers(0, 6)))
        dtype = draw(st.sampled_from(["<f8", ">f4", "<i4", "|b1"]))
        arr = np.arange(int(np.prod(shape)), dtype=float).reshape(shape).astype(dtype)
        data = npy_bytes(arr)
        cut = draw(st.integers(0, len(data)))
        return data if draw(st.booleans()) else data[:cut]
    descr = draw(st.sampled_from(_DESCR) | st.text(max_size=6).map(repr))
    shape = draw(st.lists(st.integers(-5, 2**62) | st.sampled_from(["True", "1.5", "'a'"]),
                          max_size=4))
    shape_text = "(" + "".join(f"{s}, " for s in shape) + ")"
    fortran = draw(st.sampled_from(["False", "True", "0", "None"]))
    header = (f"{{'descr': {descr if descr.startswith(chr(39)) else repr(descr)}, "
              f"'fortran_order': {fortran}, 'shape': {shape_text}, }}")
    if draw(st.integers(0, 4)) == 0:
        header = header[: draw(st.integers(0, len(header)))]
    return _npy_raw(header, draw(st.binary(max_size=256)),
                    version=draw(st.sampled_from([1, 2, 3])))


@st.composite
def npz_files(draw) -> bytes:
    """A ``.npz``: members named t, gyro and others holding arrays or junk, stored or
    deflated, sometimes cut short."""
    b = io.BytesIO()
    method = draw(st.sampled_from([zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED]))
    with zipfile.ZipFile(b, "w", method) as z:
        for name in draw(st.lists(st.sampled_from(["t", "gyro", "accel", "qw", "x"]),
                                  max_size=4, unique=True)):
            member = draw(npy_files()) if draw(st.booleans()) else npy_bytes(
                np.zeros(draw(st.sampled_from([(5,), (5, 3), (5, 1), (3, 5), (), (0, 3)]))))
            z.writestr(name + ".npy", member)
    data = b.getvalue()
    if draw(st.integers(0, 3)) == 0 and data:
        i = draw(st.integers(0, len(data) - 1))
        data = data[:i] + bytes([data[i] ^ 0xFF]) + data[i + 1:]
    return data


@st.composite
def mat_files(draw) -> bytes:
    """A MATLAB v5 file of variables with any class, dims, data type and data length, each
    possibly compressed."""
    variables = []
    for name in draw(st.lists(st.sampled_from(["imu_gyr", "imu_acc", "sampling_rate", "imu",
                                               "imu_mag", "opt_quat", "movement", "z"]),
                              max_size=6, unique=True)):
        dims = tuple(draw(st.lists(st.integers(-2, 70), min_size=1, max_size=4)))
        n = draw(st.integers(0, 300))
        variables.append(_mat_matrix(
            name, cls=draw(st.sampled_from([6, 6, 6, 7, 9, 2, 4, 5, 1, 99])), dims=dims,
            data=np.arange(n, dtype="<f8").tobytes(),
            dtype_code=draw(st.sampled_from([9, 9, 7, 5, 2, 14, 0, 99])),
            flags=draw(st.sampled_from([0, 0, 0x800, 0x200]))))
    return mat_v5(variables, compress=draw(st.booleans()))


_TOML_VALUE = st.recursive(
    st.one_of(st.integers(-(2**63), 2**63 - 1).map(str), st.floats().map(
        lambda x: "nan" if x != x else ("inf" if x == float("inf") else (
            "-inf" if x == float("-inf") else repr(x)))),
        st.booleans().map(lambda b: "true" if b else "false"),
        st.text(max_size=8).map(lambda s: '"' + s.replace("\\", "").replace('"', "")
                                .replace("\n", "") + '"')),
    lambda inner: st.lists(inner, max_size=4).map(lambda xs: "[" + ", ".join(xs) + "]"),
    max_leaves=10)
_KEYS = ["half_angle_deg", "cone_rate_hz", "spin_rate_dps", "sample_rate_hz", "duration",
         "subsamples", "coefficients", "structure", "krylov_rates", "precision", "motion",
         "alpha", "step", "exact_exp"]
_GYRO = ["white_noise", "bias", "gm_sigma", "gm_tau", "scale_factor", "misalignment",
         "quantization", "saturation"]


@st.composite
def toml_scenarios(draw) -> bytes:
    """A scenario whose sections hold values of any TOML type for the real keys."""
    algorithms = draw(st.sampled_from(['["rotvec:N=2"]', '["rk4"]', "[]", "5", "[1]",
                                       '["rotvec:N=2", "rotvec:N=2"]', '["nope"]']))
    lines = [f"algorithms = {algorithms}", 'metrics = ["max_error_rad"]',
             f"seed = {draw(_TOML_VALUE)}",
             "[sensor]", "sample_rate_hz = 200.0", "duration = 0.3", "[motion]"]
    for k in draw(st.lists(st.sampled_from(_KEYS), max_size=3, unique=True)):
        lines.append(f"{k} = {draw(_TOML_VALUE)}")
    if draw(st.booleans()):
        lines.append("[gyro]")
        for k in draw(st.lists(st.sampled_from(_GYRO), max_size=3, unique=True)):
            lines.append(f"{k} = {draw(_TOML_VALUE)}")
    if draw(st.booleans()):
        lines.append("[grid]")
        for k in draw(st.lists(st.sampled_from(_KEYS + [f'"gyro.{g}"' for g in _GYRO]),
                               max_size=2, unique=True)):
            lines.append(f"{k} = {draw(_TOML_VALUE)}")
    return "\n".join(lines).encode("utf-8", "surrogatepass")
