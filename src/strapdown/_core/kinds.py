"""The kind of gyro data, shared by every layer (numpy-free, importable anywhere).

A gyro record holds either angular increments ``Δθ = ∫ ω dt`` (rad) over consecutive
sample intervals or angular-rate samples ``ω`` (rad/s); conventions in :mod:`strapdown`.
The sensor models (:mod:`strapdown.truth.sensors`), the log readers
(:mod:`strapdown.io.readers`) and the algorithm families
(:mod:`strapdown.algorithms.family`) all say which one with this type.
"""

from __future__ import annotations

from typing import Literal, get_args

__all__ = ["INPUT_KINDS", "InputKind"]

#: What a gyro record holds: angular increments (rad) or rate samples (rad/s).
InputKind = Literal["increment", "rate"]
#: The values of :data:`InputKind`.
INPUT_KINDS: tuple[InputKind, ...] = get_args(InputKind)
