"""The export configurations whose generated C is kept in ``golden/`` (one per template path:
every exported algorithm and structure, pair and triple terms, float and double)."""

from __future__ import annotations

from typing import Any

_ATTITUDE: list[dict[str, Any]] = [
    *({"algorithm": "rotvec", "structure": "conventional", "subsamples": n} for n in (1, 2, 3, 5)),
    {"algorithm": "rotvec", "structure": "conventional", "subsamples": 4,
     "coefficients": "finite-amplitude"},
    *({"algorithm": "rotvec", "structure": "realtime", "subsamples": n} for n in (2, 3, 5)),
    *({"algorithm": "rotvec", "structure": "single-chain", "subsamples": n} for n in (2, 3, 5)),
    {"algorithm": "rotvec", "structure": "single-chain", "subsamples": 3,
     "coefficients": "finite-amplitude"},
    {"algorithm": "rate-single", "structure": "conventional"},
    {"algorithm": "rate-two", "structure": "conventional"},
    {"algorithm": "rate-three", "structure": "conventional"},
    {"algorithm": "rate-three", "structure": "sliding"},
    {"algorithm": "rk4", "structure": "conventional"},
]


def _named(kw: dict[str, Any]) -> dict[str, Any]:
    """Distinct default names for the finite-amplitude variants."""
    if kw.get("coefficients"):
        s = kw["structure"].replace("-", "_")
        return {**kw, "name": f"sd_{kw['algorithm']}_{s}_fa_n{kw['subsamples']}"}
    return kw


CONFIGS: list[dict[str, Any]] = [
    *(_named({**kw, "real": real}) for kw in _ATTITUDE for real in ("double", "float")),
    *({"algorithm": "nav", "structure": s, "subsamples": n}
      for s, n in (("conventional", 1), ("conventional", 3), ("single-chain", 3))),
]
