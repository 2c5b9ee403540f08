"""Shared test helpers: the hypothesis profile, ``quat_close``, the BROAD data.

The hypothesis strategies live in ``tests/strategies.py`` (``from strategies import ...``).
"""

from __future__ import annotations

import os
import re
import subprocess
import time
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


def _shared_dir(name: str, env_var: str) -> Path | None:
    """A shared data set: ``$env_var``, else ``shared/data/NAME`` beside this checkout, else
    beside the checkout this one was cloned from (CI clones into a temporary directory)."""
    env = os.environ.get(env_var)
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
        cand = root.parent / "shared" / "data" / name
        if cand.is_dir():
            return cand
    return None


BROAD = _shared_dir("broad", "STRAPDOWN_BROAD")
#: The OpenAXES recordings, found as BROAD's are (a path that may not exist when absent).
OPENAXES = _shared_dir("openaxes", "STRAPDOWN_OPENAXES") or Path("/nonexistent/openaxes")


#: Tests that take what another module's tests computed in this process: each runs after
#: that module's tests (or right after the one test named), in its pytest-xdist unit (so on
#: the same worker).
RUN_AFTER = {
    # tests/shared_runs.py: the README's strapdown benchmark-ahrs and reproduce plaksiy2024
    "tests/ahrs/test_ahrs.py::test_broad_acceptance_against_fusion_and_vqf":
        "tests/docs/test_docs_commands.py",
    "tests/cli/test_cli.py::test_reproduce_plaksiy_writes_report":
        "tests/docs/test_docs_commands.py",
    # the report's strapdown advise on a 400 Hz log: the K(ω) of those bins (mpmath, cached in
    # the process) computed by test_advise's 400 Hz tests, before its 1 kHz ones evict them
    "tests/reproduce/test_high_order.py::test_full_report":
        "tests/apps/test_advise.py::test_verified_recommendation_meets_the_budget_against_truth",
}


def pytest_collection_modifyitems(session, config, items):
    """Each test of :data:`RUN_AFTER` right after the last test of its module, or the test
    it names (the same order on every worker: pytest-xdist checks that they collected the
    same list)."""
    for nodeid, after in RUN_AFTER.items():
        pos = next((i for i, it in enumerate(items) if it.nodeid == nodeid), None)
        if pos is None:
            continue
        item = items.pop(pos)
        last = max((i for i, it in enumerate(items)
                    if it.nodeid == after or it.nodeid.split("::", 1)[0] == after),
                   default=None)
        items.insert(pos if last is None else last + 1, item)


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
    process, e.g. tests/apps/test_advise.py), and a test of :data:`RUN_AFTER` joins the unit
    of the module whose run it takes.
    Big units are handed out first. (``--dist loadgroup`` with ``xdist_group`` marks would
    say the same, but pytest 9.2 ignores the node-id suffix pytest-xdist 3.8 groups by.)"""
    if config.getvalue("dist") != "load":
        return None
    from xdist.scheduler import LoadScopeScheduling

    root = Path(str(config.rootpath))
    shared: dict[str, bool] = {}

    class ModuleFixtureScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            if nodeid in RUN_AFTER:
                return RUN_AFTER[nodeid].split("::", 1)[0]
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


#: strapdown.warmup's parts, each with its compile time on a cold cache (s, this machine):
#: the AHRS filter is one kernel of ~33 s, the attitude algorithms ~11 s, navigation ~7 s.
WARM_PARTS = {"ahrs": 33.0, "attitude": 11.0, "navigation": 7.0}
#: Fewer collected tests than this (a module or a package run by hand): no warm-up.
WARM_MIN_TESTS = 300


def _warm_shares(workers: int) -> list[list[str]]:
    """The parts split over ``workers`` workers, longest first to the least loaded."""
    shares: list[list[str]] = [[] for _ in range(workers)]
    load = [0.0] * workers
    for part, cost in sorted(WARM_PARTS.items(), key=lambda kv: -kv[1]):
        i = load.index(min(load))
        shares[i].append(part)
        load[i] += cost
    return shares


def pytest_collection_finish(session):
    """Under pytest-xdist, compile numba's kernels once for the whole run before any test.

    On a cold cache (a fresh clone, CI) every process compiles the kernels it calls that are
    not yet in numba's on-disk cache, and numba has no lock: the two workers, and the
    command lines the tests start, each compiled the AHRS filter (~33 s) whenever they met it
    before another had written it. Here each worker compiles its share of
    ``strapdown.warmup``'s parts (written to the cache the tests and their subprocesses
    read), then waits until every share is done; from then on every process loads them
    (well under a second). The tests are unchanged: the same kernels, the same machine
    code. The compile-notice tests use a cache of their own (NUMBA_CACHE_DIR), still cold."""
    workerinput = getattr(session.config, "workerinput", None)
    basetemp = session.config.option.basetemp
    if workerinput is None or basetemp is None or len(session.items) < WARM_MIN_TESTS:
        return
    done = Path(basetemp).parent / "numba-warm"  # the run's temporary root: shared
    done.mkdir(exist_ok=True)
    workers = int(workerinput["workercount"])
    index = int(workerinput["workerid"].removeprefix("gw"))
    mine = _warm_shares(workers)[index] if index < workers else []
    for part in mine:
        from strapdown.apps.warmup import warmup

        try:
            warmup([part])
            note = "ok"
        except Exception as exc:  # the tests that call it fail, and say why
            note = f"failed: {exc!r}"
        (done / f"{part}.tmp").write_text(note)
        (done / f"{part}.tmp").replace(done / part)
    deadline = time.monotonic() + 1800.0
    while (not all((done / part).is_file() for part in WARM_PARTS)
           and time.monotonic() < deadline):
        time.sleep(0.1)
