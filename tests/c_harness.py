"""Compile generated C and drive it through ctypes (shared by the export-c tests)."""

from __future__ import annotations

import ctypes
import shutil
import subprocess

import numpy as np
import pytest

from strapdown.codegen.export_c import export_c

FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-fPIC", "-shared",
         "-ffp-contract=off"]


def compiler() -> str:
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        pytest.fail("no C compiler (cc, gcc or clang) on PATH: the export-c equivalence "
                    "harness needs one; install gcc")
    return cc


def build(tmp_path, **kw):
    e = export_c(tmp_path, **kw)
    lib = tmp_path / f"lib{e.name}.so"
    res = subprocess.run([compiler(), *FLAGS, "-o", str(lib), str(tmp_path / f"{e.name}.c"),
                          "-lm"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    return e, ctypes.CDLL(str(lib))


def drive(e, lib, samples, q0):
    real = ctypes.c_double if e.real == "double" else ctypes.c_float
    dt = np.float64 if e.real == "double" else np.float32
    getattr(lib, f"{e.name}_state_size").restype = ctypes.c_ulong
    state = ctypes.create_string_buffer(int(getattr(lib, f"{e.name}_state_size")()))
    update = getattr(lib, f"{e.name}_update")
    update.restype = ctypes.c_int
    getattr(lib, f"{e.name}_init")(state, np.asarray(q0, dt).ctypes.data_as(
        ctypes.POINTER(real)))
    out = np.zeros(4, dt)
    po = out.ctypes.data_as(ctypes.POINTER(real))
    xs = np.ascontiguousarray(samples, dtype=dt)
    rows = [np.asarray(q0, float)]
    for k in range(xs.shape[0]):
        if update(state, xs[k].ctypes.data_as(ctypes.POINTER(real)), po):
            rows.append(out.astype(float).copy())
    return np.array(rows)
