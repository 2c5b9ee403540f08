"""MkDocs hooks that generate the reference site's computed pages (``mkdocs.yml``: ``hooks``).

Nothing here is written into the checkout: every page below is added to the build in memory
(``File.generated``), so ``make docs`` on a fresh clone leaves only ``site/`` behind.

``api/``
    the API reference: one page per public module of ``src/strapdown`` (every module whose
    dotted path has no part starting with ``_``, except the command-line modules, which have
    their own page), rendered by mkdocstrings from the numpy-style docstrings, and
    ``api/index.md``, which lists every name ``import strapdown`` exports with its module.
``cli.md``
    every ``strapdown`` command's ``--help``, taken from the parser the command runs
    (``strapdown.cli.build_parser``), so the page cannot disagree with the program.
``gallery/``
    every ``examples/*.py`` script, executed at build time in a fresh temporary directory
    (matplotlib on the Agg backend): its source, what it printed and every figure it left
    open. A script that fails fails the build.
``reproductions/``
    the reports of paper reproductions (``strapdown reproduce NAME --out DIR``), run at build
    time with their figures and tables: the quick one, :data:`BUILD_REPRODUCTIONS`, by
    default; ``STRAPDOWN_DOCS_REPRODUCTIONS=all`` (or a comma-separated list of names) for a
    published site, which then takes minutes (``reproduce sculling`` alone 1.5 min).

The scripts and reproductions run as subprocesses started when the configuration is loaded,
two at a time, while MkDocs reads the pages.
"""

from __future__ import annotations

import argparse
import html
import logging
import os
import pkgutil
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

from mkdocs.structure.files import File, Files

log = logging.getLogger("mkdocs.plugins.strapdown_docs")

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
#: Reproductions run at build time by default: the one under 10 s, also with a cold numba
#: cache (li2017 takes 15-30 s, wang-sliding 35 s cold: it compiles the EKF, sculling 1.5
#: min), so that `make docs` and the test that builds the site stay under a minute.
BUILD_REPRODUCTIONS = ("plaksiy2024",)
#: The longest first, so that two workers finish together.
_BY_DURATION = ("sculling", "li2017", "high-order", "wang-sliding", "zhang2021", "wang-rate",
                "plaksiy2024")


def build_reproductions() -> tuple[str, ...]:
    """The reproductions this build runs (``STRAPDOWN_DOCS_REPRODUCTIONS``)."""
    from strapdown.reproduce import REPRODUCTIONS

    wanted = os.environ.get("STRAPDOWN_DOCS_REPRODUCTIONS", "").strip()
    if not wanted:
        return BUILD_REPRODUCTIONS
    names = list(REPRODUCTIONS) if wanted == "all" else [n.strip() for n in wanted.split(",")]
    unknown = [n for n in names if n not in REPRODUCTIONS]
    if unknown:
        raise ValueError(f"STRAPDOWN_DOCS_REPRODUCTIONS: unknown {unknown}; choose from "
                         f"{', '.join(REPRODUCTIONS)} or all")
    return tuple(sorted(names, key=lambda n: _BY_DURATION.index(n)
                        if n in _BY_DURATION else -1))
#: Files of a reproduction report that the site carries (the rest are linked to nothing).
REPORT_SUFFIXES = {".md", ".png", ".csv"}
#: Longest a gallery script or a reproduction may run at build time (s).
TIMEOUT = 300

_state: dict = {}


# ---------------------------------------------------------------- running the scripts
def _driver(script: Path) -> str:
    """Python source that runs *script* as ``__main__`` and saves the figures it left open."""
    return textwrap.dedent(f"""\
        import runpy, sys
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        plt.show = lambda *a, **k: None
        sys.argv = [{str(script)!r}]
        runpy.run_path({str(script)!r}, run_name="__main__")
        for i, num in enumerate(plt.get_fignums(), 1):
            plt.figure(num).savefig(f"_figure{{i}}.png", dpi=90, bbox_inches="tight")
        """)


def _run(argv: list[str], cwd: Path) -> tuple[subprocess.CompletedProcess, float]:
    # this checkout's package, whichever one is installed
    path = os.pathsep.join(filter(None, [str(REPO / "src"), os.environ.get("PYTHONPATH")]))
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONHASHSEED="0", PYTHONPATH=path)
    t0 = time.perf_counter()
    proc = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=TIMEOUT)
    return proc, time.perf_counter() - t0


def _run_example(script: Path, work: Path) -> dict:
    cwd = work / f"example-{script.stem}"
    cwd.mkdir()
    (cwd / "examples").symlink_to(EXAMPLES, target_is_directory=True)
    proc, seconds = _run([sys.executable, "-c", _driver(script)], cwd)
    if proc.returncode:
        raise RuntimeError(f"examples/{script.name} failed (exit {proc.returncode}):\n"
                           f"{proc.stderr[-3000:]}")
    figures = sorted(cwd.glob("_figure*.png"), key=lambda p: int(p.stem[7:]))
    return {"stdout": proc.stdout, "figures": [p.read_bytes() for p in figures],
            "seconds": seconds}


def _run_reproduction(name: str, work: Path) -> dict:
    out = work / f"reproduce-{name}"
    argv = [sys.executable, "-m", "strapdown.cli", "reproduce", name, "--out", str(out),
            "--no-progress"]
    proc, seconds = _run(argv, work)
    if proc.returncode:
        raise RuntimeError(f"strapdown reproduce {name} failed (exit {proc.returncode}):\n"
                           f"{proc.stderr[-3000:]}")
    files = {p.name: p.read_bytes() for p in sorted(out.iterdir())
             if p.is_file() and p.suffix in REPORT_SUFFIXES}
    return {"files": files, "seconds": seconds}


def on_config(config, **kwargs):
    """Start the gallery scripts and the reproductions (two at a time)."""
    work = Path(tempfile.mkdtemp(prefix="strapdown-docs-"))
    pool = ThreadPoolExecutor(max_workers=2)
    jobs: dict[str, Future] = {}
    names = build_reproductions()
    for name in names:  # the longest first
        jobs[f"reproduce:{name}"] = pool.submit(_run_reproduction, name, work)
    for script in sorted(EXAMPLES.glob("*.py")):
        jobs[f"example:{script.stem}"] = pool.submit(_run_example, script, work)
    _state.update(work=work, pool=pool, jobs=jobs, reproductions=names)
    return config


def on_post_build(config, **kwargs):
    _cleanup()


def on_build_error(error, **kwargs):
    _cleanup()


def _cleanup() -> None:
    pool = _state.pop("pool", None)
    if pool is not None:
        pool.shutdown(wait=True, cancel_futures=True)
    work = _state.pop("work", None)
    if work is not None:
        shutil.rmtree(work, ignore_errors=True)


# ---------------------------------------------------------------- the API reference
#: Deprecated aliases of moved modules: not documented (their docstrings say where to go).
DEPRECATED_ALIASES = frozenset({"strapdown.algorithms.navigation"})


def public_modules() -> list[str]:
    """Every public module of the package but the command-line modules and the deprecated
    aliases, sorted."""
    import strapdown

    names = ["strapdown"]
    for info in pkgutil.walk_packages(strapdown.__path__, "strapdown."):
        parts = info.name.split(".")
        if (any(p.startswith("_") for p in parts[1:]) or parts[1] == "cli"
                or info.name in DEPRECATED_ALIASES):
            continue
        names.append(info.name)
    return sorted(names)


def _api_pages() -> dict[str, str]:
    import strapdown

    modules = public_modules()
    pages = {f"api/{mod}.md": f"::: {mod}\n    options:\n      show_root_heading: true\n"
                              "      heading_level: 1\n" for mod in modules}
    rows, private = [], []
    for name, mod in sorted(strapdown._EXPORTS.items()):
        if mod in modules:
            target = f"./{mod}.md#{mod}.{name}"
        else:  # defined in a private module: rendered on this page
            target = f"#{mod}.{name}"
            private.append(f"::: {mod}.{name}\n    options:\n      show_root_heading: true\n"
                           "      heading_level: 3\n")
        rows.append(f"| [`{name}`]({target}) | `{mod}` |")
    mods = [f"| `strapdown.{attr}` | [`{mod}`](./{mod}.md) |"
            for attr, mod in sorted(strapdown._MODULES.items())]
    listing = "\n".join(f"- [`{m}`](./{m}.md)" for m in modules)
    pages["api/index.md"] = (
        "# API reference\n\n"
        "Generated from the docstrings (numpy style) of the source. The conventions every "
        "function follows (frames, units, time stamps, quaternion order) are on the "
        "[conventions page](../conventions.md); the command line is on "
        "[its own page](../cli.md).\n\n"
        "## What `import strapdown` gives\n\n"
        "Each name is imported from its module on first use, so `import strapdown` stays "
        "cheap.\n\n| name | defined in |\n|---|---|\n" + "\n".join(rows) +
        "\n\nSubpackages reachable as attributes:\n\n| attribute | module |\n|---|---|\n" +
        "\n".join(mods) + "\n\nDefined in a private module:\n\n" + "\n".join(private) +
        "\n## Every public module\n\n" + listing + "\n")
    return pages


# ---------------------------------------------------------------- the command line
def _cli_page() -> str:
    from strapdown.cli import COMMANDS, build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    os.environ.setdefault("COLUMNS", "100")
    parts = ["# Command line\n",
             "Every command's `--help`, as `strapdown` prints it (generated from the parser "
             "at build time). Frames, units, time stamps and quaternion order are on the "
             "[conventions page](conventions.md); exit statuses are the same for every "
             "command (below). Worked examples: the [tutorial](tutorial.md).\n",
             "## `strapdown` {: #cli-strapdown }\n",
             "```text\n" + parser.format_help().rstrip() + "\n```\n"]
    names = [m.__name__.rsplit(".", 1)[1].replace("_", "-") for m in COMMANDS]
    for name in names:
        parts += [f"## `strapdown {name}`\n",
                  "```text\n" + sub.choices[name].format_help().rstrip() + "\n```\n"]
    return "\n".join(parts)


# ---------------------------------------------------------------- gallery, reproductions
def _result(key: str) -> dict:
    return _state["jobs"][key].result()


def _first_paragraph(script: Path) -> tuple[str, str]:
    import ast

    doc = ast.get_docstring(ast.parse(script.read_text("utf-8"))) or script.stem
    # reStructuredText to Markdown, as far as a script's docstring needs: roles and literals
    doc = re.sub(r":\w+:`~?([^`]+)`", r"``\1``", doc).replace("``", "`")
    title, _, rest = doc.partition("\n\n")
    return " ".join(title.split()), rest


def _gallery_pages() -> tuple[dict[str, str], dict[str, bytes]]:
    pages, blobs = {}, {}
    index = ["# Examples gallery\n",
             "Each script of `examples/` in the repository, executed when this site was built "
             "(in an empty directory; `python examples/NAME.py` from the checkout runs the "
             "same). What it printed and the figures it drew are below its source.\n"]
    for script in sorted(EXAMPLES.glob("*.py")):
        res = _result(f"example:{script.stem}")
        title, rest = _first_paragraph(script)
        index.append(f"- [{html.escape(title)}]({script.stem}.md) — `examples/{script.name}`")
        body = [f"# {title}\n", f"`examples/{script.name}` — ran in {res['seconds']:.1f} s at "
                "build time.\n"]
        if rest:
            body.append(rest.strip() + "\n")
        body.append("## Source\n\n```python\n" + script.read_text("utf-8").rstrip() + "\n```\n")
        body.append("## Output\n\n```text\n" + (res["stdout"].rstrip() or "(nothing)") +
                    "\n```\n")
        for i, png in enumerate(res["figures"], 1):
            name = f"{script.stem}_{i}.png"
            blobs[f"gallery/{name}"] = png
            body.append(f"![{script.stem}, figure {i}]({name})\n")
        pages[f"gallery/{script.stem}.md"] = "\n".join(body)
    pages["gallery/index.md"] = "\n".join(index) + "\n"
    return pages, blobs


def _reproduction_pages() -> tuple[dict[str, str], dict[str, bytes]]:
    pages, blobs = {}, {}
    from strapdown.reproduce import REPRODUCTIONS

    names = _state["reproductions"]
    index = ["# Reproduction reports\n",
             "Reports generated when this site was built, each by the command named on it "
             "(tables, figures and the comparison with the printed numbers). What every "
             "reproduction found is in [Paper reproductions](../reproductions.md). A default "
             "build runs the quick ones; `STRAPDOWN_DOCS_REPRODUCTIONS=all make docs` runs "
             "every one (minutes). Any of them: `strapdown reproduce NAME --out DIR`.\n"]
    for name in names:
        res = _result(f"reproduce:{name}")
        index.append(f"- [`strapdown reproduce {name}`]({name}/report.md): "
                     f"{REPRODUCTIONS[name].subject} (ran in {res['seconds']:.0f} s)")
        for fname, data in res["files"].items():
            path = f"reproductions/{name}/{fname}"
            if fname.endswith(".md"):
                pages[path] = data.decode("utf-8")
            else:
                blobs[path] = data
    skipped = [n for n in REPRODUCTIONS if n not in names]
    if skipped:
        index.append("\nNot run for this build: " + ", ".join(
            f"`{n}` ({REPRODUCTIONS[n].subject})" for n in skipped) + ".")
    pages["reproductions/index.md"] = "\n".join(index) + "\n"
    return pages, blobs


def on_files(files: Files, config, **kwargs) -> Files:
    t0 = time.perf_counter()
    pages = {**_api_pages(), "cli.md": _cli_page()}
    blobs: dict[str, bytes] = {}
    for make in (_gallery_pages, _reproduction_pages):
        p, b = make()
        pages.update(p)
        blobs.update(b)
    for uri, text in {**pages, **blobs}.items():
        files.append(File.generated(config, uri, content=text))
    log.info("docs_site: generated %d pages and %d figures (waited %.1f s for the scripts)",
             len(pages), len(blobs), time.perf_counter() - t0)
    return files
