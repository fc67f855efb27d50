"""The dimension-RRT search on a waypoint array, in numpy: what :class:`~tpee_ompl.planning.dimension_rrt.DimensionRRT` runs.

:class:`Search` holds the current path ``W`` (h, n) and does one sample per :meth:`Search.iterate`
(improvement on a valid path, else the feasibility phase: :class:`ConnectTrees` without prescribed
groups, :class:`LayeredTrees` with them or when a connect path does not fit the h steps); the algorithm:
:mod:`tpee_ompl.planning.dimension_rrt`.  No OMPL problem definition here (validity: :class:`Checker`).
"""

from __future__ import annotations

from dataclasses import dataclass

import functools
from collections.abc import Callable

import numpy as np

from .connect_trees import RANGE_FRACTION, ConnectTrees
from .grouped_space import GroupedSpace
from .layered_trees import LayeredTrees, spread_waypoints
from .search_checker import Checker, segment_key
from .search_draws import GROUP_BLOCK, SampleDraws
from .waypoint_shortcuts import respread_candidate, sweep_until_settled

__all__ = ["Search", "SearchSettings"]


@dataclass(frozen=True)
class SearchSettings:
    """What every search of one solve shares: ``narrow_after`` and ``narrowing`` (the narrowing region,
    :mod:`~tpee_ompl.planning.search_draws`), ``connect`` (connect trees for a first path without prescribed
    groups), ``shortcuts`` (the shortcut sweeps on a valid path), ``settle`` (the rows will not be released, so
    with a prescribed group the sweeps repeat until settled)."""

    narrow_after: int
    narrowing: float
    connect: bool = True
    shortcuts: bool = False
    settle: bool = False


class Search(SampleDraws):
    """The dimension-RRT iteration on a waypoint array; OMPL-free apart from the checker.  ``range_``: per planned
    group, the least padding of its narrowed region; ``initial``: a first guess of the waypoints; ``turns``: a
    connect path's turning points to fit (``h`` raised); ``local``: narrowed samples around one waypoint at a time
    (the released search; :meth:`SampleDraws._group_draws`)."""

    def __init__(self, grouped: GroupedSpace, checker: Checker, rng: np.random.Generator, start: np.ndarray,
                 goal: np.ndarray, settings: SearchSettings, range_: dict[int, np.ndarray],
                 initial: np.ndarray | None = None, turns: np.ndarray | None = None, local: bool = False) -> None:
        self.checker = checker
        self.dist = grouped.layout.distance
        W = grouped.initial_waypoints(start, goal)
        if initial is not None:
            for gi in grouped.planned:
                d = grouped.group_dims(gi)
                W[1:-1, d] = initial[1:-1, d]
        self.W = W
        V = np.ones(len(W), dtype=bool)
        checked = np.ones(len(W) - 1, dtype=bool)  # the motions whose validity E states
        if all(W[k : k + 2].tobytes() in checker.passed for k in range(len(W) - 1)):
            self.V, self.E = V, V[1:].copy()  # a path whose motions all passed si.checkMotion (released rows)
        else:
            V[1:-1] = checker.states(W[1:-1])
            self.V = V
            self.E = V[:-1] & V[1:]
            if V.all() or grouped.prescribed or not settings.connect or initial is not None or turns is not None:
                # in full at once: the initial path is often valid, and then screening a coarse subset first only costs
                self.E[self.E] = checker.check_motions(W[:-1][self.E], W[1:][self.E])
            else:  # the connect trees grow from the start and goal alone: the valid prefix and suffix go unused
                checked[:] = self.E[:] = False
        self.L = self.dist(W[:-1], W[1:])
        self._init_draws(grouped, rng, settings.narrow_after, settings.narrowing, range_, local)
        self._tree: LayeredTrees | None = None
        self._connect: ConnectTrees | None = None
        self._use_connect = settings.connect
        self._guess = initial is not None
        self.unfitted: np.ndarray | None = None
        """Turning points of a connect-tree path that did not fit the h steps (None: no such path)."""
        self._spread_pending = False
        self._known: dict[bytes, bool] = {W[k : k + 2].tobytes(): bool(self.E[k]) for k in range(len(W) - 1)
                                          if self.V[k] and self.V[k + 1] and checked[k]}
        """Segment (two waypoint rows as bytes) -> motion valid, for every motion checked so far."""
        # feasibility phase: all planned groups vary jointly (with one planned group: that group), their DOFs in
        # index order, so that its samples, and so the first path, do not depend on how the DOFs are grouped
        self._fdims = grouped.planned_dims
        self._fbounds = (grouped.layout.lower[self._fdims], grouped.layout.upper[self._fdims])
        self._hold = not grouped.prescribed
        self.delta = grouped.layout.delta
        self._shortcuts = settings.shortcuts
        self._settle = settings.settle and bool(grouped.prescribed)  # rows kept to the end: sweeps until settled
        self._shortcut_due = self.valid  # the valid path changed since the last sweep (or is new)
        if turns is not None and not self.valid:  # a connect path found with fewer steps (h raised)
            self._use_connect = False
            self._fit(turns)

    @property
    def valid(self) -> bool:
        return bool(self.V.all() and self.E.all())

    @property
    def connecting(self) -> bool:
        """Whether the connect trees are growing (a higher h would only start them again: h matters once they met)."""
        return self._connect is not None

    @property
    def trees(self) -> LayeredTrees | None:
        """The feasibility phase's layered trees while they grow (else None): for inspection only."""
        return self._tree

    @property
    def cost(self) -> float:
        return float(self.L.sum())

    def iterate(self, limit: int = 1, stop: Callable[[], bool] | None = None,
                found: Callable[[np.ndarray, float], None] | None = None) -> int:
        """Draw one sample and try it at every intermediate step (up to ``limit`` samples; see below).

        On a valid path the sample is the current group's (paper's rule), followed with ``shortcuts`` by
        :func:`sweep_until_settled` over that group when the path changed (one sweep unless ``settle``);
        before, it covers all planned groups at once and grows the connect trees (no prescribed group) or the layered
        trees.  Returns the number of waypoints changed (feasibility phase: 1 when a path was found,
        0 otherwise).

        With ``limit > 1`` on a valid path, up to ``limit - 1`` samples that the cost test rejects at
        every step (with a group of every DOF, also those whose state the look-ahead found colliding) are
        first passed over in one vectorised step, unless a shortcut sweep is due (it runs after the next
        sample, and the samples after it are tested against the swept path); in the connect trees, up to ``limit``
        samples go through in one call, until the trees meet or ``stop()`` (asked before each sample
        after the first): either way the same samples and result as single calls.  When they meet, their path
        through every tree node (each motion checked) goes to ``found(path, cost)`` before it is fitted to the h
        steps, and ``stop()`` is asked before the fit checks a motion (RRTConnect's first path, as soon as
        it has one).
        """
        if self._spread_pending:
            self._spread()
        valid = self.valid
        if limit > 1 and valid and not (self._shortcuts and self._shortcut_due):
            # (a sweep due runs after the next sample: the samples after it are tested against the swept path)
            self._pass_rejected(limit - 1)
        gi = self.current_group()
        if not valid and self._tree is None and self._connect is None:
            if self.unfitted is not None:  # a connect path with more turns than steps seeds the layered trees
                self._tree = self._layered(*self._seed_path(self.unfitted))
            elif self._hold and self._use_connect:
                self._use_connect = False  # once per search: a path that does not fit hands over to layered trees
                span = float(self.checker.si.getMaximumExtent())
                # from the start and goal alone, as RRTConnect's, unless a first guess was given: the
                # straight line's valid prefix pinned the trees to the wall it ends at (4-D hole:
                # median samples to a first path 77-193 -> 5-38)
                V = self.V.copy()
                if not self._guess:
                    V[1:-1] = False
                self._connect = ConnectTrees(self.W, V, self.E, self.g.layout, RANGE_FRACTION * span, self.checker.tree_motions,
                                             None if self.checker.batched else self.checker.check_step)
            else:
                self._tree = self._layered(self.W, self.V, self.E)
        if self._connect is not None:
            return self._connect_samples(max(1, limit), stop, found)
        c = self.draw(gi if valid else None)
        self.samples += 1
        self.group_samples[gi] += 1
        if not valid:
            return self._grow(c)
        accepted = self._improve(gi, c)
        if self._shortcuts and (accepted or self._shortcut_due):
            self._shortcut_due = False
            # until settled on rows kept to the end (Table 4 at 500 samples: 1.2-1.9 % shorter), else once (the
            # pipeline's rows phase and the released search: more sweeps cost them more than they save)
            accepted += sweep_until_settled(self.W, self.L, self._dims[gi], self.g.layout, self.checker,
                                            None if self._settle else 1, stop)
            accepted += 0 if self.g.prescribed else self._respread()
        return accepted

    def _respread(self) -> int:
        """Give a collapsed waypoint's step to the longest segment (:func:`respread_candidate`) when that passes."""
        S = respread_candidate(self.W, self.L, self.g.layout)
        if S is None:
            return 0
        LS = self.dist(S[:-1], S[1:])
        if LS.sum() > self.L.sum() or not self._passes(S):
            return 0
        self.W[:], self.L[:] = S, LS
        return 1

    def _passes(self, S: np.ndarray) -> bool:
        """Whether S (h, n), the valid path W with waypoints moved, passes: its moved waypoints and new motions."""
        W = self.W
        self._known.update((W[a : a + 2].tobytes(), True) for a in range(len(W) - 1))  # W's motions are valid
        moved = (S[1:-1] != W[1:-1]).any(axis=1)
        return bool(self.checker.states(S[1:-1][moved]).all()) and not self._check_segments(S)

    def _layered(self, W: np.ndarray, V: np.ndarray, E: np.ndarray) -> LayeredTrees:
        if self.g.prescribed:  # without, the planar arms and point problems gained on some and lost on others
            self._feasibility_region(W)
        return LayeredTrees(W, V, E, self._fdims, self._hold, functools.partial(self.delta, dims=self._fdims))

    def _connect_samples(self, limit: int, stop: Callable[[], bool] | None,
                         found: Callable[[np.ndarray, float], None] | None = None) -> int:
        """Feasibility phase without prescribed groups: up to ``limit`` RRTConnect iterations (the random rows
        :meth:`draw` would use); once the trees meet, the path is fitted to the h steps (:meth:`_fit`) or
        handed to the layered trees.  Returns 1 when the path was fitted, else 0."""
        k = len(self._fdims)
        self._refill(k)
        U = self._uniform[self._ui : self._ui + min(limit, len(self._uniform) - self._ui)]
        lo, hi = self._fbounds
        X = np.repeat(self.W[:1], len(U), axis=0)
        X[:, self._fdims] = lo + U[:, 1:] * (hi - lo)
        base = self.samples

        def counting() -> bool:  # asked after each sample but the last: ``samples`` counts them as they are drawn
            self.samples += 1
            return stop()

        P, used = self._connect.run(X, None if stop is None else counting)
        self.samples = base
        self._ui += used
        planned = self.g.planned
        for s in range(self.samples, self.samples + used):
            self.group_samples[planned[(s // GROUP_BLOCK) % len(planned)]] += 1
        self.samples += used
        if P is None:
            return 0
        for k in np.flatnonzero(self._connect.verified):  # single tree edges: checked in path direction
            key = segment_key(P[k], P[k + 1])
            self._known[key] = True
            self.checker.passed.add(key)
        if found is not None:
            E = self._connect.edges
            self.checker.passed.update(segment_key(E[k], E[k + 1]) for k in range(len(E) - 1))
            found(E, float(self.dist(E[:-1], E[1:]).sum()))
        self._connect = None
        return int(self._fit(P, stop))

    def _seed_path(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The polyline P (K, n) at h evenly spaced points, with their validity and their motions'."""
        lay = self.g.layout
        s = np.concatenate(([0.0], np.cumsum(lay.distance(P[:-1], P[1:]))))
        at = np.linspace(0.0, s[-1], self.g.h)
        k = np.clip(np.searchsorted(s, at, side="right") - 1, 0, len(P) - 2)
        W = lay.interpolate(P[k], P[k + 1], np.clip((at - s[k]) / np.maximum(s[k + 1] - s[k], 1e-300), 0.0, 1.0))
        W[0], W[-1] = self.W[0], self.W[-1]
        V = np.ones(len(W), dtype=bool)
        V[1:-1] = self.checker.states(W[1:-1])
        E = V[:-1] & V[1:]
        E[E] = self.checker.motions(W[:-1][E], W[1:][E])
        for k in np.flatnonzero(V[:-1] & V[1:]):
            self._known[W[k : k + 2].tobytes()] = bool(E[k])
        return W, V, E

    def _fit(self, P: np.ndarray, stop: Callable[[], bool] | None = None) -> bool:
        """Take the turning points P (K, n) from start to goal as the path when they fit the h steps.

        While K > h, the interior point whose shortcut saves most and passes in full is dropped; the
        runs are checked as whole motions and the path adopted with its points held (:meth:`_adopt`).
        False when more points than steps remain, a run fails as one motion or ``stop()`` (asked before each
        shortcut's check, a long path costs up to K^2 of them, and before the runs' checks); :attr:`unfitted`
        then holds the points, for a higher h or the layered trees."""
        h, dist = self.g.h, self.dist
        while len(P) > h:
            gain = dist(P[:-2], P[1:-1]) + dist(P[1:-1], P[2:]) - dist(P[:-2], P[2:])
            for i in (np.argsort(-gain, kind="stable") + 1).tolist():
                if stop is not None and stop():
                    self.unfitted = P
                    return False
                if not self._check_segments(P[[i - 1, i + 1]]):
                    P = np.delete(P, i, axis=0)
                    break
            else:
                self.unfitted = P
                return False
        W = np.vstack([P, np.repeat(P[-1:], h - len(P), axis=0)])
        unchecked = any(W[k : k + 2].tobytes() not in self._known and (W[k] != W[k + 1]).any() for k in range(len(W) - 1))
        if unchecked and stop is not None and stop():
            self.unfitted = P
            return False
        if self._check_segments(W):
            self.unfitted = P
            return False
        self._adopt(W)
        return True

    def _grow(self, c: np.ndarray) -> int:
        """Layered trees: grow them with the sample c (motions checked lazily); 1 when the path is complete.

        c is checked at every step t with a forward node before or a backward node after it (once when
        holding).  Of the steps with both, the one with the shortest motions completes a candidate
        path, whose unchecked motions are checked now: all pass and it is the path; a failed one kills
        the node it leads into (and its subtree), and c joins through its motions that passed.  At the
        other steps c joins on unchecked motions; when holding, once per tree, at the lowest forward /
        highest backward step whose motion passes in full (screening let trees through thin walls)."""
        tree = self._tree
        d = tree.dims
        h = self.g.h
        fi_all, bi_all = tree.nearest(c)
        ts = [t for t in range(1, h - 1) if fi_all[t - 1] >= 0 or bi_all[t - 1] >= 0]
        if not ts:
            return 0
        base = tree.base
        ts_a = np.array(ts)
        C = base[ts_a].copy()
        C[:, d] = c
        vc = np.repeat(self.checker.states(C[:1]), len(ts)) if self._hold else self.checker.states(C)
        fi = np.array([fi_all[t - 1] for t in ts])
        bi = np.array([bi_all[t - 1] for t in ts])
        both = (vc & (fi >= 0) & (bi >= 0)).nonzero()[0]
        tried = -1
        joined: set[int] = set()  # holding: the trees c joined already
        if len(both):
            k = int(both[0])  # the only step with both trees' nodes, else the one with the shortest motions:
            if len(both) > 1:
                A, B = base[ts_a[both] - 1].copy(), base[ts_a[both] + 1].copy()
                A[:, d], B[:, d] = tree.fwd.values[fi[both]], tree.bwd.values[bi[both]]
                k = int(both[np.argmin(self.dist(A, C[both]) + self.dist(C[both], B))])
            tried, t = k, ts[k]
            W, owners = tree.path(t, c, int(fi[k]), int(bi[k]))
            bad = self._check_segments(W)
            if not bad:
                self._adopt(W)
                self._tree = None
                return 1
            for seg in bad:
                side, node = owners.get(seg, ("", -1))
                if side == "f":
                    tree.fwd.kill(node)
                elif side == "b":
                    tree.bwd.kill(node)
            f, b = int(fi[k]), int(bi[k])
            known = self._known  # c joins through a motion checked in full, or of zero length
            passed = []
            for k in (t - 1, t):
                ok = known.get(W[k : k + 2].tobytes())
                passed.append(not (W[k] != W[k + 1]).any() if ok is None else ok)
            if passed[0] and tree.fwd.alive[f]:
                tree.fwd.add(c, t, f)
                joined.add(id(tree.fwd))
            if passed[1] and tree.bwd.alive[b]:
                tree.bwd.add(c, t, b)
                joined.add(id(tree.bwd))
        # the other steps: c joins on unchecked motions; holding, once per tree, at the lowest step
        # (forward) or highest (backward) whose motion passes in full
        if self._hold:
            if not vc[0]:
                return 0
            adds = []
            for tr, p, order, sgn in ((tree.fwd, fi, range(len(ts)), 1), (tree.bwd, bi, range(len(ts) - 1, -1, -1), -1)):
                seen = []
                for k in order:
                    if id(tr) not in joined and p[k] >= 0 and tr.alive[p[k]] and int(p[k]) not in seen:
                        seen.append(int(p[k]))
                        adds.append((tr, int(p[k]), int(tr.steps[p[k]]) + sgn))
        else:
            adds = [(tr, int(p[k]), ts[k]) for k in range(len(ts)) if k != tried and vc[k]
                    for tr, p in ((tree.fwd, fi), (tree.bwd, bi)) if p[k] >= 0]
        for tr, p, t in adds:
            if not tr.alive[p] or (self._hold and id(tr) in joined):  # a node killed above; holding: joined already
                continue
            if self._hold:  # checked in full: coarse screening let the trees through thin walls
                ct, pt = base[t].copy(), base[int(tr.steps[p])].copy()
                ct[d], pt[d] = c, tr.values[p]
                if self._check_segments(np.stack([pt, ct] if tr is tree.fwd else [ct, pt])):
                    continue
                joined.add(id(tr))
            tr.add(c, t, p)  # not holding: lazily, the motion is checked once a candidate path uses it
        return 0

    def _check_segments(self, W: np.ndarray) -> list[int]:
        """Segments of W (K, n) found invalid (lazy checking: called once W is a complete candidate).

        The waypoints are known valid; zero-length and known segments cost nothing.  Batched, every
        16th state is screened, longest stretch first (:meth:`Checker.first_failing_motion`: the first
        failing segment alone is reported), else all are checked in full.  Per-state: in full in order
        (``si.checkMotion``'s bisection beats a Python screen), up to the first failure.  Results are kept."""
        known, checker = self._known, self.checker
        keys = [W[k : k + 2].tobytes() for k in range(len(W) - 1)]
        bad = [k for k, key in enumerate(keys) if not known.get(key, True)]
        moving = (W[1:] != W[:-1]).any(axis=1).tolist()
        todo = [k for k, key in enumerate(keys) if moving[k] and key not in known]
        if bad or not todo:
            return bad
        if not checker.batched:
            for k in todo:
                known[keys[k]] = ok = checker.check_motion(W[k], W[k + 1])
                if not ok:
                    return [k]
            return []
        ends = np.array(todo)
        k = checker.first_failing_motion(W[ends], W[ends + 1], bisect=True)  # finds most failing motions
        if k >= 0:
            known[keys[todo[k]]] = False
            return [todo[k]]
        # all of them: a motion the coarse test missed may not be the only one
        for k, ok in zip(todo, checker.check_motions(W[ends], W[ends + 1])):
            if not ok:
                bad.append(k)
            known[keys[k]] = bool(ok)
        return bad

    def _adopt(self, W: np.ndarray) -> None:
        """Take W (h, n), checked by the trees, as the current (valid) path; held (repeated) waypoints are
        spread along its segments at the next :meth:`iterate` (:meth:`_spread`), after it is posted."""
        self.W[:] = W
        self.V[:] = True
        self.E[:] = True
        self.L[:] = self.dist(W[:-1], W[1:])
        self._spread_pending = self._hold
        self._shortcut_due = True

    def _spread(self) -> None:
        """Move held waypoints onto the path's segments, kept only when that path passes the checker."""
        self._spread_pending = False
        S = spread_waypoints(self.W, self.g.layout.interpolate, self.dist)
        if S is not self.W and self._passes(S):
            self.W[:] = S
            self.L[:] = self.dist(S[:-1], S[1:])

    def _improve(self, gi: int, c: np.ndarray) -> int:
        """Paper's rule on a valid path: replace W[t] when valid, connected and shorter (V, E stay all true)."""
        d = self._dims[gi]
        W, L = self.W, self.L
        C = W[1:-1].copy()
        C[:, d] = c
        A, B = W[:-2], W[2:]
        dl, dr = self.dist(A, C), self.dist(C, B)
        shorter = dl + dr < L[:-1] + L[1:] - 1e-12
        if not shorter.any():
            return 0
        ts = np.flatnonzero(shorter)
        yes = np.ones(len(ts), dtype=bool)
        C = C[ts]
        vc, left, right = self.checker.candidates(C, A[ts], B[ts], yes, yes, yes, self.hit_validity(C))
        ok = vc & left & right
        accepted = 0
        last = -2
        for k in np.flatnonzero(ok):
            t = int(ts[k]) + 1
            if t == last + 1:
                continue
            W[t] = C[k]
            L[t - 1], L[t] = dl[t - 1], dr[t - 1]
            accepted += 1
            last = t
        return accepted
