"""DimensionRRTOptions.max_h: the feasibility phase raises the number of fake-time steps when h cannot bridge."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.grouped_space import GroupedSpace
from tpee_ompl.planning.paths import path_passes_motion_checks


def _two_walls() -> og.SimpleSetup:
    """2-D box: a wall from the bottom at x in [-0.4, -0.3] (y < 0.6) and one from the top at x in
    [0.3, 0.4] (y > -0.6).  From (-0.9, -0.9) to (0.9, 0.9) a path needs at least three turns."""
    space = ob.RealVectorStateSpace(2)
    space.setBounds(-1.0, 1.0)
    ss = og.SimpleSetup(space)

    def valid(s: ob.State) -> bool:
        x, y = s[0], s[1]
        return not ((-0.4 < x < -0.3 and y < 0.6) or (0.3 < x < 0.4 and y > -0.6))

    ss.setStateValidityChecker(valid)
    si = ss.getSpaceInformation()
    si.setStateValidityCheckingResolution(0.005)
    a, b = si.allocState(), si.allocState()
    a[0], a[1], b[0], b[1] = -0.9, -0.9, 0.9, 0.9
    ss.setStartAndGoalStates(a, b)
    ss._keep = (valid, a, b)
    si.setup()
    return ss


def _solve(ss: og.SimpleSetup, **kw) -> tuple[DimensionRRT, ob.PlannerStatus]:
    ss.clear()
    planner = DimensionRRT(ss.getSpaceInformation(), groups=[[0, 1]], seed=0, **kw)
    ss.setPlanner(planner)
    return planner, ss.solve(30.0)


def test_fixed_h_that_cannot_bridge_times_out_at_its_sample_cap_in_the_layered_trees() -> None:
    ss = _two_walls()
    planner, status = _solve(ss, h=3, max_samples=1500, connect=False)
    assert status == ob.PlannerStatus.TIMEOUT
    st = planner.last_run_stats()
    assert st["h"] == 3 and st["samples"] == 1500


def test_fixed_h_that_cannot_bridge_still_returns_the_connect_trees_path() -> None:
    ss = _two_walls()
    planner, status = _solve(ss, h=3, max_samples=1500)
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    st = planner.last_run_stats()
    assert st["h"] == 3 and st["solutions_posted"] == 1
    path = ss.getSolutionPath()
    assert path.getStateCount() > 3  # every tree node on the way: more turns than the steps hold
    assert path_passes_motion_checks(ss.getSpaceInformation(), path)


def test_max_h_raises_h_by_inserting_steps_until_a_path_exists() -> None:
    ss = _two_walls()
    planner, status = _solve(ss, h=3, max_samples=6000, max_h=17)
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    st = planner.last_run_stats()
    assert st["h"] in (5, 9, 17)
    path = ss.getSolutionPath()
    assert path.getStateCount() == st["h"]
    assert path_passes_motion_checks(ss.getSpaceInformation(), path)
    again, _ = _solve(ss, h=3, max_samples=6000, max_h=17)
    assert again.last_run_stats()["best_cost"] == st["best_cost"]  # deterministic under seed and cap


def test_a_connect_path_with_more_turns_than_steps_raises_h_at_once() -> None:
    ss = _two_walls()

    def samples_to_first_path(**kw) -> int:
        planner, status = _solve(ss, h=3, max_samples=3000, max_h=17, **kw)
        assert status == ob.PlannerStatus.EXACT_SOLUTION
        assert path_passes_motion_checks(ss.getSpaceInformation(), ss.getSolutionPath())
        return next(n for _, cost, n in planner.last_run_stats()["progress"] if math.isfinite(cost))

    # the layered trees need over 1000 samples here (h raised after 500 without a path each time)
    assert samples_to_first_path() < 500 < samples_to_first_path(connect=False)


def test_refined_space_keeps_prescribed_rows_at_even_steps_on_the_same_polyline() -> None:
    space = ob.RealVectorStateSpace(3)
    space.setBounds(-2.0, 2.0)
    rows = np.array([[0.0], [0.5], [1.5], [1.0]])
    grouped = GroupedSpace(space, [[0], [1, 2]], 4, {0: rows})
    start, goal = np.array([0.0, -1.0, 0.0]), np.array([1.0, 1.0, 0.5])
    finer = grouped.refined(start, goal)
    assert finer.h == 7 and finer.planned == [1]
    np.testing.assert_allclose(finer.prescribed[0][0::2], rows)
    np.testing.assert_allclose(finer.prescribed[0][1::2, 0], [0.25, 1.0, 1.25])
    np.testing.assert_allclose(finer.initial_waypoints(start, goal)[[0, -1]], [start, goal])


@pytest.mark.parametrize("bad", [2, 0, "7"])
def test_bad_max_h_is_refused(bad) -> None:
    space = ob.RealVectorStateSpace(2)
    space.setBounds(-1.0, 1.0)
    with pytest.raises(ValueError, match="max_h"):
        DimensionRRT(ob.SpaceInformation(space), max_h=bad)


def test_h_is_not_raised_while_the_connect_trees_have_not_met() -> None:
    """Helper review, 2026-11-27: every 500 samples without a path raised h and started the connect trees again, on a
    2-D maze up to h = 8193 (h only matters once the trees met and their path is fitted to the steps)."""
    space = ob.RealVectorStateSpace(2)
    space.setBounds(-1.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: not -0.05 < s[0] < 0.05)  # a full wall: the trees never meet
    si = ss.getSpaceInformation()
    a, b = si.allocState(), si.allocState()
    a[0], a[1], b[0], b[1] = -0.9, 0.0, 0.9, 0.0
    ss.setStartAndGoalStates(a, b)
    planner, status = _solve(ss, h=3, max_h=10_000, max_samples=2500)
    assert status == ob.PlannerStatus.TIMEOUT
    assert planner.last_run_stats()["h"] == 3 and planner.last_run_stats()["samples"] == 2500


def test_stall_counts_from_the_connect_trees_path_when_it_cannot_be_fitted() -> None:
    ss = _two_walls()
    planner, status = _solve(ss, h=3, max_samples=3000, stall_samples=400)
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    st = planner.last_run_stats()
    first = next(n for _, cost, n in st["progress"] if math.isfinite(cost))
    assert st["solutions_posted"] == 1 and st["samples"] == first + 400 < 3000
