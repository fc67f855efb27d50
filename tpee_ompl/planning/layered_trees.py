"""The feasibility phase of dimension-RRT: layered forward/backward trees over fake-time steps.

Before the first valid path the search grows a forward tree from the start and a backward tree from
the goal.  A node is the planned DOFs' values at one fake-time step (the other DOFs are those of
the base path at that step); every node is valid and reached from its parent by a valid motion.
See :mod:`tpee_ompl.planning.dimension_rrt` for how samples are placed.

*Holding* (only without prescribed groups, where a node's configuration does not depend on its
step): a node of step s also serves every later step (forward tree) or earlier step (backward tree)
by staying where it is, a zero-length and therefore valid motion.  A path then has fewer distinct
waypoints than steps; :func:`spread_waypoints` puts the repeated ones back on its segments.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["Tree", "LayeredTrees", "spread_waypoints"]


class Tree:
    """Nodes of one layered tree: values (N, k), fake-time step and parent index of each."""

    def __init__(self, k: int) -> None:
        self.values = np.empty((16, k))
        self.steps = np.empty(16, dtype=int)
        self.parents: list[int] = []

    def __len__(self) -> int:
        return len(self.parents)

    def add(self, x: np.ndarray, step: int, parent: int) -> int:
        n = len(self.parents)
        if n == len(self.values):
            self.values = np.concatenate([self.values, np.empty_like(self.values)])
            self.steps = np.concatenate([self.steps, np.empty_like(self.steps)])
        self.values[n] = x
        self.steps[n] = step
        self.parents.append(parent)
        return n

    def sq_dist(self, x: np.ndarray, delta: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> np.ndarray:
        D = delta(self.values[: len(self.parents)], x)
        return np.einsum("ij,ij->i", D, D)

    def layer_sizes(self) -> list[tuple[int, np.ndarray]]:
        """(step, node indices) of each non-empty step, steps ascending."""
        st = self.steps[: len(self.parents)]
        return [(int(s), np.flatnonzero(st == s)) for s in np.unique(st)]


def _nearest(d2: np.ndarray, ok: np.ndarray) -> int:
    if not ok.any():
        return -1
    return int(np.argmin(np.where(ok, d2, np.inf)))


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
        prev = self.fwd.add(W[0, d], 0, -1)
        t = 1
        while t < h - 1 and V[t] and E[t - 1]:
            prev = self.fwd.add(W[t, d], t, prev)
            t += 1
        prev = self.bwd.add(W[h - 1, d], h - 1, -1)
        t = h - 2
        while t > 0 and V[t] and E[t]:
            prev = self.bwd.add(W[t, d], t, prev)
            t -= 1

    def nearest(self, c: np.ndarray) -> tuple[list[int], list[int]]:
        """For each intermediate step t = 1 .. h-2: the nearest forward node that can precede c at t
        (step t-1, or any step <= t-1 when holding) and the nearest backward node that can follow
        it (step t+1, or >= t+1); -1 where there is none."""
        df, db = self.fwd.sq_dist(c, self.delta), self.bwd.sq_dist(c, self.delta)
        sf, sb = self.fwd.steps[: len(self.fwd)], self.bwd.steps[: len(self.bwd)]
        fi, bi = [], []
        for t in range(1, self.h - 1):
            fi.append(_nearest(df, sf <= t - 1 if self.hold else sf == t - 1))
            bi.append(_nearest(db, sb >= t + 1 if self.hold else sb == t + 1))
        return fi, bi

    def anchor(self, u: float) -> np.ndarray:
        """Values of a tree node picked by u in [0, 1): a uniform non-empty step of either tree, then a uniform node."""
        layers = [(tree, idx) for tree in (self.fwd, self.bwd) for _, idx in tree.layer_sizes()]
        x = u * len(layers)
        tree, idx = layers[int(x)]
        return tree.values[idx[int((x - int(x)) * len(idx))]]

    def path(self, t: int, c: np.ndarray, f: int, b: int) -> np.ndarray:
        """The waypoints (h, n) through forward node f, c at step t, backward node b (held nodes repeated)."""
        W = self.base.copy()
        d = self.dims
        W[t, d] = c
        end = t  # fill steps [node step, end) with the node's values, walking back to the start
        while f >= 0:
            s = int(self.fwd.steps[f])
            W[s:end, d] = self.fwd.values[f]
            end, f = s, self.fwd.parents[f]
        begin = t + 1  # fill steps [begin, node step] walking on to the goal
        while b >= 0:
            s = int(self.bwd.steps[b])
            W[begin : s + 1, d] = self.bwd.values[b]
            begin, b = s + 1, self.bwd.parents[b]
        return W


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
        out.append(interpolate(np.broadcast_to(P[k], (len(frac), P.shape[1])),
                               np.broadcast_to(P[k + 1], (len(frac), P.shape[1])), frac))
    return np.vstack(out)
