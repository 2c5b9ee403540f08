"""Shared test helpers: hypothesis strategies for rotations over batch shapes, the BROAD data."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

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


def _broad_dir() -> Path | None:
    """The BROAD trials: $STRAPDOWN_BROAD, else ``shared/data/broad`` beside this checkout,
    else beside the checkout this one was cloned from (CI clones into a temporary directory)."""
    env = os.environ.get("STRAPDOWN_BROAD")
    if env:
        return Path(env)
    repo = Path(__file__).resolve().parents[1]
    roots = [repo]
    try:
        origin = subprocess.run(["git", "-C", str(repo), "config", "--get", "remote.origin.url"],
                                capture_output=True, text=True, check=False).stdout.strip()
    except OSError:
        origin = ""
    if origin and Path(origin).is_dir():
        roots.append(Path(origin).resolve())
    for root in roots:
        cand = root.parent / "shared" / "data" / "broad"
        if cand.is_dir():
            return cand
    return None


BROAD = _broad_dir()
