"""Helpers shared by the command-line tests: run ``main`` to its exit, make a command fail."""

from __future__ import annotations

import pytest

from strapdown.cli import main


def exit_of(capsys, *args) -> tuple[int, str]:
    """``main(args)``'s exit status and what it wrote on stderr."""
    with pytest.raises(SystemExit) as exc:
        main(list(args))
    return exc.value.code, capsys.readouterr().err


def evaluate_raises(monkeypatch, error: BaseException) -> None:
    """Make ``strapdown evaluate`` raise ``error`` from inside the command."""
    from strapdown.analysis import evaluate

    def boom(cfg):
        raise error

    monkeypatch.setattr(evaluate, "evaluate", boom)
