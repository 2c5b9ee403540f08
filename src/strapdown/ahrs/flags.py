"""What the AHRS did with its measurements at each output: :class:`MeasurementFlag`.

:attr:`strapdown.ahrs.AhrsResult.flags` holds, per output, the bitwise or of
these flags; :meth:`strapdown.ahrs.AhrsResult.fraction` gives the share of
outputs with one set, e.g. ``result.fraction(MeasurementFlag.MAG_USED)``. The
compiled loop (:mod:`strapdown.ahrs._kernel`) writes their integer values.
"""

from __future__ import annotations

import enum

__all__ = ["MeasurementFlag"]


class MeasurementFlag(enum.IntFlag):
    """Measurement-update outcomes of one filter output (combinable bits).

    Attributes
    ----------
    ACC_USED
        The accelerometer update was applied.
    ACC_REJECTED
        Its innovation failed the NIS gate (hard gating): not applied.
    MAG_USED
        The magnetometer heading update was applied.
    MAG_REJECTED
        Its innovation failed the NIS gate: not applied.
    MAG_DISTURBED
        The field's norm or dip departed from the reference, or had not yet
        stayed within the tolerances for ``mag_settle_s``: no heading update while
        the rejection budget ``mag_reject_s`` lasts, a de-weighted one (with
        ``MAG_USED``) after it.
    REST
        The rest detector fired: a zero-rate update of the gyro bias.
    ACC_RECOVERED
        Accelerometer recovery: rejections of a quiet accelerometer lasted
        ``recover_acc_s``, the tilt covariance was inflated and the update forced.
    MAG_RECOVERED
        Heading recovery: rejections of a plausible field lasted
        ``recover_mag_s``, the heading covariance was inflated and the update forced.
    ACC_DISTURBED
        Raw accelerometer model: the specific force's norm departed from g by
        more than ``acc_norm_tol``: no accelerometer update.
    MAG_OFFSET
        The online hard-iron estimate changed the offset subtracted from the field
        (``AhrsConfig.hard_iron_s``; :attr:`strapdown.ahrs.AhrsResult.mag_offset` is
        the last one): the field's reference norm, dip and heading were carried over.
    """

    ACC_USED = 1
    ACC_REJECTED = 2
    MAG_USED = 4
    MAG_REJECTED = 8
    MAG_DISTURBED = 16
    REST = 32
    ACC_RECOVERED = 64
    MAG_RECOVERED = 128
    ACC_DISTURBED = 256
    MAG_OFFSET = 512
