"""--progress/--no-progress of the long commands whose progress is a line per stage
(reproduce, benchmark-ahrs): the lines appear on stderr only when asked (or on a terminal)."""

from __future__ import annotations

import types

import pytest

from strapdown.cli import main


@pytest.fixture
def fake_reproduction(monkeypatch):
    import strapdown.reproduce as rep

    given = []

    def reproduce(out, *, progress=None):
        given.append({"progress": progress})
        if progress is not None:
            progress("Table 1: drift constants")
        return f"{out}/report.md"

    monkeypatch.setattr(rep, "reproduction", lambda name: types.SimpleNamespace(
        reproduce=reproduce))
    return given


@pytest.mark.parametrize(("command", "line"), [
    (["reproduce", "li2017", "--out", "r"], "Table 1: drift constants"),
    (["benchmark-ahrs", "broad", "--out", "r"], "01_trial: strapdown-ekf"),
])
def test_stage_lines_only_with_progress(request, capsys, command, line):
    given = request.getfixturevalue("fake_reproduction" if command[0] == "reproduce"
                                    else "fake_benchmark")
    assert main([*command, "--progress"]) == 0
    assert capsys.readouterr().err == line + "\n"
    assert main([*command, "--no-progress"]) == 0
    assert capsys.readouterr().err == "" and given[-1]["progress"] is None
    assert main(command) == 0  # neither: only on a terminal (captured stderr is not one)
    assert capsys.readouterr().err == "" and given[-1]["progress"] is None
