"""Compile strapdown's numba kernels ahead of time: :func:`warmup`.

The compiled loops are built on their first use in an environment and cached by numba
(:mod:`strapdown._core.compile_notice`): seconds for an attitude algorithm, up to a minute
for the AHRS filter. A service, a notebook or a benchmark that must not pay that on its
first real call runs :func:`warmup` once, e.g. after installing; on a warm cache it takes
well under a second per part.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Literal, get_args

import numpy as np

if TYPE_CHECKING:
    from strapdown.algorithms.family import Rk4Step
    from strapdown.algorithms.spec import CoefficientName

__all__ = ["PARTS", "Part", "warmup"]

#: What :func:`warmup` can prepare: every attitude algorithm in every update structure (the
#: kernels of ``AlgorithmSpec.run``, the structures and ``strapdown evaluate``), the WGS-84
#: navigation (``navigate``, ``strapdown nav``), the AHRS filter (``ekf``, ``offline_ekf``,
#: ``strapdown ahrs``).
Part = Literal["attitude", "navigation", "ahrs"]
PARTS: tuple[Part, ...] = get_args(Part)


def warmup(parts: Iterable[Part] = PARTS, *,
           log: Callable[[str], None] | None = None) -> dict[str, float]:
    """Compile (or load from numba's cache) the kernels of ``parts`` on tiny inputs.

    Parameters
    ----------
    parts : iterable of {"attitude", "navigation", "ahrs"}
        What to prepare (default: all).
    log : callable, optional
        Receives one line as each part starts.

    Returns
    -------
    dict
        Seconds each part took (a cold cache: the compile time; warm: a fraction of a second).
    """
    steps = {"attitude": _attitude, "navigation": _navigation, "ahrs": _ahrs}
    parts = tuple(parts)
    bad = [p for p in parts if p not in steps]
    if bad:
        raise ValueError(f"unknown warm-up part(s) {', '.join(map(repr, bad))}; choose from "
                         f"{', '.join(PARTS)}")
    from strapdown._core.compile_notice import notice

    took: dict[str, float] = {}
    with notice(lambda _line: None):  # no "call warmup()" notice while warming up
        for part in parts:
            if log is not None:
                log(f"warming up {part}")
            start = time.perf_counter()
            steps[part]()
            took[part] = time.perf_counter() - start
    return took


def _attitude() -> None:
    """Every registered algorithm in every structure it runs in, on a short coning motion
    (the finite-amplitude sets too: their triple terms are kernels of their own)."""
    from strapdown.algorithms.rate import RK4_STEPS
    from strapdown.algorithms.spec import REGISTRY
    from strapdown.analysis.evaluate import EvaluationConfig, evaluate

    for name, fam in REGISTRY.items():
        configs: list[dict] = []
        if fam.stepped:  # the quaternion algorithms take whole steps: a motion of their own
            configs = [dict(motion="krylov", algorithm=name, duration=2.0, step=0.1,
                            alpha=0.45, beta=0.675)]
        else:
            sets: list[CoefficientName | None] = [None]
            if fam.coning_sets:
                sets.append("finite-amplitude")
            steps: list[Rk4Step] = list(RK4_STEPS) if "rk4_step" in fam.options else ["2td"]
            configs = [dict(algorithm=name, structure=s, coefficients=c, rk4_step=r,
                            sample_rate_hz=600.0, duration=0.2)
                       for s in fam.structures for c in sets for r in steps]
        for fields in configs:
            try:
                evaluate(EvaluationConfig.of(**fields))
            except ValueError:  # a combination the family refuses: nothing to compile
                pass


def _navigation() -> None:
    """Both navigation structures, with and without sculling, at rest."""
    from strapdown.navigation import navigate

    n, h = 12, 0.01
    gyro = np.zeros((n, 3))
    accel = np.tile([0.0, 0.0, -9.8 * h], (n, 1))
    for structure in ("conventional", "single-chain"):
        for sculling in (True, False):
            navigate(gyro, accel, 2, h=h, lat=0.7, lon=0.1, height=0.0, structure=structure,
                     sculling=sculling)


def _ahrs() -> None:
    """The filter, causal and offline, with and without a magnetometer, on 2 s at rest."""
    from strapdown.ahrs import ekf, offline_ekf

    n = 200
    t = np.arange(n) * 0.01
    gyro = np.zeros((n, 3))
    acc = np.tile([0.0, 0.0, 9.81], (n, 1))
    mag = np.tile([0.0, 20.0, -40.0], (n, 1))
    for run in (ekf, offline_ekf):
        run(t, gyro, acc, mag)
        run(t, gyro, acc)
