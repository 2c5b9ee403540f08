"""Instructions per update of the generated AHRS in C and of its compiled peers, counted by
valgrind's callgrind (repeatable on a loaded machine, where a clock is not).

    python benchmarks/ahrs_c_callgrind.py [double,float,vqf,vqfoff,fusion]

Each program of ``strapdown bench``'s compiled AHRS comparison (:mod:`strapdown.apps.bench_c`:
ours generated at 200 Hz in double and float, VQF's C++ real-time and offline, Fusion's C,
all at ``-O2``) runs once over 2 × 10⁴ and once over 6 × 10⁴ samples of the bench's
spin-coning record; the difference of the instruction totals over 4 × 10⁴ is the cost per
sample without the start-up and the record's reading. Needs valgrind and a C/C++ compiler;
the peers' sources as for ``strapdown bench`` (``$STRAPDOWN_PEER_SRC``).
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path

from strapdown.apps import bench_c
from strapdown.apps.bench import _imu

NAMES = {"double": "c-strapdown-ahrs-double", "float": "c-strapdown-ahrs-float",
         "vqf": "cpp-vqf-realtime", "vqfoff": "cpp-vqf-offline", "fusion": "c-fusion-ahrs"}
N1, N2 = 20_000, 60_000


def main() -> None:
    which = sys.argv[1].split(",") if len(sys.argv) > 1 else list(NAMES)
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        files = {}
        for n in (N1, N2):
            t, g, a, m = _imu(n)
            files[n] = bench_c._record_file(d, g, a, m).rename(d / f"imu{n}.bin")
        ts = float(t[1] - t[0])
        for name, _peer, make in bench_c._programs(d, ts, bench_c.peer_sources()):
            key = next(k for k, v in NAMES.items() if v == name)
            if key not in which:
                continue
            cmd = make()
            if isinstance(cmd, str):
                print(f"{name}: skipped ({cmd})")
                continue
            total = []
            for n in (N1, N2):
                res = subprocess.run(["valgrind", "--tool=callgrind",
                                      f"--callgrind-out-file={d / f'cg.{key}.{n}'}", cmd[0],
                                      str(files[n]), "1", repr(ts), *cmd[1:]],
                                     capture_output=True, text=True, check=True)
                found = re.search(r"Collected : (\d+)", res.stderr)
                assert found, res.stderr[-400:]
                total.append(int(found.group(1)))
            print(f"{name}: {(total[1] - total[0]) / (N2 - N1):.0f} instructions per sample",
                  flush=True)


if __name__ == "__main__":
    main()
