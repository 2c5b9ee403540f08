"""Hypothesis strategies over values for the property tests.

Every strategy here is built from values (``st.floats``, ``st.tuples``,
``st.builds``, :func:`hypothesis.extra.numpy.arrays` with float elements), never
from an integer seed fed to numpy's random generator, so a failing example
shrinks to a small, readable one (an axis, an angle, a short array) rather than
to an opaque seed.

Angles are drawn by *kind* (generic, tiny, near π, near 2π) because the
interesting round-off lives at the ends of the range: ``sin(x)/x`` series below
:data:`strapdown.rotation.SMALL_ANGLE`, ``w → 0`` at 180°, ``w → −1`` at 360°.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from strapdown.algorithms.coning import (
    MAX_SUBSAMPLES,
    CoefficientSet,
    coefficient_set,
    coefficient_set_names,
)
from strapdown.rotation import dcm_from_quat

__all__ = [
    "CONING_CHOICES",
    "PAIR_CONING_CHOICES",
    "angles",
    "batch_shapes",
    "chunk_sizes",
    "coning_sets",
    "increments",
    "rotation_matrices",
    "rotvecs",
    "sign_masks",
    "split",
    "unit_quaternions",
    "unit_vectors",
]

_FLOAT = {"allow_nan": False, "allow_infinity": False}


def _coning_choices() -> tuple[tuple[str, int], ...]:
    out = []
    for name in coefficient_set_names():
        for n in range(1, MAX_SUBSAMPLES + 1):
            try:
                coefficient_set(name, n)
            except ValueError:  # e.g. 'miller' exists for N = 3 only
                continue
            out.append((name, n))
    return tuple(out)


#: Every (name, N) that :func:`strapdown.algorithms.coning.coefficient_set` accepts.
CONING_CHOICES: tuple[tuple[str, int], ...] = _coning_choices()


def batch_shapes() -> st.SearchStrategy[tuple[int, ...]]:
    """Leading batch shapes ``()``, ``(1,)``, ``(k,)`` and ``(k, m)`` (k, m ≤ 4).

    Shrinks towards ``()``.
    """
    side = st.integers(1, 4)
    return st.one_of(st.just(()), st.just((1,)), st.tuples(side), st.tuples(side, side))


def unit_vectors() -> st.SearchStrategy[np.ndarray]:
    """Unit 3-vectors: the coordinate axes (±) or a point on the sphere.

    The sphere point is ``(√(1−z²) cos λ, √(1−z²) sin λ, z)`` with ``z`` uniform in
    [−1, 1] and ``λ`` in [0, 2π) (area-uniform), so no draw is rejected.
    """
    axes = st.sampled_from([np.array(a, dtype=np.float64) for a in
                            ((1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, 0, 0), (0, -1, 0),
                             (0, 0, -1))])

    def _sphere(z, lon):
        r = math.sqrt(max(0.0, 1.0 - z * z))
        u = np.array([r * math.cos(lon), r * math.sin(lon), z])
        return u / np.linalg.norm(u)

    sphere = st.builds(_sphere, st.floats(-1.0, 1.0, **_FLOAT),
                       st.floats(0.0, 2 * math.pi, exclude_max=True, **_FLOAT))
    return st.one_of(axes, sphere)


def _log10(lo: float, hi: float) -> st.SearchStrategy[float]:
    """``10**e`` with the exponent ``e`` uniform in [lo, hi] (log-uniform magnitudes)."""
    return st.floats(lo, hi, **_FLOAT).map(lambda e: 10.0 ** e)


def angles(max_angle: float = math.pi) -> st.SearchStrategy[float]:
    """Rotation angles in [0, π) (``max_angle = π``) or [0, 2π] (``max_angle = 2π``).

    Kinds: exactly 0; generic; tiny, 1e-300 … 1e-2 (the series branch); near π
    from below, π − 1e-2 … π − 1e-12. With ``max_angle = π`` every angle stays
    at least 1e-12 below π, so the rounded ``|u a|`` of :func:`rotvecs` never
    passes π (beyond π the principal rotation vector is the opposite one). With
    ``max_angle = 2π`` also π itself, just above π and near 2π (``w ≈ −1``).
    """
    if max_angle not in (math.pi, 2 * math.pi):
        raise ValueError(f"max_angle must be π or 2π, got {max_angle!r}")
    below_pi = _log10(-12.0, -2.0).map(lambda d: math.pi - d)
    if max_angle == math.pi:
        return st.one_of(st.just(0.0), st.floats(0.0, math.pi - 1e-12, **_FLOAT),
                         _log10(-300.0, -2.0), below_pi)
    return st.one_of(st.just(0.0), st.floats(0.0, 2 * math.pi, **_FLOAT), _log10(-300.0, -2.0),
                     below_pi, st.just(math.pi), _log10(-12.0, -2.0).map(lambda d: math.pi + d),
                     _log10(-12.0, -2.0).map(lambda d: 2 * math.pi - d))


def _rotvec(max_angle: float) -> st.SearchStrategy[np.ndarray]:
    return st.builds(lambda u, a: u * a, unit_vectors(), angles(max_angle))


def _batched(one: st.SearchStrategy[np.ndarray], shape, width: int):
    """Arrays ``(*shape, width)`` whose rows are drawn independently from ``one``."""
    shapes = batch_shapes() if shape is None else st.just(tuple(shape))

    def _fill(s):
        n = math.prod(s)
        return st.lists(one, min_size=n, max_size=n).map(
            lambda rows: np.array(rows, dtype=np.float64).reshape((*s, width)))

    return shapes.flatmap(_fill)


def rotvecs(shape=None, *, max_angle: float = math.pi) -> st.SearchStrategy[np.ndarray]:
    """Rotation vectors ``(*shape, 3)`` = unit axis × angle (see :func:`angles`).

    ``shape=None`` draws the batch shape from :func:`batch_shapes`. With the
    default ``max_angle = π`` every vector is the principal one, so
    ``rotvec_from_quat(quat_from_rotvec(φ)) == φ`` to round-off.
    """
    return _batched(_rotvec(max_angle), shape, 3)


def _quat_from_axis_angle(u, a, flip):
    q = np.concatenate([[math.cos(0.5 * a)], math.sin(0.5 * a) * u])
    q = q / np.linalg.norm(q)
    return -q if flip else q


def unit_quaternions(shape=None) -> st.SearchStrategy[np.ndarray]:
    """Unit quaternions ``(*shape, 4)`` of either sign.

    ``[cos(a/2), sin(a/2) u]`` with ``a`` from ``angles(2π)`` (near identity,
    ``w ≈ ±1``; near 180°, ``w ≈ 0``; generic), optionally negated; plus the
    exact ±identity and exact 180° rotations ``[0, u]`` (``w = 0``, where the
    sign of ``q`` cannot be normalised away).
    """
    one = st.one_of(
        st.builds(_quat_from_axis_angle, unit_vectors(), angles(2 * math.pi), st.booleans()),
        st.sampled_from([np.array([1.0, 0, 0, 0]), np.array([-1.0, 0, 0, 0])]),
        st.builds(lambda u: np.concatenate([[0.0], u]), unit_vectors()),
    )
    return _batched(one, shape, 4)


def sign_masks(shape) -> st.SearchStrategy[np.ndarray]:
    """±1.0 arrays of ``shape`` (broadcast against ``(*shape, 4)`` as ``mask[..., None]``)."""
    return hnp.arrays(np.bool_, tuple(shape)).map(lambda b: np.where(b, -1.0, 1.0))


def rotation_matrices(shape=None) -> st.SearchStrategy[np.ndarray]:
    """Proper rotation matrices ``(*shape, 3, 3)``: ``dcm_from_quat`` of
    :func:`unit_quaternions`."""
    return unit_quaternions(shape).map(dcm_from_quat)


def increments(rows, *, max_abs: float = 0.5) -> st.SearchStrategy[np.ndarray]:
    """Angular increments ``(rows, 3)`` (rad) with every component in [−max_abs, max_abs].

    ``rows`` is an int or a strategy of ints. Every component is drawn (no fill
    value: repeated rows would have no coning, ``θ × θ = 0``). The whole array is
    scaled by ``10**e``, ``e`` in [−12, 0], so tiny-increment runs (the
    small-angle branch of every update) are drawn as often as large ones;
    components shrink to 0.
    """
    rows_st = st.just(int(rows)) if isinstance(rows, int) else rows
    elements = st.floats(-max_abs, max_abs, width=64, **_FLOAT)
    arrays = rows_st.flatmap(lambda r: hnp.arrays(np.float64, (r, 3), elements=elements,
                                                  fill=st.nothing()))
    scale = st.one_of(st.just(1.0), _log10(-12.0, 0.0))
    return st.builds(lambda a, s: a * s, arrays, scale)


def chunk_sizes(*, max_chunk: int = 40, max_chunks: int = 12) -> st.SearchStrategy[list[int]]:
    """Chunk sizes for a stream, zeros included (an empty chunk must be harmless).

    Use with :func:`split`: the increments left after the listed chunks go in one
    last chunk, so every list covers the whole record.
    """
    return st.lists(st.integers(0, max_chunk), max_size=max_chunks)


def split(x: np.ndarray, sizes: list[int]) -> list[np.ndarray]:
    """``x`` cut into consecutive chunks of ``sizes``, the rest (possibly empty) last."""
    out = []
    i = 0
    for s in sizes:
        out.append(x[i:i + s])
        i = min(i + s, x.shape[0])
    out.append(x[i:])
    return out


#: The (name, N) of :data:`CONING_CHOICES` whose sets have pair terms only (the
#: finite-amplitude sets add triple cross products and run conventional or single-chain).
PAIR_CONING_CHOICES: tuple[tuple[str, int], ...] = tuple(
    c for c in CONING_CHOICES if not coefficient_set(*c).triples)


def coning_sets() -> st.SearchStrategy[CoefficientSet]:
    """A named pair-only coning set: any name of ``coefficient_set_names()`` × every N it
    accepts (:data:`PAIR_CONING_CHOICES`). Shrinks towards the first name with N = 1."""
    return st.sampled_from(PAIR_CONING_CHOICES).map(lambda c: coefficient_set(*c))
