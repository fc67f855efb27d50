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
to the fake-time steps in :mod:`tpee_ompl.planning.dimension_search`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .grouped_space import RealVectorLayout
from .layered_trees import Tree, valid_ends

__all__ = ["ConnectTrees", "RANGE_FRACTION"]

RANGE_FRACTION = 0.2
"""A tree step is at most this fraction of the space's maximum extent (RRTConnect's default range)."""


class ConnectTrees:
    """Start and goal trees grown as RRTConnect grows them; :meth:`step` takes one sample."""

    def __init__(self, W: np.ndarray, V: np.ndarray, E: np.ndarray, layout: RealVectorLayout, range_: float,
                 check_motions: Callable[[np.ndarray, np.ndarray, bool], int]) -> None:
        """W (h, n): base path, V / E validity of its waypoints / motions (its valid prefix and suffix
        seed the trees); ``check_motions(A, B, starts)``: how many of the motions A[k] -> B[k] pass
        in order before the first that does not (B[k] included, A[k] too when ``starts``)."""
        self.layout = layout
        self.range = float(range_)
        self._check = check_motions
        n = W.shape[1]
        self.trees = (Tree(n), Tree(n))
        self.lines: tuple[list[int], list[int]] = ([], [])
        """Per tree and node: the node its straight line into this node starts from (parent for a
        single step, the connect's first node for the steps of one connect; -1 for the root)."""
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
        return self._check(A, B, False) if k == 0 else self._check(B, A, True)

    def step(self, q: np.ndarray) -> np.ndarray | None:
        """One RRTConnect iteration towards the sample q (n,); the path's turning points (K, n) from
        start to goal once the trees meet, else None."""
        a = self._turn
        self._turn = 1 - a
        new = self._extend(a, q, single=True)
        if new < 0:
            return None
        x = self.trees[a].values[new]
        end = self._extend(1 - a, x, single=False)
        if end < 0 or np.any(self.layout.delta(self.trees[1 - a].values[end], x) != 0.0):
            return None
        pa, pb = self._chain(a, new), self._chain(1 - a, end)
        P = np.vstack([pa[::-1], pb[1:]])  # from tree a's root to tree b's root
        return P if a == 0 else P[::-1]

    def _extend(self, k: int, target: np.ndarray, single: bool) -> int:
        """Grow tree k towards target: one step of at most ``range`` (``single``), or steps until it is
        reached or one is blocked.  Returns the last node added (-1: none)."""
        tree, lay = self.trees[k], self.layout
        values = tree.values[: len(tree)]
        D = target - values if not lay.has_circular else lay.delta(values, target)  # node -> target
        if lay.is_plain:
            d2 = np.einsum("ij,ij->i", D, D)
            i = int(d2.argmin())
            d = math.sqrt(float(d2[i]))
        else:  # the space's own metric (weighted subspace distances), as OMPL's nearest neighbours use
            dist = lay.distance(values, target)
            i = int(dist.argmin())
            d = float(dist[i])
        a = values[i]  # a view: nothing is added to the tree before its last use
        if d == 0.0:
            return -1 if single else i
        if single:
            frac = np.array([min(1.0, self.range / d)])
        else:
            m = max(1, math.ceil(d / self.range))
            frac = np.arange(1, m + 1) / m
        pts = lay.wrap(a + frac[:, None] * D[i])
        if frac[-1] == 1.0:
            pts[-1] = target
        starts = np.empty_like(pts)
        starts[0] = a
        starts[1:] = pts[:-1]
        last, prev = -1, i
        for j in range(self._motions(k, starts, pts)):
            last = prev = self._add(k, pts[j], prev, i)
        return last

    def _chain(self, k: int, node: int) -> np.ndarray:
        """Turning points from node back to tree k's root (straight runs of one connect merged)."""
        tree, lines = self.trees[k], self.lines[k]
        out = [tree.values[node]]
        while lines[node] >= 0:
            node = lines[node]
            out.append(tree.values[node])
        return np.array(out)
