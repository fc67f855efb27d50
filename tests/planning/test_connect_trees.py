"""tpee_ompl.planning.connect_trees: RRTConnect's two trees, the feasibility phase without prescribed groups."""

from __future__ import annotations

import numpy as np
from helpers.planning_spaces import box_problem

from tpee_ompl.planning.connect_trees import ConnectTrees
from tpee_ompl.planning.grouped_space import GroupedSpace
from tpee_ompl.planning.paths import path_passes_motion_checks, set_state
from tpee_ompl.planning.search_checker import Checker


def _trees(si, start, goal, calls: list | None = None, range_: float = 0.3, lean: bool = False) -> ConnectTrees:
    grouped = GroupedSpace(si, [[0, 1]], 5)
    checker = Checker(si, grouped.layout, batch=False)

    def check(A: np.ndarray, B: np.ndarray, starts: bool) -> int:
        if calls is not None:
            calls.append((A.copy(), B.copy(), starts))
        n = 0
        while n < len(A) and (not starts or checker.states(A[n : n + 1])[0]) and checker.check_motion(A[n], B[n]):
            n += 1
        return n

    W = np.linspace(start, goal, 5)
    V = np.array([True, False, False, False, True])  # only the ends seed the trees
    return ConnectTrees(W, V, np.zeros(4, dtype=bool), grouped.layout, range_, check,
                        checker.check_step if lean else None)


def test_trees_meet_around_a_wall_with_turning_points_that_pass_check_motion() -> None:
    si, _ = box_problem(lo=(-0.1, -1.0), hi=(0.1, 0.5))  # a wall with a gap at the top
    start, goal = np.array([-0.8, 0.0]), np.array([0.8, 0.0])
    trees = _trees(si, start, goal)
    rng = np.random.default_rng(0)
    P = None
    for _ in range(2000):
        P = trees.step(rng.uniform(-1, 1, 2))
        if P is not None:
            break
    assert P is not None
    np.testing.assert_array_equal(P[[0, -1]], [start, goal])
    assert path_passes_motion_checks(si, P)
    assert np.any(P[:, 1] > 0.5)  # through the gap


def test_a_connect_is_one_straight_segment_and_goal_tree_states_are_checked_themselves() -> None:
    si, _ = box_problem(lo=(0.9, 0.9), hi=(1.0, 1.0))  # nothing in the way
    start, goal = np.array([-0.9, -0.9]), np.array([0.9, -0.9])
    calls: list = []
    trees = _trees(si, start, goal, calls, range_=0.1)
    P = trees.step(np.array([-0.9, 0.9]))  # start tree steps 0.1 up, the goal tree connects in 18 steps
    assert P is not None and len(P) == 3
    np.testing.assert_allclose(P[1], [-0.9, -0.8])
    assert len(trees.trees[1]) > 10  # the connect's steps are nodes of the goal tree...
    assert [starts for _, _, starts in calls] == [False, True]  # ...checked as one call, in path direction
    _, B, _ = calls[1]
    np.testing.assert_allclose(B[0], goal)  # goal tree motions run towards the goal: new state -> parent


def test_a_blocked_connect_keeps_the_steps_before_the_block() -> None:
    si, _ = box_problem(lo=(-0.05, -1.0), hi=(0.05, 1.0))  # a full wall: never connects
    start, goal = np.array([-0.8, 0.0]), np.array([0.8, 0.0])
    trees = _trees(si, start, goal, range_=0.1)
    assert trees.step(np.array([-0.7, 0.0])) is None  # start tree reaches the sample...
    n_goal = len(trees.trees[1])
    assert n_goal > 1  # ...the goal tree advances towards it until the wall
    assert np.all(trees.trees[1].values[:n_goal, 0] > 0.05)


def test_lean_per_state_steps_grow_the_same_trees_and_mark_the_checked_edges() -> None:
    si, _ = box_problem(lo=(-0.1, -1.0), hi=(0.1, 0.5))
    start, goal = np.array([-0.8, 0.0]), np.array([0.8, 0.0])
    Q = np.random.default_rng(3).uniform(-1, 1, (2000, 2))
    stops: list[int] = []
    arrays, lean = _trees(si, start, goal), _trees(si, start, goal, lean=True)
    P, used = arrays.run(Q)
    P2, used2 = lean.run(Q, stop=lambda: stops.append(1) and False)
    assert P is not None and used == used2 and len(stops) == used - 1
    np.testing.assert_array_equal(P, P2)
    for k in (0, 1):
        n = len(arrays.trees[k])
        np.testing.assert_array_equal(arrays.trees[k].values[:n], lean.trees[k].values[:n])
    assert len(lean.verified) == len(P) - 1 and any(lean.verified)
    a, b = si.allocState(), si.allocState()
    for k in np.flatnonzero(lean.verified):  # a single tree edge, checked in the path's direction
        assert si.checkMotion(set_state(a, P[k]), set_state(b, P[k + 1]))
    assert lean.run(Q[:10], stop=lambda: True) == (None, 1)  # stop is asked after the first sample
