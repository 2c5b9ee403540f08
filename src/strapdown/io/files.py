"""Atomic file output: write beside the target, then rename over it."""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from pathlib import Path


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
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, str(path)) from None
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and exc.filename in (tmp, Path(tmp)):
            raise OSError(exc.errno, exc.strerror, str(path)) from None
        raise


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
