"""Streaming: feed increments or rate samples in chunks of any size, O(1) memory,
bit-identical results.

A stream carries exactly the state the one-shot run carries from one sample
to the next — the last attitude(s) and the few samples still needed —
and calls the same compiled kernels on ``[history, chunk]``, so the outputs
equal the one-shot run's to the last bit whatever the chunking (tested with
random chunk sizes). :class:`RotvecStream` runs the rotation-vector structures on
increments, :class:`RateStream` the rate-input algorithms of :mod:`.rate` on uniformly
spaced rate samples.

>>> s = RotvecStream("realtime", coefficient_set("table3", 3), h=1e-4)  # doctest: +SKIP
>>> for chunk in chunks:                                                # doctest: +SKIP
...     out = s.feed(chunk)      # AttitudeSolution of the outputs this chunk completes
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from strapdown._core.validation import as_vectors, finite_array, positive
from strapdown.algorithms import _kernels
from strapdown.algorithms.coning import CoefficientSet, triple_arrays
from strapdown.algorithms.family import IncrementStructure
from strapdown.algorithms.finite_amplitude import triple_terms
from strapdown.algorithms.rate import Rk4, WindowedRateFamily, single_period_algorithm
from strapdown.algorithms.structures import (
    AttitudeSolution,
    UpdateStructure,
    _run_windowed,
    _unit_q0,
    increment_structure,
    single_chain_coefficients,
)

if TYPE_CHECKING:
    from strapdown.algorithms.family import RateCoefficients
    from strapdown.algorithms.spec import AlgorithmSpec

__all__ = ["RateStream", "RotvecStream"]

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

    def __init__(self, structure: IncrementStructure | UpdateStructure,
                 coefficients: CoefficientSet, *, h: float, t0: float = 0.0,
                 q0: ArrayLike | None = None) -> None:
        st = increment_structure(structure)  # the registered object: it answers the facts
        if not isinstance(coefficients, CoefficientSet):
            raise ValueError("coefficients must be a CoefficientSet")
        st.check_set(coefficients)
        self.structure = st
        self.coefficients = coefficients
        self.h = positive(h, "h (sample interval)")
        self.t0 = float(finite_array(t0, "t0"))
        self._q0 = _unit_q0(q0)
        self.n = coefficients.n
        self._triple = triple_arrays(coefficients.triples)
        if st.own_startup:  # the single chain: its own table
            self._table = st.table(coefficients)
            if st.triple(coefficients):  # the single chain's own triple set
                self._triple = triple_arrays(triple_terms("single-chain", self.n))
                self._steady = np.array([float(c) for c in single_chain_coefficients(self.n)])
        if st.interleaved:
            self._ks = st.table(coefficients)
        self._buf = _EMPTY  # increments carried over
        self._qhist: NDArray[np.float64] | None = None  # last attitude(s)
        self._count = 0  # increments consumed so far
        self._emitted = 0  # outputs emitted so far

    @property
    def samples(self) -> int:
        """Increments fed so far."""
        return self._count + self._buf.shape[0] if self.structure.whole_updates else (
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


class RateStream:
    """Rate-input attitude from a stream of uniformly spaced rate samples.

    Runs what :meth:`strapdown.algorithms.spec.AlgorithmSpec.run_rates` runs on the whole
    record — ``rate-single``, ``rate-two``, ``rate-three`` (conventional, or the sliding
    scheme of Wang, Wang & Wang's eqs. 20–29) and ``rk4`` (:mod:`strapdown.algorithms.rate`)
    — chunk by chunk, with the same kernels on ``[carried samples, chunk]``: the outputs,
    their times and chains equal the one-shot run's to the last bit whatever the chunking.

    Parameters
    ----------
    spec : AlgorithmSpec
        A rate-input algorithm (``spec.input_kind == "rate"``).
    td : float
        Sample period (s): the one-shot run's ``(t[-1] − t[0]) / (n − 1)`` for uniform
        stamps (:func:`strapdown.algorithms.rate.check_rate_record`).
    t0 : float
        Time of the first sample (s).
    q0 : array_like (4,), optional
        ``q_n_b`` at ``t0`` (default identity; normalised).

    Notes
    -----
    Carried between chunks: the samples from the next update's first on (at most the
    window's span: 1 for rate-single, 2 for rate-two and rk4's 2td step, 3 for rate-three),
    and the last attitude — the last three for the sliding scheme, whose update ``k``
    continues the chain of output ``k − 3``. The initial attitude is the first output of
    the first call that completes an update; fewer samples than ``spec.min_samples`` in
    all give no output. The stream does not validate the rates (finite, uniform): that is
    the caller's (:func:`~strapdown.algorithms.rate.check_rate_record` on a whole record).
    """

    def __init__(self, spec: AlgorithmSpec, *, td: float, t0: float = 0.0,
                 q0: ArrayLike | None = None) -> None:
        fam = spec.family
        self.spec = spec
        self.td = positive(td, "td (sample period)")
        self.t0 = float(finite_array(t0, "t0"))
        self._q0 = _unit_q0(q0)
        self._sliding = spec.update_structure.interleaved
        self._rk4 = isinstance(fam, Rk4)
        if self._rk4:
            self._mode = 0 if spec.rk4_step == "2td" else 1
            self._step = 2 if self._mode == 0 else 1
            self._span = self._step
        elif isinstance(fam, WindowedRateFamily):
            self._alg = fam.windowed(spec)
            if self._alg.history:
                raise ValueError(f"{spec} needs samples before its update (history)")
            coefficients = cast("RateCoefficients", spec.resolved_coefficients)
            self._startup = single_period_algorithm(coefficients) if self._sliding else None
            self._step = 1 if self._sliding else self._alg.update
            self._span = self._alg.span
        else:
            raise ValueError(f"RateStream runs the rate-input algorithms, not {spec}")
        self._buf = _EMPTY  # rates from the next update's first sample on
        self._qhist: NDArray[np.float64] | None = None  # last attitude(s)
        self._emitted = 0  # outputs emitted so far
        self._count = 0  # samples fed so far

    @property
    def samples(self) -> int:
        """Rate samples fed so far."""
        return self._count

    def feed(self, rates: ArrayLike) -> AttitudeSolution:
        """Consume rates ``(m, 3)`` (rad/s); return the outputs they complete (maybe none)."""
        x = as_vectors(rates, "rates")
        if x.ndim != 2:
            raise ValueError(f"rates must have shape (m, 3), got {x.shape}")
        self._count += x.shape[0]
        data = np.ascontiguousarray(np.concatenate([self._buf, x]) if self._buf.size else x)
        span, step = self._span, self._step
        updates = (data.shape[0] - 1 - span) // step + 1 if data.shape[0] > span else 0
        if updates <= 0:
            self._buf = data.copy()
            return self._solution(np.empty((0, 4)))
        if self._sliding:
            q = self._sliding_updates(data, updates)
        else:
            q = np.empty((updates + 1, 4))
            q[0] = self._q0 if self._qhist is None else self._qhist[-1]
            if self._rk4:
                _kernels.rk4_kernel(data, self.td, q[0].copy(), self._mode, q)
            else:
                _run_windowed(data, self._alg, self.td, 0, step, 1, q)
            new = q if self._qhist is None else q[1:]
            self._qhist = q[-1:].copy()
            q = new
        self._buf = data[updates * step:].copy()
        return self._solution(q)

    def _sliding_updates(self, data: NDArray[np.float64], updates: int) -> NDArray[np.float64]:
        """The sliding scheme's new outputs: at start-up ``q0`` and two single-period steps
        first (as the one-shot run), then update ``k`` from output ``k − 3``."""
        u = self._alg.update
        q = np.empty((updates + u, 4))
        if self._qhist is None:
            q[0] = self._q0
            assert self._startup is not None
            _run_windowed(data, self._startup, self.td, 0, 1, 1, q[:u])
            _run_windowed(data, self._alg, self.td, 0, 1, u, q)
            self._qhist = q[-u:].copy()
            return q
        q[:u] = self._qhist
        _run_windowed(data, self._alg, self.td, 0, 1, u, q)
        self._qhist = q[-u:].copy()
        return q[u:]

    def _solution(self, q: NDArray[np.float64]) -> AttitudeSolution:
        """The outputs ``q`` with their times (the one-shot run's arithmetic: sample index
        as a float times td, plus t0) and chains."""
        first, m = self._emitted, q.shape[0]
        self._emitted += m
        step = self._step
        t = np.arange(first * step, (first + m) * step, step, dtype=np.float64)[:m]
        t *= self.td
        t += self.t0
        if self._sliding:
            u = self._alg.update
            return AttitudeSolution(t, q, "sliding", None, self.td, self.td,
                                    (np.arange(first, first + m) % u).astype(int))
        name = "rk4" if self._rk4 else "windowed"
        return AttitudeSolution(t, q, name, None, self.td, step * self.td,
                                np.zeros(m, int))
