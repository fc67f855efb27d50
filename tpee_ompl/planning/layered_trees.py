"""The feasibility phase of dimension-RRT: layered forward/backward trees over fake-time steps.

Before the first valid path the search grows a forward tree from the start and a backward tree from
the goal.  A node is the planned DOFs' values at one fake-time step (the other DOFs are those of
the base path at that step); every node is valid.  Motions are checked *lazily* (as in LazyRRT):
a node may hang on an unchecked motion, and the motions of a candidate path are checked only when
the path is complete (:meth:`LayeredTrees.path` names the node each segment leads into, so a failed
segment kills that node and its subtree).  See :mod:`tpee_ompl.planning.dimension_rrt` for how
samples are placed.

*Holding* (only without prescribed groups, where a node's configuration does not depend on its
step): a node of step s also serves every later step (forward tree) or earlier step (backward tree)
by staying where it is, a zero-length and therefore valid motion.  A path then has fewer distinct
waypoints than steps; :func:`spread_waypoints` puts the repeated ones back on its segments.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

__all__ = ["Tree", "LayeredTrees", "spread_waypoints", "valid_ends"]


def valid_ends(V: np.ndarray, E: np.ndarray) -> tuple[int, int]:
    """The path's valid prefix and suffix (V: waypoint validity, E: motion validity, h waypoints): the
    last step f reachable from the start and the first step b that reaches the goal through valid
    waypoints and motions, among the intermediate steps (f = 0 / b = h - 1 when there are none)."""
    h = len(V)
    f = 0
    while f + 1 < h - 1 and V[f + 1] and E[f]:
        f += 1
    b = h - 1
    while b - 1 > 0 and V[b - 1] and E[b - 1]:
        b -= 1
    return f, b


class Tree:
    """Nodes of one layered tree: values (N, k), fake-time step, parent index and liveness of each.

    A node is *dead* once the motion into it (or into one of its ancestors) failed a check; dead
    nodes are never nearest neighbours or parents again.
    """

    def __init__(self, k: int) -> None:
        self.values = np.empty((16, k))
        self.steps = np.empty(16, dtype=int)
        self.alive = np.zeros(16, dtype=bool)
        self.parents: list[int] = []

    def __len__(self) -> int:
        return len(self.parents)

    def add(self, x: np.ndarray, step: int, parent: int) -> int:
        n = len(self.parents)
        if n == len(self.values):
            self.values = np.concatenate([self.values, np.empty_like(self.values)])
            self.steps = np.concatenate([self.steps, np.empty_like(self.steps)])
            self.alive = np.concatenate([self.alive, np.zeros_like(self.alive)])
        self.values[n] = x
        self.steps[n] = step
        self.alive[n] = True
        self.parents.append(parent)
        return n

    def kill(self, i: int) -> None:
        """Mark node i and all its descendants dead (a child's index is always above its parent's)."""
        alive, parents = self.alive, self.parents
        alive[i] = False
        for j in range(i + 1, len(parents)):
            if alive[j] and not alive[parents[j]]:
                alive[j] = False

    def layers(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The live nodes ordered by step, then index, with each step's start in that order and its count."""
        live = self.alive[: len(self.parents)].nonzero()[0]
        st = self.steps[live]
        order = np.argsort(st, kind="stable")
        live, st = live[order], st[order]
        start = np.concatenate(([True], st[1:] != st[:-1])).nonzero()[0] if len(st) else np.zeros(0, dtype=int)
        return live, start, np.diff(np.append(start, len(st)))


def _running_best(best: list[tuple[float, int]]) -> list[tuple[float, int]]:
    """Prefix minimum of (distance, index) pairs: the nearest over steps 0..s, lowest index among equals."""
    out, cur = [], (math.inf, -1)
    for d, i in best:
        if i >= 0 and (d < cur[0] or (d == cur[0] and (cur[1] < 0 or i < cur[1]))):
            cur = (d, i)
        out.append(cur)
    return out


class LayeredTrees:
    """Forward tree from the start and backward tree from the goal, seeded with the valid prefix and
    suffix of the base path W (V: waypoint validity, E: motion validity)."""

    def __init__(self, W: np.ndarray, V: np.ndarray, E: np.ndarray, dims: np.ndarray, hold: bool,
                 delta: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> None:
        self.dims = d = dims
        self.hold = hold
        self.delta = delta
        self.base = W.copy()
        self.h = h = len(W)
        self.fwd, self.bwd = Tree(len(d)), Tree(len(d))
        f, b = valid_ends(V, E)
        for t in range(f + 1):
            self.fwd.add(W[t, d], t, t - 1)
        for i, t in enumerate(range(h - 1, b - 1, -1)):
            self.bwd.add(W[t, d], t, i - 1)

    def nearest(self, c: np.ndarray) -> tuple[list[int], list[int]]:
        """For each intermediate step t = 1 .. h-2: the nearest forward node that can precede c at t
        (step t-1, or any step <= t-1 when holding) and the nearest backward node that can follow
        it (step t+1, or >= t+1); -1 where there is none.  The lowest index wins among equals."""
        h, fwd, bwd = self.h, self.fwd, self.bwd
        nf, nb = len(fwd), len(bwd)
        # both trees in one pass (a handful of numpy calls per sample): backward steps shifted by h
        D = self.delta(np.concatenate((fwd.values[:nf], bwd.values[:nb])), c)
        d2 = np.einsum("ij,ij->i", D, D)
        key = np.concatenate((fwd.steps[:nf], bwd.steps[:nb] + h))
        live = np.concatenate((fwd.alive[:nf], bwd.alive[:nb])).nonzero()[0]
        order = live[np.lexsort((d2[live], key[live]))]  # by step, then distance, then index (stable)
        ko = key[order]
        first = order[np.concatenate(([True], ko[1:] != ko[:-1])).nonzero()[0]].tolist() if len(order) else []
        best = [(math.inf, -1)] * (2 * h)
        for i, s, d in zip(first, key[first].tolist(), d2[first].tolist()):
            best[s] = (d, i if i < nf else i - nf)
        bf, bb = best[:h], best[h:]
        if self.hold:  # the nearest over all steps before (forward) / after (backward)
            bf, bb = _running_best(bf), _running_best(bb[::-1])[::-1]
        return [bf[t - 1][1] for t in range(1, h - 1)], [bb[t + 1][1] for t in range(1, h - 1)]

    def path(self, t: int, c: np.ndarray, f: int, b: int) -> tuple[np.ndarray, dict[int, tuple[str, int]]]:
        """The waypoints (h, n) through forward node f, c at step t, backward node b (held nodes repeated).

        Also returns, for each segment k (W[k] -> W[k+1]) that is a tree motion, the node it leads
        into: ``("f", i)`` forward node i, ``("b", i)`` backward node i (the motion to its parent),
        ``("c", -1)`` the motions into and out of c (segments t-1 and t).  The other segments join
        two equal held waypoints (zero length).
        """
        W = self.base.copy()
        d = self.dims
        W[t, d] = c
        owners: dict[int, tuple[str, int]] = {t - 1: ("c", -1), t: ("c", -1)}
        end = t  # fill steps [node step, end) with the node's values, walking back to the start
        while f >= 0:
            s = int(self.fwd.steps[f])
            W[s:end, d] = self.fwd.values[f]
            if s > 0:
                owners[s - 1] = ("f", f)
            end, f = s, self.fwd.parents[f]
        begin = t + 1  # fill steps [begin, node step] walking on to the goal
        while b >= 0:
            s = int(self.bwd.steps[b])
            W[begin : s + 1, d] = self.bwd.values[b]
            if s < self.h - 1:
                owners[s] = ("b", b)
            begin, b = s + 1, self.bwd.parents[b]
        return W, owners


def spread_waypoints(W: np.ndarray, interpolate: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
                     distance: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> np.ndarray:
    """W (h, n) with repeated consecutive waypoints moved onto the path's segments.

    The distinct waypoints are kept; the freed steps are handed out one at a time to the segment
    whose pieces are longest, and placed evenly along it.  The geometry does not change (every new
    waypoint lies on a segment of W), only where the steps sit on it.
    """
    keep = np.ones(len(W), dtype=bool)
    keep[1:] = distance(W[1:], W[:-1]) > 0.0  # the first waypoint of each run of equal ones
    P = W[keep]
    P[-1] = W[-1]  # the goal row itself (equal values)
    if len(P) == len(W) or len(P) < 2:
        return W
    L = distance(P[:-1], P[1:])
    pieces = np.ones(len(L), dtype=int)
    for _ in range(len(W) - len(P)):
        pieces[int(np.argmax(L / pieces))] += 1
    out = [P[:1]]
    for k in range(len(L)):
        frac = np.arange(1, pieces[k] + 1) / pieces[k]
        run = interpolate(np.broadcast_to(P[k], (len(frac), P.shape[1])),
                          np.broadcast_to(P[k + 1], (len(frac), P.shape[1])), frac)
        run[-1] = P[k + 1]  # the kept waypoint itself, not its value interpolated at 1.0
        out.append(run)
    return np.vstack(out)
