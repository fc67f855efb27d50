"""The feasibility phase of dimension-RRT without prescribed groups: RRTConnect's two trees.

Without a prescribed group a waypoint's configuration does not depend on its fake-time step, so a
first path need not be searched step by step.  :class:`ConnectTrees` grows a tree from the start and
one from the goal as OMPL's RRTConnect does: per sample, the tree whose turn it is extends towards
it by at most ``range`` (the motion checked in full), then the other tree connects to the new node
in steps of at most ``range`` until it reaches it or a step is blocked; the trees then swap.  Motions
are checked in the direction a path runs (goal tree: node towards its parent), as RRTConnect checks
them.  Seeded with the valid prefix and suffix of the base path (the search passes a first guess only).

The result is the path's turning points: the steps of one connect lie on one straight line and
count as one segment (that longer motion is checked again, as one motion, when the path is fitted
to the fake-time steps in :mod:`tpee_ompl.planning.dimension_search`); :attr:`ConnectTrees.verified`
says which of its segments are single tree edges, checked already, and :attr:`ConnectTrees.edges` is
the same path through every tree node on the way (a valid path as it stands, posted before the fit).

A sample costs Python time that RRTConnect spends in C++, so the per-sample path is kept lean: with
a per-state checker (``check_step``) a step is one ``si.checkMotion`` on plain lists, and
:meth:`ConnectTrees.run` takes a block of samples per call.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .layered_trees import Tree, valid_ends
from .space_layout import RealVectorLayout

__all__ = ["ConnectTrees", "RANGE_FRACTION"]

RANGE_FRACTION = 0.2
"""A tree step is at most this fraction of the space's maximum extent (RRTConnect's default range)."""


class ConnectTrees:
    """Start and goal trees grown as RRTConnect grows them; :meth:`step` takes one sample, :meth:`run` a block."""

    def __init__(self, W: np.ndarray, V: np.ndarray, E: np.ndarray, layout: RealVectorLayout, range_: float,
                 check_motions: Callable[[np.ndarray, np.ndarray, bool], int],
                 check_step: Callable[[list[float], list[float], bool], bool] | None = None) -> None:
        """W (h, n): base path, V / E validity of its waypoints / motions (its valid prefix and suffix
        seed the trees); ``check_motions(A, B, starts)``: how many of the motions A[k] -> B[k] pass
        in order before the first that does not (B[k] included, A[k] too when ``starts``);
        ``check_step(a, b, start)``, optional: the same for one motion given as plain lists (a
        per-state checker's lean path; ``check_motions`` is then not called)."""
        self.layout = layout
        self.range = float(range_)
        self._check = check_motions
        self._check_step = check_step
        n = W.shape[1]
        self.trees = (Tree(n), Tree(n))
        self.lines: tuple[list[int], list[int]] = ([], [])
        """Per tree and node: the node its straight line into this node starts from (parent for a
        single step, the connect's first node for the steps of one connect; -1 for the root)."""
        self.verified: list[bool] = []
        """Once the trees met: per segment of the returned path, whether it is one tree edge (checked)."""
        self.edges: np.ndarray | None = None
        """Once the trees met: the path through every tree node on the way (each segment a tree edge, checked)."""
        f, b = valid_ends(V, E)
        for t in range(f + 1):
            self._add(0, W[t], t - 1, t - 1)
        for i, t in enumerate(range(len(W) - 1, b - 1, -1)):
            self._add(1, W[t], i - 1, i - 1)
        self._turn = 0

    def _add(self, k: int, x: np.ndarray, parent: int, line: int) -> int:
        self.lines[k].append(line)
        return self.trees[k].add(x, 0, parent)

    def _motions(self, k: int, A: np.ndarray, B: np.ndarray) -> int:
        """How many of the tree-k motions A[j] -> B[j] (parent side first, B new) pass, in order: checked
        in path direction, goal tree B[j] -> A[j] with the state B[j] itself (a motion check covers
        its end only)."""
        one = self._check_step
        if one is None:
            return self._check(A, B, False) if k == 0 else self._check(B, A, True)
        n = 0
        for a, b in zip(A.tolist(), B.tolist()):
            if not (one(a, b, False) if k == 0 else one(b, a, True)):
                break
            n += 1
        return n

    def run(self, Q: np.ndarray, stop: Callable[[], bool] | None = None) -> tuple[np.ndarray | None, int]:
        """:meth:`step` for the samples Q (m, n) in order, until the trees meet or ``stop()`` is true
        (asked before each sample after the first).  Returns the path (or None) and the samples used."""
        rows = Q.tolist()
        for j in range(len(Q)):
            if j and stop is not None and stop():
                return None, j
            P = self.step(Q[j], rows[j])
            if P is not None:
                return P, j + 1
        return None, len(Q)

    def step(self, q: np.ndarray, q_list: list[float] | None = None) -> np.ndarray | None:
        """One RRTConnect iteration towards the sample q (n,) (``q_list``: the same as a list, when at
        hand); the path's turning points (K, n) from start to goal once the trees meet, else None."""
        a = self._turn
        self._turn = 1 - a
        new = self._extend_once(a, q, q_list)
        if new < 0:
            return None
        end, reached = self._extend(1 - a, self.trees[a].values[new])
        if not reached:
            return None
        (pa, va), (pb, vb) = self._chain(a, new), self._chain(1 - a, end)
        P = np.vstack([pa[::-1], pb[1:]])  # from tree a's root to tree b's root
        verified = va[::-1] + vb
        if a == 1:
            P, verified = P[::-1], verified[::-1]
        self.verified = verified
        E = np.vstack([self._nodes(a, new)[::-1], self._nodes(1 - a, end)[1:]])
        self.edges = E[::-1] if a == 1 else E
        return P

    def _nearest(self, k: int, target: np.ndarray) -> tuple[int, float, np.ndarray]:
        """Tree k's node nearest to target in the space's metric: (index, distance, target - node)."""
        lay, tree = self.layout, self.trees[k]
        values = tree.values[: len(tree.parents)]
        if lay.is_plain:
            D = target - values
            d2 = np.einsum("ij,ij->i", D, D)
            i = int(d2.argmin())
            return i, math.sqrt(d2[i]), D[i]
        # the space's own metric (weighted subspace distances), as OMPL's nearest neighbours use
        dist = lay.distance(values, target)
        i = int(dist.argmin())
        return i, float(dist[i]), lay.delta(values[i], target)

    def _extend_once(self, k: int, target: np.ndarray, target_list: list[float] | None = None) -> int:
        """Grow tree k one step of at most ``range`` towards target; the node added, else -1."""
        i, d, D = self._nearest(k, target)
        if d == 0.0:
            return -1
        a = self.trees[k].values[i]
        one = self._check_step
        if one is None:
            b = target if d <= self.range else self.layout.wrap(a + (self.range / d) * D)
            ok = self._motions(k, a[None], b[None]) == 1
        else:  # plain lists: a numpy call per value costs more than the arithmetic
            al = a.tolist()
            if d <= self.range:
                b, bl = target, (target_list if target_list is not None else target.tolist())
            elif self.layout.has_circular:
                b = self.layout.wrap(a + (self.range / d) * D)
                bl = b.tolist()
            else:
                f = self.range / d
                bl = [x + f * dx for x, dx in zip(al, D.tolist())]  # a + f * D, as numpy rounds it
                b = bl
            ok = one(al, bl, False) if k == 0 else one(bl, al, True)
        return self._add(k, b, i, i) if ok else -1

    def _extend(self, k: int, target: np.ndarray) -> tuple[int, bool]:
        """Grow tree k towards target in steps of at most ``range`` until it is reached or one is
        blocked (RRTConnect's connect).  Returns the last node added (the nearest node when it is at
        the target already, -1 when none) and whether the target was reached."""
        i, d, D = self._nearest(k, target)
        if d == 0.0:
            return i, True
        lay, one = self.layout, self._check_step
        a = self.trees[k].values[i]
        m = max(1, math.ceil(d / self.range))
        last, prev = -1, i
        if one is not None and not lay.has_circular:  # plain lists, as in _extend_once
            al, Dl = a.tolist(), D.tolist()
            q = al
            for j in range(1, m + 1):
                p = [x + (j / m) * dx for x, dx in zip(al, Dl)] if j < m else target.tolist()  # a + j/m D
                if not (one(q, p, False) if k == 0 else one(p, q, True)):
                    return last, False
                last = prev = self._add(k, p, prev, i)
                q = p
            return last, True
        pts = lay.wrap(a + (np.arange(1, m + 1) / m)[:, None] * D)
        pts[-1] = target
        starts = np.empty_like(pts)
        starts[0] = a
        starts[1:] = pts[:-1]
        n = self._motions(k, starts, pts)
        for j in range(n):
            last = prev = self._add(k, pts[j], prev, i)
        return last, n == m

    def _nodes(self, k: int, node: int) -> np.ndarray:
        """Every node's values from node back to tree k's root."""
        parents, out = self.trees[k].parents, [node]
        while parents[out[-1]] >= 0:
            out.append(parents[out[-1]])
        return self.trees[k].values[out]

    def _chain(self, k: int, node: int) -> tuple[np.ndarray, list[bool]]:
        """Turning points from node back to tree k's root (straight runs of one connect merged), and per
        segment whether it is one tree edge."""
        tree, lines = self.trees[k], self.lines[k]
        out, single = [tree.values[node]], []
        while lines[node] >= 0:
            single.append(lines[node] == tree.parents[node])
            node = lines[node]
            out.append(tree.values[node])
        return np.array(out), single
