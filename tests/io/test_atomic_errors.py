"""An OSError while writing atomically names the file the user asked for, not the hidden
temporary file beside it."""

from __future__ import annotations

import os
import tempfile

import pytest

from strapdown.io.files import atomic_path, write_text


def test_temp_file_creation_error_names_the_target(tmp_path, monkeypatch):
    def refuse(*, prefix, suffix, dir):
        raise PermissionError(13, "Permission denied", os.path.join(dir, prefix + "x" + suffix))

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    with pytest.raises(PermissionError) as exc:
        write_text(tmp_path / "att.csv", "t\n")
    assert exc.value.filename == str(tmp_path / "att.csv") and exc.value.errno == 13


def test_error_writing_the_temp_file_names_the_target_and_leaves_nothing(tmp_path):
    with pytest.raises(OSError) as exc, atomic_path(tmp_path / "fig.png") as tmp:
        raise OSError(28, "No space left on device", str(tmp))
    assert exc.value.filename == str(tmp_path / "fig.png") and exc.value.errno == 28
    assert list(tmp_path.iterdir()) == []


def test_other_errors_pass_unchanged(tmp_path):
    with pytest.raises(OSError) as exc, atomic_path(tmp_path / "a.csv"):
        raise FileNotFoundError(2, "No such file or directory", "input.csv")
    assert exc.value.filename == "input.csv"
