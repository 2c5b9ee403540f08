"""Shared test helpers: the hypothesis profile, ``quat_close``, the BROAD data.

The hypothesis strategies live in ``tests/strategies.py`` (``from strategies import ...``).
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
from hypothesis import settings

settings.register_profile("default", deadline=None, max_examples=60)
settings.load_profile("default")


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
