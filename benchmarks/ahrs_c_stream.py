"""Stream 10^7 samples through the generated AHRS in float (``export-c --algorithm ahrs
--float float``): the largest departure of the output quaternion's norm from 1, NaN or
error returns, and the time.

    python benchmarks/ahrs_c_stream.py [--samples 10000000] [--real float] [--out FILE.json]

The record: a simulated flight at 200 Hz (:func:`strapdown.codegen.ahrs_count.simulated_imu`'s
motion, generated chunk by chunk at its running time: rest, then spin and coning, noise and a
gyro bias), fed in chunks of 10^6 samples to one filter instance through a batch driver.
Needs a C compiler.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from strapdown.codegen.ahrs_c import generate_ahrs
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.truth.motions import SpinConing

DRIVER = r"""
#include <stddef.h>
#include "NAME.h"
int NAME_run(long n, const NAME_real *g, const NAME_real *a, const NAME_real *m,
             NAME_real *q, int *rc, NAME_state *s);
int NAME_run(long n, const NAME_real *g, const NAME_real *a, const NAME_real *m,
             NAME_real *q, int *rc, NAME_state *s)
{
    long i;
    for (i = 0; i < n; ++i) rc[i] = NAME_update(s, g + 3 * i, a + 3 * i, m + 3 * i, q + 4 * i);
    return 0;
}
"""
FS = 200.0


def chunk(start: int, n: int, rng):
    """Samples start … start + n − 1 of the simulated flight."""
    t = (start + np.arange(n)) / FS
    m = SpinConing(math.radians(10.0), 2 * math.pi * 0.5, math.radians(20.0))
    tm = np.maximum(t - 3.0, 0.0)
    c = dcm_from_quat(m.attitude(tm))
    gyro = np.where((t > 3.0)[:, None], m.rate(tm), 0.0) + np.array([0.01, -0.005, 0.003])
    gyro += 1e-3 * rng.normal(size=(n, 3))
    acc = np.einsum("nji,j->ni", c, [0.0, 0.0, 9.80665]) + 0.02 * rng.normal(size=(n, 3))
    mag = np.einsum("nji,j->ni", c, [0.0, 20.0, -40.0]) + 0.3 * rng.normal(size=(n, 3))
    return gyro, acc, mag


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--samples", type=int, default=10_000_000)
    ap.add_argument("--real", choices=["float", "double"], default="float")
    ap.add_argument("--out", default=None, help="write the record as JSON")
    args = ap.parse_args(argv)
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        sys.exit("a C compiler (cc, gcc or clang) is needed")
    e = generate_ahrs(FS, real=args.real, name="stream")
    dt = np.float32 if args.real == "float" else np.float64
    rng = np.random.default_rng(11)
    worst, nan, errors, done, seconds = 0.0, 0, 0, 0, 0.0
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / "stream.h").write_text(e.header)
        (d / "stream.c").write_text(e.source)
        (d / "drv.c").write_text(DRIVER.replace("NAME", e.name))
        subprocess.run([cc, "-std=c99", "-O2", "-fPIC", "-shared", "-o", str(d / "lib.so"),
                        str(d / "stream.c"), str(d / "drv.c"), "-lm"], check=True)
        lib = ctypes.CDLL(str(d / "lib.so"))
        size = lib.stream_state_size
        size.restype = ctypes.c_ulong
        state = ctypes.create_string_buffer(int(size()))
        lib.stream_init(state)
        while done < args.samples:
            n = min(1_000_000, args.samples - done)
            g, a, m = (np.ascontiguousarray(x, dt) for x in chunk(done, n, rng))
            q = np.zeros((n, 4), dt)
            rc = np.zeros(n, np.intc)
            p = [x.ctypes.data_as(ctypes.c_void_p) for x in (g, a, m, q, rc)]
            t0 = time.perf_counter()
            lib.stream_run(ctypes.c_long(n), *p, state)
            seconds += time.perf_counter() - t0
            ok = rc == 0
            qq = q[ok].astype(np.float64)
            nan += int(np.count_nonzero(~np.isfinite(q)))
            errors += int(np.count_nonzero(rc < 0))
            if qq.size:
                worst = max(worst, float(np.max(np.abs(np.linalg.norm(qq, axis=1) - 1.0))))
            done += n
    rec = {"samples": done, "real": args.real, "max_norm_departure": worst, "nan": nan,
           "error_returns": errors, "seconds_in_c": seconds,
           "samples_per_s": done / seconds}
    print(json.dumps(rec, indent=2))
    if args.out:
        Path(args.out).write_text(json.dumps(rec, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
