"""Throughput of the rotation-vector structures (``make bench``).

Reports samples per second on 10^7 increments for each N and structure, and
the ratio to a single NumPy pass over the same input (``theta.sum(axis=1)``
plus one elementwise multiply: a memory-bandwidth floor). Numbers are printed,
never asserted; run on an idle machine.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from strapdown.coning import coefficient_set
from strapdown.structures import conventional, realtime, single_chain


def best_of(fn, repeat: int) -> float:
    fn()  # warm-up (numba compilation / cache load)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--samples", type=int, default=10_000_000)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--json", action="store_true")
    a = p.parse_args(argv)
    rng = np.random.default_rng(0)
    theta = rng.normal(size=(a.samples, 3)) * 1e-3
    floor = best_of(lambda: (theta * 2.0).sum(axis=1), a.repeat)
    floor_rate = a.samples / floor
    records = [{"name": "numpy-single-pass", "samples_per_s": floor_rate,
                "ratio_to_numpy_pass": 1.0, "peer": "numpy"}]
    for n in range(1, 6):
        cs = coefficient_set("table3", n)
        m = a.samples - a.samples % n
        runs = (
            ("conventional", lambda cs=cs, m=m: conventional(theta[:m], cs, h=1e-4)),
            ("realtime", lambda cs=cs: realtime(theta, cs, h=1e-4)),
            ("single-chain", lambda n=n: single_chain(theta, n, h=1e-4)),
        )
        for name, fn in runs:
            rate = a.samples / best_of(fn, a.repeat)
            records.append({"name": f"rotvec-N{n}-{name}", "samples_per_s": rate,
                            "ratio_to_numpy_pass": rate / floor_rate, "peer": None})
    if a.json:
        print(json.dumps(records, indent=2))
    else:
        print(f"{'name':28s} {'samples/s':>14s} {'× numpy pass':>13s}")
        for r in records:
            print(f"{r['name']:28s} {r['samples_per_s']:14.3e} {r['ratio_to_numpy_pass']:13.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
