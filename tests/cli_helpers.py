"""Helpers shared by the command-line tests: run ``main`` to its exit, make a command fail,
start a child that Ctrl-C reaches."""

from __future__ import annotations

import signal

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


def default_sigint() -> None:
    """``preexec_fn`` for a child the test sends SIGINT: its disposition back to the default.
    A shell starts background jobs (``make test &``) with SIGINT ignored, children inherit
    that, and Python then installs no KeyboardInterrupt handler: the Ctrl-C tests would fail
    for the way the suite was started, not for the code."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
