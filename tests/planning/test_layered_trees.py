"""tpee_ompl.planning.layered_trees: lazily checked layered trees of the feasibility phase."""

from __future__ import annotations

import numpy as np
import pytest

from tpee_ompl.planning.layered_trees import LayeredTrees


def _delta(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    return np.asarray(B, dtype=float) - np.asarray(A, dtype=float)


def test_killing_a_node_kills_its_subtree_and_hides_it_from_nearest() -> None:
    W = np.linspace([0.0, 0.0], [1.0, 0.0], 5)
    V = np.array([True, False, False, False, True])
    E = np.zeros(4, dtype=bool)
    trees = LayeredTrees(W, V, E, np.array([0, 1]), hold=True, delta=_delta)
    a = trees.fwd.add(np.array([0.2, 0.5]), 1, 0)
    b = trees.fwd.add(np.array([0.4, 0.5]), 2, a)
    other = trees.fwd.add(np.array([0.2, -0.5]), 1, 0)
    fi, _ = trees.nearest(np.array([0.45, 0.5]))
    assert fi[-1] == b
    trees.fwd.kill(a)
    assert not trees.fwd.alive[a] and not trees.fwd.alive[b] and trees.fwd.alive[other]
    fi, _ = trees.nearest(np.array([0.45, 0.5]))
    assert b not in fi and a not in fi
    live, start, count = trees.fwd.layers()
    assert trees.fwd.alive[live].all() and (count > 0).all() and count.sum() == len(live)
    assert (np.diff(trees.fwd.steps[live]) >= 0).all() and len(start) == len(np.unique(trees.fwd.steps[live]))


@pytest.mark.parametrize("hold", [True, False])
def test_nearest_is_the_closest_live_node_of_the_allowed_steps_lowest_index_on_ties(hold: bool) -> None:
    rng = np.random.default_rng(11)
    h = 7
    W = np.linspace([0.0, 0.0], [1.0, 0.0], h)
    trees = LayeredTrees(W, np.r_[True, np.zeros(h - 2, bool), True], np.zeros(h - 1, bool), np.array([0, 1]),
                         hold=hold, delta=_delta)
    grid = np.round(rng.uniform(-1, 1, (40, 2)) * 4) / 4  # coarse values: many equal distances
    for tree, lo, hi in ((trees.fwd, 0, h - 2), (trees.bwd, 2, h)):
        for x in grid:
            step = int(rng.integers(lo, hi))
            parents = np.flatnonzero(tree.steps[: len(tree)] < step) if tree is trees.fwd else \
                np.flatnonzero(tree.steps[: len(tree)] > step)
            if len(parents):
                tree.add(x, step, int(rng.choice(parents)))
        tree.kill(int(rng.integers(1, len(tree))))
    for c in np.round(rng.uniform(-1, 1, (30, 2)) * 4) / 4:
        fi, bi = trees.nearest(c)
        for t in range(1, h - 1):
            for tree, got, allowed in ((trees.fwd, fi[t - 1], (lambda s: s <= t - 1) if hold else (lambda s: s == t - 1)),
                                       (trees.bwd, bi[t - 1], (lambda s: s >= t + 1) if hold else (lambda s: s == t + 1))):
                n = len(tree)
                ok = tree.alive[:n] & allowed(tree.steps[:n])
                d2 = ((tree.values[:n] - c) ** 2).sum(axis=1)
                want = int(np.argmin(np.where(ok, d2, np.inf))) if ok.any() else -1
                assert got == want


def test_candidate_path_names_the_node_each_segment_leads_into() -> None:
    W = np.linspace([0.0, 0.0], [1.0, 0.0], 7)
    V = np.array([True] + [False] * 5 + [True])
    trees = LayeredTrees(W, V, np.zeros(6, dtype=bool), np.array([0, 1]), hold=True, delta=_delta)
    f = trees.fwd.add(np.array([0.1, 0.3]), 1, 0)
    b = trees.bwd.add(np.array([0.8, 0.3]), 4, 0)
    path, owners = trees.path(2, np.array([0.5, 0.4]), f, b)
    np.testing.assert_allclose(path[[1, 2, 4]], [[0.1, 0.3], [0.5, 0.4], [0.8, 0.3]])
    np.testing.assert_allclose(path[[0, -1]], W[[0, -1]])
    assert owners[0] == ("f", f) and owners[1] == ("c", -1) and owners[2] == ("c", -1)
    assert owners[4] == ("b", b) and 3 not in owners  # steps 3 and 4 both hold b (a zero-length motion)


def test_spread_keeps_the_distinct_waypoints_bit_for_bit_and_moves_only_repeated_ones() -> None:
    from tpee_ompl.planning.layered_trees import spread_waypoints

    rng = np.random.default_rng(4)
    P = rng.uniform(-2.9, 2.9, (4, 3))
    W = np.vstack([P[:2], P[1:2], P[2:], P[3:], P[3:]])  # held: row 1 once, the goal twice

    def interpolate(A, B, t):
        return A + np.asarray(t)[..., None] * (B - A)

    S = spread_waypoints(W, interpolate, lambda A, B: np.linalg.norm(B - A, axis=-1))
    assert len(S) == len(W) and np.all(np.linalg.norm(np.diff(S, axis=0), axis=1) > 0)
    for p in P:  # each kept waypoint is in S exactly (not interpolated at 1.0)
        assert any(np.array_equal(p, s) for s in S)
