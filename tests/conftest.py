"""Shared test helpers: hypothesis strategies for rotations over batch shapes."""

from __future__ import annotations

import numpy as np
from hypothesis import settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

settings.register_profile("default", deadline=None, max_examples=60)
settings.load_profile("default")

BATCH_SHAPES = hnp.array_shapes(min_dims=0, max_dims=3, min_side=1, max_side=4)


@st.composite
def rotvecs(draw, shape=None):
    """Rotation vectors over [0, π]: generic, near 0 (down to 1e-20) and near π."""
    shape = draw(BATCH_SHAPES) if shape is None else shape
    n = int(np.prod(shape)) if shape else 1
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=(n, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    kind = rng.integers(0, 3, size=n)
    generic = rng.uniform(0, np.pi, size=n)
    tiny = 10.0 ** rng.uniform(-20, -2, size=n)
    near_pi = np.pi - 10.0 ** rng.uniform(-9, -2, size=n)
    angle = np.choose(kind, [generic, tiny, near_pi])
    return (axis * angle[:, None]).reshape((*shape, 3))


def quat_close(p, q, atol):
    """q ≡ −q comparison."""
    p = np.asarray(p)
    q = np.asarray(q)
    d = np.minimum(np.linalg.norm(p - q, axis=-1), np.linalg.norm(p + q, axis=-1))
    return np.all(d <= atol)
