"""Cone-axis drift of the increment structures under classical coning, memoised.

The measurement behind Li & Zhang (2017) Tables 1–3: a structure runs on the
classical-coning motion of its eq. 7 (cone rate :data:`CONE_RATE`, 1 Hz) with ``spp``
increments per cone period, and the drift about the cone axis is the mean over the
structure's interleaved chains of each chain's least-squares slope, sampled at whole
cone periods (:func:`strapdown.analysis.accuracy.chain_drift_rate`). Only Ωh = 2π/spp
and the half-cone angle ``a`` set the drift constant, so the cone rate is fixed.

:func:`drift_mp` runs in arbitrary precision (exact increments and exact rational
coefficients), :func:`drift_f64` in float64 through the same pipeline as
``strapdown evaluate``. Both are memoised: the reproduction's tables and the tests
ask for the same configurations more than once.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from strapdown.algorithms.coning import ConingSetName, coefficient_set
from strapdown.algorithms.family import IncrementStructure
from strapdown.algorithms.precision import run_mp
from strapdown.algorithms.structures import run_structure
from strapdown.analysis.accuracy import attitude_errors, chain_drift_rate
from strapdown.truth import sensors
from strapdown.truth.motions import ClassicalConing

__all__ = ["CONE_RATE", "DIGITS", "drift_f64", "drift_mp"]

#: Cone rate Ω (rad/s) of every run here: 1 Hz.
CONE_RATE = 2.0 * math.pi
#: Default significant digits of :func:`drift_mp`.
DIGITS = 50


@functools.lru_cache(maxsize=512)
def drift_mp(a: float, spp: int, n: int, structure: IncrementStructure,
             coefficients: ConingSetName = "table3", periods: int = 2,
             digits: int = DIGITS) -> float:
    """Cone-axis drift (rad/s) in arbitrary precision, mean over the interleaved chains.

    Parameters
    ----------
    a : float
        Half-cone angle (rad).
    spp : int
        Increments per cone period (Ωh = 2π/spp); every update of every chain must
        land on whole periods (e.g. a multiple of 60 for N = 1 … 5).
    n : int
        Subsamples N.
    structure : {"conventional", "realtime", "single-chain"}
    coefficients : ConingSetName
        A named set of :func:`strapdown.algorithms.coning.coefficient_set`.
    periods : int
        Cone periods simulated.
    digits : int
        Significant decimal digits of the arithmetic.

    Returns
    -------
    float
        Drift about the cone axis (rad/s), negative for the Table 1 law
        ``−c a²Ω(Ωh)^{2N}``.

    Raises
    ------
    ValueError
        When a chain's outputs do not fall on whole cone periods.
    """
    motion = ClassicalConing(a, CONE_RATE)
    h = motion.period / spp
    cs = coefficient_set(coefficients, n)
    s = run_mp(motion, cs, structure=structure, h=h, samples=periods * spp, digits=digits)
    k = s.startup
    chains = chain_drift_rate(s.t[k:], s.err[k:, 0], s.chain[k:], period=motion.period)
    if not all(c.method == "whole-periods" for c in chains):
        raise ValueError(f"spp = {spp} does not put every {structure} chain of N = {n} on "
                         "whole cone periods; the drift would include the periodic error")
    return float(np.mean([c.rate for c in chains]))


@functools.lru_cache(maxsize=64)
def drift_f64(a: float, spp: int, n: int, structure: IncrementStructure,
              periods: int = 20) -> float:
    """Cone-axis drift (rad/s) in float64, Table 3 coefficients, mean over the chains.

    Same pipeline as ``strapdown evaluate``: float64 increments from the closed form,
    the structure, errors against the exact attitude. Parameters as :func:`drift_mp`.
    """
    motion = ClassicalConing(a, CONE_RATE)
    h = motion.period / spp
    rec = sensors.increments(motion, h, periods * spp)
    sol = run_structure(structure, rec.data, coefficient_set("table3", n), h=h,
                        q0=motion.attitude(0.0))
    err, _ = attitude_errors(sol.t, sol.q, motion)
    k = sol.startup
    chains = chain_drift_rate(sol.t[k:], err[k:, 0], sol.chain[k:], period=motion.period)
    return float(np.mean([c.rate for c in chains]))
