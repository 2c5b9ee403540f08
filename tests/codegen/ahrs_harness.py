"""Compile a generated AHRS module with a batch driver and stream a recording through it
(shared by the AHRS export tests and the slow 10^7-sample run)."""

from __future__ import annotations

import ctypes
import subprocess
from pathlib import Path

import numpy as np

from c_harness import compiler
from strapdown.codegen.ahrs_c import generate_ahrs
from strapdown.rotation.quaternion import quat_conjugate, quat_multiply

STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Wconversion"]

# every update's return value, attitude and flags, in one call (ctypes per sample is slow)
DRIVER = r"""
#include <stddef.h>
#include "NAME.h"
int NAME_run(long n, const NAME_real *g, const NAME_real *a, const NAME_real *m,
             NAME_real *q, int *rc, unsigned *flags, NAME_state *s);
int NAME_run(long n, const NAME_real *g, const NAME_real *a, const NAME_real *m,
             NAME_real *q, int *rc, unsigned *flags, NAME_state *s)
{
    long i;
    for (i = 0; i < n; ++i) {
        rc[i] = NAME_update(s, g + 3 * i, a + 3 * i, m ? m + 3 * i : NULL, q + 4 * i);
        flags[i] = s->flags;
    }
    return 0;
}
"""


def build(folder: Path, opt: str = "-O2", **kw):
    """Generate (``generate_ahrs(**kw)``), compile with the strict flags plus ``opt``,
    return (export, library).

    ``-O2`` (the default) is what a firmware build uses; ``-O1`` keeps the strict flags'
    flow-analysis warnings (``-Wmaybe-uninitialized`` needs an optimising compile) at 40 %
    of the compile time (1.8 s against 4.5 s per module, loaded machine): the tests that
    build one module per option use it. Both compile IEEE arithmetic as written
    (``-ffp-contract=off``, no fast-math), so the results are the same."""
    e = generate_ahrs(**kw)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{e.name}.h").write_text(e.header)
    (folder / f"{e.name}.c").write_text(e.source)
    (folder / f"{e.name}_drv.c").write_text(DRIVER.replace("NAME", e.name))
    lib = folder / f"lib{e.name}.so"
    res = subprocess.run([compiler(), *STRICT, opt, "-ffp-contract=off", "-fPIC", "-shared",
                          "-o", str(lib), str(folder / f"{e.name}.c"),
                          str(folder / f"{e.name}_drv.c"), "-lm"],
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    return e, ctypes.CDLL(str(lib))


class Stream:
    """A filter instance of a built module: feed chunks, get (q, return codes, flags)."""

    def __init__(self, e, lib):
        self.e, self.lib = e, lib
        self.dt = np.float64 if e.real == "double" else np.float32
        size = getattr(lib, f"{e.name}_state_size")
        size.restype = ctypes.c_ulong
        self.state = ctypes.create_string_buffer(int(size()))
        getattr(lib, f"{e.name}_init")(self.state)

    def feed(self, gyro, acc, mag=None):
        n = len(gyro)
        g = np.ascontiguousarray(gyro, self.dt)
        a = np.ascontiguousarray(acc, self.dt)
        m = None if mag is None else np.ascontiguousarray(mag, self.dt)
        q = np.zeros((n, 4), self.dt)
        rc = np.zeros(n, np.intc)
        fl = np.zeros(n, np.uintc)

        def p(x):
            return None if x is None else x.ctypes.data_as(ctypes.c_void_p)

        getattr(self.lib, f"{self.e.name}_run")(ctypes.c_long(n), p(g), p(a), p(m), p(q), p(rc),
                                                p(fl), self.state)
        return q.astype(float), rc, fl


def run(e, lib, gyro, acc, mag=None):
    """One fresh filter over the whole record."""
    return Stream(e, lib).feed(gyro, acc, mag)


def angle(p, q):
    """Rotation angle between attitudes (rad), q and −q the same."""
    dq = quat_multiply(quat_conjugate(p), q)
    return 2.0 * np.arctan2(np.linalg.norm(dq[:, 1:], axis=1), np.abs(dq[:, 0]))
