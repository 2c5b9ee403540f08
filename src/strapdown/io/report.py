"""Shared output for reproduction reports: tables as CSV + Markdown, figures as PNG."""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from strapdown.io.files import csv_table, markdown_table, save_figure, write_text


def prepare_out(out: str | os.PathLike[str]) -> Path:
    """Create the output directory; refuse a path that is an existing file."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out} exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    return out


class ReportWriter:
    """Writes a report's tables and figures atomically and remembers their names."""

    def __init__(self, out: Path):
        self.out = out
        self.files: list[str] = []

    def table(self, stem: str, header: list[str], rows: list[list]) -> str:
        """Write ``stem.csv`` and ``stem.md``; return the Markdown."""
        write_text(self.out / f"{stem}.csv", csv_table(header, rows))
        md = markdown_table(header, rows)
        write_text(self.out / f"{stem}.md", md)
        self.files += [f"{stem}.csv", f"{stem}.md"]
        return md

    def figure(self, name: str, fig) -> str:
        """Save and close a matplotlib figure."""
        import matplotlib.pyplot as plt

        save_figure(fig, self.out / name, dpi=120, bbox_inches="tight")
        plt.close(fig)
        self.files.append(name)
        return name

    def file_list(self) -> list[str]:
        """Markdown links to every file written."""
        return [f"- [{f}]({f})" for f in self.files]


@dataclass
class Report:
    """One report being written: where it goes, what has been said, how to say more.

    Attributes
    ----------
    out : Path
        The output directory.
    writer : ReportWriter
        Writes the tables and figures and remembers their names.
    say : callable
        The progress callback (a no-op when none was given).
    plt : module
        ``matplotlib.pyplot`` on the headless Agg backend.
    t_start : float
        ``time.perf_counter()`` when the report began.
    parts : list of str
        The Markdown sections, in order; each reproduction joins them its own way.
    """

    out: Path
    writer: ReportWriter
    say: Callable[[str], None]
    plt: Any
    t_start: float
    parts: list[str] = field(default_factory=list)

    @classmethod
    def begin(cls, out: str | os.PathLike[str],
              progress: Callable[[str], None] | None = None) -> Report:
        """Start a report: headless matplotlib, the output directory, its writer."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        out = prepare_out(out)
        say = progress or (lambda _msg: None)
        return cls(out, ReportWriter(out), say, plt, time.perf_counter())

    def add(self, *texts: str) -> None:
        """Append Markdown parts."""
        self.parts.extend(texts)

    def table(self, stem: str, header: list[str], rows: list[list]) -> str:
        """Write ``stem.csv`` and ``stem.md`` (see :meth:`ReportWriter.table`)."""
        return self.writer.table(stem, header, rows)

    def figure(self, name: str, fig) -> str:
        """Save and close a figure (see :meth:`ReportWriter.figure`)."""
        return self.writer.figure(name, fig)

    def file_list(self) -> list[str]:
        """Markdown links to every file written so far."""
        return self.writer.file_list()

    def elapsed(self) -> float:
        """Seconds since the report began."""
        return time.perf_counter() - self.t_start

    def write(self, text: str) -> Path:
        """Write ``report.md`` (atomically); returns its path."""
        return write_text(self.out / "report.md", text)

