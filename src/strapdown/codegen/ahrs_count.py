"""What a generated AHRS module costs: state size and floating-point operations per update,
measured, not estimated.

The module is compiled as C++ with its real type replaced by a class that counts every
operation (``templates/count.hpp``) and fed a simulated recording at its sample rate
(rest, then spin and coning, with noise and a gyro bias); the counts of each update are
collected (mean and largest per update, the update that completes the initial window
reported apart, since it runs the window's samples through the filter). Counted in the
double build; the float build runs the same code. ``add`` counts additions and
subtractions, ``trig`` sin, cos, asin, atan and atan2, ``exp`` exp and pow, ``cmp`` floating
comparisons and fabs. Needs a C++ compiler (``c++``, ``g++`` or ``clang++``).
"""

from __future__ import annotations

import math
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from strapdown.codegen.ahrs_c import AhrsExport

__all__ = ["OPS", "AhrsCost", "count_operations", "simulated_imu", "state_size"]

#: The operation classes counted, in the counter's order.
OPS = ("add", "mul", "div", "sqrt", "trig", "exp", "cmp")

_MAIN = r"""
#include <cstdio>
#include <vector>
#include "NAME.h"
unsigned long long sd_count::n[sd_count::NOPS];
int main(int argc, char **argv)
{
    (void)argc;
    FILE *f = std::fopen(argv[1], "rb");
    long n = 0;
    int use_mag = 0;
    if (!f || std::fread(&n, sizeof n, 1, f) != 1) return 2;
    if (std::fread(&use_mag, sizeof use_mag, 1, f) != 1) return 2;
    std::vector<double> d(static_cast<size_t>(n) * 9);
    if (std::fread(d.data(), sizeof(double), d.size(), f) != d.size()) return 2;
    static NAME_state s;
    NAME_init(&s);
    unsigned long long tot[sd_count::NOPS] = {0}, mx[sd_count::NOPS] = {0};
    unsigned long long win[sd_count::NOPS] = {0};
    long counted = 0, waits = 0;
    for (long k = 0; k < n; ++k) {
        NAME_real g[3], a[3], m[3], q[4];
        for (int i = 0; i < 3; ++i) {
            g[i] = d[9 * k + i];
            a[i] = d[9 * k + 3 + i];
            m[i] = d[9 * k + 6 + i];
        }
        for (int o = 0; o < sd_count::NOPS; ++o) sd_count::n[o] = 0;
        int rc = NAME_update(&s, g, a, use_mag ? m : nullptr, q);
        if (rc == 1) { ++waits; continue; }
        if (rc != 0) return 3;
        if (k == waits) {
            for (int o = 0; o < sd_count::NOPS; ++o) win[o] = sd_count::n[o];
            continue;
        }
        ++counted;
        for (int o = 0; o < sd_count::NOPS; ++o) {
            tot[o] += sd_count::n[o];
            if (sd_count::n[o] > mx[o]) mx[o] = sd_count::n[o];
        }
    }
    std::printf("%lu %ld\n", (unsigned long)sizeof(NAME_state), counted);
    for (int o = 0; o < sd_count::NOPS; ++o)
        std::printf("%.3f %llu %llu\n", double(tot[o]) / double(counted), mx[o], win[o]);
    return 0;
}
"""


@dataclass(frozen=True)
class AhrsCost:
    """State size (bytes, double build on this machine's ABI; float: the reals halve) and
    operations per update: ``mean``, ``max`` per class, ``window`` the update that
    completes the initial window."""

    state_bytes: int
    updates: int
    mean: dict[str, float]
    max: dict[str, int]
    window: dict[str, int]


def simulated_imu(h: float, seconds: float = 30.0, seed: int = 3):
    """(gyro, acc, mag) of a simulated recording at period h: 3 s at rest, then spin and
    coning (10° cone at 0.5 Hz, 20 °/s spin), noise and a gyro bias."""
    from strapdown.rotation.dcm import dcm_from_quat
    from strapdown.truth.motions import SpinConing

    rng = np.random.default_rng(seed)
    t = np.arange(round(seconds / h)) * h
    m = SpinConing(math.radians(10.0), 2 * math.pi * 0.5, math.radians(20.0))
    tm = np.maximum(t - 3.0, 0.0)
    c = dcm_from_quat(m.attitude(tm))
    n = t.size
    gyro = np.where((t > 3.0)[:, None], m.rate(tm), 0.0) + np.array([0.01, -0.005, 0.003])
    gyro += 1e-3 * rng.normal(size=(n, 3))
    acc = np.einsum("nji,j->ni", c, [0.0, 0.0, 9.80665]) + 0.02 * rng.normal(size=(n, 3))
    mag = np.einsum("nji,j->ni", c, [0.0, 20.0, -40.0]) + 0.3 * rng.normal(size=(n, 3))
    return gyro, acc, mag


def state_size(e: AhrsExport) -> int:
    """``sizeof(NAME_state)`` of the module as the system C compiler lays it out.

    Raises
    ------
    RuntimeError
        Without a C compiler, or when the build fails.
    """
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        raise RuntimeError("measuring the state size needs a C compiler (cc, gcc or clang)")
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / f"{e.name}.h").write_text(e.header)
        (d / "size.c").write_text(f'#include <stdio.h>\n#include "{e.name}.h"\nint main(void) '
                                  f'{{ printf("%lu\\n", (unsigned long)sizeof({e.name}_state)); '
                                  "return 0; }\n")
        res = subprocess.run([cc, "-std=c99", "-o", str(d / "size"), str(d / "size.c")],
                             capture_output=True, text=True)
        if res.returncode != 0:
            raise RuntimeError(f"the size build failed: {res.stderr[-2000:]}")
        return int(subprocess.run([str(d / "size")], capture_output=True, text=True,
                                  check=True).stdout)


def _cxx() -> str | None:
    return shutil.which("c++") or shutil.which("g++") or shutil.which("clang++")


def count_operations(e: AhrsExport, seconds: float = 30.0) -> AhrsCost:
    """Measure ``e``'s state size and operations per update (see the module docstring).

    Raises
    ------
    RuntimeError
        Without a C++ compiler, or when the counting build or run fails (its message).
    """
    cxx = _cxx()
    if cxx is None:
        raise RuntimeError("counting operations needs a C++ compiler (c++, g++ or clang++)")
    templates = Path(__file__).parent / "templates"
    if e.real != "double":  # the same code: counted in its double twin
        from strapdown.codegen.ahrs_c import generate_ahrs

        e = generate_ahrs(h=e.h, real="double", mag=e.mag, algorithm=e.algorithm,
                          config=e.config, name=e.name)
    header = e.header.replace(f"typedef {e.real} {e.name}_real;",
                              f'#include "count.hpp"\ntypedef Counted<double> {e.name}_real;')
    header = header.replace(f"typedef double {e.name}_wide;",
                            f"typedef Counted<double> {e.name}_wide;")
    gyro, acc, mag = simulated_imu(e.h, seconds)
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / f"{e.name}.h").write_text(header)
        (d / f"{e.name}.cpp").write_text(e.source)
        (d / "main.cpp").write_text(_MAIN.replace("NAME", e.name))
        shutil.copy(templates / "count.hpp", d / "count.hpp")
        data = d / "imu.bin"
        with open(data, "wb") as f:
            f.write(np.int64(gyro.shape[0]).tobytes() + np.int32(int(e.mag)).tobytes())
            f.write(np.ascontiguousarray(np.hstack([gyro, acc, mag]), np.float64).tobytes())
        exe = d / "count"
        res = subprocess.run([cxx, "-std=c++20", "-O1", "-w", "-o", str(exe), str(d / "main.cpp"),
                              str(d / f"{e.name}.cpp")], capture_output=True, text=True)
        if res.returncode != 0:
            raise RuntimeError(f"the counting build failed: {res.stderr[-2000:]}")
        run = subprocess.run([str(exe), str(data)], capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError(f"the counting run failed (exit {run.returncode})")
    lines = run.stdout.split("\n")
    size, updates = (int(v) for v in lines[0].split())
    rows = [line.split() for line in lines[1:1 + len(OPS)]]
    return AhrsCost(size, updates, {o: float(r[0]) for o, r in zip(OPS, rows, strict=True)},
                    {o: int(r[1]) for o, r in zip(OPS, rows, strict=True)},
                    {o: int(r[2]) for o, r in zip(OPS, rows, strict=True)})
