"""The streaming process (`strapdown run` on a .npy log) imports neither sympy nor matplotlib."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

_SCRIPT = """
import sys
from strapdown.cli import main
rc = main(["run", "--imu", sys.argv[1], "--increments", "--units", "rad", "--structure",
           sys.argv[3], "--subsamples", "3", "--out", sys.argv[2]])
print(rc, ",".join(m for m in ("sympy", "matplotlib") if m in sys.modules) or "none")
"""


@pytest.mark.parametrize("structure", ["conventional", "realtime", "single-chain"])
def test_streaming_run_imports_no_computer_algebra_or_plotting(tmp_path, structure):
    th = np.full((600, 3), 1e-4)
    np.save(tmp_path / "log.npy", np.column_stack([np.arange(1, 601) * 1e-3, th]))
    out = subprocess.run([sys.executable, "-c", _SCRIPT, str(tmp_path / "log.npy"),
                          str(tmp_path / "att.csv"), structure],
                         capture_output=True, text=True, check=True).stdout.split()
    assert out[-2:] == ["0", "none"]
    assert (tmp_path / "att.csv").stat().st_size > 0
