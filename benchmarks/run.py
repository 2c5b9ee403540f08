"""Run every throughput benchmark, print the table and save the records as JSON.

Usage: ``python benchmarks/run.py [--out reports/bench.json] [strapdown bench options]``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from strapdown.apps import bench
from strapdown.io.files import write_text


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, allow_abbrev=False)
    p.add_argument("--out", default="reports/bench.json")
    p.add_argument("--samples", type=int, default=10_000_000)
    p.add_argument("--ekf-samples", type=int, default=1_000_000)
    p.add_argument("--stream-samples", type=int, default=100_000_000)
    p.add_argument("--earth-samples", type=int, default=1_000_000,
                   help="increments of the Earth navigation benchmark")
    a = p.parse_args(argv)
    recs = bench.run_benchmarks(a.samples, stream_samples=a.stream_samples,
                                ekf_samples=a.ekf_samples, earth_samples=a.earth_samples,
                                log=lambda line: print(line, file=sys.stderr))
    write_text(Path(a.out), json.dumps(recs, indent=2))
    for r in recs:
        if "peak_rss_mb" in r:
            print(f"{r['name']:38s} peak RSS {r['peak_rss_mb']:.0f} MB")
        elif r.get("skipped"):
            print(f"{r['name']:38s} skipped: {r['skipped']}")
        elif r.get("ratio") is not None:  # a ratio of two records (sculling: ours / peer)
            print(f"{r['name']:38s} {r['ratio']:11.3g}×")
        elif r.get("samples_per_s"):
            print(f"{r['name']:38s} {r['samples_per_s']:11.3e}/s  "
                  f"{r['ratio_to_numpy_pass']:8.4f} × numpy  {r['peer'] or ''}")
        else:
            print(f"{r['name']:38s} failed: {r.get('error')}")
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
