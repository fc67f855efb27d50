"""Shortcuts between fake-time waypoints: the target is the shortest point, every move keeps the path valid."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.planning_spaces import box_problem, free_so2_space
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning import waypoint_shortcuts
from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.dimension_search import Search, SearchSettings
from tpee_ompl.planning.grouped_space import GroupedSpace
from tpee_ompl.planning.paths import path_passes_motion_checks, path_to_array
from tpee_ompl.planning.search_checker import Checker
from tpee_ompl.planning.waypoint_shortcuts import (
    SWEEP_MIN_GAIN,
    respread_candidate,
    shortcut_targets,
    shortcut_waypoints,
    sweep_until_settled,
)


def _through(A: np.ndarray, X: np.ndarray, B: np.ndarray) -> np.ndarray:
    return np.linalg.norm(X - A, axis=-1) + np.linalg.norm(B - X, axis=-1)


def test_target_is_the_shortest_point_when_the_other_dofs_stay(rng: np.random.Generator) -> None:
    si, _ = box_problem(lo=(0.9, 0.9, 0.9, 0.9), hi=(1.0, 1.0, 1.0, 1.0))
    layout = GroupedSpace(si, [[0, 1], [2, 3]], 5).layout
    dims = np.array([2, 3])
    A, X, B = (rng.uniform(-1, 1, (50, 4)) for _ in range(3))
    T = shortcut_targets(A, X, B, dims, layout)
    assert np.array_equal(T[:, :2], X[:, :2])  # the fixed DOFs stay
    for _ in range(20):  # no other value of the moved DOFs is shorter
        Y = T.copy()
        Y[:, dims] += rng.normal(0.0, 0.05, (50, 2))
        assert np.all(_through(A, T, B) <= _through(A, Y, B) + 1e-12)


def test_with_every_dof_moved_the_target_is_the_projection_onto_the_neighbours_segment() -> None:
    si, _ = box_problem()
    layout = GroupedSpace(si, [[0, 1]], 3).layout
    A, X, B = np.array([[-0.5, 0.0]]), np.array([[0.1, 0.6]]), np.array([[0.5, 0.0]])
    assert np.allclose(shortcut_targets(A, X, B, np.array([0, 1]), layout), [[0.1, 0.0]])


def test_continuous_joints_are_moved_the_short_way_round() -> None:
    si = free_so2_space()
    layout = GroupedSpace(si, [[0, 1]], 3).layout
    A, X, B = np.array([[3.0, 0.0]]), np.array([[0.0, 1.0]]), np.array([[-3.0, 0.0]])
    T = shortcut_targets(A, X, B, np.array([0]), layout)
    # A and B are 0.28 rad apart through +-pi: the shortest point of joint 0 lies there, not at 0
    assert abs(abs(T[0, 0]) - np.pi) < 1e-9 and T[0, 1] == 1.0
    assert -np.pi <= T[0, 0] < np.pi


@pytest.mark.parametrize("batch", [True, False])
def test_a_sweep_only_shortens_the_path_and_keeps_every_motion_valid(batch: bool, rng: np.random.Generator) -> None:
    si, _ = box_problem(lo=(-0.2, -0.2), hi=(0.2, 0.2))
    grouped = GroupedSpace(si, [[0, 1]], 7)
    checker = Checker(si, grouped.layout, batch)
    start, goal = np.array([-0.9, 0.0]), np.array([0.9, 0.0])
    # a valid zigzag around the box: above it, with detours up and down
    W = np.array([start, [-0.6, 0.5], [-0.3, 0.9], [0.0, 0.4], [0.3, 0.9], [0.6, 0.5], goal])
    assert checker.states(W).all() and checker.check_motions(W[:-1], W[1:]).all()
    L = grouped.layout.distance(W[:-1], W[1:])
    lengths = [L.sum()]
    for _ in range(30):
        if not shortcut_waypoints(W, L, np.array([0, 1]), grouped.layout, checker):
            break
        assert np.allclose(L, grouped.layout.distance(W[:-1], W[1:]))
        lengths.append(L.sum())
    assert np.all(np.diff(lengths) < 0) and len(lengths) > 3
    assert np.array_equal(W[0], start) and np.array_equal(W[-1], goal)
    assert checker.states(W).all() and checker.check_motions(W[:-1], W[1:]).all()
    # from 3.3 to within 10 % of the shortest way over the box, 2 |(-0.9, 0) -> (-0.2, 0.2)| + 0.4
    assert 2 * np.hypot(0.7, 0.2) + 0.4 < lengths[-1] < 1.1 * (2 * np.hypot(0.7, 0.2) + 0.4) < 0.7 * lengths[0]


def _zigzag(batch: bool = True) -> tuple[np.ndarray, np.ndarray, GroupedSpace, Checker]:
    """A valid zigzag path over a box (7 waypoints), its segment lengths, space and checker."""
    si, _ = box_problem(lo=(-0.2, -0.2), hi=(0.2, 0.2))
    grouped = GroupedSpace(si, [[0, 1]], 7)
    checker = Checker(si, grouped.layout, batch)
    W = np.array([[-0.9, 0.0], [-0.6, 0.5], [-0.3, 0.9], [0.0, 0.4], [0.3, 0.9], [0.6, 0.5], [0.9, 0.0]])
    return W, grouped.layout.distance(W[:-1], W[1:]), grouped, checker


def _settled_in_full(W: np.ndarray, L: np.ndarray, grouped: GroupedSpace, checker: Checker) -> tuple[np.ndarray, list[float]]:
    """W after sweeps with every move checked in full, as long as each gains SWEEP_MIN_GAIN, and the path's
    length before the first sweep and after each."""
    W, L = W.copy(), L.copy()
    lengths = [float(L.sum())]
    for _ in range(100):
        moved = shortcut_waypoints(W, L, np.array([0, 1]), grouped.layout, checker)
        lengths.append(float(L.sum()))
        if not moved or lengths[-2] - lengths[-1] < SWEEP_MIN_GAIN * lengths[-2]:
            break
    return W, lengths


def test_sweeps_repeat_until_one_gains_less_than_the_threshold() -> None:
    W, L, grouped, checker = _zigzag()
    dims = np.array([0, 1])
    once_W, once_L = W.copy(), L.copy()
    shortcut_waypoints(once_W, once_L, dims, grouped.layout, checker)
    # the same sweeps one at a time: each gains at least SWEEP_MIN_GAIN of the length, but the last
    R, lengths = _settled_in_full(W, L, grouped, checker)
    moves = sweep_until_settled(W, L, dims, grouped.layout, checker, max_sweeps=100)
    assert moves > 0 and np.array_equal(W, R) and np.isclose(L.sum(), lengths[-1])
    assert 2 < len(lengths) - 1 < 100 and L.sum() < once_L.sum()
    assert checker.states(W).all() and checker.check_motions(W[:-1], W[1:]).all()
    assert np.allclose(L, grouped.layout.distance(W[:-1], W[1:]))


def test_settling_sweeps_check_the_changed_motions_in_full_once_at_the_end(monkeypatch: pytest.MonkeyPatch) -> None:
    W, L, grouped, checker = _zigzag()
    assert checker.batched
    reference = _settled_in_full(W, L, grouped, checker)[0]
    calls: list[int] = []
    real = checker.check_motions
    monkeypatch.setattr(checker, "check_motions", lambda A, B: calls.append(len(A)) or real(A, B))
    sweep_until_settled(W, L, np.array([0, 1]), grouped.layout, checker, max_sweeps=100)
    assert calls == [6] and np.array_equal(W, reference)  # every segment changed; checked once


def test_a_waypoint_whose_neighbour_moved_after_it_was_tried_is_tried_again() -> None:
    # free space, one waypoint off the line: its neighbours move towards it, then theirs, sweep after sweep
    si, _ = box_problem(lo=(0.9, 0.9), hi=(1.0, 1.0))
    grouped = GroupedSpace(si, [[0, 1]], 7)
    checker = Checker(si, grouped.layout, True)
    W = np.array([[-0.9, 0.0], [-0.6, 0.0], [-0.3, 0.5], [0.0, 0.0], [0.3, 0.0], [0.6, 0.0], [0.9, 0.0]])
    L = grouped.layout.distance(W[:-1], W[1:])
    reference = _settled_in_full(W, L, grouped, checker)[0]
    first = W.copy()
    shortcut_waypoints(first, L.copy(), np.array([0, 1]), grouped.layout, checker)
    assert np.array_equal(first[5], W[5])  # waypoint 5 does not move in the first sweep (it is on its chord) ...
    assert not np.array_equal(reference[5], W[5])  # ... but once waypoint 4 has moved
    sweep_until_settled(W, L, np.array([0, 1]), grouped.layout, checker, max_sweeps=100)
    assert np.array_equal(W, reference)


def test_settling_sweeps_start_again_with_full_checks_when_a_screened_move_fails(monkeypatch: pytest.MonkeyPatch) -> None:
    W, L, grouped, checker = _zigzag()
    reference = _settled_in_full(W, L, grouped, checker)[0]
    calls: list[int] = []
    real = checker.check_motions

    def first_fails(A: np.ndarray, B: np.ndarray) -> np.ndarray:
        calls.append(len(A))
        return np.zeros(len(A), dtype=bool) if len(calls) == 1 else real(A, B)

    monkeypatch.setattr(checker, "check_motions", first_fails)
    moves = sweep_until_settled(W, L, np.array([0, 1]), grouped.layout, checker, max_sweeps=100)
    assert moves > 0 and calls == [6] and np.array_equal(W, reference)
    assert np.allclose(L, grouped.layout.distance(W[:-1], W[1:]))
    assert checker.states(W).all() and checker.check_motions(W[:-1], W[1:]).all()


def _false_for(n: int):
    """A termination condition that holds from its (n + 1)-th call on."""
    calls = iter(range(10**6))
    return lambda: next(calls) >= n


def test_sweeps_end_at_the_batch_of_candidates_at_which_the_termination_condition_holds(monkeypatch: pytest.MonkeyPatch) -> None:
    """The condition is asked before each batch of candidates (a whole sweep took 2-3 ms at a 10-ms budget)."""
    W, L, grouped, checker = _zigzag()
    W0 = W.copy()
    assert sweep_until_settled(W, L, np.array([0, 1]), grouped.layout, checker, max_sweeps=100, stop=lambda: True) == 0
    assert np.array_equal(W, W0)  # held from the start: nothing is tried
    one_W, one_L = W.copy(), L.copy()
    full = shortcut_waypoints(one_W, one_L, np.array([0, 1]), grouped.layout, checker)
    before = float(L.sum())
    part = sweep_until_settled(W, L, np.array([0, 1]), grouped.layout, checker, max_sweeps=100, stop=_false_for(1))
    assert 0 < part < full and L.sum() < before  # one batch taken, then stopped
    assert np.allclose(L, grouped.layout.distance(W[:-1], W[1:])) and checker.check_motions(W[:-1], W[1:]).all()
    # a failed final check with the condition holding: the path stays where it was, no sweeps in full
    W, L, grouped, checker = _zigzag()
    W0 = W.copy()
    monkeypatch.setattr(checker, "check_motions", lambda A, B: np.zeros(len(A), dtype=bool))
    assert sweep_until_settled(W, L, np.array([0, 1]), grouped.layout, checker, max_sweeps=100, stop=_false_for(1)) == 0
    assert np.array_equal(W, W0) and np.allclose(L, grouped.layout.distance(W[:-1], W[1:]))


def test_sweeps_stop_at_max_sweeps(monkeypatch: pytest.MonkeyPatch) -> None:
    W, L, grouped, checker = _zigzag()
    one_W, one_L = W.copy(), L.copy()
    shortcut_waypoints(one_W, one_L, np.array([0, 1]), grouped.layout, checker)
    sweep_until_settled(W, L, np.array([0, 1]), grouped.layout, checker, max_sweeps=1)
    assert np.array_equal(W, one_W)
    monkeypatch.setattr(waypoint_shortcuts, "MAX_SWEEPS", 2)  # the default is read at the call
    calls: list[int] = []
    real = waypoint_shortcuts.shortcut_waypoints
    monkeypatch.setattr(waypoint_shortcuts, "shortcut_waypoints", lambda *a: calls.append(1) or real(*a))
    W, L, grouped, checker = _zigzag()
    sweep_until_settled(W, L, np.array([0, 1]), grouped.layout, checker)
    assert len(calls) == 2


def test_a_collapsed_waypoint_gives_its_step_to_the_longest_segment_without_lengthening_the_path() -> None:
    si, _ = box_problem(lo=(-0.2, -0.2), hi=(0.2, 0.2))
    layout = GroupedSpace(si, [[0, 1]], 7).layout
    W = np.array([[-0.9, 0.0], [-0.5, 0.5], [0.0, 0.5], [0.001, 0.5], [0.4, 0.5], [0.6, 0.3], [0.9, 0.0]])
    L = layout.distance(W[:-1], W[1:])
    S = respread_candidate(W, L, layout)
    assert S is not None and S.shape == W.shape and np.array_equal(S[[0, -1]], W[[0, -1]])
    kept = [w for w in W.tolist() if w != [0.001, 0.5]]  # the inner end of the collapsed segment whose neighbours are closest
    assert all(w in S.tolist() for w in kept)
    new = [w for w in S.tolist() if w not in kept]
    assert len(new) == 1 and np.allclose(new[0], [-0.7, 0.25])  # the middle of the longest segment
    LS = layout.distance(S[:-1], S[1:])
    assert LS.sum() <= L.sum() and LS.min() > 0.1 * LS.mean()
    assert respread_candidate(S, LS, layout) is None  # nothing collapsed any more


def test_the_released_search_respreads_collapsed_waypoints_into_a_valid_shorter_path() -> None:
    si, _ = box_problem(lo=(-0.2, -0.2), hi=(0.2, 0.2))
    grouped = GroupedSpace(si, [[0], [1]], 7)
    start, goal = np.array([-0.9, 0.0]), np.array([0.9, 0.0])
    W = np.array([start, [-0.5, 0.5], [0.0, 0.5], [0.001, 0.5], [0.4, 0.5], [0.6, 0.3], goal])
    search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(0), start, goal,
                    settings=SearchSettings(narrow_after=200, narrowing=0.5, shortcuts=True),
                    range_={0: np.full(1, 0.02), 1: np.full(1, 0.02)}, initial=W)
    assert search.valid
    before = search.cost
    assert search._respread() == 1
    assert search.valid and search.cost <= before and search.L.min() > 0.1 * search.L.mean()
    assert path_passes_motion_checks(si, search.W)
    moved = search.W.copy()
    assert search._respread() == 0  # nothing collapsed any more: the path stays
    assert np.array_equal(search.W, moved)


def _solve_3d(shortcuts: bool | None, seed: int, prescribed: bool = True, **options: object) -> tuple[DimensionRRT, float]:
    si, _ = box_problem(lo=(-0.3, -0.3, -0.5), hi=(0.3, 0.3, 0.5))
    ss = og.SimpleSetup(si)
    start, goal = si.allocState(), si.allocState()
    for k, (a, b) in enumerate(((-0.9, 0.9), (0.0, 0.1), (0.0, -0.1))):
        start[k], goal[k] = a, b
    ss.setStartAndGoalStates(start, goal)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    row = {0: np.linspace(-0.9, 0.9, 7)[:, None]} if prescribed else None
    planner = DimensionRRT(si, groups=[[0], [1, 2]], h=7, max_samples=300, seed=seed, shortcuts=shortcuts,
                           prescribed=row, **options)
    ss.setPlanner(planner)
    assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
    path = ss.getSolutionPath()
    assert path_passes_motion_checks(si, path)
    return planner, path.length()


def test_with_a_prescribed_group_shortcuts_give_shorter_paths_at_a_sample_cap() -> None:
    off = [_solve_3d(False, seed)[1] for seed in range(5)]
    on = [_solve_3d(True, seed)[1] for seed in range(5)]
    assert np.mean(on) < np.mean(off)


def test_shortcuts_are_on_by_default_only_with_a_prescribed_group() -> None:
    assert _solve_3d(None, 0)[0].settings()["shortcuts"] == "True"
    assert _solve_3d(None, 0, prescribed=False)[0].settings()["shortcuts"] == "False"
    assert _solve_3d(True, 0, prescribed=False)[0].settings()["shortcuts"] == "True"


def test_one_rule_decides_the_shortcuts_default() -> None:
    from tpee_ompl.planning.dimension_rrt import DimensionRRTOptions, shortcuts_on

    assert shortcuts_on(DimensionRRTOptions(), prescribed=True) is True
    assert shortcuts_on(DimensionRRTOptions(), prescribed=False) is False
    assert shortcuts_on(DimensionRRTOptions(shortcuts=False), prescribed=True) is False
    assert shortcuts_on(DimensionRRTOptions(shortcuts=True), prescribed=False) is True


def test_rows_kept_to_the_end_sweep_until_settled_else_once(monkeypatch: pytest.MonkeyPatch) -> None:
    maxima: list[int | None] = []
    real = waypoint_shortcuts.sweep_until_settled

    def spy(*a: object, **kw: object) -> int:
        maxima.append(a[5] if len(a) > 5 else kw.get("max_sweeps"))
        return real(*a, **kw)

    monkeypatch.setattr("tpee_ompl.planning.dimension_search.sweep_until_settled", spy)
    _solve_3d(True, 0)
    assert maxima and set(maxima) == {None}  # the default, MAX_SWEEPS
    maxima.clear()
    _solve_3d(True, 0, prescribed=False)
    assert maxima and set(maxima) == {1}
    maxima.clear()
    planner, _ = _solve_3d(True, 0, release_after=30)  # rows to be released: once, before and after
    assert planner.last_run_stats()["released_at"] is not None and maxima and set(maxima) == {1}


def test_repeated_sweeps_give_shorter_paths_at_a_sample_cap(monkeypatch: pytest.MonkeyPatch) -> None:
    many = [_solve_3d(True, seed)[1] for seed in range(5)]
    monkeypatch.setattr(waypoint_shortcuts, "MAX_SWEEPS", 1)
    once = [_solve_3d(True, seed)[1] for seed in range(5)]
    assert np.mean(many) < np.mean(once)


def test_settling_sweeps_skip_unmoved_waypoints_with_the_same_paths_and_fewer_checks(monkeypatch: pytest.MonkeyPatch) -> None:
    def run() -> list[tuple[bytes, int]]:
        out = []
        for seed in range(3):
            planner, _ = _solve_3d(True, seed)
            out.append((path_to_array(planner.getProblemDefinition().getSolutionPath(), 3).tobytes(),
                        planner.last_run_stats()["collision_checks"]))
        return out

    skipping = run()
    real = waypoint_shortcuts.shortcut_waypoints
    monkeypatch.setattr(waypoint_shortcuts, "shortcut_waypoints", lambda W, L, d, lay, c, dirty=None, screen_only=False, stop=None: real(W, L, d, lay, c, None, screen_only,
                                                                                    stop))
    full = run()
    assert [p for p, _ in skipping] == [p for p, _ in full]
    assert sum(c for _, c in skipping) < sum(c for _, c in full)


def test_on_the_wearer_settling_sweeps_leave_only_paths_that_pass_check_motion(robot: WearerArm, monkeypatch: pytest.MonkeyPatch) -> None:
    """With the project's batched validator (lone candidates screened at every 4th state, ``check_motions``)."""
    from tpee_ompl.model.queries import load_queries
    from tpee_ompl.planning import dimension_search
    from tpee_ompl.planning.setup import make_simple_setup
    from tpee_ompl.planning.tpee import tpee_dimension_rrt

    screened: list[bool] = []
    real_candidates = Checker.candidates

    def candidates(self: Checker, *a: object, screen_only: bool = False, **kw: object) -> tuple:
        screened.append(screen_only)
        return real_candidates(self, *a, screen_only=screen_only, **kw)

    monkeypatch.setattr(Checker, "candidates", candidates)
    real_settle = waypoint_shortcuts.sweep_until_settled
    settles: list[int] = []
    for q in load_queries("planning_necessary", robot)[::40]:  # three sector pairs
        ss = make_simple_setup(robot, q.start, q.goal)
        si = ss.getSpaceInformation()

        def checked(W: np.ndarray, L: np.ndarray, *a: object, si: ob.SpaceInformation = si, **kw: object) -> int:
            moved = real_settle(W, L, *a, **kw)
            settles.append(moved)
            assert path_passes_motion_checks(si, W) and np.allclose(L, np.linalg.norm(np.diff(W, axis=0), axis=1))
            return moved

        monkeypatch.setattr(dimension_search, "sweep_until_settled", checked)
        ss.setPlanner(tpee_dimension_rrt(si, q.from_sector, q.to_sector, max_samples=400, seed=3))
        assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
        assert path_passes_motion_checks(si, ss.getSolutionPath())
    assert any(screened) and sum(m > 0 for m in settles) >= 3  # the lazy moves were exercised
