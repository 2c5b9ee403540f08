"""Shared test helpers: the hypothesis profile, ``quat_close``, the BROAD data.

The hypothesis strategies live in ``tests/strategies.py`` (``from strategies import ...``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
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


@pytest.fixture
def fake_benchmark(monkeypatch):
    """``benchmark-ahrs``'s BROAD run replaced: it says one stage line when given a progress
    callback and keeps each call's ``config`` and ``progress``, in order."""
    from strapdown.apps import ahrs_benchmark

    calls = []

    def benchmark(directory, out, *, algorithm, heading_offset_removed, config=None,
                  progress=None):
        calls.append({"config": config, "progress": progress})
        if progress is not None:
            progress("01_trial: strapdown-ekf")
        return {}

    monkeypatch.setattr(ahrs_benchmark, "benchmark", benchmark)
    return calls


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
    Big units are handed out first, after those of the modules that cannot run the AHRS
    filter (:func:`_may_run_ahrs`: its compile is then still under way). (``--dist
    loadgroup`` with ``xdist_group`` marks would say the same, but pytest 9.2 ignores the
    node-id suffix pytest-xdist 3.8 groups by.)"""
    if config.getvalue("dist") != "load":
        return None
    from xdist.scheduler import LoadScopeScheduling

    root = Path(str(config.rootpath))
    shared: dict[str, bool] = {}
    ordered: list[bool] = []

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

        def _assign_work_unit(self, node) -> None:
            """Before the first unit goes out: the units that cannot meet the background
            AHRS compile first (big ones first within each group, as before), so that no
            worker waits for it at the start; the others by the time it is done."""
            if not ordered:
                ordered.append(True)
                order = sorted(self.workqueue.items(),
                               key=lambda kv: _may_run_ahrs(root, kv[0].split("::", 1)[0]))
                self.workqueue.clear()
                self.workqueue.update(order)
            super()._assign_work_unit(node)

    return ModuleFixtureScheduling(config, log)


#: strapdown.warmup's parts that the workers compile before any test, each with its compile
#: time on a cold cache (s, this machine): the attitude algorithms ~11 s, navigation ~7 s.
WARM_PARTS = {"attitude": 11.0, "navigation": 7.0}
#: The part compiled in a process of its own while the tests run: the AHRS filter, one numba
#: kernel of 60-90 CPU-s (ekf_kernel). Only the tests that may call it wait for it.
WARM_BACKGROUND = "ahrs"
#: Fewer collected tests than this (a module or a package run by hand): no warm-up.
WARM_MIN_TESTS = 300
#: A test module whose source names none of these runs no AHRS filter, in its process or in
#: another (the command line, a fuzz worker, a documented command, a sweep's pool): it need
#: not wait for the background compile. Any other module waits (a wrong guess costs time,
#: never a result: the filter then compiles where it is called, as without the warm-up).
_AHRS_FREE_IF_NONE_OF = re.compile(
    r"ahrs|ekf|subprocess|sys\.executable|popen|inprocess|fuzz|strapdown\.cli|cli_helpers|"
    r"runpy|multiprocessing|dask|warmup|shared_runs|benchmark|broad|openaxes|recording|"
    r"export_c|codegen|docs|apps|^import strapdown\b|^from strapdown import\b",
    re.I | re.M)
_ahrs_cache: dict[str, bool] = {}


def _may_run_ahrs(root: Path, module: str) -> bool:
    """Whether a test module may run the AHRS filter (see :data:`_AHRS_FREE_IF_NONE_OF`)."""
    if module not in _ahrs_cache:
        try:
            text = (root / module).read_text(encoding="utf-8")
        except OSError:
            text = "ahrs"
        _ahrs_cache[module] = _AHRS_FREE_IF_NONE_OF.search(text) is not None
    return _ahrs_cache[module]


def _warm_shares(workers: int) -> list[list[str]]:
    """The parts split over ``workers`` workers, longest first to the least loaded."""
    shares: list[list[str]] = [[] for _ in range(workers)]
    load = [0.0] * workers
    for part, cost in sorted(WARM_PARTS.items(), key=lambda kv: -kv[1]):
        i = load.index(min(load))
        shares[i].append(part)
        load[i] += cost
    return shares


#: Writes the marker of a warm-up part when it is done (or failed), in its own process.
_BACKGROUND_WARM = """\
import sys
from pathlib import Path
done, part = Path(sys.argv[1]), sys.argv[2]
note = "ok"
try:
    from strapdown.apps.warmup import warmup
    warmup([part])
except BaseException as exc:
    note = f"failed: {exc!r}"
(done / f"{part}.tmp").write_text(note)
(done / f"{part}.tmp").replace(done / part)
"""
_warm: dict = {}


def _wait_for(done: Path, parts) -> None:
    """Until each part's marker is there (or the background process that makes one died)."""
    deadline = time.monotonic() + 1800.0
    pidfile = done / f"{WARM_BACKGROUND}.pid"
    while time.monotonic() < deadline:
        missing = [p for p in parts if not (done / p).is_file()]
        if not missing:
            return
        if missing == [WARM_BACKGROUND] and pidfile.is_file():
            try:
                os.kill(int(pidfile.read_text()), 0)
            except (ValueError, ProcessLookupError):
                if not (done / WARM_BACKGROUND).is_file():
                    return  # killed: the tests compile it where they call it
        time.sleep(0.1)


def pytest_collection_finish(session):
    """Under pytest-xdist, compile numba's kernels once for the whole run.

    On a cold cache (a fresh clone, CI) every process compiles the kernels it calls that are
    not yet in numba's on-disk cache, and numba has no lock: the two workers, and the
    command lines the tests start, each compiled the AHRS filter (~33 s then, 60-90 s since
    its online hard iron) whenever they met it before another had written it. Here each
    worker compiles its share of ``strapdown.warmup``'s :data:`WARM_PARTS` (written to the
    cache the tests and their subprocesses read), then waits until every share is done;
    from then on every process loads them (well under a second). The AHRS filter
    (:data:`WARM_BACKGROUND`) compiles in a process of its own, started by the first
    worker, while the workers run the tests that cannot call it (the scheduler hands those
    out first); a test of any other module waits for it (:func:`pytest_runtest_setup`).
    Before, the second worker sat idle for the whole AHRS compile (~46 s of a core). The
    tests are unchanged: the same kernels, the same machine code. The compile-notice tests
    use a cache of their own (NUMBA_CACHE_DIR), still cold."""
    workerinput = getattr(session.config, "workerinput", None)
    basetemp = session.config.option.basetemp
    if workerinput is None or basetemp is None or len(session.items) < WARM_MIN_TESTS:
        return
    done = Path(basetemp).parent / "numba-warm"  # the run's temporary root: shared
    done.mkdir(exist_ok=True)
    _warm["done"] = done
    workers = int(workerinput["workercount"])
    index = int(workerinput["workerid"].removeprefix("gw"))
    if index == 0:  # stdout is not the worker's: pytest-xdist talks to it over its pipes
        proc = subprocess.Popen([sys.executable, "-c", _BACKGROUND_WARM, str(done),
                                 WARM_BACKGROUND], stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL)
        (done / f"{WARM_BACKGROUND}.pid.tmp").write_text(str(proc.pid))
        (done / f"{WARM_BACKGROUND}.pid.tmp").replace(done / f"{WARM_BACKGROUND}.pid")
        _warm["proc"] = proc
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
    _wait_for(done, list(WARM_PARTS))


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    """A test that may run the AHRS filter waits for its background compile (its fixtures
    too); the others go ahead."""
    done = _warm.get("done")
    if done is None or _warm.get("ahrs-ready"):
        return
    if _may_run_ahrs(Path(str(item.config.rootpath)), item.nodeid.split("::", 1)[0]):
        _wait_for(done, [WARM_BACKGROUND])
        _warm["ahrs-ready"] = True


def pytest_sessionfinish(session):
    """A run cut short does not leave the background compile behind."""
    proc = _warm.get("proc")
    if proc is not None and proc.poll() is None:
        proc.kill()
        proc.wait()
