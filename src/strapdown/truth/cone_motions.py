"""Cone-angle reference motions of Zhang & Yu (2021): its simulations and a true spin + coning.

Each is a :class:`strapdown.truth.motions.ConeAngleMotion` with polynomial cone angles
``C_c_b = Rx(δ1) Rz(δ2) Rx(δ3 − δ1)``, so the attitude and the increments are exact.
"""

from __future__ import annotations

import math

from strapdown.truth.motions import ConeAngleMotion

__all__ = ["spin_coning", "zhang_yu_simulation"]

_D = math.radians


def zhang_yu_simulation(number: int) -> ConeAngleMotion:
    """The motion of simulation ``number`` (1–4) of Zhang & Yu (2021), Tables 5 and 6.

    Table 5 (simulations 1 and 3): roll 0°, half cone 0°, cone speed 360 °/s, rolling
    speed 360 °/s, half-cone rate 1.146 °/s. The text's "initial roll angle 30°"
    contradicts the table; we use the table. Table 6 (simulations 2 and 4) adds
    rolling and precession accelerations of 24 °/s². Simulations 3 and 4 repeat 1
    and 2 for navigation.

    Raises
    ------
    ValueError
        For a number other than 1, 2, 3 or 4.
    """
    if number not in (1, 2, 3, 4):
        raise ValueError(f"Zhang & Yu (2021) have simulations 1–4, got {number!r}")
    acc = (_D(24), 0.0, _D(24)) if number in (2, 4) else (0.0, 0.0, 0.0)
    return ConeAngleMotion.polynomial((0.0, 0.0, 0.0), (_D(360), _D(1.146), _D(360)), acc)


def spin_coning(half_angle_deg: float = 5.0, cone_dps: float = 360.0,
                spin_dps: float = 3600.0) -> ConeAngleMotion:
    """A true spin + coning motion in cone angles: δ1 = Ωt − π/2, δ2 = a, δ3 = ω_s t.

    Zhang & Yu (2021) simulate cone speed equal to rolling speed, a rotation about a
    nearly fixed axis with no coning; this motion adds real coning. The defaults
    (a = 5°, Ω = 360 °/s, ω_s = 3600 °/s) repeat every second.

    Parameters
    ----------
    half_angle_deg : float
        Half-cone angle a (deg).
    cone_dps : float
        Cone (precession) rate Ω (°/s).
    spin_dps : float
        Spin (roll) rate ω_s (°/s).
    """
    return ConeAngleMotion.polynomial((-math.pi / 2, _D(half_angle_deg), 0.0),
                                      (_D(cone_dps), 0.0, _D(spin_dps)))
