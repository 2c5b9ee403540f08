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


def test_ctrl_c_as_the_temporary_file_is_created_leaves_nothing(tmp_path, monkeypatch):
    """A Ctrl-C arriving just after the temporary file exists, before its name is known to
    the clean-up, is held back until it is (a signalled sweep once left such a file)."""
    import signal

    made = tempfile.mkstemp

    def then_interrupted(**kw):
        fd, name = made(**kw)
        os.kill(os.getpid(), signal.SIGINT)  # Python's handler raises KeyboardInterrupt
        return fd, name

    monkeypatch.setattr(tempfile, "mkstemp", then_interrupted)
    # Python's own handler, also when the suite was started with SIGINT ignored (a
    # background job): restored by signal.signal at the end
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            write_text(tmp_path / "case.json", "{}")
    finally:
        signal.signal(signal.SIGINT, previous)
    assert list(tmp_path.iterdir()) == []
