"""The dimension-RRT search on a waypoint array, in numpy: what :class:`~tpee_ompl.planning.dimension_rrt.DimensionRRT` runs.

:class:`Checker` answers validity of states and motions for one ``SpaceInformation`` (one batched
``are_valid`` call per pass when the setup offers it, else ``si.isValid`` / ``si.checkMotion``);
:class:`Search` holds the current path ``W`` (h, n) and does one sample per :meth:`Search.iterate`
(improvement on a valid path, else the feasibility phase's :class:`LayeredTrees`).  The algorithm is
described in :mod:`tpee_ompl.planning.dimension_rrt`; nothing here touches the planner's OMPL problem
definition, so it can be driven and tested without one.
"""

from __future__ import annotations

import math

import numpy as np
from ompl import base as ob

from .grouped_space import GroupedSpace, RealVectorLayout
from .layered_trees import LayeredTrees, spread_waypoints
from .paths import motion_interior_states, unchecked_motion_states

__all__ = ["Checker", "Search", "segment_key"]

_COARSE_STRIDE = 8
"""First pass over a motion checks every 8th interior state (collisions span many states)."""
_UNIFORM_FRACTION = 0.1
"""Share of samples drawn uniformly over the bounds once the sampling region has narrowed."""
_NARROWING_UNIT = 100
"""The narrowing factor applies per this many samples."""
_GROUP_BLOCK = 100
"""With several planned groups, each gets this many consecutive samples in turn."""
_REPAIR_FRACTION = 0.5
"""Share of repair samples while no valid path exists."""
_REPAIR_SIGMA = (0.01, 0.1)
"""Repair samples: Gaussian around a waypoint, sigma log-uniform in this range times the bound widths."""


def segment_key(a: np.ndarray, b: np.ndarray) -> bytes:
    """Key of the motion a -> b (n,): the bytes of its two float64 ends, as ``W[k : k + 2].tobytes()``."""
    return np.ascontiguousarray(a, dtype=float).tobytes() + np.ascontiguousarray(b, dtype=float).tobytes()


class Checker:
    """Validity of states and motions for one SpaceInformation, batched when the setup allows it."""

    def __init__(self, si: ob.SpaceInformation, layout: RealVectorLayout, batch: bool) -> None:
        self.si = si
        self.layout = layout
        svc = si.getStateValidityChecker()
        mv = si.getMotionValidator()
        are_valid = getattr(svc, "are_valid", None)
        self.step: float | None = None
        self.euclid = True
        if batch and callable(are_valid):
            factor = max(1, int(si.getStateSpace().getValidSegmentCountFactor()))
            if isinstance(getattr(mv, "step", None), float) and callable(getattr(mv, "check_motions", None)):
                # BatchedMotionValidator: Euclidean, ceil(|b-a| / step) segments (step / factor)
                self.step = float(mv.effective_step()) if callable(getattr(mv, "effective_step", None)) else mv.step
            elif type(mv) is ob.MotionValidator:  # the C++ default, DiscreteMotionValidator
                self.step = float(si.getStateSpace().getLongestValidSegmentLength()) / factor
                self.euclid = layout.is_plain
        self.batched = self.step is not None
        self._are_valid = are_valid if self.batched else None
        all_valid = getattr(mv, "all_valid", None)
        # the project's validator screens a motion's evenly spaced states (straight lines only: no SO2 wrap)
        self._all_valid = all_valid if self.batched and callable(all_valid) and layout.is_plain else None
        if self.step is None:  # only for the coarse screening of motions (si.checkMotion decides)
            factor = max(1, int(si.getStateSpace().getValidSegmentCountFactor()))
            self._coarse_step = float(si.getStateSpace().getLongestValidSegmentLength()) / factor
            self.euclid = layout.is_plain
        else:
            self._coarse_step = self.step
        counter_owner = getattr(svc, "robot", svc)
        self._counter_owner = counter_owner if isinstance(getattr(counter_owner, "collision_checks", None), int) else None
        self.own_checks = 0
        self._longest = float(si.getStateSpace().getLongestValidSegmentLength())
        self._s1, self._s2 = si.allocState(), si.allocState()
        self.passed: set[bytes] = set()
        """Keys (:func:`segment_key`) of the motions that passed ``si.checkMotion`` here."""

    def counter(self) -> int:
        """Configurations checked so far (the robot's counter when available, else our own count)."""
        return self._counter_owner.collision_checks if self._counter_owner is not None else self.own_checks

    def states(self, Q: np.ndarray) -> np.ndarray:
        """Validity of configurations Q (m, n)."""
        if len(Q) == 0:
            return np.zeros(0, dtype=bool)
        self.own_checks += len(Q)
        if self._are_valid is not None:
            return np.asarray(self._are_valid(Q), dtype=bool)
        s = self._s1
        out = np.empty(len(Q), dtype=bool)
        for k, q in enumerate(Q):
            self.layout.write(s, q)
            out[k] = self.si.isValid(s)
        return out

    def interior(self, A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Interior states of motions A[k] -> B[k]: (states (M, n), motion index (M,), step index j >= 1).

        SO2 entries move the short way round and are wrapped into [-pi, pi), as ``SO2StateSpace``
        interpolates."""
        lay = self.layout
        if not lay.has_circular:
            return motion_interior_states(A, B, self._coarse_step, None if self.euclid else lay.distance(A, B))
        S, idx, j = motion_interior_states(A, A + lay.delta(A, B), self._coarse_step, lay.distance(A, B))
        return lay.wrap(S), idx, j

    def coarse(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Whether every 8th interior state of the motions A[k] -> B[k] is valid (one batched call, or
        per-state checks): most invalid motions already fail here (not all: a thin wall can fit
        between two of those states)."""
        K = len(A)
        if K == 0:
            return np.ones(0, dtype=bool)
        S, idx, j = self.interior(A, B)
        c = j % _COARSE_STRIDE == 0
        return np.bincount(idx[c][~self.states(S[c])], minlength=K) == 0

    def motions(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Validity of the motions A[k] -> B[k] (valid ends assumed): :meth:`coarse`, then
        :meth:`check_motions` for the motions still in question."""
        out = np.zeros(len(A), dtype=bool)
        go = np.flatnonzero(self.coarse(A, B))
        out[go] = self.check_motions(A[go], B[go])
        return out

    def check_motions(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """:meth:`check_motion` of each motion A[k] -> B[k]; with the project's validator, in one
        screened call over the very states ``si.checkMotion`` would check (end state included)."""
        if self._all_valid is None or len(A) < 2:
            return np.array([self.check_motion(a, b) for a, b in zip(A, B)], dtype=bool)
        chunks = [unchecked_motion_states(a, b, self.step) for a, b in zip(A, B)]
        self.own_checks += sum(len(c) for c in chunks)  # at most
        ok = np.asarray(self._all_valid(chunks), dtype=bool)
        self.passed.update(segment_key(A[k], B[k]) for k in np.flatnonzero(ok))
        return ok

    def check_motion(self, a: np.ndarray, b: np.ndarray) -> bool:
        """``si.checkMotion`` of a -> b (n,); a motion that passes is remembered in :attr:`passed`."""
        self.layout.write(self._s1, a)
        self.layout.write(self._s2, b)
        self.own_checks += max(1, math.ceil(float(self.layout.distance(a, b)) / self._longest))
        ok = bool(self.si.checkMotion(self._s1, self._s2))
        if ok:
            self.passed.add(segment_key(a, b))
        return ok

    def candidates(
        self, C: np.ndarray, A: np.ndarray, B: np.ndarray, left_known: np.ndarray, right_known: np.ndarray, strict: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Evaluate candidate waypoints C (m, n) between neighbours A and B (m, n).

        ``left_known[k]`` / ``right_known[k]`` false means that neighbour is invalid, so that motion is
        invalid without a check.  For ``strict[k]`` candidates only all-valid matters, so the second
        motion is not finished once one fails.  Returns validity of C, of A->C and of C->B (ends incl.).
        """
        m = len(C)
        vc = self.states(C) if not self.batched else None
        if self.batched:
            # pass 1: candidate states + every 8th interior state of motions whose other end is valid
            SL, iL, jL = self.interior(A, C)
            SR, iR, jR = self.interior(C, B)
            cL, cR = (jL % _COARSE_STRIDE == 0) & left_known[iL], (jR % _COARSE_STRIDE == 0) & right_known[iR]
            ok = self.states(np.concatenate([C, SL[cL], SR[cR]]))
            vc = ok[:m]
            nl = int(cL.sum())
            badL = np.bincount(iL[cL][~ok[m : m + nl]], minlength=m) > 0
            badR = np.bincount(iR[cR][~ok[m + nl :]], minlength=m) > 0
            goL = vc & left_known & ~badL
            goR = vc & right_known & ~badR
            both = goL & goR
            goL &= both | ~strict
            goR &= both | ~strict
            # pass 2: the remaining interior states of motions still in question
            if self._all_valid is not None:  # screened by the motion validator: the same verdicts
                bL, bR = np.searchsorted(iL, np.arange(m + 1)), np.searchsorted(iR, np.arange(m + 1))
                kL, kR = np.flatnonzero(goL), np.flatnonzero(goR)
                self.own_checks += int((bL[kL + 1] - bL[kL]).sum() + (bR[kR + 1] - bR[kR]).sum())  # at most
                ok2 = self._all_valid([SL[bL[k] : bL[k + 1]] for k in kL] + [SR[bR[k] : bR[k + 1]] for k in kR])
                left, right = goL.copy(), goR.copy()
                left[kL], right[kR] = ok2[: len(kL)], ok2[len(kL) :]
                return vc, left, right
            fL, fR = ~cL & goL[iL], ~cR & goR[iR]
            ok2 = self.states(np.concatenate([SL[fL], SR[fR]]))
            nl2 = int(fL.sum())
            left = goL & (np.bincount(iL[fL][~ok2[:nl2]], minlength=m) == 0)
            right = goR & (np.bincount(iR[fR][~ok2[nl2:]], minlength=m) == 0)
            return vc, left, right
        left = np.zeros(m, dtype=bool)
        right = np.zeros(m, dtype=bool)
        for k in range(m):
            if not vc[k]:
                continue
            if left_known[k]:
                left[k] = self.check_motion(A[k], C[k])
            if right_known[k] and (left[k] or not strict[k]):
                right[k] = self.check_motion(C[k], B[k])
        return vc, left, right


class Search:
    """The dimension-RRT iteration on a waypoint array; OMPL-free apart from the checker."""

    def __init__(
        self,
        grouped: GroupedSpace,
        checker: Checker,
        rng: np.random.Generator,
        start: np.ndarray,
        goal: np.ndarray,
        narrow_after: int,
        narrowing: float,
        range_: np.ndarray,
        initial: np.ndarray | None = None,
    ) -> None:
        self.g = grouped
        self.checker = checker
        self.rng = rng
        self.narrow_after = narrow_after
        self.narrowing = narrowing
        self.range_ = range_
        self.dist = grouped.layout.distance
        W = grouped.initial_waypoints(start, goal)
        if initial is not None:
            for gi in grouped.planned:
                d = grouped.group_dims(gi)
                W[1:-1, d] = initial[1:-1, d]
        self.W = W
        V = np.ones(len(W), dtype=bool)
        V[1:-1] = checker.states(W[1:-1])
        self.V = V
        self.E = V[:-1] & V[1:]
        self.E[self.E] = checker.motions(W[:-1][self.E], W[1:][self.E])
        self.L = self.dist(W[:-1], W[1:])
        self.samples = 0
        self.group_samples = {gi: 0 for gi in grouped.planned}
        self.narrow_start: dict[int, int | None] = {gi: None for gi in grouped.planned}
        self._dims = {gi: grouped.group_dims(gi) for gi in grouped.planned}
        self._bounds = {gi: grouped.group_bounds(gi) for gi in grouped.planned}
        self._tree: LayeredTrees | None = None
        self._known: dict[bytes, bool] = {W[k : k + 2].tobytes(): bool(self.E[k]) for k in range(len(W) - 1)
                                          if self.V[k] and self.V[k + 1]}
        """Segment (two waypoint rows as bytes) -> motion valid, for every motion checked so far."""
        # feasibility phase: all planned groups vary jointly (with one planned group: that group)
        self._fdims = np.concatenate([self._dims[gi] for gi in grouped.planned]) if grouped.planned else np.zeros(0, int)
        self._fbounds = (grouped.layout.lower[self._fdims], grouped.layout.upper[self._fdims])
        self._hold = not grouped.prescribed
        self.delta = grouped.layout.delta
        self._uniform = np.empty((0, 0))
        self._normal = np.empty((0, 0))
        self._ui = 0

    @property
    def valid(self) -> bool:
        return bool(self.V.all() and self.E.all())

    @property
    def cost(self) -> float:
        return float(self.L.sum())

    def _next_random(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Buffered randomness for one sample: 3 + k uniforms and k standard normals."""
        if self._ui >= len(self._uniform) or self._uniform.shape[1] != k + 3:
            self._uniform = self.rng.random((1024, k + 3))
            self._normal = self.rng.standard_normal((1024, k))
            self._ui = 0
        i = self._ui
        self._ui += 1
        return self._uniform[i], self._normal[i]

    def current_group(self) -> int:
        planned = self.g.planned
        return planned[(self.samples // _GROUP_BLOCK) % len(planned)]

    def draw(self, gi: int | None) -> np.ndarray:
        """One sample: for group gi (narrowed or uniform), or with gi None for the feasibility phase's
        joint planned DOFs (repair around a tree node, or uniform); see the module docstring."""
        d = self._fdims if gi is None else self._dims[gi]
        lo, hi = self._fbounds if gi is None else self._bounds[gi]
        u, z = self._next_random(len(d))
        span = hi - lo
        if gi is None:
            if u[0] < _REPAIR_FRACTION and self._tree is not None:
                anchor = self._tree.anchor(u[1])
                sigma = span * _REPAIR_SIGMA[0] * (_REPAIR_SIGMA[1] / _REPAIR_SIGMA[0]) ** u[2]
                return np.clip(anchor + sigma * z, lo, hi)
            return lo + u[3:] * span
        n0 = self.narrow_start[gi]
        if n0 is None and self.group_samples[gi] >= self.narrow_after:
            n0 = self.narrow_start[gi] = self.group_samples[gi]
        if n0 is not None and u[0] >= _UNIFORM_FRACTION:
            m = self.group_samples[gi] - n0
            pad = np.maximum(self.range_[gi], span * self.narrowing ** (m / _NARROWING_UNIT))
            vals = self.W[:, d]
            lo = np.maximum(lo, vals.min(axis=0) - pad)
            hi = np.minimum(hi, vals.max(axis=0) + pad)
        return lo + u[3:] * (hi - lo)

    def iterate(self, limit: int = 1) -> int:
        """Draw one sample and try it at every intermediate step (up to ``limit`` samples on a valid path).

        On a valid path the sample is the current group's (paper's rule); before, it covers all
        planned groups at once and grows the layered trees.  Returns the number of waypoints
        changed (feasibility phase: 1 when the layered trees connected, 0 otherwise).

        With ``limit > 1`` on a valid path, the samples that the cost test rejects at every step are
        first passed over in one vectorised step (at most ``limit - 1`` of them): they change nothing
        but the counters, so the result is that of as many single calls, with the same random numbers.
        """
        if limit > 1 and self.valid:
            self._pass_rejected(limit - 1)
        gi = self.current_group()
        valid = self.valid
        if not valid and self._tree is None:
            self._tree = LayeredTrees(self.W, self.V, self.E, self._fdims, self._hold, self.delta)
        c = self.draw(gi if valid else None)
        self.samples += 1
        self.group_samples[gi] += 1
        return self._improve(gi, c) if valid else self._grow(c)

    def _pass_rejected(self, limit: int) -> None:
        """Advance past the next samples (at most ``limit``, within the current group's block and the
        random buffer) that :meth:`_improve` would reject on cost alone, stopping before the first one it
        would not: :meth:`draw` and the cost test of :meth:`_improve` for many samples at once."""
        gi = self.current_group()
        d = self._dims[gi]
        k = len(d)
        if self._ui >= len(self._uniform) or self._uniform.shape[1] != k + 3:
            self._uniform = self.rng.random((1024, k + 3))
            self._normal = self.rng.standard_normal((1024, k))
            self._ui = 0
        n = min(limit, _GROUP_BLOCK - self.samples % _GROUP_BLOCK, len(self._uniform) - self._ui)
        if n <= 0:
            return
        U = self._uniform[self._ui : self._ui + n]
        lo, hi = self._bounds[gi]
        span = hi - lo
        C = lo + U[:, 3:] * (hi - lo)
        g0 = self.group_samples[gi]
        n0 = self.narrow_start[gi]
        if n0 is None and g0 + n - 1 >= self.narrow_after:
            n0 = max(g0, self.narrow_after)
        if n0 is not None:
            g = g0 + np.arange(n)
            narrow = np.flatnonzero((g >= n0) & (U[:, 0] >= _UNIFORM_FRACTION))
            if len(narrow):
                scale = np.array([self.narrowing ** ((int(m) - n0) / _NARROWING_UNIT) for m in g[narrow]])
                pad = np.maximum(self.range_[gi], span * scale[:, None])
                vals = self.W[:, d]
                nlo = np.maximum(lo, vals.min(axis=0) - pad)
                nhi = np.minimum(hi, vals.max(axis=0) + pad)
                C[narrow] = nlo + U[narrow, 3:] * (nhi - nlo)
        W, L = self.W, self.L
        X = np.broadcast_to(W[1:-1], (n,) + W[1:-1].shape).copy()
        X[:, :, d] = C[:, None, :]
        shorter = (self.dist(W[:-2], X) + self.dist(X, W[2:]) < L[:-1] + L[1:] - 1e-12).any(axis=1)
        j = int(np.argmax(shorter)) if shorter.any() else n
        if j == 0:
            return
        self._ui += j
        self.samples += j
        self.group_samples[gi] = g0 + j
        if self.narrow_start[gi] is None and n0 is not None and g0 + j - 1 >= n0:
            self.narrow_start[gi] = n0

    def _grow(self, c: np.ndarray) -> int:
        """Feasibility phase: grow the layered trees with the sample c, motions checked lazily.

        c is checked as a waypoint at every step t that has a forward node before it or a backward
        node after it (once when holding: the configuration is then the same at every step).  Of the
        steps with both, the one with the shortest motions completes a candidate path, whose not yet
        checked motions are checked now: all pass and it is the path; a failed motion kills the node
        it leads into (and its subtree), and c joins the trees through those of its motions that
        passed in full.  At the other steps c joins the trees on unchecked motions that pass
        :meth:`Checker.coarse`; when holding, once per tree instead, at the lowest forward / highest
        backward step whose motion passes in full (coarse screening alone let trees grow through
        thin walls there).  Returns 1 when the path is complete, else 0.
        """
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
        both = np.flatnonzero(vc & (fi >= 0) & (bi >= 0))
        tried = -1
        joined: set[int] = set()  # holding: the trees c joined already
        if len(both):
            A = base[ts_a[both] - 1].copy()
            B = base[ts_a[both] + 1].copy()
            A[:, d] = tree.fwd.values[fi[both]]
            B[:, d] = tree.bwd.values[bi[both]]
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
            passed = [known.get(W[k : k + 2].tobytes(), not np.any(W[k] != W[k + 1])) for k in (t - 1, t)]
            if passed[0] and tree.fwd.alive[f]:
                tree.fwd.add(c, t, f)
                joined.add(id(tree.fwd))
            if passed[1] and tree.bwd.alive[b]:
                tree.bwd.add(c, t, b)
                joined.add(id(tree.bwd))
        # the other steps: c joins on unchecked motions that pass the coarse test; holding, once per
        # tree, at the lowest step (forward) or highest (backward) whose motion passes in full
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
        if not adds:
            return 0
        E = np.empty((2 * len(adds), self.g.n))
        for m, (tr, p, t) in enumerate(adds):
            ct = base[t].copy()
            ct[d] = c
            pt = base[int(tr.steps[p])].copy()
            pt[d] = tr.values[p]
            E[2 * m], E[2 * m + 1] = (pt, ct) if tr is tree.fwd else (ct, pt)
        checker = self.checker
        # one call when batched; per state, in order, skipping what holding makes useless
        ok = checker.coarse(E[0::2], E[1::2]) if checker.batched and not self._hold else None
        for m, (tr, p, t) in enumerate(adds):
            if self._hold and id(tr) in joined:
                continue
            if self._hold:  # checked in full: coarse screening alone let motions through thin walls
                good = self._check_segments(E[2 * m : 2 * m + 2]) == []
            else:
                good = ok[m] if ok is not None else checker.coarse(E[2 * m : 2 * m + 1], E[2 * m + 1 : 2 * m + 2])[0]
            if good:
                tr.add(c, t, p)
                joined.add(id(tr))
        return 0

    def _check_segments(self, W: np.ndarray) -> list[int]:
        """Segments of W (K, n) found invalid (lazy checking: called once W is a complete candidate).

        The waypoints are known valid; zero-length segments and segments checked before cost
        nothing; the others go through :meth:`Checker.coarse` together (any failure there ends the
        check), then ``si.checkMotion`` one by one.  Every result is remembered."""
        known, checker = self._known, self.checker
        keys = [W[k : k + 2].tobytes() for k in range(len(W) - 1)]
        bad = [k for k, key in enumerate(keys) if not known.get(key, True)]
        todo = [k for k, key in enumerate(keys) if key not in known and np.any(W[k] != W[k + 1])]
        if bad or not todo:
            return bad
        ends = np.array(todo)
        good = checker.coarse(W[ends], W[ends + 1])  # finds most failing motions at once
        bad = [k for k, g in zip(todo, good) if not g]
        for k in bad:
            known[keys[k]] = False
        if bad:
            return bad
        # all of them: a motion the coarse test missed may not be the only one
        for k, ok in zip(todo, checker.check_motions(W[ends], W[ends + 1])):
            if not ok:
                bad.append(k)
            known[keys[k]] = bool(ok)
        return bad

    def _adopt(self, W: np.ndarray) -> None:
        """Take W (h, n), checked by the trees, as the current (valid) path.

        Held (repeated) waypoints are first spread along the path's segments when the spread path
        passes the checker too, so every fake-time step can take part in the improvement."""
        if self._hold:
            S = spread_waypoints(W, self.g.layout.interpolate, self.dist)
            if S is not W and self.checker.states(S[1:-1]).all() and self.checker.motions(S[:-1], S[1:]).all():
                W = S
        self.W[:] = W
        self.V[:] = True
        self.E[:] = True
        self.L[:] = self.dist(W[:-1], W[1:])

    def _improve(self, gi: int, c: np.ndarray) -> int:
        """Paper's rule on a valid path: replace W[t] when valid, connected and shorter."""
        d = self._dims[gi]
        # only called on a valid path (V, E all true); an accepted candidate is valid and both its
        # motions are, so V and E stay all true and only W and L change
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
        vc, left, right = self.checker.candidates(C[ts], A[ts], B[ts], yes, yes, yes)
        ok = vc & left & right
        accepted = 0
        last = -2
        for k in np.flatnonzero(ok):
            t = int(ts[k]) + 1
            if t == last + 1:
                continue
            W[t] = C[t - 1]
            L[t - 1], L[t] = dl[t - 1], dr[t - 1]
            accepted += 1
            last = t
        return accepted
