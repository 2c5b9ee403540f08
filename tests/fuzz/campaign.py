"""The fuzz campaign: the corpus and seeded mutations of valid files through every reader
(the Python API, in worker processes) and every command that reads a file (the console
entry point, ``python -m strapdown.cli``, one process per command line).

Run from the repository (``make fuzz`` runs the long profile)::

    .venv/bin/python tests/fuzz/campaign.py --profile long

Every run is under a memory cap (``RLIMIT_AS`` of :data:`MEMORY_CAP` set in the child) and
a time limit (killed after :data:`KILL_AFTER` s). A run fails the campaign when it ends in
an exception other than :class:`strapdown.InputError` (API), a traceback, a signal or an
exit status other than 0, 2 and 3 (command line), takes over :data:`TIME_LIMIT` s (the API's
kernels are compiled before any timing; a command line's first run over it, which may have
compiled, is judged by a second run), peaks
over :data:`PEAK_LIMIT_MB` MB of resident memory (the process's own high-water mark,
``VmHWM``, not ``ru_maxrss``, which counts the parent's RSS at fork; for the API the worker's
mark, an upper bound of each input's own peak; a worker over it is restarted), leaves a
partial output (any file after a failed run, a hidden temporary file after any run), or when a
corpus file meant to be refused is read (or one meant to be read is refused). The closing
table gives the counts per format; the exit status is 1 when anything failed.
"""

from __future__ import annotations

import argparse
import json
import os
import queue
import resource
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import traceback
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

TESTS = Path(__file__).resolve().parents[1]
if str(TESTS) not in sys.path:
    sys.path.insert(0, str(TESTS))

from fuzz import corpus  # noqa: E402
from fuzz.mutate import mutate  # noqa: E402
from fuzz.targets import API, CLI  # noqa: E402

#: Address-space limit of every fuzzed process (bytes): imports and the numba runtime take
#: ~0.7 GB of address space (0.24 GB resident), so 2 GiB leaves ~1.3 GB for one input.
MEMORY_CAP = 2 * 1024**3
#: A run over this many seconds fails the campaign; one over KILL_AFTER is killed.
TIME_LIMIT = 10.0
KILL_AFTER = 30.0
#: Peak resident memory allowed (MB).
PEAK_LIMIT_MB = 500.0
#: Generated inputs per format, and command lines per format, of each profile.
PROFILES = {
    "quick": {"per_format": {"csv": 8, "npy": 8, "npz": 8, "mat": 8, "h5": 2, "toml": 6},
              "cli_per_format": 1, "workers": 1, "corpus": True},
    "long": {"per_format": {"csv": 2600, "npy": 2000, "npz": 1800, "mat": 2200, "h5": 500,
                            "toml": 1400},
             "cli_per_format": 70, "workers": 2, "corpus": True},
}
_SEEDS = {"csv": ("csv", "ahrs_csv"), "npy": ("npy",), "npz": ("npz", "npz_stored"),
          "mat": ("mat", "mat", "mat_z", "mat73"), "h5": ("h5",), "toml": ("toml",)}


def _cap() -> None:
    """``preexec_fn``: the memory cap, and a process group of its own (to kill it whole)."""
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))
    os.setsid()


def _own_peak_mb() -> float:
    """This process's own peak resident memory (MB) since it was started: ``VmHWM``.

    Not ``ru_maxrss``: Linux keeps the high-water mark across ``execve``, and a forked child
    starts with its parent's resident pages, so ``ru_maxrss`` of any child is at least the
    RSS of the process that started it (under pytest, the whole test session's ~750 MB).
    """
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except (OSError, ValueError):
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _peak_mb() -> float:
    """The worker's peak: its own, or a child's (the guarded h5py reader) — a child's
    ``ru_maxrss`` includes the worker's RSS when it was forked, an upper bound."""
    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    return max(_own_peak_mb(), kids)


#: How a command line is run: ``python -m strapdown.cli`` as the console entry point runs
#: it (``runpy``), reporting its own peak (:func:`_own_peak_mb`) into the file
#: ``$STRAPDOWN_FUZZ_PEAK`` at exit.
_CLI_MAIN = """\
import atexit, os, runpy

def _peak():
    with open("/proc/self/status", encoding="ascii") as f:
        kb = next((line.split()[1] for line in f if line.startswith("VmHWM:")), "nan")
    with open(os.environ["STRAPDOWN_FUZZ_PEAK"], "w") as f:
        f.write(repr(float(kb) / 1024.0))

atexit.register(_peak)
runpy.run_module("strapdown.cli", run_name="__main__", alter_sys=True)
"""


def _files(d: Path) -> list[str]:
    return sorted(str(p.relative_to(d)) for p in d.rglob("*") if p.is_file())


# ------------------------------------------------------------------------------ worker
def _one(fmt: str, name: str, path: Path) -> dict:
    """Run one API target on one file, in the worker; its result record."""
    from strapdown import InputError

    call = dict(API[fmt])[name]
    scratch = Path(tempfile.mkdtemp(prefix="fz-"))
    t0 = time.perf_counter()
    outcome, detail = "ok", ""
    try:
        call(path, scratch)
    except InputError as exc:
        outcome, detail = "input", str(exc)[:300]
        if len(str(exc)) > 500:
            outcome, detail = "long-message", f"{len(str(exc))} characters"
    except BaseException as exc:  # anything else fails the campaign
        if isinstance(exc, (KeyboardInterrupt, SystemExit)):
            raise
        tb = traceback.extract_tb(exc.__traceback__)[-1]
        outcome = "other"
        detail = (f"{type(exc).__name__}: {str(exc)[:200]} at {Path(tb.filename).name}:"
                  f"{tb.lineno}")
    seconds = time.perf_counter() - t0
    left = _files(scratch)
    hidden = [f for f in left if any(part.startswith(".") for part in Path(f).parts)]
    partial = hidden if outcome == "ok" or name == "sweep" else left
    shutil.rmtree(scratch, ignore_errors=True)
    return {"target": name, "outcome": outcome, "detail": detail, "seconds": seconds,
            "peak_mb": _peak_mb(), "partial": partial}


def worker() -> None:
    """Read ``{"id", "fmt", "path"}`` lines on stdin; for each, every API target of the
    format, announcing each (``{"id", "start"}``) and reporting its record."""
    import warnings

    warnings.simplefilter("ignore")
    out = sys.stdout
    for line in sys.stdin:
        task = json.loads(line)
        for name, _ in API[task["fmt"]]:
            out.write(json.dumps({"id": task["id"], "start": name}) + "\n")
            out.flush()
            rec = _one(task["fmt"], name, Path(task["path"]))
            rec["id"] = task["id"]
            out.write(json.dumps(rec) + "\n")
            out.flush()
        out.write(json.dumps({"id": task["id"], "done": True}) + "\n")
        out.flush()


class _Worker:
    """A worker process under the memory cap; restarted after a crash, a hang or a peak."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen | None = None
        self.lines: queue.Queue = queue.Queue()

    def start(self) -> None:
        code = (f"import sys; sys.path.insert(0, {str(TESTS)!r}); "
                "from fuzz.campaign import worker; worker()")
        self.proc = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                     text=True, bufsize=1, preexec_fn=_cap)
        self.lines = queue.Queue()
        threading.Thread(target=self._reader, args=(self.proc.stdout, self.lines),
                         daemon=True).start()

    @staticmethod
    def _reader(stream, lines: queue.Queue) -> None:
        """Every line the worker writes, then None at its end (a thread: select() on a
        buffered pipe would miss lines already read into the buffer)."""
        for line in stream:
            lines.put(line)
        lines.put(None)

    def stop(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, 9)
            except ProcessLookupError:
                pass
            self.proc.wait()
        self.proc = None

    def _line(self, timeout: float) -> dict | None:
        try:
            line = self.lines.get(timeout=timeout)
        except queue.Empty:
            return None
        return json.loads(line) if line else {"eof": True}

    def run(self, task: dict, limit: float = KILL_AFTER) -> list[dict]:
        """Every target's record for ``task`` (a crash or hang gives a record too)."""
        if self.proc is None:
            self.start()
        assert self.proc is not None and self.proc.stdin is not None
        self.proc.stdin.write(json.dumps(task) + "\n")
        self.proc.stdin.flush()
        recs, current = [], None
        while True:
            msg = self._line(limit)
            if msg is None or "eof" in msg:
                code = None if msg is None else self.proc.wait()
                self.stop()
                what = "hang" if msg is None else f"crash (exit {code})"
                recs.append({"target": current, "outcome": what, "detail": "", "seconds":
                             KILL_AFTER if msg is None else 0.0, "peak_mb": 0.0, "partial": []})
                return recs
            if "start" in msg:
                current = msg["start"]
            elif msg.get("done"):
                if any(r["peak_mb"] > PEAK_LIMIT_MB for r in recs):
                    self.stop()  # reset the high-water mark
                return recs
            else:
                recs.append(msg)


# ------------------------------------------------------------------------------ inputs
@dataclass
class Input:
    id: int
    fmt: str
    path: Path
    origin: str  # corpus:<name> or mutation:<seed>:<k>
    expect: str = "any"
    target: str = ""


def inputs(profile: dict, d: Path, seed: int) -> list[Input]:
    """The corpus (if the profile has it) and the generated inputs, written under ``d``."""
    out: list[Input] = []
    if profile["corpus"]:
        for e in corpus.build(d / "corpus"):
            out.append(Input(len(out), e.fmt, e.path, f"corpus:{e.name}", e.expect, e.target))
    seeds = corpus.valid_seeds(d)
    gen = d / "generated"
    gen.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    suffix = {"csv": ".csv", "npy": ".npy", "npz": ".npz", "mat": ".mat", "h5": ".h5",
              "toml": ".toml"}
    for fmt, n in profile["per_format"].items():
        pool = [seeds[k] for k in _SEEDS[fmt]]
        for k in range(n):
            which = int(rng.integers(len(pool)))
            data = pool[which]
            for _ in range(1 + int(rng.integers(3))):
                data = mutate(data, fmt, rng, pool)
            path = gen / f"{fmt}-{k:05d}{suffix[fmt]}"
            path.write_bytes(data)
            out.append(Input(len(out), fmt, path, f"mutation:{_SEEDS[fmt][which]}:{k}"))
    return out


# ------------------------------------------------------------------------------ CLI
def run_cli(args: list[str], imu: Path, scratch: Path) -> dict:
    """One ``python -m strapdown.cli`` run under the cap; its record."""
    argv = [a.replace("{imu}", str(imu)).replace("{out}", str(scratch)) for a in args]
    fd, peak_file = tempfile.mkstemp(prefix="fz-peak-")
    os.close(fd)
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        p = subprocess.Popen([sys.executable, "-c", _CLI_MAIN, *argv], stdout=out,
                             stderr=err, stdin=subprocess.DEVNULL, preexec_fn=_cap,
                             env={**os.environ, "STRAPDOWN_FUZZ_PEAK": peak_file})
        status, usage = None, None
        while time.perf_counter() - t0 < KILL_AFTER:
            pid, status, usage = os.wait4(p.pid, os.WNOHANG)
            if pid:
                break
            time.sleep(0.01)
        else:
            os.killpg(p.pid, 9)
            _, status, usage = os.wait4(p.pid, 0)
        p.returncode = -1  # reaped here; keep Popen from waiting again
        seconds = time.perf_counter() - t0
        err.seek(0)
        text = err.read().decode("utf-8", "replace")
    try:  # the run's own peak; ru_maxrss (an upper bound, see _own_peak_mb) if it died
        peak = float(Path(peak_file).read_text() or "nan")
    except ValueError:
        peak = float("nan")
    os.unlink(peak_file)
    if not peak == peak:
        peak = usage.ru_maxrss / 1024.0 if usage else 0.0
    sig = os.WTERMSIG(status) if os.WIFSIGNALED(status) else 0
    code = os.WEXITSTATUS(status) if os.WIFEXITED(status) else None
    left = _files(scratch)
    hidden = [f for f in left if any(part.startswith(".") for part in Path(f).parts)]
    ok = code in (0, 2, 3) and not sig and "Traceback" not in text
    if code == 2 and len(text.strip().splitlines()) != 1:
        ok = False
    partial = hidden if code in (0, 3) or argv[0] == "sweep" else left
    return {"command": argv[0], "code": code, "signal": sig, "seconds": seconds,
            "peak_mb": peak, "ok": ok,
            "partial": partial, "stderr": text.strip()[-300:]}


# ------------------------------------------------------------------------------ summary
@dataclass
class Tally:
    inputs: int = 0
    runs: int = 0
    ok: int = 0
    refused: int = 0
    failures: list[str] = field(default_factory=list)
    slowest: float = 0.0
    peak_mb: float = 0.0
    #: the peak of the same runs on the format's valid corpus files (imports, numba runtime:
    #: what a trivially valid input costs); ``peak_mb`` less this is what hostile input adds
    valid_peak_mb: float = 0.0
    cli_runs: int = 0
    cli_ok: int = 0
    cli_refused: int = 0

    def measure(self, inp: Input, rec: dict) -> None:
        """Take a run's time and peak memory (a valid input's also as the baseline)."""
        self.slowest = max(self.slowest, rec["seconds"])
        self.peak_mb = max(self.peak_mb, rec["peak_mb"])
        if inp.origin.endswith("_valid"):
            self.valid_peak_mb = max(self.valid_peak_mb, rec["peak_mb"])


def _judge(t: Tally, inp: Input, rec: dict) -> None:
    t.runs += 1
    t.measure(inp, rec)
    where = f"{inp.origin} [{rec['target']}]"
    if rec["outcome"] == "ok":
        t.ok += 1
    elif rec["outcome"] == "input":
        t.refused += 1
    else:
        t.failures.append(f"{where}: {rec['outcome']} {rec['detail']}")
    if rec["seconds"] > TIME_LIMIT:
        t.failures.append(f"{where}: {rec['seconds']:.1f} s")
    if rec["peak_mb"] > PEAK_LIMIT_MB:
        t.failures.append(f"{where}: peak {rec['peak_mb']:.0f} MB")
    if rec["partial"]:
        t.failures.append(f"{where}: partial output {rec['partial'][:3]}")
    if rec["target"] == inp.target and inp.expect != "any":
        got = {"ok": "ok", "input": "error"}.get(rec["outcome"], "failure")
        if got != inp.expect:
            t.failures.append(f"{where}: expected {inp.expect}, got {rec['outcome']} "
                              f"{rec['detail'][:120]}")


def _api(items: list[Input], workers: int, tallies: dict[str, Tally], say) -> None:
    """Run the inputs through the API targets on ``workers`` worker processes."""
    lock = threading.Lock()
    queue = list(items)
    done = [0]

    def loop(w: _Worker) -> None:
        try:
            while True:
                with lock:
                    if not queue:
                        return
                    inp = queue.pop(0)
                recs = w.run({"id": inp.id, "fmt": inp.fmt, "path": str(inp.path)})
                with lock:
                    for r in recs:
                        _judge(tallies[inp.fmt], inp, r)
                    done[0] += 1
                    if done[0] % 500 == 0:
                        say(f"  {done[0]}/{len(items)} inputs")
        finally:
            w.stop()

    warm = _Worker()  # compile (or load) the numba kernels once, before any timing
    for inp in items:
        if inp.origin.startswith("corpus:") and inp.origin.endswith("_valid"):
            warm.run({"id": -1, "fmt": inp.fmt, "path": str(inp.path)}, limit=1800.0)
    # the warm worker goes on as the first worker (its imports and kernels are loaded: the
    # quick profile's one worker no longer starts and loads them a second time); its peak
    # mark then includes the valid files', an upper bound as for any worker
    threads = [threading.Thread(target=loop, args=(warm if k == 0 else _Worker(),))
               for k in range(workers)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()


def _cli(items: list[Input], per_format: int, tallies: dict[str, Tally], scratch: Path,
         rng: np.random.Generator) -> None:
    by_fmt: dict[str, list[Input]] = defaultdict(list)
    timed: set[tuple[str, ...]] = set()  # the command lines run once already
    for i in items:
        by_fmt[i.fmt].append(i)
    for fmt, group in by_fmt.items():
        corpus_first = [i for i in group if i.origin.startswith("corpus:")]
        rest = [i for i in group if not i.origin.startswith("corpus:")]
        picks = corpus_first[:per_format]
        if len(picks) < per_format and rest:
            extra = rng.choice(len(rest), size=min(per_format - len(picks), len(rest)),
                               replace=False)
            picks += [rest[int(k)] for k in extra]
        t = tallies[fmt]
        for k, inp in enumerate(picks):
            args = CLI[fmt][k % len(CLI[fmt])]
            d = scratch / f"cli-{fmt}-{k}"
            d.mkdir(parents=True)
            rec = run_cli(args, inp.path, d)
            if rec["seconds"] > TIME_LIMIT and tuple(args) not in timed:
                # a command's first run may compile kernels no API target needed (a fresh
                # clone's `nav`: 12 CPU-s): it is run again, and the second run is judged
                # (a slow input stays slow; the compile is cached by then)
                shutil.rmtree(d, ignore_errors=True)
                d.mkdir(parents=True)
                rec = run_cli(args, inp.path, d)
            timed.add(tuple(args))
            shutil.rmtree(d, ignore_errors=True)
            t.cli_runs += 1
            t.measure(inp, rec)
            where = f"{inp.origin} [strapdown {rec['command']}]"
            if not rec["ok"]:
                t.failures.append(f"{where}: exit {rec['code']} signal {rec['signal']}: "
                                  f"{rec['stderr'][-200:]}")
            elif rec["code"] == 2:
                t.cli_refused += 1
            else:
                t.cli_ok += 1
            if rec["seconds"] > TIME_LIMIT:
                t.failures.append(f"{where}: {rec['seconds']:.1f} s")
            if rec["peak_mb"] > PEAK_LIMIT_MB:
                t.failures.append(f"{where}: peak {rec['peak_mb']:.0f} MB")
            if rec["partial"]:
                t.failures.append(f"{where}: partial output {rec['partial'][:3]}")


def campaign(profile_name: str, seed: int = 16, say=print, keep: Path | None = None
             ) -> dict[str, Tally]:
    """Run a profile; the tallies per format."""
    profile = PROFILES[profile_name]
    root = Path(tempfile.mkdtemp(prefix="strapdown-fuzz-")) if keep is None else keep
    try:
        items = inputs(profile, root, seed)
        tallies = {f: Tally() for f in corpus.FORMATS}
        for i in items:
            tallies[i.fmt].inputs += 1
        say(f"{len(items)} inputs ({sum(1 for i in items if i.origin.startswith('corpus'))} "
            f"from the corpus), {profile['workers']} worker(s)")
        _api(items, profile["workers"], tallies, say)
        say("command lines ...")
        _cli(items, profile["cli_per_format"], tallies, root / "cli",
             np.random.default_rng(seed + 1))
        return tallies
    finally:
        if keep is None:
            shutil.rmtree(root, ignore_errors=True)


def report(tallies: dict[str, Tally]) -> str:
    """The closing table: counts per format, then every failure. ``peak MB``: the highest
    peak of any run of the format; ``valid MB``: the same runs on its valid corpus files."""
    head = (f"{'format':7s} {'inputs':>7s} {'API runs':>9s} {'read':>7s} {'refused':>8s} "
            f"{'CLI runs':>9s} {'CLI ok':>7s} {'CLI exit 2':>10s} {'failures':>9s} "
            f"{'slowest s':>10s} {'peak MB':>8s} {'valid MB':>9s}")
    lines = [head, "-" * len(head)]
    total = Counter()
    for fmt, t in tallies.items():
        lines.append(f"{fmt:7s} {t.inputs:7d} {t.runs:9d} {t.ok:7d} {t.refused:8d} "
                     f"{t.cli_runs:9d} {t.cli_ok:7d} {t.cli_refused:10d} {len(t.failures):9d} "
                     f"{t.slowest:10.2f} {t.peak_mb:8.0f} {t.valid_peak_mb:9.0f}")
        total.update(inputs=t.inputs, runs=t.runs, ok=t.ok, refused=t.refused, cli=t.cli_runs,
                     cli_ok=t.cli_ok, cli_refused=t.cli_refused, failures=len(t.failures))
    lines.append(f"{'total':7s} {total['inputs']:7d} {total['runs']:9d} {total['ok']:7d} "
                 f"{total['refused']:8d} {total['cli']:9d} {total['cli_ok']:7d} "
                 f"{total['cli_refused']:10d} {total['failures']:9d} "
                 f"{max(t.slowest for t in tallies.values()):10.2f} "
                 f"{max(t.peak_mb for t in tallies.values()):8.0f} "
                 f"{max(t.valid_peak_mb for t in tallies.values()):9.0f}")
    for fmt, t in tallies.items():
        for f in t.failures[:50]:
            lines.append(f"FAIL {fmt}: {f}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--profile", choices=sorted(PROFILES), default="long")
    p.add_argument("--seed", type=int, default=16)
    p.add_argument("--keep", type=Path, default=None, help="write the inputs here and keep them")
    args = p.parse_args(argv)
    t0 = time.time()
    tallies = campaign(args.profile, args.seed, keep=args.keep)
    print(report(tallies))
    print(f"elapsed {time.time() - t0:.0f} s")
    return 1 if any(t.failures for t in tallies.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
