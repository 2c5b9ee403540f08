"""Streaming: feed increments in chunks of any size, O(1) memory, bit-identical results.

A stream carries exactly the state the one-shot run carries from one sample
to the next — the last attitude(s) and the few increments still needed —
and calls the same compiled kernels on ``[history, chunk]``, so the outputs
equal the one-shot run's to the last bit whatever the chunking (tested with
random chunk sizes).

>>> s = RotvecStream("realtime", coefficient_set("table3", 3), h=1e-4)  # doctest: +SKIP
>>> for chunk in chunks:                                                # doctest: +SKIP
...     out = s.feed(chunk)      # AttitudeSolution of the outputs this chunk completes
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import as_quaternions, as_vectors, finite_array, positive
from strapdown.algorithms import _kernels
from strapdown.algorithms.coning import CoefficientSet, triple_arrays
from strapdown.algorithms.family import IncrementStructure
from strapdown.algorithms.finite_amplitude import triple_terms
from strapdown.algorithms.structures import (
    STRUCTURES,
    AttitudeSolution,
    single_chain_coefficients,
    single_chain_table,
    stack_sets,
    startup_sets,
)

__all__ = ["RotvecStream"]

_EMPTY = np.empty((0, 3))


class RotvecStream:
    """Rotation-vector attitude from a stream of increments.

    Parameters
    ----------
    structure : {"conventional", "realtime", "single-chain"}
    coefficients : CoefficientSet
        N and the coning set (the single chain takes ``table3`` or ``none``).
    h : float
        Increment interval (s).
    t0 : float
        Start time (s).
    q0 : array_like (4,), optional
        Initial ``q_n_b``.

    Notes
    -----
    Outputs are returned by :meth:`feed` as soon as the increments that
    complete them have arrived; the initial attitude is the first output of
    the first call that returns any. The real-time structure holds back its
    first N − 1 start-up outputs until N increments have arrived.
    """

    def __init__(self, structure: IncrementStructure, coefficients: CoefficientSet, *, h: float,
                 t0: float = 0.0, q0: ArrayLike | None = None) -> None:
        if structure not in STRUCTURES:
            raise ValueError(f"unknown structure {structure!r}; choose conventional, realtime "
                             "or single-chain")
        if not isinstance(coefficients, CoefficientSet):
            raise ValueError("coefficients must be a CoefficientSet")
        if coefficients.triples and structure == "realtime":
            raise ValueError(f"the real-time structure runs pair-only sets; "
                             f"{coefficients.name!r} has triple cross products")
        self.structure = structure
        self.coefficients = coefficients
        self.h = positive(h, "h (sample interval)")
        self.t0 = float(finite_array(t0, "t0"))
        if q0 is None:
            q0 = np.array([1.0, 0.0, 0.0, 0.0])
        q0 = as_quaternions(q0, "q0")
        if q0.shape != (4,):
            raise ValueError(f"q0 must have shape (4,), got {q0.shape}")
        self._q0 = q0 / np.linalg.norm(q0)
        self.n = coefficients.n
        self._triple = triple_arrays(coefficients.triples)
        if structure == "single-chain":
            if coefficients.name not in ("table3", "none", "finite-amplitude"):
                raise ValueError("the single chain takes 'table3' (designed optimum), "
                                 "'finite-amplitude' or 'none'")
            self._table = single_chain_table(self.n if coefficients.name != "none" else 1)
            if coefficients.name == "finite-amplitude":  # the single chain's own triple set
                self._triple = triple_arrays(triple_terms("single-chain", self.n))
                self._steady = np.array([float(c) for c in single_chain_coefficients(self.n)])
        if structure == "realtime":
            self._ks = stack_sets(startup_sets(coefficients))
        self._buf = _EMPTY  # increments carried over
        self._qhist: NDArray[np.float64] | None = None  # last attitude(s)
        self._count = 0  # increments consumed so far
        self._emitted = 0  # outputs emitted so far

    @property
    def samples(self) -> int:
        """Increments fed so far."""
        return self._count + self._buf.shape[0] if self.structure == "conventional" else (
            self._count)

    def feed(self, increments: ArrayLike) -> AttitudeSolution:
        """Consume a chunk ``(m, 3)``; return the outputs it completes (possibly none)."""
        x = as_vectors(increments, "increments")
        if x.ndim != 2:
            raise ValueError(f"increments must have shape (m, 3), got {x.shape}")
        return getattr(self, "_feed_" + self.structure.replace("-", "_"))(x)

    # ------------------------------------------------------------------ structures
    def _out(self, q, period, first_index, chain=None):
        t = self.t0 + (np.arange(q.shape[0]) + first_index) * period
        ch = np.zeros(q.shape[0], int) if chain is None else chain
        self._emitted += q.shape[0]
        return AttitudeSolution(t, q, self.structure, self.coefficients, self.h, period, ch)

    def _feed_conventional(self, x):
        n = self.n
        data = np.concatenate([self._buf, x]) if self._buf.size else x
        m = data.shape[0] // n
        self._buf = data[m * n:].copy()
        first = self._qhist is None
        q = np.empty((m + 1, 4))
        q[0] = self._q0 if first else self._qhist[-1]
        if m and self.coefficients.triples:
            _kernels.conventional_triple_kernel(np.ascontiguousarray(data[:m * n]),
                                                np.ascontiguousarray(self.coefficients.matrix),
                                                *self._triple, q[0], q)
        elif m:
            _kernels.conventional_kernel(np.ascontiguousarray(data[:m * n]),
                                         np.ascontiguousarray(self.coefficients.matrix), q[0], q)
        self._count += m * n
        self._qhist = q[-1:].copy()
        rows = q if first else q[1:]
        return self._out(rows, n * self.h, 0 if first else self._emitted)

    def _feed_single_chain(self, x):
        nm1 = self._table.shape[0] - 1
        data = np.ascontiguousarray(np.concatenate([self._buf, x]) if self._buf.size else x)
        start = self._buf.shape[0]
        first = self._qhist is None
        q = np.empty((x.shape[0] + 1, 4))
        q[0] = self._q0 if first else self._qhist[-1]
        if self._triple[3].size:  # finite-amplitude: plain start-up rows, then the triple kernel
            r = max(0, min(x.shape[0], nm1 - self._count))
            _kernels.single_chain_kernel(np.ascontiguousarray(data[:start + r]), self._table,
                                         start, self._count, q[:r + 1])
            if x.shape[0] > r:
                _kernels.single_chain_triple_kernel(data, self._steady, *self._triple,
                                                    start + r, q[r:])
        else:
            _kernels.single_chain_kernel(data, self._table, start, self._count, q)
        self._count += x.shape[0]
        keep = min(nm1, data.shape[0])
        self._buf = data[data.shape[0] - keep:].copy() if keep else _EMPTY
        self._qhist = q[-1:].copy()
        rows = q if first else q[1:]
        return self._out(rows, self.h, 0 if first else self._emitted)

    def _feed_realtime(self, x):
        n = self.n
        if self._qhist is None:  # start-up: wait for N increments, then the one-shot kernel
            data = np.concatenate([self._buf, x]) if self._buf.size else x
            if data.shape[0] < n:
                self._buf = data.copy()
                return self._out(np.empty((0, 4)), self.h, 0)
            data = np.ascontiguousarray(data)
            q = np.empty((data.shape[0] + 1, 4))
            _kernels.realtime_kernel(data, self._ks, self._q0, q)
            self._count = data.shape[0]
            self._buf = data[data.shape[0] - (n - 1):].copy() if n > 1 else _EMPTY
            self._qhist = q[-n:].copy()
            return self._out(q, self.h, 0, np.arange(q.shape[0]) % n)
        data = np.ascontiguousarray(np.concatenate([self._buf, x]) if n > 1 else x)
        q = np.empty((n + x.shape[0], 4))
        q[:n] = self._qhist
        _kernels.realtime_steady_kernel(data, np.ascontiguousarray(self._ks[n - 1]), q)
        new = q[n:]
        first_index = self._count + 1
        self._count += x.shape[0]
        self._buf = data[data.shape[0] - (n - 1):].copy() if n > 1 else _EMPTY
        self._qhist = q[-n:].copy()
        return self._out(new, self.h, first_index, (np.arange(new.shape[0]) + first_index) % n)
