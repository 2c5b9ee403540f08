"""Throughput benchmarks (``strapdown bench``, ``make bench``). Reported, never asserted.

For 10⁷ samples each: every rotation-vector structure (N = 1 … 5), the
rate-input algorithms, RK4 and Plaksiy's A1–A3, as samples per second and as
a ratio to a single NumPy pass over the same input array (``2·x`` summed
along the last axis: a memory-bandwidth floor). Peers, when installed
(``pip install strapdown[bench]``), do the equivalent per-sample attitude
update: scipy ``Rotation`` in a Python loop, ``ahrs.filters.AngularRate``
and ``smsfusion.StrapdownINS.update``; they are timed on fewer samples and
reported per sample. The AHRS EKF (every propagation algorithm, with
accelerometer and magnetometer updates at every output) runs on
``ekf_samples`` samples, next to the AHRS peers VQF (offline, C++) and Fusion
(per-sample Python calls into C) on the same data; and the same filter generated as C
(``export-c --algorithm ahrs``, double and float) compiled with the system C compiler at
``-O2`` and timed in C beside VQF's C++ (real-time and offline) and Fusion's C, whose
sources are fetched with pip on first use (:mod:`strapdown.apps.bench_c`). Peak resident memory
(VmHWM) of a 10⁸-sample stream is measured in a fresh subprocess; about
140 MB of it is the interpreter with numpy, scipy and numba loaded.

The velocity/attitude strapdown update (sculling compensation) runs on the exact classical
sculling motion (θ0 = 1°, A = 10 m/s², 10 Hz, ψ = 0, 1200 Hz samples, no gravity;
:func:`strapdown.truth.sculling.classical_sculling`): ours, compiled, on ``nav_samples``
increments (conventional N = 2 and the single chain N = 2), and
``smsfusion.StrapdownINS.update`` on ``peer_samples`` rate and specific-force samples of
the same motion at the same rate; the record ``sculling-ours-over-smsfusion`` gives the
throughput ratio ours (conventional N = 2) / smsfusion.

The Earth navigation (:func:`strapdown.navigation.navigate`, conventional N = 2 and the
single chain N = 2, WGS-84, the default velocity set) runs on a synthetic log of
``earth_samples`` increments (default ``min(nav_samples, 10⁶)``: a level vehicle at rest at
40° N with small vibrations, 1 kHz), reported as increments per second (the body
increments and the Earth step together).

With a ``log``, each benchmark announces itself (``[k/total] name``) before it
runs. A peer that is not installed is not dropped silently: its record has
``skipped``, saying which package is missing and the extra that installs it.
"""

from __future__ import annotations

import importlib
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["COMPILED_MIN", "PEER_EXTRA", "run_benchmarks"]

#: How to install the peers (each skipped peer's record says it).
PEER_EXTRA = "pip install 'strapdown[bench]'"
#: Fewest samples for which the compiled AHRS programs are timed by default.
COMPILED_MIN = 10_000


@dataclass(frozen=True)
class _Job:
    """One benchmark: its record name, peer package (None: ours), timed function, sample
    count and timed runs; ``fn`` None with ``skipped`` the reason: a peer that cannot run."""

    name: str
    peer: str | None
    fn: Callable[[], object] | None
    samples: int
    repeat: int
    skipped: str | None = None


def _import_peer(package: str):
    """``(module, None)``, or ``(None, why)`` when the peer cannot be imported."""
    try:
        return importlib.import_module(package), None
    except ModuleNotFoundError:
        return None, f"{package} not installed ({PEER_EXTRA})"
    except ImportError as exc:  # installed but broken (a missing shared library, ...)
        return None, f"{package} not importable: {exc}"


def _best(fn, repeat):
    fn()  # warm-up: numba compilation or cache load
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _ours(samples, repeat):
    """The NumPy floor's function and our algorithms' jobs on ``samples`` increments."""
    from strapdown.algorithms import rate
    from strapdown.algorithms.coning import coefficient_set
    from strapdown.algorithms.quaternion import QuaternionAlgorithm, quaternion_attitude
    from strapdown.algorithms.structures import conventional, realtime, single_chain

    rng = np.random.default_rng(0)
    theta = rng.normal(size=(samples, 3)) * 1e-3
    omega = theta * 1e4
    t = np.arange(samples) * 1e-4
    runs = []
    for n in range(1, 6):
        cs = coefficient_set("table3", n)
        m = samples - samples % n
        runs += [
            (f"rotvec-N{n}-conventional", lambda cs=cs, m=m: conventional(theta[:m], cs, h=1e-4)),
            (f"rotvec-N{n}-realtime", lambda cs=cs: realtime(theta, cs, h=1e-4)),
            (f"rotvec-N{n}-single-chain", lambda n=n: single_chain(theta, n, h=1e-4)),
        ]
    runs += [
        ("rate-single-conventional", lambda: rate.rate_attitude(t, omega, algorithm="rate-single")),
        ("rate-three-conventional", lambda: rate.rate_attitude(t, omega, algorithm="rate-three")),
        ("rate-three-sliding", lambda: rate.rate_attitude(t, omega, algorithm="rate-three",
                                                          structure="sliding")),
        ("rk4-2td-conventional", lambda: rate.rate_attitude(t, omega, algorithm="rk4")),
    ]
    for name, sub in (("miller", 3), ("panov", 2), ("power", 2)):
        m = samples - samples % sub
        alg = QuaternionAlgorithm.stated(name)
        runs.append((f"{name}-conventional",
                     lambda alg=alg, m=m: quaternion_attitude(theta[:m], alg, step=3e-4)))
    floor = _Job("numpy-single-pass", None, lambda: (theta * 2.0).sum(axis=1), samples, repeat)
    return floor, [_Job(name, None, fn, samples, repeat) for name, fn in runs]


def _imu(samples):
    """A smooth IMU record with gravity and field: spin + coning at 200 Hz."""
    import math

    from strapdown.rotation.dcm import dcm_from_quat
    from strapdown.truth.motions import SpinConing

    t = np.arange(samples) / 200.0
    m = SpinConing(math.radians(10.0), 2 * math.pi * 0.5, math.radians(20.0))
    c = dcm_from_quat(m.attitude(t))
    acc = np.einsum("nji,j->ni", c, [0.0, 0.0, 9.80665])
    mag = np.einsum("nji,j->ni", c, [0.0, 20.0, -40.0])
    return t, m.rate(t), acc, mag


def _ahrs(samples, repeat):
    """Jobs of the AHRS EKF (each propagation algorithm) and of the AHRS peers."""
    from strapdown.ahrs import ekf

    t, w, acc, mag = _imu(samples)
    jobs = []
    for alg in ("rate-single", "rate-three", "rate-three:structure=sliding", "rk4",
                "rotvec:N=3"):
        name = "ahrs-ekf-" + alg.replace(":structure=", "-").replace(":N=", "-N")
        jobs.append(_Job(name, None, lambda alg=alg: ekf(t, w, acc, mag, algorithm=alg),
                         samples, repeat))
    vqf, why = _import_peer("vqf")
    jobs.append(_Job("vqf-offline-9d", "vqf", vqf and (
        lambda: vqf.offlineVQF(w, acc, mag, 1 / 200.0, {})), samples, repeat, why))
    imufusion, why = _import_peer("imufusion")
    few = min(samples, 50_000)

    def fusion():
        a = imufusion.Ahrs()
        a.set_sample_period(1 / 200.0)
        g, ag = np.degrees(w[:few]), acc[:few] / 9.80665
        for i in range(few):
            a.update(g[i], ag[i], mag[i])

    jobs.append(_Job("imufusion-ahrs", "imufusion", imufusion and fusion, few, 1, why))
    return jobs


def _peers(samples):
    """Jobs of the per-sample attitude-update peers (timed once each)."""
    rng = np.random.default_rng(1)
    theta = rng.normal(size=(samples, 3)) * 1e-3
    from scipy.spatial.transform import Rotation

    def scipy_loop():
        r = Rotation.identity()
        for th in theta:
            r = r * Rotation.from_rotvec(th)
        return r

    ahrs, why_ahrs = _import_peer("ahrs")
    smsfusion, why_sms = _import_peer("smsfusion")

    def sms():
        ins = smsfusion.StrapdownINS(1e4, np.r_[np.zeros(6), 1.0, 0, 0, 0, np.zeros(6)])
        f = np.array([0.0, 0.0, -9.80665])
        for w in theta * 1e4:
            ins.update(f, w)
        return ins

    return [
        _Job("scipy-rotation-loop", "scipy", scipy_loop, samples, 1),
        _Job("ahrs-angularrate", "ahrs", ahrs and (
            lambda: ahrs.filters.AngularRate(gyr=theta * 1e4, frequency=1e4,
                                             q0=np.array([1.0, 0, 0, 0]))),
             samples, 1, why_ahrs),
        _Job("smsfusion-strapdownins", "smsfusion", smsfusion and sms, samples, 1, why_sms),
    ]


#: The sculling motion of the velocity benchmarks: θ0 (rad), Ω (rad/s), A (m/s²), 1/h (Hz).
SCULLING_BENCH = (0.017453292519943295, 2 * np.pi * 10.0, 10.0, 1200.0)


def _sculling(nav_samples: int, peer_samples: int, repeat: int) -> list[_Job]:
    """Jobs of the velocity/attitude update on the exact sculling motion: ours (conventional
    and single chain, N = 2) and smsfusion's StrapdownINS (rate and specific-force samples)."""
    import functools

    from strapdown.algorithms.velocity import NavStructure
    from strapdown.navigation import integrate_inertial
    from strapdown.truth.sculling import classical_sculling

    theta0, om, acc, rate = SCULLING_BENCH
    mo, h = classical_sculling(theta0, om, acc, 0.0), 1.0 / rate
    edges = np.arange(nav_samples + 1) * h
    g, a = mo.increments(edges), mo.velocity_increments(edges)
    q0 = mo.attitude(0.0)
    structures: tuple[NavStructure, ...] = ("conventional", "single-chain")
    jobs = [_Job(f"nav-sculling-N2-{st}", None, functools.partial(
        integrate_inertial, g, a, 2, h=h, q0=q0, structure=st), nav_samples, repeat)
        for st in structures]
    smsfusion, why = _import_peer("smsfusion")
    pe = edges[: peer_samples + 1]
    w, f = mo.rate(pe[:-1]), mo.specific_force(pe[:-1])

    def sms():
        ins = smsfusion.StrapdownINS(rate, np.r_[np.zeros(6), q0, np.zeros(6)], g=0.0)
        for k in range(w.shape[0]):
            ins.update(f[k], w[k])
        return ins

    jobs.append(_Job("smsfusion-strapdownins-sculling", "smsfusion", smsfusion and sms,
                     w.shape[0], 1, why))
    return jobs


#: The Earth navigation benchmark's log: sample interval (s), latitude (rad), height (m).
EARTH_BENCH = (0.001, 0.7, 100.0)


def _earth_log(samples: int) -> tuple[np.ndarray, np.ndarray]:
    """Gyro (rad) and accelerometer (m/s) increments of a level vehicle at rest at
    :data:`EARTH_BENCH` (the Earth's rate and normal gravity, NED body axes) with small
    zero-mean vibrations of its rates and specific force."""
    from strapdown.truth import earth

    h, lat, height = EARTH_BENCH
    t = np.arange(samples) * h
    w = earth.earth_rate(lat) + np.column_stack([
        2e-3 * np.sin(3.1 * t), 1e-3 * np.cos(2.3 * t), 5e-4 * np.sin(1.7 * t)])
    f = np.array([0.0, 0.0, -float(earth.gravity(lat, height))]) + np.column_stack([
        0.05 * np.sin(2.9 * t), 0.03 * np.cos(1.3 * t), 0.02 * np.sin(4.1 * t)])
    return w * h, f * h


def _earth(samples: int, repeat: int) -> list[_Job]:
    """Jobs of the Earth navigation (:func:`strapdown.navigation.navigate`) on
    :func:`_earth_log`: conventional N = 2 and the single chain N = 2."""
    import functools

    from strapdown.navigation import navigate

    h, lat, height = EARTH_BENCH
    g, a = _earth_log(samples)
    return [_Job(f"nav-earth-N2-{st}", None, functools.partial(
        navigate, g, a, 2, h=h, lat=lat, lon=0.1, height=height, structure=st), samples,
        repeat) for st in ("conventional", "single-chain")]


def _sculling_ratio(recs: list[dict]) -> dict:
    """``sculling-ours-over-smsfusion``: throughput ours (conventional N = 2) / smsfusion on
    the same sculling motion; ``skipped`` when either record has no rate."""
    by = {r["name"]: r for r in recs}
    ours = by.get("nav-sculling-N2-conventional", {}).get("samples_per_s")
    sms = by.get("smsfusion-strapdownins-sculling", {})
    rec: dict = {"name": "sculling-ours-over-smsfusion", "ratio": None, "peer": "smsfusion"}
    if ours is None or sms.get("samples_per_s") is None:
        return {**rec, "skipped": sms.get("skipped") or sms.get("error") or "not measured"}
    return {**rec, "ratio": ours / sms["samples_per_s"]}


def _record(job: _Job, floor: float | None) -> dict:
    """Time ``job`` (the floor itself when ``floor`` is None) into its record."""
    rec: dict = {"name": job.name, "samples_per_s": None, "ratio_to_numpy_pass": None,
                 "peer": job.peer}
    if job.fn is None:
        return {**rec, "skipped": job.skipped}
    try:
        r = job.samples / _best(job.fn, job.repeat)
    except Exception as exc:  # a peer's API drift must not sink the whole benchmark
        if job.peer is None:
            raise
        return {**rec, "error": f"{type(exc).__name__}: {exc}"}
    return {**rec, "samples_per_s": r, "ratio_to_numpy_pass": 1.0 if floor is None
            else r / floor}


_STREAM_SCRIPT = """
import sys, numpy as np
from strapdown.algorithms.coning import coefficient_set
from strapdown.algorithms.streaming import RotvecStream
total, chunk, structure = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
s = RotvecStream(structure, coefficient_set("table3", 3), h=1e-4)
rng = np.random.default_rng(0)
done = 0
last = None
while done < total:
    m = min(chunk, total - done)
    out = s.feed(rng.normal(size=(m, 3)) * 1e-3)
    if out.q.shape[0]:
        last = out.q[-1]
    done += m
# VmHWM: this address space's peak (ru_maxrss would include the parent's before exec)
hwm = [l for l in open("/proc/self/status") if l.startswith("VmHWM")][0].split()[1]
print(int(hwm) / 1024.0, float(last[0]))
"""


def _stream_memory(total, structure, chunk=1 << 16):
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-c", _STREAM_SCRIPT, str(total), str(chunk),
                          structure], capture_output=True, text=True, check=True)
    mb = float(res.stdout.split()[0])
    return {"name": f"stream-{structure}-N3-{total:.0e}-samples", "peak_rss_mb": mb,
            "seconds": time.perf_counter() - t0, "chunk": chunk, "peer": None}


def run_benchmarks(samples: int = 10_000_000, peer_samples: int = 20_000, repeat: int = 3,
                   stream_samples: int = 100_000_000, ekf_samples: int = 1_000_000, *,
                   nav_samples: int = 2_000_000, compiled_samples: int | None = None,
                   earth_samples: int | None = None,
                   log: Callable[[str], None] | None = None) -> list[dict]:
    """All benchmark records (see the module docstring); ``nav_samples=0`` skips the
    velocity/sculling and Earth navigation benchmarks; ``earth_samples`` the Earth
    navigation's increments (default ``min(nav_samples, 10⁶)``). ``compiled_samples``:
    samples of the compiled AHRS and its compiled peers (default ``ekf_samples``, or none
    below :data:`COMPILED_MIN` samples, where a compiled program's timing would be mostly
    its start-up).

    ``log`` receives ``[k/total] name`` before each benchmark runs, and one line naming
    the peers that are skipped and why, before the first.
    """
    say = log or (lambda _m: None)
    floor_job, ours = _ours(samples, repeat)
    jobs = [floor_job, *ours, *_peers(peer_samples), *(_ahrs(ekf_samples, repeat)
                                                        if ekf_samples else ()),
            *(_sculling(nav_samples, peer_samples, repeat) if nav_samples else ()),
            *(_earth(min(nav_samples, 1_000_000) if earth_samples is None else earth_samples,
                     repeat) if nav_samples else ())]
    streams = ("conventional", "realtime") if stream_samples else ()
    skipped = [j for j in jobs if j.fn is None]
    if skipped:
        say("skipping " + "; ".join(f"{j.name}: {j.skipped}" for j in skipped))
    total = len(jobs) - len(skipped) + len(streams)
    done = 0
    recs: list[dict] = []
    for job in jobs:
        if job.fn is not None:
            done += 1
            say(f"[{done}/{total}] {job.name}")
        recs.append(_record(job, None if job is floor_job else recs[0]["samples_per_s"]))
    for structure in streams:
        done += 1
        say(f"[{done}/{total}] stream-{structure}: peak memory of {stream_samples:.0e} samples")
        recs.append(_stream_memory(stream_samples, structure))
    if nav_samples:
        recs.append(_sculling_ratio(recs))
    if compiled_samples is None:
        compiled_samples = ekf_samples if ekf_samples >= COMPILED_MIN else 0
    if compiled_samples:
        recs += _compiled_ahrs(compiled_samples, repeat, recs[0]["samples_per_s"], say)
    return recs


def _compiled_ahrs(samples: int, repeat: int, floor: float, say) -> list[dict]:
    """The AHRS compiled from its generated C beside VQF's C++ and Fusion's C
    (:func:`strapdown.apps.bench_c.c_ahrs_records`), ratios to the NumPy floor."""
    from strapdown.apps.bench_c import c_ahrs_records

    recs = c_ahrs_records(samples, repeat, _imu, log=say)
    for r in recs:
        if r["samples_per_s"] is not None:
            r["ratio_to_numpy_pass"] = r["samples_per_s"] / floor
    return recs

