"""Input validation shared by every public function.

Each checker returns a float64 array and raises :class:`ValueError` whose
message names the argument and the problem (shape, NaN, sign, ordering).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "as_dcms",
    "as_quaternions",
    "as_times",
    "as_vectors",
    "finite_array",
    "first_bad_step",
    "positive",
    "positive_int",
]


def finite_array(x: ArrayLike, name: str) -> NDArray[np.float64]:
    """Return ``x`` as float64, raising if it holds NaN or infinity."""
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be numeric, got {type(x).__name__}") from exc
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))
        where = tuple(int(i) for i in bad[0])
        raise ValueError(f"{name} contains NaN or infinity (first at index {where})")
    return a


def _trailing(x: ArrayLike, name: str, trailing: tuple[int, ...], label: str
              ) -> NDArray[np.float64]:
    a = finite_array(x, name)
    k = len(trailing)
    if a.ndim < k or a.shape[a.ndim - k :] != trailing:
        expected = "(..., " + ", ".join(str(d) for d in trailing) + ")"
        raise ValueError(f"{name} must be {label} of shape {expected}, got shape {a.shape}")
    return a


def as_vectors(x: ArrayLike, name: str = "vector") -> NDArray[np.float64]:
    """3-vectors, shape ``(..., 3)``."""
    return _trailing(x, name, (3,), "3-vectors")


def as_quaternions(x: ArrayLike, name: str = "quaternion") -> NDArray[np.float64]:
    """Scalar-first quaternions, shape ``(..., 4)``; non-zero norm required."""
    q = _trailing(x, name, (4,), "scalar-first quaternions")
    if np.any(np.all(q == 0.0, axis=-1)):  # not the norm: it underflows below 1e-154
        raise ValueError(f"{name} contains a zero quaternion")
    return q


def as_dcms(x: ArrayLike, name: str = "dcm") -> NDArray[np.float64]:
    """Direction cosine matrices, shape ``(..., 3, 3)``."""
    return _trailing(x, name, (3, 3), "direction cosine matrices")


def as_times(t: ArrayLike, name: str = "t", *, min_len: int = 1) -> NDArray[np.float64]:
    """Strictly increasing 1-D time stamps."""
    a = finite_array(t, name)
    if a.ndim != 1:
        raise ValueError(f"{name} must be 1-D time stamps of shape (n,), got shape {a.shape}")
    if a.size < min_len:
        raise ValueError(f"{name} needs at least {min_len} samples, got {a.size}")
    if a.size > 1:
        fault = first_bad_step(np.diff(a))
        if fault is not None:
            i = fault[0]
            raise ValueError(
                f"{name} must be strictly increasing: {name}[{i + 1}] = {a[i + 1]!r} "
                f"does not exceed {name}[{i}] = {a[i]!r}"
            )
    return a


def first_bad_step(d: NDArray[np.float64]) -> tuple[int, str] | None:
    """First non-positive time step in ``d = diff(t)``: ``(i, "duplicated" | "non-monotonic")``,
    so that ``t[i + 1]`` does not exceed ``t[i]``; ``None`` if ``t`` strictly increases."""
    if d.size == 0 or d.min() > 0:  # one pass, no temporary: the common case
        return None
    i = int(np.argmax(d <= 0))
    return i, "duplicated" if d[i] == 0 else "non-monotonic"


def positive(x: object, name: str) -> float:
    """A finite, strictly positive scalar."""
    try:
        v = float(x)  # type: ignore[arg-type]  # any object: float() decides (TypeError below)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a positive number, got {x!r}") from exc
    if not np.isfinite(v) or v <= 0.0:
        raise ValueError(f"{name} must be a finite positive number, got {x!r}")
    return v


def positive_int(x: object, name: str) -> int:
    """A strictly positive integer (bools rejected)."""
    if isinstance(x, bool) or not isinstance(x, int | np.integer):
        raise ValueError(f"{name} must be a positive integer, got {x!r}")
    if x <= 0:
        raise ValueError(f"{name} must be a positive integer, got {x!r}")
    return int(x)
