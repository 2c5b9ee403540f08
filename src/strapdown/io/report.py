"""Shared output for reproduction reports: tables as CSV + Markdown, figures as PNG."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from strapdown.io.files import csv_table, markdown_table, save_figure, write_text


def prepare_out(out: str | Path) -> Path:
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


def begin_report(out: str | Path, progress: Callable[[str], None] | None):
    """Start a report: headless matplotlib, the output directory, its writer, a progress
    callback and the start time. Returns ``(out, writer, say, plt, t_start)``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = prepare_out(out)
    say = progress or (lambda _msg: None)
    return out, ReportWriter(out), say, plt, time.perf_counter()
