"""Golden outputs of the ``strapdown`` command line, recorded before a refactor, compared after.

The tool drives the command line only, so the same script records the old and the new code:
every command runs as a subprocess ::

    [sys.executable, "-c", "import sys; from strapdown.cli import main; sys.exit(main())", *args]

in a fresh temporary working directory, with the caller's environment passed through
(``PYTHONPATH`` selects which ``strapdown`` is run; the record's manifest says which one was).

What ``record`` runs (see :func:`commands` for the exact list):

* ``reproduce NAME --out report`` for every paper the CLI accepts (tables, reports);
* ``evaluate ... --json`` on ~30 configurations covering every algorithm family (rotvec
  conventional / real-time / single-chain with several N and coefficient sets, rate-single,
  rate-three conventional and sliding, rk4 both steps, miller / panov / power on the Krylov
  motion, arbitrary precision, spin and spin + coning), a few in text mode, and rejected input;
* ``coefficients --form F --subsamples N --json`` for every form, N = 1 … 6 and both targets,
  plus the min-norm rule, ``--ignore-quadrature``, ``--previous``, text mode and rejected input;
* ``export-c`` for every algorithm / structure combination it accepts (rotvec N = 1 … 6, the
  named coefficient sets, float, both rate coefficient sets) and the combinations it rejects;
* ``ahrs`` on every BROAD trial (``--broad DIR``), plus propagation / frame / flag variants on
  the first trial;
* ``--version`` and every subcommand's ``--help``.

For each command ``OUTDIR/<group>/<label>/`` holds ``command.json`` (arguments and exit code),
``stdout.txt``, ``stderr.txt`` and ``files/`` (everything the command wrote, except images,
which are not byte-stable). ``OUTDIR/manifest.json`` says which ``strapdown`` ran (its
``__file__``), the library versions, and per-command run times; ``compare`` does not compare it
byte by byte.

Usage (from the repository root)::

    PYTHONPATH=/work/base/src .venv/bin/python tools/golden.py record /work/golden/before
    .venv/bin/python tools/golden.py record /work/golden/after          # the refactored code
    .venv/bin/python tools/golden.py compare /work/golden/before /work/golden/after

``compare`` checks file by file: identical bytes, else identical after
:func:`normalise_text` (report run times, version strings, temporary directories, package
source paths), else for CSV / JSON / other text the numbers are parsed and the maximum
absolute and relative differences reported. It exits 0 only if every file matches exactly or
within ``--rtol`` (default 1e-15 relative), listing the files that needed the tolerance.
Differences in ``stderr.txt`` of commands that succeeded are reported but do not fail the
comparison (progress and warnings may legitimately change); for commands that exited non-zero
stderr carries the error message and is compared like any other file.
"""

from __future__ import annotations

import argparse
import csv
import difflib
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

CLI = "import sys; from strapdown.cli import main; sys.exit(main())"
PROBE = ("import json, strapdown, numpy, scipy, numba, mpmath, sympy; "
         "print(json.dumps({'strapdown_file': strapdown.__file__, "
         "'strapdown_version': strapdown.__version__, 'numpy': numpy.__version__, "
         "'scipy': scipy.__version__, 'numba': numba.__version__, "
         "'mpmath': mpmath.__version__, 'sympy': sympy.__version__}))")
REPRODUCTIONS = ("li2017", "plaksiy2024", "zhang2021", "wang-rate", "wang-sliding")
FORMS = ("cross-with-last", "lag", "all-pairs", "single-chain", "uncompressed", "rate",
         "rate-three")
TARGETS = ("coning", "polynomial")
SUBCOMMANDS = ("evaluate", "coefficients", "export-c", "run", "compare", "sweep", "ahrs",
               "benchmark-ahrs", "reproduce")
SKIPPED_SUFFIXES = (".png", ".jpg", ".jpeg", ".pdf", ".svg")  # figures are not byte-stable
TMP_PREFIX = "strapdown-golden-"
MANIFEST = "manifest.json"
DEFAULT_RTOL = 1e-15

# Environment pinned on top of the caller's (PYTHONPATH and everything else pass through):
# argparse wraps usage and help to COLUMNS; UTF-8 output; one BLAS thread so parallel jobs do
# not compete; a fixed hash seed so set ordering cannot vary between runs.
PINNED_ENV = {
    "COLUMNS": "100",
    "PYTHONIOENCODING": "utf-8",
    "PYTHONUTF8": "1",
    "PYTHONHASHSEED": "0",
    "MPLBACKEND": "Agg",
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
}


# ------------------------------------------------------------------------------ commands
@dataclass(frozen=True)
class Command:
    """One CLI invocation: ``key`` names its record directory (``group/label``)."""

    key: str
    args: tuple[str, ...]
    links: tuple[tuple[str, str], ...] = ()  # (name in the working directory, target path)


def _evaluate_configs() -> list[tuple[str, list[str]]]:
    coning = ["--sample-rate-hz", "600", "--duration", "10"]
    krylov = ["--motion", "krylov", "--step", "0.1", "--duration", "200"]
    return [
        # rotation vector, conventional structure, several N and coefficient sets
        ("rotvec-conventional-n1-table3", [*coning, "--subsamples", "1"]),
        ("rotvec-conventional-n2-table3", [*coning, "--subsamples", "2",
                                           "--coefficients", "table3"]),
        ("rotvec-conventional-n3-default", []),  # the CLI defaults: 10 kHz, 2 s, N = 3
        ("rotvec-conventional-n4-lag", [*coning, "--subsamples", "4", "--coefficients", "lag"]),
        ("rotvec-conventional-n5-eq6-printed", [*coning, "--subsamples", "5",
                                                "--coefficients", "eq6-printed"]),
        ("rotvec-conventional-n3-miller", [*coning, "--subsamples", "3",
                                           "--coefficients", "miller"]),
        ("rotvec-conventional-n2-none", [*coning, "--subsamples", "2", "--coefficients", "none"]),
        ("rotvec-conventional-n6-table3", ["--half-angle-deg", "5", "--cone-rate-hz", "5",
                                           "--sample-rate-hz", "600", "--duration", "6",
                                           "--subsamples", "6"]),
        # real-time and single-chain structures
        ("rotvec-realtime-n3-table3", ["--sample-rate-hz", "600", "--duration", "20",
                                       "--subsamples", "3", "--structure", "realtime"]),
        ("rotvec-realtime-n4-lag", [*coning, "--subsamples", "4", "--coefficients", "lag",
                                    "--structure", "realtime"]),
        ("rotvec-single-chain-n3", ["--sample-rate-hz", "600", "--duration", "20",
                                    "--subsamples", "3", "--structure", "single-chain"]),
        ("rotvec-single-chain-n5", [*coning, "--subsamples", "5", "--structure", "single-chain"]),
        # rate input
        ("rate-single-derived", [*coning, "--algorithm", "rate-single"]),
        ("rate-single-paper", [*coning, "--algorithm", "rate-single", "--coefficients", "paper"]),
        ("rate-three-conventional-derived", [*coning, "--algorithm", "rate-three"]),
        ("rate-three-conventional-paper", [*coning, "--algorithm", "rate-three",
                                           "--coefficients", "paper"]),
        ("rate-three-sliding-derived", [*coning, "--algorithm", "rate-three",
                                        "--structure", "sliding"]),
        ("rate-three-sliding-paper", [*coning, "--algorithm", "rate-three",
                                      "--structure", "sliding", "--coefficients", "paper"]),
        ("rk4-2td", [*coning, "--algorithm", "rk4"]),
        ("rk4-td-interp", [*coning, "--algorithm", "rk4", "--rk4-step", "td-interp"]),
        # Plaksiy's quaternion algorithms on the Krylov-angle motion
        ("miller-krylov-readme", ["--motion", "krylov", "--krylov-rates", "0.3", "0.5", "0.1",
                                  "--algorithm", "miller", "--alpha", "0.45", "--beta", "0.675",
                                  "--step", "0.1", "--duration", "200"]),
        ("miller-krylov-default-exact-exp", [*krylov, "--algorithm", "miller", "--exact-exp"]),
        ("panov-krylov", [*krylov, "--algorithm", "panov"]),
        ("panov-krylov-alpha", [*krylov, "--algorithm", "panov", "--alpha", "0.7"]),
        ("power-krylov", [*krylov, "--algorithm", "power"]),
        # arbitrary precision (small)
        ("precision50-rotvec-n5", ["--half-angle-deg", "5.7e-5", "--sample-rate-hz", "60",
                                   "--duration", "2", "--subsamples", "5", "--precision", "50"]),
        ("precision30-realtime-n2", ["--sample-rate-hz", "600", "--duration", "1",
                                     "--subsamples", "2", "--structure", "realtime",
                                     "--precision", "30"]),
        ("precision30-rate-three", ["--sample-rate-hz", "600", "--duration", "1",
                                    "--algorithm", "rate-three", "--precision", "30"]),
        # spin and spin + coning
        ("spin-coning-rotvec-n3", ["--motion", "spin-coning", "--half-angle-deg", "2",
                                   "--cone-rate-hz", "3", "--spin-rate-dps", "720",
                                   "--sample-rate-hz", "1000", "--duration", "4"]),
        ("spin-coning-rate-three", ["--motion", "spin-coning", "--half-angle-deg", "2",
                                    "--cone-rate-hz", "3", "--spin-rate-dps", "720",
                                    "--sample-rate-hz", "1000", "--duration", "4",
                                    "--algorithm", "rate-three"]),
        ("spin-rotvec-single-chain", ["--motion", "spin", "--spin-rate-dps", "3600",
                                      "--sample-rate-hz", "2000", "--duration", "2",
                                      "--structure", "single-chain"]),
    ]


def commands(broad: Path | None) -> list[Command]:
    """Every command ``record`` runs, longest first (they run in parallel)."""
    cmds = [Command(f"reproduce/{name}", ("reproduce", name, "--out", "report"))
            for name in REPRODUCTIONS]

    if broad is not None:
        trials = sorted(broad.glob("*.mat"))
        for trial in trials:
            link = (trial.name, str(trial))
            cmds.append(Command(f"ahrs/{trial.stem}",
                                ("ahrs", "--imu", trial.name, "--out", "attitude.csv"), (link,)))
        if trials:
            first = trials[0]
            link = (first.name, str(first))
            for label, extra in [
                ("rate-three", ["--algorithm", "rate-three"]),
                ("rate-three-sliding", ["--algorithm", "rate-three:structure=sliding"]),
                ("rk4", ["--algorithm", "rk4"]),
                ("rotvec-n3", ["--algorithm", "rotvec:N=3"]),
                ("ned-declination", ["--frame", "NED", "--declination-deg", "3.5"]),
                ("no-mag", ["--no-mag"]),
                ("no-gating", ["--no-gating"]),
            ]:
                cmds.append(Command(f"ahrs-variants/{first.stem}-{label}",
                                    ("ahrs", "--imu", first.name, "--out", "attitude.csv",
                                     *extra), (link,)))

    for label, extra in _evaluate_configs():
        cmds.append(Command(f"evaluate/{label}", ("evaluate", *extra, "--json")))
    for label, extra in [
        ("text-rotvec-realtime", ["--subsamples", "3", "--structure", "realtime",
                                  "--sample-rate-hz", "600", "--duration", "20"]),
        ("text-miller-krylov", ["--motion", "krylov", "--algorithm", "miller",
                                "--step", "0.1", "--duration", "200"]),
        ("text-precision", ["--half-angle-deg", "5.7e-5", "--sample-rate-hz", "60",
                            "--duration", "2", "--subsamples", "5", "--precision", "50"]),
        ("reject-miller-no-step", ["--algorithm", "miller", "--motion", "krylov", "--json"]),
        ("reject-subsamples-7", ["--subsamples", "7", "--json"]),
        ("reject-rk4-coefficients", ["--algorithm", "rk4", "--coefficients", "paper", "--json"]),
        ("reject-unknown-structure", ["--structure", "windowed", "--json"]),
    ]:
        cmds.append(Command(f"evaluate/{label}", ("evaluate", *extra)))

    for form in FORMS:
        for target in TARGETS:
            for n in range(1, 7):
                cmds.append(Command(f"coefficients/{form}-{target}-n{n}",
                                    ("coefficients", "--form", form, "--subsamples", str(n),
                                     "--target", target, "--json")))
    for label, extra in [
        ("all-pairs-min-norm-n3", ["--form", "all-pairs", "--subsamples", "3",
                                   "--rule", "min-norm", "--json"]),
        ("uncompressed-polynomial-min-norm-n2", ["--form", "uncompressed", "--subsamples", "2",
                                                 "--target", "polynomial", "--rule", "min-norm",
                                                 "--json"]),
        ("uncompressed-n2-previous1", ["--form", "uncompressed", "--subsamples", "2",
                                       "--previous", "1", "--json"]),
        ("uncompressed-n3-previous2", ["--form", "uncompressed", "--subsamples", "3",
                                       "--previous", "2", "--json"]),
        ("rate-n2-ignore-quadrature", ["--form", "rate", "--subsamples", "2",
                                       "--ignore-quadrature", "--json"]),
        ("rate-three-ignore-quadrature", ["--form", "rate-three", "--subsamples", "3",
                                          "--ignore-quadrature", "--json"]),
        ("text-cross-with-last-n4", ["--form", "cross-with-last", "--subsamples", "4"]),
        ("text-all-pairs-polynomial-n3", ["--form", "all-pairs", "--subsamples", "3",
                                          "--target", "polynomial"]),
        ("text-rate-three-ignore-quadrature", ["--form", "rate-three", "--subsamples", "3",
                                               "--ignore-quadrature"]),
        ("text-single-chain-n1", ["--form", "single-chain", "--subsamples", "1"]),
        ("reject-n0", ["--form", "lag", "--subsamples", "0", "--json"]),
        ("reject-n-negative", ["--form", "cross-with-last", "--subsamples", "-1", "--json"]),
        ("reject-unknown-form", ["--form", "pairs", "--subsamples", "3", "--json"]),
    ]:
        cmds.append(Command(f"coefficients/{label}", ("coefficients", *extra)))

    exports: list[tuple[str, list[str]]] = []
    for structure in ("conventional", "realtime", "single-chain"):
        for n in range(1, 7):
            exports.append((f"rotvec-{structure}-n{n}",
                            ["--algorithm", "rotvec", "--structure", structure,
                             "--subsamples", str(n)]))
    for coeffs, n in [("lag", 4), ("eq6-printed", 4), ("miller", 3), ("none", 2)]:
        exports.append((f"rotvec-conventional-n{n}-{coeffs}",
                        ["--algorithm", "rotvec", "--subsamples", str(n),
                         "--coefficients", coeffs]))
    exports += [
        ("rotvec-realtime-n3-lag", ["--algorithm", "rotvec", "--structure", "realtime",
                                    "--coefficients", "lag"]),
        ("rotvec-single-chain-n3-float", ["--algorithm", "rotvec", "--structure",
                                          "single-chain", "--float", "float"]),
        ("rotvec-conventional-n3-named", ["--algorithm", "rotvec", "--name", "flight_att"]),
    ]
    for coeffs in ("derived", "paper"):
        exports.append((f"rate-single-conventional-{coeffs}",
                        ["--algorithm", "rate-single", "--coefficients", coeffs,
                         "--sample-rate-hz", "600"]))
        for structure in ("conventional", "sliding"):
            exports.append((f"rate-three-{structure}-{coeffs}",
                            ["--algorithm", "rate-three", "--structure", structure,
                             "--coefficients", coeffs, "--sample-rate-hz", "600"]))
    exports += [
        ("rate-three-sliding-default-rate", ["--algorithm", "rate-three", "--structure",
                                             "sliding"]),
        ("rate-three-conventional-float", ["--algorithm", "rate-three", "--float", "float",
                                           "--sample-rate-hz", "1000"]),
        ("rk4-conventional", ["--algorithm", "rk4", "--sample-rate-hz", "600"]),
        ("rk4-conventional-float", ["--algorithm", "rk4", "--float", "float",
                                    "--sample-rate-hz", "1000"]),
        ("reject-rotvec-sliding", ["--algorithm", "rotvec", "--structure", "sliding"]),
        ("reject-single-chain-lag", ["--algorithm", "rotvec", "--structure", "single-chain",
                                     "--coefficients", "lag"]),
        ("reject-rate-single-sliding", ["--algorithm", "rate-single", "--structure",
                                        "sliding"]),
        ("reject-rate-three-realtime", ["--algorithm", "rate-three", "--structure",
                                        "realtime"]),
        ("reject-rk4-sliding", ["--algorithm", "rk4", "--structure", "sliding"]),
        ("reject-rk4-coefficients", ["--algorithm", "rk4", "--coefficients", "paper"]),
        ("reject-bad-name", ["--algorithm", "rotvec", "--name", "1bad-name"]),
        ("reject-zero-rate", ["--algorithm", "rk4", "--sample-rate-hz", "0"]),
    ]
    for label, extra in exports:
        cmds.append(Command(f"export-c/{label}", ("export-c", *extra, "--out", "flight")))

    cmds.append(Command("cli/version", ("--version",)))
    cmds.append(Command("cli/help", ("--help",)))
    cmds.extend(Command(f"cli/help-{sub}", (sub, "--help")) for sub in SUBCOMMANDS)
    cmds.append(Command("cli/reject-no-command", ()))
    return cmds


# ------------------------------------------------------------------------------ record
def child_env() -> dict[str, str]:
    """The caller's environment (PYTHONPATH included) with :data:`PINNED_ENV` on top."""
    env = dict(os.environ)
    env.update(PINNED_ENV)
    return env


def probe(env: dict[str, str]) -> dict:
    """Which ``strapdown`` (and which numerical libraries) the subprocesses import."""
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True,
                         text=True, encoding="utf-8", check=True, cwd=tempfile.gettempdir())
    return json.loads(out.stdout)


def check_selection(info: dict, env: dict[str, str]) -> None:
    """Refuse to record if PYTHONPATH is set but ``strapdown`` is imported from elsewhere."""
    entries = [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    if not entries:
        return
    pkg = Path(info["strapdown_file"]).resolve()
    if not any(pkg.is_relative_to(Path(p).resolve()) for p in entries):
        raise SystemExit(f"golden: PYTHONPATH={env['PYTHONPATH']} is set but strapdown is "
                         f"imported from {pkg}")


def run_one(cmd: Command, out: Path, tmp_root: Path, env: dict[str, str],
            timeout: float) -> dict:
    """Run one command in a fresh working directory and store its outputs under ``out``."""
    work = Path(tempfile.mkdtemp(prefix="cwd-", dir=tmp_root))
    for name, target in cmd.links:
        (work / name).symlink_to(target)
    argv = [sys.executable, "-c", CLI, *cmd.args]
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(argv, cwd=work, env=env, capture_output=True, timeout=timeout)
        code, stdout, stderr = proc.returncode, proc.stdout, proc.stderr
    except subprocess.TimeoutExpired as exc:
        code = "timeout"
        stdout, stderr = exc.stdout or b"", (exc.stderr or b"") + b"\n[golden: timed out]\n"
    seconds = time.perf_counter() - t0

    dest = out / cmd.key
    dest.mkdir(parents=True)
    (dest / "command.json").write_text(
        json.dumps({"args": list(cmd.args), "exit_code": code}, indent=2) + "\n",
        encoding="utf-8")
    (dest / "stdout.txt").write_bytes(stdout)
    (dest / "stderr.txt").write_bytes(stderr)
    skipped = []
    for path in sorted(work.rglob("*")):
        if path.is_symlink() or not path.is_file():
            continue
        rel = path.relative_to(work)
        if path.suffix.lower() in SKIPPED_SUFFIXES:
            skipped.append(str(rel))
            continue
        target = dest / "files" / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, target)
    shutil.rmtree(work, ignore_errors=True)
    return {"key": cmd.key, "args": list(cmd.args), "exit_code": code,
            "seconds": round(seconds, 3), "skipped_files": skipped}


def record(out: Path, broad: Path | None, jobs: int, timeout: float) -> int:
    if out.exists() and any(out.iterdir()):
        print(f"golden: {out} exists and is not empty", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    env = child_env()
    info = probe(env)
    check_selection(info, env)
    print(f"golden: strapdown {info['strapdown_version']} from {info['strapdown_file']}",
          file=sys.stderr)
    cmds = commands(broad)
    t_start = time.perf_counter()
    started = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    results = []
    with tempfile.TemporaryDirectory(prefix=TMP_PREFIX) as tmp, \
            ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(run_one, c, out, Path(tmp), env, timeout) for c in cmds]
        for i, fut in enumerate(as_completed(futures), 1):
            r = fut.result()
            results.append(r)
            print(f"[{i:3d}/{len(cmds)}] exit {r['exit_code']!s:>7}  {r['seconds']:7.1f} s  "
                  f"{r['key']}", file=sys.stderr)
    total = time.perf_counter() - t_start
    order = {c.key: i for i, c in enumerate(cmds)}
    results.sort(key=lambda r: order[r["key"]])
    manifest = {
        "tool": "tools/golden.py", "format": 1, **info,
        "python": sys.version, "executable": sys.executable,
        "pythonpath": os.environ.get("PYTHONPATH"), "pinned_env": PINNED_ENV,
        "broad_dir": None if broad is None else str(broad), "jobs": jobs,
        "started": started, "total_seconds": round(total, 1), "commands": results,
    }
    (out / MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
    failed = [r for r in results if r["exit_code"] != 0
              and "/reject-" not in r["key"] and r["key"] != "cli/reject-no-command"]
    slow = sorted((r for r in results if r["seconds"] > 60), key=lambda r: -r["seconds"])
    print(f"golden: {len(results)} commands in {total:.0f} s (wall, {jobs} jobs) -> {out}",
          file=sys.stderr)
    for r in slow:
        print(f"golden: slow: {r['key']} {r['seconds']:.0f} s", file=sys.stderr)
    for r in failed:
        print(f"golden: unexpected exit {r['exit_code']}: {r['key']}", file=sys.stderr)
    return 1 if failed else 0


# ------------------------------------------------------------------------------ compare
# Each rule: (name, pattern, replacement). Applied to every text file before comparing.
NORMALISATIONS = [
    # reproduction reports state their run time: "Generated by `strapdown reproduce X` ... in
    # 48 s." and wang-sliding's "Run time 50 s."
    ("report run time",
     re.compile(r"(Generated by `strapdown reproduce [\w-]+`(?: \([^)]*\))? in )\d+(?:\.\d+)? s"),
     r"\1<ELAPSED> s"),
    ("report run time", re.compile(r"\bRun time \d+(?:\.\d+)? s"), "Run time <ELAPSED> s"),
    # the package version ("strapdown 0.1.0" in --version and in report headers)
    ("version string",
     re.compile(r"\bstrapdown v?\d+\.\d+(?:\.\d+)?(?:(?:\.|\+|-)?(?:dev|post|rc|a|b)\w*)*"),
     "strapdown <VERSION>"),
    # the record's temporary working directories, wherever the system puts them
    ("temporary directory",
     re.compile(r"[^\s'\"]*/" + re.escape(TMP_PREFIX) + r"[\w]+(?:/cwd-[\w]+)?"), "<TMP>"),
    # absolute paths of the package's source files (tracebacks, warnings): old and new code
    # live in different checkouts; the path inside the package is kept
    ("package source path",
     re.compile(r"(?:/[^\s'\":/]+)+/strapdown/((?:[\w.]+/)*[\w.]+\.py)"), r"<PKG>/\1"),
]


def normalise_text(text: str) -> str:
    """Replace run times, version strings, temporary directories and package source paths."""
    for _name, pattern, repl in NORMALISATIONS:
        text = pattern.sub(repl, text)
    return text


def normalisations_needed(a: str, b: str) -> list[str]:
    """Names of the rules whose matches differ between two texts (what made them differ)."""
    needed = []
    for name, pattern, _repl in NORMALISATIONS:
        found_a = [m.group(0) for m in pattern.finditer(a)]
        found_b = [m.group(0) for m in pattern.finditer(b)]
        if found_a != found_b and name not in needed:
            needed.append(name)
    return needed


_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])")


@dataclass
class NumericDiff:
    """Largest differences between two files' numbers; ``mismatch`` if not numbers alone."""

    max_abs: float = 0.0
    max_rel: float = 0.0
    where: str = ""
    mismatch: str = ""

    def add(self, a: float, b: float, where: str) -> None:
        if a == b or (math.isnan(a) and math.isnan(b)):
            return
        if math.isinf(a) or math.isinf(b) or math.isnan(a) or math.isnan(b):
            d = r = math.inf
        else:
            d = abs(a - b)
            r = d / max(abs(a), abs(b))
        if r > self.max_rel or (r == self.max_rel and d > self.max_abs):
            self.where = f"{where}: {a!r} vs {b!r}"
        self.max_abs = max(self.max_abs, d)
        self.max_rel = max(self.max_rel, r)


def _as_float(s: str) -> float | None:
    try:
        return float(s)
    except ValueError:
        return None


def _diff_json(a, b, path: str, acc: NumericDiff) -> None:
    if acc.mismatch:
        return
    if isinstance(a, bool) or isinstance(b, bool) or a is None or b is None \
            or isinstance(a, str) or isinstance(b, str):
        if a != b or type(a) is not type(b):
            acc.mismatch = f"{path or '<root>'}: {a!r} vs {b!r}"
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)):
        acc.add(float(a), float(b), path or "<root>")
    elif isinstance(a, dict) and isinstance(b, dict):
        if list(a) != list(b):
            acc.mismatch = f"{path or '<root>'}: keys {list(a)} vs {list(b)}"
            return
        for k in a:
            _diff_json(a[k], b[k], f"{path}.{k}" if path else k, acc)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            acc.mismatch = f"{path or '<root>'}: length {len(a)} vs {len(b)}"
            return
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _diff_json(x, y, f"{path}[{i}]", acc)
    else:
        acc.mismatch = f"{path or '<root>'}: {type(a).__name__} vs {type(b).__name__}"


def _diff_csv(a: str, b: str, acc: NumericDiff) -> None:
    ra, rb = list(csv.reader(io.StringIO(a))), list(csv.reader(io.StringIO(b)))
    if len(ra) != len(rb):
        acc.mismatch = f"{len(ra)} vs {len(rb)} rows"
        return
    header = ra[0] if ra else []
    for i, (x, y) in enumerate(zip(ra, rb, strict=True)):
        if len(x) != len(y):
            acc.mismatch = f"row {i}: {len(x)} vs {len(y)} cells"
            return
        for j, (u, v) in enumerate(zip(x, y, strict=True)):
            if u == v:
                continue
            fu, fv = _as_float(u), _as_float(v)
            col = header[j] if j < len(header) else str(j)
            if fu is None or fv is None:
                acc.mismatch = f"row {i}, column {col}: {u!r} vs {v!r}"
                return
            acc.add(fu, fv, f"row {i}, column {col}")


def _diff_text(a: str, b: str, acc: NumericDiff) -> None:
    la, lb = a.splitlines(), b.splitlines()
    if len(la) != len(lb):
        acc.mismatch = f"{len(la)} vs {len(lb)} lines"
        return
    for i, (x, y) in enumerate(zip(la, lb, strict=True), 1):
        if x == y:
            continue
        if _NUMBER.sub("#", x) != _NUMBER.sub("#", y):
            acc.mismatch = f"line {i}: {x!r} vs {y!r}"
            return
        for u, v in zip(_NUMBER.findall(x), _NUMBER.findall(y), strict=True):
            acc.add(float(u), float(v), f"line {i}")


def numeric_diff(name: str, a: str, b: str) -> NumericDiff:
    """Numbers of two texts compared: JSON by structure, CSV by cell, other text by line."""
    acc = NumericDiff()
    if name.endswith(".json"):
        try:
            ja, jb = json.loads(a), json.loads(b)
        except ValueError:
            _diff_text(a, b, acc)
        else:
            _diff_json(ja, jb, "", acc)
    elif name.endswith(".csv"):
        _diff_csv(a, b, acc)
    else:
        try:  # evaluate --json and coefficients --json print JSON on stdout
            ja, jb = json.loads(a), json.loads(b)
        except ValueError:
            _diff_text(a, b, acc)
        else:
            _diff_json(ja, jb, "", acc)
    return acc


def _files(root: Path) -> set[str]:
    return {p.relative_to(root).as_posix() for p in root.rglob("*")
            if p.is_file() and p.relative_to(root).as_posix() != MANIFEST}


def _exit_code(root: Path, rel: str):
    cmd = root / Path(rel).parent / "command.json"
    try:
        return json.loads(cmd.read_text(encoding="utf-8"))["exit_code"]
    except (OSError, ValueError, KeyError):
        return None


def _first_diff(a: str, b: str) -> str:
    lines = list(difflib.unified_diff(a.splitlines(), b.splitlines(), lineterm="", n=0))
    return "\n".join("      " + line for line in lines[2:8])


def compare(before: Path, after: Path, rtol: float) -> int:
    for root in (before, after):
        m = root / MANIFEST
        if m.is_file():
            info = json.loads(m.read_text(encoding="utf-8"))
            libs = ", ".join(f"{k} {info.get(k)}" for k in ("numpy", "scipy", "numba",
                                                             "mpmath", "sympy"))
            print(f"{root}: strapdown {info.get('strapdown_version')} from "
                  f"{info.get('strapdown_file')}; {libs}")
        else:
            print(f"{root}: no {MANIFEST}")
    fa, fb = _files(before), _files(after)
    identical, normalised, tolerance, differ, stderr_only = [], [], [], [], []
    for rel in sorted(fa & fb):
        ba, bb = (before / rel).read_bytes(), (after / rel).read_bytes()
        if ba == bb:
            identical.append(rel)
            continue
        try:
            ta, tb = ba.decode("utf-8"), bb.decode("utf-8")
        except UnicodeDecodeError:
            differ.append((rel, "binary files differ"))
            continue
        na, nb = normalise_text(ta), normalise_text(tb)
        if na == nb:
            normalised.append((rel, normalisations_needed(ta, tb)))
            continue
        nd = numeric_diff(rel, na, nb)
        if nd.mismatch:
            detail = f"not only numbers differ ({nd.mismatch})\n{_first_diff(na, nb)}"
        elif nd.max_rel <= rtol:
            tolerance.append((rel, nd))
            continue
        else:
            detail = (f"max abs {nd.max_abs:.3e}, max rel {nd.max_rel:.3e} "
                      f"(largest at {nd.where})")
        if rel.endswith("/stderr.txt") and _exit_code(before, rel) == 0 \
                and _exit_code(after, rel) == 0:
            stderr_only.append((rel, detail))
        else:
            differ.append((rel, detail))

    print(f"\n{len(identical)} files byte-identical")
    for rel, rules in normalised:
        print(f"NORMALISED  {rel}  ({', '.join(rules)})")
    for rel, nd in tolerance:
        print(f"TOLERANCE   {rel}  max abs {nd.max_abs:.3e}, max rel {nd.max_rel:.3e}")
    for rel, detail in stderr_only:
        print(f"STDERR      {rel}  (command succeeded; not counted): {detail}")
    for rel, detail in differ:
        print(f"DIFF        {rel}  {detail}")
    for rel in sorted(fa - fb):
        print(f"MISSING     {rel}  (in {before} only)")
    for rel in sorted(fb - fa):
        print(f"EXTRA       {rel}  (in {after} only)")
    bad = len(differ) + len(fa - fb) + len(fb - fa)
    print(f"\n{len(identical)} identical, {len(normalised)} identical after normalisation, "
          f"{len(tolerance)} within rtol {rtol:g}, {len(stderr_only)} stderr-only, "
          f"{len(differ)} different, {len(fa - fb)} missing, {len(fb - fa)} extra")
    print("OK" if bad == 0 else "FAILED")
    return 0 if bad == 0 else 1


# ------------------------------------------------------------------------------ main
def _default_broad() -> Path | None:
    env = os.environ.get("STRAPDOWN_BROAD")
    if env:
        return Path(env)
    beside = Path(__file__).resolve().parents[2] / "shared" / "data" / "broad"
    return beside if beside.is_dir() else None


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="golden.py", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("record", help="run every command and store its outputs in OUTDIR")
    r.add_argument("outdir", type=Path)
    r.add_argument("--broad", type=Path, default=None,
                   help="directory of BROAD .mat trials (default $STRAPDOWN_BROAD, else "
                   "../shared/data/broad beside the checkout)")
    r.add_argument("--no-broad", action="store_true", help="skip the ahrs commands")
    r.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                   help="commands run in parallel (default: CPU count)")
    r.add_argument("--timeout", type=float, default=3600.0, help="per command (s)")
    c = sub.add_parser("compare", help="compare two record directories file by file")
    c.add_argument("before", type=Path)
    c.add_argument("after", type=Path)
    c.add_argument("--rtol", type=float, default=DEFAULT_RTOL,
                   help=f"relative tolerance on numbers (default {DEFAULT_RTOL:g})")
    args = p.parse_args(argv)
    if args.command == "compare":
        return compare(args.before, args.after, args.rtol)
    broad = None
    if not args.no_broad:
        broad = args.broad or _default_broad()
        if broad is None or not any(broad.glob("*.mat")):
            p.error(f"no BROAD .mat trials in {broad}; give --broad DIR or --no-broad")
        broad = broad.resolve()
    return record(args.outdir, broad, max(1, args.jobs), args.timeout)


if __name__ == "__main__":
    sys.exit(main())
