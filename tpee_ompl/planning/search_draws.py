"""How dimension-RRT draws its samples: a buffer of uniforms, the narrowing region, and the cost test run ahead.

:class:`SampleDraws` is the sampling half of :class:`~tpee_ompl.planning.dimension_search.Search`: with
several planned groups each gets :data:`GROUP_BLOCK` consecutive samples in turn; after ``narrow_after``
samples of a group, 90 % are drawn from the bounding box of the current path's values of that group
(released: of one waypoint's), padded by ``max(range_, span * narrowing ** (m / 100))``, the rest
uniformly over the bounds.  Before a path, with a prescribed group, the layered trees' samples of all planned
DOFs are drawn the same way around the path they start from (the straight line between the prescribed rows, or
a first guess): 90 % from the box it sweeps padded by :data:`FEASIBILITY_PAD` of each DOF's range, doubled every
:data:`FEASIBILITY_DOUBLING` samples, so that a detour stays near the blocked line while one is enough, and the
rest uniformly (a departure from the paper's uniform samples: ``docs/dimension_rrt.md``); without a prescribed
group they stay uniform.  On a valid path most samples are shorter at no step; :meth:`SampleDraws._pass_rejected`
passes over them with one vectorised cost test, run ahead over up to :data:`AHEAD` samples and kept while
the path stays the same, and with a group of every DOF also over the samples whose state the look-ahead
found colliding (:meth:`SampleDraws._hit_states`): the same samples, and the same paths, as drawing them
one by one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from .grouped_space import GroupedSpace
from .search_checker import Checker

__all__ = ["AHEAD", "FEASIBILITY_DOUBLING", "FEASIBILITY_PAD", "GROUP_BLOCK", "SampleDraws"]

_UNIFORM_FRACTION = 0.1  # share of samples drawn uniformly over the bounds once the region has narrowed
_NARROWING_UNIT = 100  # the narrowing factor applies per this many samples
FEASIBILITY_PAD: float | None = 0.25
"""With a prescribed group, the layered trees' samples (no path yet) are drawn, all but the uniform share, from the
box the path they start from sweeps, padded by this fraction of each DOF's range.  None: uniform over the bounds, as
the paper.  Chosen with :data:`FEASIBILITY_DOUBLING` on the 36 held-out queries of each set
(``experiments/feasibility_region.py``)."""
FEASIBILITY_DOUBLING = 16
"""Samples after which that padding doubles (after about 2 x this many the box covers the bounds)."""
GROUP_BLOCK = 100
"""With several planned groups, each gets this many consecutive samples in turn."""
AHEAD = 256
"""Most samples whose cost test runs ahead at once (one planned group): at 5,000 / 20,000 samples per
run the library pipeline took 0.76 / 0.68 of the time it took with the test run per call (at most 63
samples, ``limit - 1``; ``experiments/speed_switches.py look-ahead``)."""


class _Ahead(NamedTuple):
    """The cost test run ahead (:meth:`SampleDraws._ahead_test`)."""

    key: tuple
    start: int  # the buffer row of C[0]
    C: np.ndarray  # the samples
    n0: int | None  # their narrowing start
    valid: dict[bytes, bool]  # validity of the hits' candidate states (their bytes), checked together
    live: np.ndarray  # indices into C of the samples shorter at some step whose state is not known to collide


def _swept_box(vals: np.ndarray, circ: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The least and greatest of each column of vals (m, k); for an angle (``circ``) the ends of the arc the
    path sweeps, across +-pi, not the values' min and max."""
    if circ is not None:
        vals = np.where(circ, np.unwrap(vals, axis=0, period=2 * math.pi), vals)
    return vals.min(axis=0), vals.max(axis=0)


class SampleDraws:
    """The sample draws of :class:`~tpee_ompl.planning.dimension_search.Search` (module docstring); the
    subclass sets ``W``, ``L``, ``dist``, ``checker``, ``_fdims`` and ``_fbounds`` (the feasibility phase's DOFs)."""

    W: np.ndarray
    checker: Checker
    L: np.ndarray
    dist: Callable[[np.ndarray, np.ndarray], np.ndarray]
    _fdims: np.ndarray
    _fbounds: tuple[np.ndarray, np.ndarray]

    def _init_draws(self, grouped: GroupedSpace, rng: np.random.Generator, narrow_after: int, narrowing: float,
                    range_: dict[int, np.ndarray], local: bool) -> None:
        self.g = grouped
        self.rng = rng
        self.narrow_after = narrow_after
        self.narrowing = narrowing
        self.range_ = range_
        self._local = local
        self.samples = 0
        self.group_samples = {gi: 0 for gi in grouped.planned}
        self.narrow_start: dict[int, int | None] = {gi: None for gi in grouped.planned}
        self._dims = {gi: grouped.group_dims(gi) for gi in grouped.planned}
        self._bounds = {gi: grouped.group_bounds(gi) for gi in grouped.planned}
        circular = grouped.layout.circular
        self._circular = {gi: circular[d] if circular[d].any() else None for gi, d in self._dims.items()}
        self._uniform = np.empty((0, 0))
        self._ui = 0
        self._buffers = 0  # buffers drawn so far (identifies the current one)
        self._ahead: _Ahead | None = None
        self._drawn: tuple | None = None
        self._scales = np.zeros(0)
        self._cut: int | None = None  # the offset from which every group's padding is its range_
        self._floor: float | None = None  # the smallest scale any padding needs (:meth:`_scale`; only once narrowing)
        self._fregion: tuple[np.ndarray, np.ndarray, np.ndarray | None, int] | None = None  # :meth:`_feasibility_region`

    def _feasibility_region(self, W: np.ndarray) -> None:
        """Draw the feasibility phase's samples around W (h, n), the path the layered trees start from: the box
        its planned DOFs sweep, padded as :data:`FEASIBILITY_PAD` says (module docstring)."""
        if FEASIBILITY_PAD is None:  # uniform over the bounds, as the paper (a switch for experiments)
            self._fregion = None
            return
        circ = self.g.layout.circular[self._fdims]
        circ = circ if circ.any() else None
        self._fregion = (*_swept_box(W[:, self._fdims], circ), circ, self.samples)

    def _refill(self, k: int) -> None:
        """A fresh buffer of 1024 samples' randomness (one uniform picking narrowed or uniform, then k values)."""
        if self._ui >= len(self._uniform) or self._uniform.shape[1] != k + 1:
            self._uniform = self.rng.random((1024, k + 1))
            self._ui = 0
            self._buffers += 1

    def _next_random(self, k: int) -> np.ndarray:  # one sample's 1 + k uniforms (see :meth:`_refill`)
        self._refill(k)
        self._ui += 1
        return self._uniform[self._ui - 1]

    def current_group(self) -> int:
        """The planned group the next sample is for (each gets :data:`GROUP_BLOCK` samples in turn)."""
        planned = self.g.planned
        return planned[(self.samples // GROUP_BLOCK) % len(planned)]

    def draw(self, gi: int | None) -> np.ndarray:
        """One sample: for group gi (narrowed or uniform), or with gi None for the feasibility phase's
        joint planned DOFs (with a prescribed group around the path the layered trees start from, else
        uniform over their bounds); see the module docstring."""
        if gi is None:
            lo, hi = self._fbounds
            u = self._next_random(len(self._fdims))
            if self._fregion is None or u[0] < _UNIFORM_FRACTION:
                return lo + u[1:] * (hi - lo)
            vlo, vhi, circ, s0 = self._fregion
            pad = FEASIBILITY_PAD * 2.0 ** min((self.samples - s0) / FEASIBILITY_DOUBLING, 8.0) * (hi - lo)
            return self._padded_box_draws(u[None, 1:], vlo, vhi, pad, lo, hi, circ, self._fdims)[0]
        drawn, self._drawn = self._drawn, None
        if drawn is not None and drawn[:2] == (self._ui, gi):  # drawn already by :meth:`_pass_rejected`
            self._ui += 1
            c, n0 = drawn[2], drawn[3]
        else:
            C, n0 = self._group_draws(gi, self._next_random(len(self._dims[gi]))[None, :])
            c = C[0]
        if n0 is not None and self.narrow_start[gi] is None:
            self.narrow_start[gi] = n0
        return c

    def _group_draws(self, gi: int, U: np.ndarray) -> tuple[np.ndarray, int | None]:
        """The next len(U) samples of group gi from the random rows U (m, k + 1), as :meth:`draw` draws them
        one by one (W unchanged), and the narrowing start they imply (None: not narrowing yet).  With
        ``local`` a narrowed sample's box is padded around one intermediate waypoint (picked by U[:, 0])
        instead of around the whole path."""
        lo, hi = self._bounds[gi]
        span = hi - lo
        C = lo + U[:, 1:] * span
        g0 = self.group_samples[gi]
        n0 = self.narrow_start[gi]
        if n0 is None and g0 + len(U) - 1 >= self.narrow_after:
            n0 = max(g0, self.narrow_after)
        if n0 is not None:
            narrow = np.flatnonzero((U[:, 0] >= _UNIFORM_FRACTION) & (g0 + np.arange(len(U)) >= n0))
            if len(narrow):
                if self._cut is not None and g0 - n0 >= self._cut:  # every padding is range_ from here on
                    pad = self.range_[gi]
                else:
                    pad = np.maximum(self.range_[gi], span * self._scale(g0 - n0 + narrow)[:, None])
                vals = self.W[:, self._dims[gi]]
                circ = self._circular[gi]
                if self._local:
                    m = len(vals) - 2
                    t = 1 + np.minimum((U[narrow, 0] - _UNIFORM_FRACTION) / (1 - _UNIFORM_FRACTION) * m, m - 1).astype(int)
                    vlo = vhi = vals[t]
                else:
                    vlo, vhi = _swept_box(vals, circ)
                C[narrow] = self._padded_box_draws(U[narrow, 1:], vlo, vhi, pad, lo, hi, circ, self._dims[gi])
        return C, n0

    def _padded_box_draws(self, U: np.ndarray, vlo: np.ndarray, vhi: np.ndarray, pad: np.ndarray | float,
                          lo: np.ndarray, hi: np.ndarray, circ: np.ndarray | None, dims: np.ndarray) -> np.ndarray:
        """Samples from the uniforms U (m, k): uniform in the box [vlo, vhi] of DOFs ``dims`` padded by ``pad``
        and cut at the bounds [lo, hi]; an angle's box (``circ``) wraps round +-pi instead of stopping there, and
        is the whole circle once the padded arc is as long (its unwrapped ends may lie beyond +-pi: cut at the
        bounds, it lost the part of the circle past them)."""
        nlo, nhi = np.maximum(lo, vlo - pad), np.minimum(hi, vhi + pad)
        if circ is not None:
            arc = circ & (vhi - vlo + 2 * pad < hi - lo)
            whole = circ & ~arc
            nlo = np.where(arc, vlo - pad, np.where(whole, lo, nlo))
            nhi = np.where(arc, vhi + pad, np.where(whole, hi, nhi))
        C = nlo + U * (nhi - nlo)
        return C if circ is None else self.g.layout.wrap(C, dims)  # back into [-pi, pi)

    def _scale(self, k: np.ndarray) -> np.ndarray:
        """``narrowing ** (k / 100)`` for ascending offsets k >= 0, memoised (``np.power`` is not bit-identical) up to
        the offset where every padding has reached its ``range_`` (later offsets get that one's: the same paddings)."""
        while self._cut is None and int(k[-1]) >= (have := len(self._scales)):
            more = range(have, max(2 * have, 128))
            self._scales = np.concatenate((self._scales, [self.narrowing ** (i / _NARROWING_UNIT) for i in more]))
            if self._floor is None:
                self._floor = min((float(np.min(self.range_[gi][hi > lo] / (hi - lo)[hi > lo]))
                                   for gi, (lo, hi) in self._bounds.items() if (hi > lo).any()),
                                  default=0.0) * (1 - 1e-12)  # (a dimension of width 0 keeps its value)
            below = np.flatnonzero(self._scales <= self._floor)
            self._cut = int(below[0]) if len(below) else None
        return self._scales[k if self._cut is None else np.minimum(k, self._cut)]

    def _pass_rejected(self, limit: int) -> None:
        """Advance past the next samples (at most ``limit``, within the group's block and the random buffer)
        that :meth:`_improve` would reject on cost alone: :meth:`draw` and its cost test, vectorised; with a
        group of every DOF also those whose state the look-ahead found invalid (:meth:`_hit_states`).  Not
        called while a shortcut sweep is due (:meth:`Search.iterate`): it runs after the next sample.

        The test runs ahead over up to :data:`AHEAD` samples (one planned group; with several, to the end
        of the group's block) and is kept while W stays the same: most samples are passed over, so later
        calls mostly look up the next one that is not."""
        gi = self.current_group()
        self._refill(len(self._dims[gi]))
        block = self._ui + GROUP_BLOCK - self.samples % GROUP_BLOCK  # the group's block ends there
        n = min(limit, min(block, len(self._uniform)) - self._ui)
        while n > 0:
            ahead = self._ahead_test(gi, block)
            u0, C, n0, hits = ahead.start, ahead.C, ahead.n0, ahead.live
            g0, o = self.group_samples[gi], self._ui - u0
            m = min(n, len(C) - o)
            i = int(np.searchsorted(hits, o))
            j = int(hits[i]) - o if i < len(hits) and hits[i] - o < m else m
            if j < m:  # the first sample not rejected, as :meth:`draw` would draw it next (W unchanged in between)
                self._drawn = (self._ui + j, gi, C[o + j], n0 if n0 is not None and g0 + j >= n0 else None)
            self._ui += j
            self.samples += j
            self.group_samples[gi] = g0 + j
            if self.narrow_start[gi] is None and n0 is not None and g0 + j - 1 >= n0:
                self.narrow_start[gi] = n0
            if j < m:
                return
            n -= m

    def _ahead_test(self, gi: int, block: int) -> _Ahead:
        """:meth:`_pass_rejected`'s cost test from the current buffer row on (at least that row), computed
        again when the path (W, L), the buffer or the group changed."""
        key = (self._buffers, gi, self._ui - self.group_samples[gi], self.W.tobytes(), self.L.tobytes())
        ahead = self._ahead
        if ahead is not None and ahead.key == key and ahead.start <= self._ui < ahead.start + len(ahead.C):
            return ahead
        W, L, d = self.W, self.L, self._dims[gi]
        end = min(len(self._uniform), self._ui + max(1, AHEAD) if len(self.g.planned) == 1 else block)
        C, n0 = self._group_draws(gi, self._uniform[self._ui : end])
        X = np.broadcast_to(W[1:-1], (len(C),) + W[1:-1].shape).copy()
        X[:, :, d] = C[:, None, :]
        shorter = self.dist(W[:-2], X) + self.dist(X, W[2:]) < L[:-1] + L[1:] - 1e-12
        hits = np.flatnonzero(shorter.any(axis=1))
        valid: dict[bytes, bool] = {}
        if len(d) == W.shape[1] and len(hits):  # the candidate at every step is the sample, in the DOFs' order
            S = np.empty((len(hits), len(d)))
            S[:, d] = C[hits]
            valid = self._hit_states(S, ahead)
            hits = hits[[valid[s.tobytes()] for s in S]] if valid else hits
        self._ahead = _Ahead(key, self._ui, C, n0, valid, hits)
        return self._ahead

    def _hit_states(self, S: np.ndarray, last: _Ahead | None) -> dict[bytes, bool]:
        """Validity of the hits' candidate states S by their bytes, in one batched call, for a group of every DOF
        (a sample is then the candidate state at every step, whatever W is): :meth:`_improve` would check
        each hit on its own, one call per sample.  With a batched checker only; the states known from the
        last look-ahead are not checked again.  :meth:`_pass_rejected` then passes over the hits whose state
        collides as over those the cost test rejects.  Library pipeline, 24 ``planning_necessary`` queries
        capped at 5,000 / 20,000 samples: the same paths in 0.89 / 0.81 of the time, 2 % more checks (the
        hits after a shorter path are checked but not all tried; ``experiments/speed_switches.py
        hit-states``).  The check runs ahead of the samples drawn, so a run capped at N samples may count
        checks of a few hits after the N-th.  With a group of some DOFs a shorter path changes the candidates
        of the later hits (tried on the paper's planner: 1.02-1.06x the time), so not there."""
        if not len(S) or not self.checker.batched:
            return {}
        known = last.valid if last is not None else {}
        out: dict[bytes, bool] = {}
        todo: dict[bytes, int] = {}
        for k, s in enumerate(S):
            b = s.tobytes()
            if b in known:
                out[b] = known[b]
            elif b not in todo:
                todo[b] = k
        if todo:
            out.update(zip(todo, self.checker.states(S[list(todo.values())]).tolist()))
        return out

    def hit_validity(self, C: np.ndarray) -> np.ndarray | None:
        """Validity of candidate states C (m, n) from the look-ahead's check of its hits, or None when one
        of them is not known (then the caller checks them)."""
        valid = self._ahead.valid if self._ahead is not None else None
        if not valid:
            return None
        out = [valid.get(c.tobytes()) for c in C]
        return None if None in out else np.array(out, dtype=bool)
