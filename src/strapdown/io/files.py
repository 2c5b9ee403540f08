"""Atomic file output: write beside the target, then rename over it.

The temporary file is ``.NAME.PID.RANDOM.SUFFIX`` beside ``NAME``: a run killed by SIGKILL
(nothing can clean up then) leaves it behind, and the next write into the same directory removes
every such file whose process no longer exists (:func:`remove_stale_temps`). A temporary file
of a live process, or one without a process id (of an older version), is left alone.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import signal
import tempfile
from pathlib import Path

from strapdown._core.signals import replaced_handlers


def _umask() -> int:
    """The process umask (read without changing it for other threads where the OS allows)."""
    try:  # Linux: /proc/self/status has a Umask line
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path in the target's directory; rename it over ``path`` on success.

    The file gets the mode a plain ``open(path, "w")`` would give it (0666 less the
    umask), not the 0600 of the private temporary file. An ``OSError`` about the temporary
    file is raised as one about ``path`` (the name the user gave); a regular file where a
    directory of ``path`` should be is a ``NotADirectoryError`` naming that file.
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:  # a regular file where a directory of the path should be
        blocker = next(p for p in path.parents if p.exists())
        raise NotADirectoryError(errno.ENOTDIR, "Not a directory (a file, where the output "
                                 "directory should be)", str(blocker)) from None
    remove_stale_temps(path.parent)
    # Ctrl-C and SIGTERM (raised as exceptions by the command line) are held back until
    # the temporary file exists and its name is bound inside the block that removes it:
    # one arriving in between would leave it behind (seen once in a signalled sweep).
    held: list[int] = []
    tmp: str | None = None
    try:
        with replaced_handlers(lambda signum, frame: held.append(signum)):
            try:
                fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.",
                                           suffix=path.suffix, dir=path.parent)
            except OSError as exc:
                raise OSError(exc.errno, exc.strerror, str(path)) from None
            os.close(fd)
        for s in dict.fromkeys(held):  # its handler runs before raise_signal returns
            signal.raise_signal(s)
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException as exc:
        if tmp is None:
            raise
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and exc.filename in (tmp, Path(tmp)):
            raise OSError(exc.errno, exc.strerror, str(path)) from None
        raise


def _alive(pid: int) -> bool:
    """Whether a process ``pid`` exists (one of another user's counts as alive)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True
    return True


#: mkstemp's names as atomic_path asks for them: ``.NAME.PID.RANDOM.SUFFIX`` (RANDOM is 8 of
#: [a-z0-9_], SUFFIX the suffix of NAME, checked in :func:`remove_stale_temps`).
_TEMP = re.compile(r"\.(?P<name>.+)\.(?P<pid>\d+)\.[a-z0-9_]{8}(?P<suffix>(\.[^.]*)?)")
#: (process id, directory) pairs already cleaned by this process: once per directory is
#: enough (a killed run's temps predate this process), and a sweep writing 10^5 case files
#: into one directory must not list it 10^5 times.
_CLEANED: set[tuple[int, str]] = set()


def remove_stale_temps(directory: str | os.PathLike, *, again: bool = False) -> list[Path]:
    """Remove the temporary files in ``directory`` left by killed runs; returns those removed.

    A stale file is named as :func:`atomic_path` names them, ``.NAME.PID.RANDOM.SUFFIX``
    with SUFFIX the suffix of NAME, and ``PID`` is not this process and no longer exists.
    Each directory is cleaned once per process unless ``again``. Errors (a file another run
    removed first, a directory that cannot be listed) are ignored: cleaning is best effort.
    """
    folder = os.path.abspath(os.fspath(directory))
    key = (os.getpid(), str(folder))
    removed: list[Path] = []
    if key in _CLEANED and not again:
        return removed
    _CLEANED.add(key)
    try:
        entries = list(os.scandir(str(folder)))
    except OSError:
        return removed
    for entry in entries:
        m = _TEMP.fullmatch(entry.name)
        if (m is None or Path(m["name"]).suffix != m["suffix"] or int(m["pid"]) == os.getpid()
                or _alive(int(m["pid"]))):
            continue
        with contextlib.suppress(OSError):
            if entry.is_file(follow_symlinks=False):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
    return removed


#: Rows formatted at once by :func:`write_csv_rows` (a few hundred kB of text).
CSV_BLOCK = 2048


def write_csv_rows(f, rows) -> None:
    """Append ``rows`` (an ``(n, m)`` float array) to the text file ``f`` as CSV, each value
    ``%.17g`` — the text of ``np.savetxt(f, rows, delimiter=",", fmt="%.17g")``, formatted
    on Python floats (about 15 % faster) :data:`CSV_BLOCK` rows at a time (a whole chunk's
    strings at once cost tens of MB of peak memory)."""
    fmt = ",".join(["%.17g"] * rows.shape[1])
    for start in range(0, rows.shape[0], CSV_BLOCK):
        f.write("".join([fmt % tuple(r) + "\n"
                         for r in rows[start:start + CSV_BLOCK].tolist()]))


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def save_figure(fig, path: str | os.PathLike, **kwargs) -> Path:
    """Save a matplotlib figure atomically."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=Path(path).suffix.lstrip(".") or "png", **kwargs)
    return Path(path)


def markdown_table(header: list[str], rows: list[list]) -> str:
    """A GitHub-flavoured Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def csv_table(header: list[str], rows: list[list]) -> str:
    """A CSV table (values quoted when they contain commas)."""

    def cell(c):
        s = str(c)
        return f'"{s}"' if ("," in s or '"' in s) else s

    return "\n".join(",".join(cell(c) for c in r) for r in [header, *rows]) + "\n"
