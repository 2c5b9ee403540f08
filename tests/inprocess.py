"""Run a documented shell line in this process when the shell adds nothing to it.

The documentation tests (tests/docs/) run the README's and the tutorial's commands as
written. Started as ``bash -c``, each ``strapdown …`` line paid a fresh interpreter, the
package's imports and numba's cache loading (1.5-2 s, most of a short command's time). A
line that is a plain ``strapdown ARGS`` (or ``python SCRIPT.py ARGS``, or several of them
joined by ``&&``) — no pipe, redirection, glob, single quote, backslash or substitution but
``"$NAME"`` of a set variable — means the same argv to the console script's
:func:`strapdown.cli.main` (``strapdown = "strapdown.cli:main"``) or to ``runpy`` for the
script, so it runs here, in the line's working directory and environment, its standard
output and error captured and its exit status kept. Any other line goes to the shell.

The console script itself, in a process of its own, stays tested where that is the point:
tests/cli/test_cli_exit_status.py, tests/cli/test_cli_signals.py, the fuzz campaign's
command lines, the compile-notice tests.
"""

from __future__ import annotations

import io
import os
import re
import runpy
import shlex
import sys
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

__all__ = ["in_process_argvs", "run_in_process"]

#: Characters that make a line the shell's business (expansion, redirection, globbing, …).
_SHELL = set("|;<>()`*?[]{}~!\\'\n#")
_VAR = re.compile(r"\$(?:(\w+)|\{(\w+)\})")
_PLAIN_VALUE = re.compile(r"[\w./:@%+,=-]+")


def _expand(word: str, env: dict[str, str]) -> str | None:
    """``$NAME`` and ``${NAME}`` of ``word`` from ``env``; None when one is unset or its value
    is not a plain word (the shell would split or glob it, or drop an empty one)."""
    bad = False

    def value(m: re.Match) -> str:
        nonlocal bad
        v = env.get(m[1] or m[2])
        if v is None or not _PLAIN_VALUE.fullmatch(v):
            bad = True
            return ""
        return v

    out = _VAR.sub(value, word)
    return None if bad else out


def in_process_argvs(line: str, env: dict[str, str]) -> list[list[str]] | None:
    """The argv lists (``strapdown`` or ``python`` first) of ``line``'s ``&&``-joined
    commands, or None when the shell is needed for any of it."""
    if any(ch in _SHELL for ch in line):
        return None
    out = []
    for part in line.split("&&"):
        if "&" in part:
            return None
        try:
            words = shlex.split(part)
        except ValueError:
            return None
        if not words:
            return None
        script = words[0] == "python" and len(words) > 1 and words[1].endswith(".py")
        if words[0] != "strapdown" and not script:
            return None
        expanded = [_expand(w, env) for w in words]
        if any(w is None for w in expanded):
            return None
        out.append([w for w in expanded if w is not None])
    return out


def _call(argv: list[str]) -> int:
    """One command: the console script's ``main`` or a script as ``__main__``."""
    code: object
    try:
        if argv[0] == "strapdown":
            from strapdown.cli import main

            code = main(argv[1:])
        else:
            script = str(Path(argv[1]).resolve())
            saved_argv, saved_path = sys.argv[:], sys.path[:]
            sys.argv = argv[1:]
            sys.path.insert(0, str(Path(script).parent))  # as `python SCRIPT` puts it first
            try:
                runpy.run_path(script, run_name="__main__")
            finally:
                sys.argv[:] = saved_argv
                sys.path[:] = saved_path
            code = 0
    except SystemExit as exc:
        code = exc.code
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=sys.stderr)  # sys.exit("message"): the interpreter prints it, status 1
    return 1


def run_in_process(argvs: list[list[str]], cwd: Path, env: dict[str, str]
                   ) -> tuple[int, str, str]:
    """Run ``argvs`` in order (as ``&&``: stop at the first failure) in ``cwd`` under
    ``env``; ``(exit status, stdout, stderr)``. The working directory and environment are
    restored after, and any figure a script left open is closed."""
    out, err = io.StringIO(), io.StringIO()
    old_cwd, old_env = os.getcwd(), dict(os.environ)
    code = 0
    try:
        os.chdir(cwd)
        os.environ.clear()
        os.environ.update(env)
        with redirect_stdout(out), redirect_stderr(err):
            for argv in argvs:
                code = _call(argv)
                if code:
                    break
    finally:
        os.chdir(old_cwd)
        os.environ.clear()
        os.environ.update(old_env)
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close("all")
    return code, out.getvalue(), err.getvalue()
