"""The guarded HDF5 reader: run as ``python -P .../strapdown/io/_hdf5_child.py`` by
:func:`strapdown.io.containers.read_hdf5` (by its path: it imports nothing of the package),
never imported by the library.

Reads one JSON request on stdin (``path``, dataset ``names``, root ``attrs``, ``matlab``,
``max_bytes``, ``max_ratio``) and writes one JSON line — ``names`` (the file's top-level
names), ``sent`` (``[kind, name]`` of each array that follows) or ``error`` (what is wrong,
a sentence) — then each array in ``.npy`` format. Each dataset is checked before it is read:
a numeric (not string, variable-length, reference, compound or null) dataset within the
memory budget and the inflation ratio. The process limits its own address space, so a file
that makes libhdf5 allocate without bound ends here, not in the caller; a crash of libhdf5
ends this process, which the caller reports as a corrupt file.
"""

from __future__ import annotations

import json
import math
import resource
import sys

import numpy as np

_MATLAB_NUMERIC = {"double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32",
                   "int64", "uint64", "logical"}


class _Refused(Exception):
    """A sentence saying what is wrong with the file."""


def _size(n: float) -> str:
    return f"{n / 1024**2:.3g} MiB" if n >= 1024**2 else f"{int(n)} bytes"


def _check(name: str, obj, req: dict) -> None:
    """Refuse a dataset that is not plain numbers, or too large for the limits."""
    import h5py

    what = f"dataset {name!r}"
    if not isinstance(obj, h5py.Dataset):
        raise _Refused(f"{what} is a group, not an array")
    dt = obj.dtype
    if h5py.check_dtype(vlen=dt) is not None:
        raise _Refused(f"{what} holds variable-length data; expected numbers")
    if h5py.check_dtype(ref=dt) is not None:
        raise _Refused(f"{what} holds references; expected numbers")
    if dt.fields is not None or dt.subdtype is not None:
        raise _Refused(f"{what} has a compound dtype (complex numbers?); expected real numbers")
    if dt.kind not in "biuf":
        raise _Refused(f"{what} holds {dt.name if dt.kind != 'O' else 'objects'}; expected "
                       "numbers")
    if obj.shape is None:
        raise _Refused(f"{what} has a null dataspace (no data)")
    cls = obj.attrs.get("MATLAB_class") if req["matlab"] else None
    if isinstance(cls, bytes) and cls.decode("latin-1") not in _MATLAB_NUMERIC:
        raise _Refused(f"variable {name!r} is a MATLAB {cls.decode('latin-1')}; expected a "
                       "numeric matrix")
    nbytes = math.prod(obj.shape) * max(dt.itemsize, 8)
    if nbytes > req["max_bytes"]:
        raise _Refused(f"{what} {obj.shape} would take {_size(nbytes)}, over the memory budget "
                       f"of {_size(req['max_bytes'])}; raise it with --max-memory or "
                       "STRAPDOWN_MAX_BYTES if the file is right")
    stored = obj.id.get_storage_size()
    raw = math.prod(obj.shape) * dt.itemsize
    if raw > 1024**2 and raw > req["max_ratio"] * max(stored, 1):
        raise _Refused(f"{what} would inflate {_size(stored)} of storage to {_size(raw)} (over "
                       f"{req['max_ratio']:g} times; a compression bomb?); raise "
                       "STRAPDOWN_MAX_RATIO if the file is right")


def _read(req: dict) -> tuple[list[str], list[tuple[str, str, np.ndarray]]]:
    import h5py

    sent = []
    with h5py.File(req["path"], "r") as f:
        names = sorted(f.keys())
        for name in req["names"]:
            if name not in names:
                continue
            try:
                obj = f[name]
            except (KeyError, OSError, RuntimeError, ValueError):
                raise _Refused(f"{name!r} is a broken link or unreadable object") from None
            _check(name, obj, req)
            if req["matlab"] and obj.attrs.get("MATLAB_empty", 0):
                sent.append(("arrays", name, np.zeros((0, 0))))
                continue
            sent.append(("arrays", name, np.asarray(obj[()], dtype=np.float64)))
        for name in req["attrs"]:
            if name in f.attrs:
                a = np.asarray(f.attrs[name])
                if a.dtype.kind not in "biuf":
                    raise _Refused(f"attribute {name!r} holds {a.dtype.name}; expected a number")
                sent.append(("attrs", name, a.astype(np.float64)))
    return names, sent


def main() -> int:
    req = json.loads(sys.stdin.buffer.read(1 << 20))
    limit = 3 * int(req["max_bytes"]) + 2 * 1024**3
    try:
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    except (ValueError, OSError):  # a lower hard limit already applies
        pass
    out = sys.stdout.buffer
    try:
        names, sent = _read(req)
    except _Refused as exc:
        out.write(json.dumps({"error": str(exc)}).encode() + b"\n")
        return 0
    except MemoryError:
        out.write(json.dumps({"error": "reading it needs more memory than the file could "
                                       "hold: the file is corrupt"}).encode() + b"\n")
        return 0
    except Exception as exc:  # libhdf5's errors on a corrupt file: OSError, KeyError, ...
        text = str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
        out.write(json.dumps({"error": f"not a readable HDF5 file ({text})"}).encode() + b"\n")
        return 0
    out.write(json.dumps({"names": names[:1000],
                          "sent": [[k, n] for k, n, _ in sent]}).encode() + b"\n")
    for _, _, a in sent:
        np.save(out, np.ascontiguousarray(a), allow_pickle=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
