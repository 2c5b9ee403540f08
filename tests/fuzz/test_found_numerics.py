"""Issue 16's "Found" examples without a regression test elsewhere (checked by grepping the
suite at the end of the issue's work): each must give a correct result or a clear error."""

from __future__ import annotations

import numpy as np


def test_attitude_from_acc_mag_at_1e200_is_the_attitude_at_unit_scale():
    from strapdown.ahrs.filter import attitude_from_acc_mag

    acc, mag = np.array([1.0, 1.0, 1.0]), np.array([1.0, 0.0, 1.0])
    want = attitude_from_acc_mag(acc, mag)
    got = attitude_from_acc_mag(acc * 1e200, mag * 1e200)
    assert np.allclose(got, want, atol=1e-12) or np.allclose(got, -want, atol=1e-12)
    tiny = attitude_from_acc_mag(acc * 1e-300, mag * 1e-310)  # subnormal field included
    assert np.allclose(tiny, want, atol=1e-12) or np.allclose(tiny, -want, atol=1e-12)
