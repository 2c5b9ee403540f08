"""Shared test helpers: the hypothesis profile, ``quat_close``, the BROAD data.

The hypothesis strategies live in ``tests/strategies.py`` (``from strategies import ...``).
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
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


_SHARED_FIXTURE = re.compile(r"""@pytest\.fixture\([^)]*scope\s*=\s*["'](?:module|class|package)""")
#: A module that shares no fixture but an in-process cache its tests fill (a line
#: ``ONE_WORKER = True`` with a comment saying which): on one worker it is filled once.
_ONE_WORKER = re.compile(r"^ONE_WORKER\s*=\s*True\b", re.M)


@pytest.hookimpl(optionalhook=True)  # a hook of pytest-xdist, absent without it
def pytest_xdist_make_scheduler(config, log):
    """``make test`` runs the suite in parallel (``pytest -n auto``): each test is a unit of
    work of its own, except that the tests of a module that builds a module-scoped fixture
    (a built site, a corpus of files, a documented session whose commands run in order) are
    one unit, so one worker builds it once, rather than every worker that gets one of them;
    so are the tests of a module that says ``ONE_WORKER = True`` (they fill a cache of the
    process, e.g. tests/apps/test_advise.py).
    Big units are handed out first. (``--dist loadgroup`` with ``xdist_group`` marks would
    say the same, but pytest 9.2 ignores the node-id suffix pytest-xdist 3.8 groups by.)"""
    if config.getvalue("dist") != "load":
        return None
    from xdist.scheduler import LoadScopeScheduling

    root = Path(str(config.rootpath))
    shared: dict[str, bool] = {}

    class ModuleFixtureScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            module = nodeid.split("::", 1)[0]
            if module not in shared:
                try:
                    text = (root / module).read_text(encoding="utf-8")
                except OSError:
                    text = ""
                shared[module] = (_SHARED_FIXTURE.search(text) is not None
                                  or _ONE_WORKER.search(text) is not None)
            return module if shared[module] else nodeid

    return ModuleFixtureScheduling(config, log)
