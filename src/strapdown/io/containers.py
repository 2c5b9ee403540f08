"""Binary containers read without trusting them: ``.npy``, ``.npz``, MATLAB ``.mat`` and HDF5.

Every reader here validates the container's structure before it allocates or decodes
anything, and turns whatever is wrong into an :class:`~strapdown._core.errors.InputError`
naming the file (never a third-party exception, never a crash of the process):

``.npy``
    The header is parsed here (magic, version, length ≤ 64 kiB, a literal dict with
    ``descr``, ``fortran_order``, ``shape``): only plain real numeric dtypes (no structured,
    object, string or complex data — nothing that could need pickle), non-negative
    dimensions, and data that fits in the file; then the array is memory-mapped.
``.npz``
    The zip directory is read by :mod:`zipfile` from a file we opened; encrypted members
    and compression other than stored or deflate are refused; each member's declared size
    is checked against the memory budget and the inflation ratio
    (:mod:`strapdown._core.limits`) and it is inflated in chunks, never past that size.
MATLAB v5 (``-v6``/``-v7``)
    **Parsed here, not by scipy**: a byte-flipped uncompressed ``.mat`` made scipy's
    reader crash the process (SIGSEGV/SIGBUS). The parser checks every tag against the
    bytes that contain it (a variable inside the file, a sub-element inside its variable),
    reads only the numeric matrices asked for (double, single, integer; not complex,
    sparse, cell, struct, char or object — those are an error naming the variable) and
    inflates compressed variables in chunks against the budget and the ratio.
MATLAB v7.3 and HDF5
    Read through h5py **in a guarded child process** (:mod:`strapdown.io._hdf5_child`):
    libhdf5 is C code we cannot validate a file for, so a file that crashes it ends the
    child, not us, and becomes an error. The child checks each dataset (numeric, not
    null, not a reference or variable-length type, within the budget and ratio) before
    reading it, runs under an address-space limit and a time limit. MATLAB v7.3 variables
    are transposed back to MATLAB's shape. MAT v4 is refused with how to convert.
"""

from __future__ import annotations

import ast
import io
import json
import math
import os
import struct
import subprocess
import sys
import zipfile
import zlib
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Literal, cast

import numpy as np
from numpy.typing import NDArray

from strapdown._core.errors import InputError, shown
from strapdown._core.limits import check_bytes, check_ratio, max_bytes, max_ratio

__all__ = ["Arrays", "NpyHeader", "open_npy", "read_hdf5", "read_mat", "read_npy_header",
           "read_npz"]

_NPY_MAGIC = b"\x93NUMPY"
_HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"
_MAX_HEADER = 65536
_CHUNK = 1 << 20
_MAX_NAMES = 30  # names listed in a message


@dataclass(frozen=True)
class Arrays:
    """What a container gave: the arrays asked for that it holds, every name it holds (for
    messages) and, for HDF5, the root attributes asked for."""

    arrays: dict[str, NDArray[Any]]
    names: list[str]
    attrs: dict[str, NDArray[Any]] = field(default_factory=dict)

    def found(self) -> str:
        """The names it holds, for a message (at most 30, elided)."""
        more = len(self.names) - _MAX_NAMES
        return shown(self.names[:_MAX_NAMES], 200) + (f" and {more} more" if more > 0 else "")


def _numeric_dtype(where: object, what: str, dt: np.dtype) -> np.dtype:
    """``dt`` if it is plain real numbers (bool, integer, float); else an InputError."""
    if dt.fields is not None or dt.subdtype is not None:
        raise InputError(f"{where}: {what} has a structured dtype; expected a plain numeric "
                         "array")
    if dt.kind == "c":
        raise InputError(f"{where}: {what} holds complex numbers; a log holds real numbers")
    if dt.kind not in "biuf" or dt.itemsize > 16:
        raise InputError(f"{where}: {what} holds {dt.name if dt.kind != 'O' else 'objects'}; "
                         "expected numbers")
    return dt


# ------------------------------------------------------------------------------------ .npy
@dataclass(frozen=True)
class NpyHeader:
    """A validated ``.npy`` header: dtype, shape, order and where the data starts."""

    dtype: np.dtype
    shape: tuple[int, ...]
    fortran: bool
    offset: int

    @property
    def nbytes(self) -> int:
        return math.prod(self.shape) * self.dtype.itemsize


def _exact(f: IO[bytes], n: int, where: object, what: str) -> bytes:
    data = f.read(n)
    if len(data) != n:
        raise InputError(f"{where}: truncated {what} ({len(data)} of {n} bytes)")
    return data


def read_npy_header(f: IO[bytes], where: object, what: str = "array") -> NpyHeader:
    """Parse and check the ``.npy`` header at ``f``'s position (see the module docstring)."""
    magic = f.read(8)
    if len(magic) < 8 or magic[:6] != _NPY_MAGIC:
        empty = "an empty file" if not magic else "not a .npy array"
        raise InputError(f"{where}: {empty} (no NumPy magic); expected an array saved by "
                         "numpy.save")
    major = magic[6]
    if major not in (1, 2, 3):
        raise InputError(f"{where}: .npy format version {major}.{magic[7]} is not known")
    size_bytes = 2 if major == 1 else 4
    (hlen,) = struct.unpack("<H" if major == 1 else "<I",
                            _exact(f, size_bytes, where, "header"))
    if hlen > _MAX_HEADER:
        raise InputError(f"{where}: .npy header of {hlen} bytes (at most {_MAX_HEADER})")
    raw = _exact(f, hlen, where, "header")
    try:
        text = raw.decode("utf-8" if major == 3 else "latin-1")
        d = ast.literal_eval(text)
    except (SyntaxError, ValueError, TypeError, MemoryError, RecursionError, UnicodeError):
        raise InputError(f"{where}: unreadable .npy header {shown(raw, 80)}") from None
    if not isinstance(d, dict) or set(d) != {"descr", "fortran_order", "shape"}:
        raise InputError(f"{where}: the .npy header must be a dict of descr, fortran_order and "
                         f"shape, got {shown(d, 80)}")
    dtype, shape = _npy_dtype(where, what, d["descr"]), _npy_shape(where, d["shape"])
    if not _representable(shape, dtype):
        raise InputError(f"{where}: the .npy shape {shown(shape, 60)} of {dtype.name} is "
                         "larger than any array can be")
    return NpyHeader(dtype, shape, _npy_order(where, d["fortran_order"]), 8 + size_bytes + hlen)


def _representable(shape: tuple[int, ...], dtype: np.dtype) -> bool:
    """Whether numpy can make an array of ``shape`` (non-negative) and ``dtype``: it refuses
    one whose nonzero dimensions overflow its index type even when a zero dimension leaves
    it empty — (0, 312, 3.7e15) is no array at all (a .npy header, a MAT-file's
    dimensions)."""
    return math.prod(max(n, 1) for n in shape) * dtype.itemsize <= np.iinfo(np.intp).max


def _npy_dtype(where: object, what: str, descr: object) -> np.dtype:
    if not isinstance(descr, str):
        raise InputError(f"{where}: {what} has a structured dtype {shown(descr, 60)}; "
                         "expected a plain numeric array")
    try:
        dt = np.dtype(descr)
    except (TypeError, ValueError, SyntaxError):
        raise InputError(f"{where}: unknown dtype {shown(descr, 40)} in the .npy header"
                         ) from None
    return _numeric_dtype(where, what, dt)


def _npy_shape(where: object, shape: object) -> tuple[int, ...]:
    if (not isinstance(shape, tuple) or len(shape) > 32
            or not all(isinstance(n, int) and not isinstance(n, bool) for n in shape)):
        raise InputError(f"{where}: the .npy shape {shown(shape, 60)} is not a tuple of "
                         "integers")
    if any(n < 0 for n in shape):
        raise InputError(f"{where}: the .npy shape {shown(shape, 60)} has a negative "
                         "dimension")
    return shape


def _npy_order(where: object, fortran: object) -> bool:
    if not isinstance(fortran, bool):
        raise InputError(f"{where}: fortran_order must be True or False, got "
                         f"{shown(fortran, 30)}")
    return fortran


def open_npy(path: str | os.PathLike[str]) -> NDArray[Any]:
    """The array of a ``.npy`` file, memory-mapped read-only once its header is checked
    and its data is known to fit in the file (a real numeric dtype, any shape)."""
    path = Path(path)
    with open(path, "rb") as f:
        hdr = read_npy_header(f, path)
        size = os.fstat(f.fileno()).st_size
    if hdr.offset + hdr.nbytes > size:
        raise InputError(f"{path}: truncated .npy: the header declares {hdr.shape} "
                         f"{hdr.dtype.name} ({hdr.nbytes} bytes), the file holds "
                         f"{max(size - hdr.offset, 0)}")
    order: Literal["C", "F"] = "F" if hdr.fortran else "C"
    if hdr.nbytes == 0:
        return np.empty(hdr.shape, hdr.dtype, order=order)
    if not hdr.shape:
        with open(path, "rb") as f:
            f.seek(hdr.offset)
            return np.frombuffer(f.read(hdr.dtype.itemsize), hdr.dtype).reshape(())
    return np.memmap(path, dtype=hdr.dtype, mode="r", offset=hdr.offset,
                     shape=tuple(hdr.shape), order=order)


# ------------------------------------------------------------------------------------ .npz
_ZIP_ERRORS = (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, ValueError, struct.error,
               zlib.error, NotImplementedError, RuntimeError, OSError, IndexError, KeyError,
               OverflowError, UnicodeError)


def read_npz(path: str | os.PathLike[str], names: Iterable[str]) -> Arrays:
    """The arrays ``names`` of a ``.npz`` archive that it holds (see the module docstring)."""
    path = Path(path)
    wanted = list(names)
    with open(path, "rb") as fh:
        size = os.fstat(fh.fileno()).st_size
        if size == 0:
            raise InputError(f"{path}: an empty file; expected a .npz archive (numpy.savez)")
        try:
            zf = zipfile.ZipFile(fh)
            members = {i.filename[:-4]: i for i in zf.infolist() if i.filename.endswith(".npy")}
        except _ZIP_ERRORS as exc:
            raise InputError(f"{path}: not a readable .npz archive ({shown(str(exc), 120)})"
                             ) from None
        with zf:
            out: dict[str, NDArray[Any]] = {}
            total = 0
            for name in wanted:
                if name in members:
                    out[name] = _npz_member(path, zf, members[name], total)
                    total += out[name].nbytes
    return Arrays(out, sorted(members))


def _npz_member(path: Path, zf: zipfile.ZipFile, info: zipfile.ZipInfo,
                used: int) -> NDArray[Any]:
    what = f"array {info.filename[:-4]!r}"
    if info.flag_bits & 0x1:
        raise InputError(f"{path}: {what} is encrypted; numpy archives are not")
    if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
        raise InputError(f"{path}: {what} uses zip compression method {info.compress_type}; "
                         "numpy archives are stored or deflated")
    check_ratio(path, info.file_size, info.compress_size, what)
    check_bytes(path, used + info.file_size, what)
    try:
        with zf.open(info) as f:
            hdr = read_npy_header(f, f"{path} ({what})", what)
            if hdr.offset + hdr.nbytes > info.file_size:
                raise InputError(f"{path}: {what} declares {hdr.shape} {hdr.dtype.name}, more "
                                 f"than its {info.file_size} bytes")
            arr = np.empty(math.prod(hdr.shape), hdr.dtype)
            buf = memoryview(arr.view(np.uint8).reshape(-1).data)
            pos = 0
            while pos < hdr.nbytes:
                n = cast(io.BufferedIOBase, f).readinto(buf[pos:pos + _CHUNK])
                if not n:
                    raise InputError(f"{path}: {what} is truncated")
                pos += n
            while f.read(_CHUNK):  # the rest, so that the CRC is checked
                pass
    except InputError:
        raise
    except _ZIP_ERRORS as exc:
        raise InputError(f"{path}: {what} is unreadable ({shown(str(exc), 120)})") from None
    return arr.reshape(hdr.shape, order="F" if hdr.fortran else "C")


# ------------------------------------------------------------------------------------ .mat
_MI = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 9: "f8", 12: "i8",
       13: "u8"}
_MATRIX, _COMPRESSED = 14, 15
_CLASSES = {1: "cell array", 2: "struct", 3: "object", 4: "char array", 5: "sparse matrix",
            16: "function handle", 17: "opaque object"}
_NUMERIC_CLASSES = range(6, 16)


class _Bounded:
    """Bytes ``read`` from a source, at most ``size`` of them (a variable or sub-element)."""

    def __init__(self, read, size: int, where: object) -> None:
        self._read, self.left, self.where = read, size, where

    def read(self, n: int) -> bytes:
        if n > self.left:
            raise InputError(f"{self.where}: a MAT-file element runs past its variable "
                             f"({n} bytes wanted, {self.left} left): the file is corrupt")
        self.left -= n
        return self._read(n)


class _Inflater:
    """A compressed variable's bytes, inflated on demand in chunks, at most ``cap`` of them."""

    def __init__(self, data: bytes, cap: int, where: object) -> None:
        self._d = zlib.decompressobj()
        self._src, self._pos, self._buf = data, 0, bytearray()
        self.cap, self.where = cap, where

    def read(self, n: int) -> bytes:
        if n > self.cap:
            raise InputError(f"{self.where}: a compressed variable declares more data than "
                             "its checked size: the file is corrupt")
        self.cap -= n
        out = bytearray()
        while len(out) < n:
            if not self._buf:
                self._more()
            take = min(n - len(out), len(self._buf))
            out += self._buf[:take]
            del self._buf[:take]
        return bytes(out)

    def _more(self) -> None:
        if self._d.eof or self._pos >= len(self._src):
            raise InputError(f"{self.where}: a compressed variable ends early: the file is "
                             "truncated or corrupt")
        piece = self._src[self._pos:self._pos + 16384]
        self._pos += len(piece)
        try:
            self._buf += self._d.decompress(piece, 0)
        except zlib.error as exc:
            raise InputError(f"{self.where}: a compressed variable is corrupt ({exc})"
                             ) from None


def _mat_tag(s, e: str, where: object) -> tuple[int, int, bytes | None]:
    """``(type, nbytes, data of a small element or None)``."""
    t, n = struct.unpack(e + "II", s.read(8))
    if t >> 16:  # small data element: nbytes in the upper half, data in the next 4 bytes
        size, t = t >> 16, t & 0xFFFF
        if size > 4:
            raise InputError(f"{where}: a small MAT-file element of {size} bytes: corrupt")
        return t, size, struct.pack(e + "I", n)[:size]
    return t, n, None


def _mat_sub(s, e: str, where: object, want: tuple[int, ...] | None, what: str
             ) -> tuple[int, bytes]:
    """A sub-element's type and data (padding skipped); its type must be among ``want``."""
    t, n, small = _mat_tag(s, e, where)
    if want is not None and t not in want:
        raise InputError(f"{where}: the {what} of a variable has MAT type {t}: the file is "
                         "corrupt")
    if small is not None:
        return t, small
    data = s.read(n)
    s.read((-n) % 8)
    return t, data


def _mat_matrix(s, e: str, where: object, wanted: set[str]
                ) -> tuple[str, NDArray[np.float64] | None]:
    """``(name, array)`` of one miMATRIX element; array None when not wanted."""
    _, flags = _mat_sub(s, e, where, (6,), "array flags")
    if len(flags) != 8:
        raise InputError(f"{where}: array flags of {len(flags)} bytes: the file is corrupt")
    word = struct.unpack(e + "I", flags[:4])[0]
    cls, complex_ = word & 0xFF, word & 0x800
    _, dims_raw = _mat_sub(s, e, where, (5,), "dimensions")
    if len(dims_raw) % 4 or not 2 <= len(dims_raw) // 4 <= 32:
        raise InputError(f"{where}: {len(dims_raw)} bytes of dimensions: the file is corrupt")
    dims = struct.unpack(f"{e}{len(dims_raw) // 4}i", dims_raw)
    _, raw_name = _mat_sub(s, e, where, (1, 2), "name")
    name = raw_name.decode("latin-1")
    if name not in wanted:
        return name, None
    what = f"variable {shown(name, 40)}"
    if cls not in _NUMERIC_CLASSES:
        raise InputError(f"{where}: {what} is a {_CLASSES.get(cls, f'MAT class {cls}')}; "
                         "expected a numeric matrix")
    if complex_:
        raise InputError(f"{where}: {what} holds complex numbers; a log holds real numbers")
    if any(d < 0 for d in dims):
        raise InputError(f"{where}: {what} has negative dimensions {dims}: the file is corrupt")
    count = math.prod(dims)
    check_bytes(where, count * 8, what)
    t, data = _mat_sub(s, e, where, tuple(_MI), f"data of {what}")
    dt = np.dtype(e + _MI[t])
    if not _representable(dims, dt):
        raise InputError(f"{where}: {what} has dimensions {dims}, larger than any array can "
                         "be: the file is corrupt")
    if len(data) != count * dt.itemsize:
        raise InputError(f"{where}: {what} declares {'x'.join(map(str, dims))} values, its data "
                         f"holds {len(data) // dt.itemsize}: the file is corrupt")
    return name, np.frombuffer(data, dt).reshape(dims, order="F").astype(np.float64)


def _looks_v4(head: bytes) -> bool:
    """A MAT v4 matrix header: type MOPT (M 0 little- or 1 big-endian), rows, columns,
    imaginary flag 0/1 and a name length of 1–64 (what scipy reads as version 4)."""
    for e in "<>":
        mopt, rows, cols, imag, namlen = struct.unpack(e + "5i", head[:20])
        if (0 <= mopt <= 1052 and mopt // 1000 == (e == ">") and rows >= 0 and cols >= 0
                and imag in (0, 1) and 1 <= namlen <= 64):
            return True
    return False


def _mat_header(f: IO[bytes], path: Path) -> str:
    """The byte order of a v5 MAT-file (``<`` or ``>``); other kinds are refused."""
    head = f.read(128)
    if not head:
        raise InputError(f"{path}: an empty file; expected a MATLAB .mat file")
    if head[:8] == _HDF5_MAGIC:
        raise InputError(f"{path}: an HDF5 file named .mat; use .h5 (or save with -v7.3)")
    if len(head) >= 20 and _looks_v4(head):
        raise InputError(f"{path}: a MAT v4 file; re-save it in MATLAB with save(file, '-v7') "
                         "or with scipy.io.savemat(file, data)")
    if len(head) < 128:
        raise InputError(f"{path}: {len(head)} bytes is too short for a MATLAB .mat file")
    endian = {b"IM": "<", b"MI": ">"}.get(head[126:128])
    if endian is None or struct.unpack(endian + "H", head[124:126])[0] != 0x0100:
        raise InputError(f"{path}: not a MATLAB v5/v7 or v7.3 .mat file (no MAT-file header)")
    return endian


def read_mat(path: str | os.PathLike[str], names: Iterable[str]) -> Arrays:
    """The numeric variables ``names`` of a MATLAB ``.mat`` file that it holds, as 2-D (or
    higher) float64 arrays in MATLAB's shape (see the module docstring)."""
    path = Path(path)
    wanted = set(names)
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        if size >= 520:
            f.seek(512)
            if f.read(8) == _HDF5_MAGIC:  # MATLAB v7.3: an HDF5 file with a 512-byte block
                return read_hdf5(path, wanted, matlab=True)
            f.seek(0)
        e = _mat_header(f, path)
        out: dict[str, NDArray[np.float64]] = {}
        found: list[str] = []
        pos = 128
        while pos + 8 <= size:
            f.seek(pos)
            t, n = struct.unpack(e + "II", _exact(f, 8, path, "variable tag"))
            end = pos + 8 + n
            if end > size:
                raise InputError(f"{path}: truncated: a variable of {n} bytes at byte {pos} runs "
                                 f"past the end of the file ({size} bytes)")
            if n == 0:  # an empty element: nothing to read
                name, arr = "", None
            elif t == _COMPRESSED:
                name, arr = _mat_compressed(f, n, e, path, wanted)
            elif t == _MATRIX:
                name, arr = _mat_matrix(_Bounded(f.read, n, path), e, path, wanted)
                end += (-n) % 8
            else:
                raise InputError(f"{path}: MAT-file element of type {t} at byte {pos} (expected "
                                 "a variable): the file is corrupt")
            if name:
                found.append(name)
            if arr is not None:
                out[name] = arr
            pos = end
    return Arrays(out, found)


def _mat_compressed(f: IO[bytes], n: int, e: str, path: Path, wanted: set[str]
                    ) -> tuple[str, NDArray[np.float64] | None]:
    check_bytes(path, n, "a compressed variable")
    z = _Inflater(f.read(n), 8, path)
    t, m = struct.unpack(e + "II", z.read(8))
    if t != _MATRIX:
        raise InputError(f"{path}: a compressed element of type {t} (expected a variable): "
                         "the file is corrupt")
    check_ratio(path, m, n, "a compressed variable")
    check_bytes(path, m, "a compressed variable")
    z.cap = m
    return _mat_matrix(z, e, path, wanted)


# ------------------------------------------------------------------------------------ HDF5
def _is_hdf5(path: Path) -> bool:
    """The HDF5 signature at byte 0, 512, 1024, … (a user block before the superblock)."""
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        at = 0
        while at + 8 <= size:
            f.seek(at)
            if f.read(8) == _HDF5_MAGIC:
                return True
            at = 512 if at == 0 else 2 * at
    return False


def read_hdf5(path: str | os.PathLike[str], names: Iterable[str], attrs: Iterable[str] = (),
              *, matlab: bool = False) -> Arrays:
    """The datasets ``names`` (and root attributes ``attrs``) of an HDF5 file that it holds,
    read by h5py in a guarded child process (see the module docstring); ``matlab``: a v7.3
    MAT-file, whose variables are transposed back to MATLAB's shape."""
    path = Path(path)
    try:
        import h5py  # noqa: F401  (the child imports it; say here how to get it)
    except ImportError:
        raise InputError(f"{path}: reading HDF5{' (MATLAB v7.3)' if matlab else ''} needs h5py: "
                         "pip install 'strapdown[hdf5]'") from None
    with open(path, "rb"):  # unreadable: the OSError names the path
        pass
    if not _is_hdf5(path):
        raise InputError(f"{path}: not an HDF5 file (no HDF5 signature)")
    size = path.stat().st_size
    request = {"path": os.fspath(path), "names": sorted(set(names)), "attrs": sorted(set(attrs)),
               "matlab": matlab, "max_bytes": max_bytes(), "max_ratio": max_ratio()}
    timeout = 60.0 + size / 20e6
    try:
        # the script by its path (-P: its folder not on sys.path), not ``-m``: the child needs
        # numpy and h5py only, and importing the package first cost each read ~0.1 CPU-s
        proc = subprocess.run([sys.executable, "-P", str(_HDF5_CHILD)],
                              input=json.dumps(request).encode(), capture_output=True,
                              timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        raise InputError(f"{path}: reading the HDF5 file took longer than {timeout:.0f} s; "
                         "it is corrupt or far larger than it looks") from None
    return _child_result(path, proc, matlab)


#: The guarded reader's script (run in a child process; see :func:`read_hdf5`).
_HDF5_CHILD = Path(__file__).with_name("_hdf5_child.py")


def _child_result(path: Path, proc: subprocess.CompletedProcess, matlab: bool) -> Arrays:
    """The arrays the HDF5 child sent, or the error it reported (or how it died)."""
    if proc.returncode < 0:
        raise InputError(f"{path}: the HDF5 library crashed reading this file (signal "
                         f"{-proc.returncode}): the file is corrupt")
    stream = io.BytesIO(proc.stdout)
    line = stream.readline(1 << 20)
    try:
        meta = json.loads(line)
    except ValueError:
        meta = None
    if proc.returncode != 0 or not isinstance(meta, dict):
        last = proc.stderr.decode("utf-8", "replace").strip().splitlines()[-1:] or ["no message"]
        raise InputError(f"{path}: the HDF5 reader failed ({shown(last[0], 160)}): the file is "
                         "corrupt or not readable")
    if meta.get("error"):
        raise InputError(f"{path}: {meta['error']}")
    out: dict[str, dict[str, NDArray[Any]]] = {"arrays": {}, "attrs": {}}
    for kind, name in meta["sent"]:
        hdr = read_npy_header(stream, path)
        a = np.frombuffer(_exact(stream, hdr.nbytes, path, "array"), hdr.dtype)
        a = a.reshape(hdr.shape).astype(np.float64)
        out[kind][name] = a.T if (matlab and kind == "arrays") else a
    return Arrays(out["arrays"], list(meta["names"]), out["attrs"])
