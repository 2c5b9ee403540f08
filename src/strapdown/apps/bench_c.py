"""The AHRS in C against its peers in C and C++ (part of ``strapdown bench``).

The generated AHRS (:mod:`strapdown.codegen.ahrs_c`, double and float, with
magnetometer) is compiled with the system C compiler at ``-O2`` and timed in C over the
same simulated IMU record as the other AHRS benchmarks, beside VQF's C++ (Laidig & Seel
(2023); real-time ``VQF::update`` per sample, and ``offlineVQF`` over the record) and
x-io's Fusion C (``FusionBiasUpdate`` + ``FusionAhrsUpdate`` per sample, float, the
settings of :mod:`strapdown.apps.ahrs_benchmark`). Each program reads the record into
memory first and reports the best of ``repeat`` timed passes (``clock_gettime``,
monotonic) as samples per second; the attitude of the last sample goes to a sink so
no pass can be optimised away.

The peers' sources are not part of this repository: they are fetched on first use with
pip (``pip download --no-binary vqf,imufusion --no-deps vqf==2.1.2 imufusion==1.3.3``)
into a cache folder (``$STRAPDOWN_PEER_SRC``, default ``~/.cache/strapdown/peer-src``)
and compiled there; a peer that cannot be fetched or built is a record with ``skipped``
saying why.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

__all__ = ["PEER_VERSIONS", "c_ahrs_records", "peer_sources"]

#: The peers' source distributions (the versions the Python benchmarks use).
PEER_VERSIONS = {"vqf": "2.1.2", "imufusion": "1.3.3"}

_READ = r"""
static double *read_record(const char *path, long *n)
{
    FILE *f = fopen(path, "rb");
    double *d;
    if (!f || fread(n, sizeof *n, 1, f) != 1) exit(2);
    d = (double *)malloc((size_t)*n * 9 * sizeof(double));
    if (!d || fread(d, sizeof(double), (size_t)*n * 9, f) != (size_t)*n * 9) exit(2);
    fclose(f);
    return d;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
"""

_OURS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "NAME.h"
READ
int main(int argc, char **argv)
{
    long n, k;
    int r, repeat = atoi(argv[2]);
    double *d = read_record(argv[1], &n), best = 1e300, sink = 0.0;
    NAME_real *x = (NAME_real *)malloc((size_t)n * 9 * sizeof(NAME_real)), q[4];
    static NAME_state s;
    (void)argc;
    for (k = 0; k < n * 9; ++k) x[k] = (NAME_real)d[k];
    for (r = 0; r < repeat; ++r) {
        double t0 = now(), t;
        NAME_init(&s);
        for (k = 0; k < n; ++k)
            if (NAME_update(&s, x + 9 * k, x + 9 * k + 3, x + 9 * k + 6, q) < 0) return 3;
        t = now() - t0;
        if (t < best) best = t;
        sink += (double)q[0];
    }
    printf("%.6e %.17g\n", (double)n / best, sink);
    return 0;
}
"""

_VQF = r"""
#include <cstdio>
#include <cstdlib>
#include <time.h>
#include <vector>
#include "vqf.hpp"
#include "offline_vqf.hpp"
READ
int main(int argc, char **argv)
{
    long n;
    int repeat = atoi(argv[2]);
    double ts = atof(argv[3]), *d = read_record(argv[1], &n), best = 1e300, sink = 0.0;
    bool offline = argc > 4;
    std::vector<double> g(n * 3), a(n * 3), m(n * 3), out(offline ? n * 4 : 4);
    for (long k = 0; k < n; ++k)
        for (int i = 0; i < 3; ++i) {
            g[3 * k + i] = d[9 * k + i];
            a[3 * k + i] = d[9 * k + 3 + i];
            m[3 * k + i] = d[9 * k + 6 + i];
        }
    for (int r = 0; r < repeat; ++r) {
        double t0 = now(), t;
        if (offline) {
            VQFParams p;
            offlineVQF(g.data(), a.data(), m.data(), (size_t)n, ts, p, nullptr, out.data(),
                       nullptr, nullptr, nullptr, nullptr, nullptr);
        } else {
            VQF v(ts);
            for (long k = 0; k < n; ++k) {
                v.update(&g[3 * k], &a[3 * k], &m[3 * k]);
                v.getQuat9D(out.data());
            }
        }
        t = now() - t0;
        if (t < best) best = t;
        sink += out[0];
    }
    std::printf("%.6e %.17g\n", (double)n / best, sink);
    return 0;
}
"""

_FUSION = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "Fusion.h"
READ
int main(int argc, char **argv)
{
    long n, k;
    int r, repeat = atoi(argv[2]);
    double *d = read_record(argv[1], &n), best = 1e300, sink = 0.0;
    float fs = (float)(1.0 / atof(argv[3]));
    FusionVector *g = malloc((size_t)n * sizeof *g), *a = malloc((size_t)n * sizeof *a),
                 *m = malloc((size_t)n * sizeof *m);
    (void)argc;
    for (k = 0; k < n; ++k) {
        int i;
        for (i = 0; i < 3; ++i) {
            g[k].array[i] = (float)(d[9 * k + i] * 57.29577951308232);
            a[k].array[i] = (float)(d[9 * k + 3 + i] / 9.80665);
            m[k].array[i] = (float)d[9 * k + 6 + i];
        }
    }
    for (r = 0; r < repeat; ++r) {
        double t0 = now(), t;
        FusionAhrs ahrs;
        FusionBias bias;
        FusionAhrsSettings st = {fs, FusionConventionEnu, 0.5f, 2000.0f, 10.0f, 10.0f, 5.0f};
        FusionBiasSettings bs = fusionBiasDefaultSettings;
        FusionQuaternion q = {{1.0f, 0.0f, 0.0f, 0.0f}};
        bs.sampleRate = fs;
        FusionAhrsInitialise(&ahrs);
        FusionAhrsSetSettings(&ahrs, &st);
        FusionBiasInitialise(&bias);
        FusionBiasSetSettings(&bias, &bs);
        for (k = 0; k < n; ++k) {
            FusionAhrsUpdate(&ahrs, FusionBiasUpdate(&bias, g[k]), a[k], m[k]);
            q = FusionAhrsGetQuaternion(&ahrs);
        }
        t = now() - t0;
        if (t < best) best = t;
        sink += (double)q.element.w;
    }
    printf("%.6e %.17g\n", (double)n / best, sink);
    return 0;
}
"""


def _cache() -> Path:
    return Path(os.environ.get("STRAPDOWN_PEER_SRC") or
                Path.home() / ".cache" / "strapdown" / "peer-src")


def peer_sources(cache: Path | None = None) -> dict[str, Path | str]:
    """The unpacked source folder of each peer, or why it is not available (fetched with
    pip into ``cache`` on first use, see the module docstring)."""
    cache = cache or _cache()
    found: dict[str, Path | str] = {}
    for pkg, version in PEER_VERSIONS.items():
        folder = cache / f"{pkg}-{version}"
        if not folder.is_dir():
            cache.mkdir(parents=True, exist_ok=True)
            res = subprocess.run([sys.executable, "-m", "pip", "download", "--quiet",
                                  "--no-binary", pkg, "--no-deps", f"{pkg}=={version}",
                                  "-d", str(cache)], capture_output=True, text=True)
            tar = cache / f"{pkg}-{version}.tar.gz"
            if res.returncode != 0 or not tar.is_file():
                found[pkg] = (f"could not fetch the {pkg} {version} sources with pip: "
                              f"{(res.stderr.strip().splitlines() or ['?'])[-1]}")
                continue
            with tarfile.open(tar) as t:
                t.extractall(cache, filter="data")
        found[pkg] = folder
    return found


def _record_file(folder: Path, gyro, acc, mag) -> Path:
    path = folder / "imu.bin"
    with open(path, "wb") as f:
        f.write(np.int64(gyro.shape[0]).tobytes())
        f.write(np.ascontiguousarray(np.hstack([gyro, acc, mag]), np.float64).tobytes())
    return path


def _build(cmd: list[str]) -> str | None:
    res = subprocess.run(cmd, capture_output=True, text=True)
    return None if res.returncode == 0 else (res.stderr.strip()[-400:] or "build failed")


def _time(cmd: list[str]) -> float:
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    return float(out.split()[0])


def _programs(d: Path, ts: float, src: dict[str, Path | str]) -> list[tuple[str, str | None,
                                                                             Callable]]:
    """(record name, peer, build → (command or why)) for ours and the peers."""
    from strapdown.codegen.ahrs_c import generate_ahrs

    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    cxx = shutil.which("c++") or shutil.which("g++") or shutil.which("clang++")
    progs: list[tuple[str, str | None, Callable]] = []
    for real in ("double", "float"):
        def ours(real=real):
            e = generate_ahrs(h=ts, real=real, name=f"bench_{real}")
            (d / f"{e.name}.h").write_text(e.header)
            (d / f"{e.name}.c").write_text(e.source)
            (d / f"{e.name}_main.c").write_text(_OURS.replace("READ", _READ)
                                                .replace("NAME", e.name))
            exe = d / e.name
            why = _build([cc or "cc", "-std=c99", "-O2", "-o", str(exe), str(d / f"{e.name}.c"),
                          str(d / f"{e.name}_main.c"), "-lm"])
            return why or [str(exe)]
        progs.append((f"c-strapdown-ahrs-{real}", None, ours))

    def vqf(offline: bool):
        if isinstance(src["vqf"], str):
            return src["vqf"]
        cpp = Path(src["vqf"]) / "vqf" / "cpp"
        exe = d / "vqf_bench"
        if not exe.exists():
            (d / "vqf_main.cpp").write_text(_VQF.replace("READ", _READ))
            why = _build([cxx or "c++", "-O2", f"-I{cpp}", "-o", str(exe), str(d / "vqf_main.cpp"),
                          str(cpp / "vqf.cpp"), str(cpp / "offline_vqf.cpp"), "-lm"])
            if why:
                return why
        return [str(exe), *(["offline"] if offline else [])]

    progs.append(("cpp-vqf-realtime", "vqf", lambda: vqf(False)))
    progs.append(("cpp-vqf-offline", "vqf", lambda: vqf(True)))

    def fusion():
        if isinstance(src["imufusion"], str):
            return src["imufusion"]
        fdir = Path(src["imufusion"]) / "Fusion"
        exe = d / "fusion_bench"
        (d / "fusion_main.c").write_text(_FUSION.replace("READ", _READ))
        why = _build([cc or "cc", "-std=c99", "-O2", f"-I{fdir}", "-o", str(exe),
                      str(d / "fusion_main.c"), *map(str, sorted(fdir.glob("*.c"))), "-lm"])
        return why or [str(exe)]

    progs.append(("c-fusion-ahrs", "imufusion", fusion))
    return progs


def c_ahrs_records(samples: int, repeat: int, imu, *,
                   log: Callable[[str], None] | None = None) -> list[dict]:
    """Records (``name``, ``samples_per_s``, ``peer``, ``language``; or ``skipped``) of the
    compiled AHRS and its compiled peers over ``samples`` samples of ``imu(samples)``
    (``t, gyro, acc, mag``)."""
    say = log or (lambda _m: None)
    t, gyro, acc, mag = imu(samples)
    ts = float(t[1] - t[0])
    src = peer_sources()
    recs = []
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        data = _record_file(d, gyro, acc, mag)
        for name, peer, make in _programs(d, ts, src):
            say(f"[c] {name}")
            rec: dict = {"name": name, "samples_per_s": None, "ratio_to_numpy_pass": None,
                   "peer": peer, "language": "C++" if name.startswith("cpp") else "C"}
            cmd = make()
            if isinstance(cmd, str):
                recs.append({**rec, "skipped": cmd})
                continue
            recs.append({**rec, "samples_per_s": _time([*cmd[:1], str(data), str(repeat),
                                                        repr(ts), *cmd[1:]])})
    return recs
