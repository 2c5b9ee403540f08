"""Coning drift of the N-subsample rotation-vector algorithms against the Table 1 law.

A 1° classical cone at 1 Hz sampled at Ωh = 2π/60 (exact angular increments), integrated by
``rotvec:N=1``, ``N=2`` and ``N=3`` in the conventional structure (Li & Zhang 2017 Table 3
coefficients). The drift about the cone axis, fitted at whole cone periods, is printed beside
the law ``−c_N a² Ω (Ωh)^{2N}`` and the error angles are drawn against time. The README's
Python example is the ``N = 2`` row.

Run: ``python examples/coning_drift.py``.
"""

from __future__ import annotations

import math

import matplotlib.pyplot as plt

from strapdown import AlgorithmSpec, ClassicalConing, attitude_errors, drift_rate
from strapdown.analysis import table1_prediction
from strapdown.truth import sensors

motion = ClassicalConing(half_angle=math.radians(1.0), cone_rate=2 * math.pi)  # 1 Hz cone
h = motion.period / 60                         # Ωh = 2π/60
gyro = sensors.increments(motion, h, 60 * 20)  # 20 cone periods of exact increments

fig, ax = plt.subplots(figsize=(7, 3.5))
print(f"{'algorithm':<12}{'drift (rad/s)':>15}{'law (rad/s)':>15}{'measured/law':>14}")
for n in (1, 2, 3):
    spec = AlgorithmSpec.parse(f"rotvec:N={n}")
    sol = spec.run(gyro, q0=motion.attitude(0.0))
    err, angle = attitude_errors(sol.t, sol.q, motion)
    drift = drift_rate(sol.t, err, period=motion.period)  # sampled at whole cone periods
    law = table1_prediction(motion.half_angle, motion.cone_rate, h, n)
    print(f"{spec!s:<12}{drift.rate[0]:>15.4g}{law:>15.4g}{drift.rate[0] / law:>14.4f}")
    ax.semilogy(sol.t[1:], angle[1:], label=str(spec))
ax.set_xlabel("t (s)")
ax.set_ylabel("attitude error (rad)")
ax.set_title("1° coning at 1 Hz, Ωh = 2π/60")
ax.legend()
fig.tight_layout()
