"""SimplifiedPlanner: RRTConnect + OMPL's PathSimplifier as one planner, its path proven and never longer."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.model.queries import load_queries
from tpee_ompl.planning.paths import path_passes_motion_checks, path_to_array
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.planning.simplified import SimplifiedPlanner


@pytest.mark.parametrize("index", [0, 37, 95])
def test_simplified_path_is_proven_reaches_the_goal_and_is_no_longer_than_the_raw_one(robot, index):
    q = load_queries("planning_necessary")[index]
    ss = make_simple_setup(robot, q.start, q.goal)
    si = ss.getSpaceInformation()
    planner = SimplifiedPlanner(si, og.RRTConnect(si))
    ss.setPlanner(planner)
    status = ss.solve(5.0)
    assert status == ob.PlannerStatus.EXACT_SOLUTION and planner.getName() == "RRTConnectSimplify"
    stats = planner.last_run_stats()
    path = ss.getSolutionPath()
    W = path_to_array(path, 4)
    assert np.allclose(W[0], q.start) and np.allclose(W[-1], q.goal)
    assert path_passes_motion_checks(si, path)
    assert stats["best_cost"] <= stats["raw_cost"] and path.length() == pytest.approx(stats["best_cost"])
    assert stats["first_solution_time"] is not None


def test_a_planner_that_finds_nothing_reports_its_status(robot):
    q = load_queries("planning_necessary")[0]
    ss = make_simple_setup(robot, q.start, q.goal)
    si = ss.getSpaceInformation()
    planner = SimplifiedPlanner(si, og.RRTConnect(si))
    ss.setPlanner(planner)
    status = ss.solve(ob.PlannerTerminationCondition(lambda: True))  # no time at all
    assert status != ob.PlannerStatus.EXACT_SOLUTION and not ss.haveExactSolutionPath()
    assert planner.last_run_stats()["first_solution_time"] is None


def test_inner_must_be_an_ompl_planner(robot):
    si = make_simple_setup(robot).getSpaceInformation()
    with pytest.raises(ValueError, match="inner"):
        SimplifiedPlanner(si, "RRTConnect")


def test_a_setup_without_an_objective_gets_the_simplified_path_by_length():
    """A plain og.SimpleSetup (no optimization objective) on a 2-D box with a wall: the path is found,
    simplified and compared by length, not a crash."""
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: not (0.45 < s[0] < 0.55 and s[1] < 0.8))
    si = ss.getSpaceInformation()
    start, goal = si.allocState(), si.allocState()
    start[0], start[1], goal[0], goal[1] = 0.1, 0.1, 0.9, 0.1
    ss.setStartAndGoalStates(start, goal)
    planner = SimplifiedPlanner(si, og.RRTConnect(si))
    ss.setPlanner(planner)
    assert ss.solve(5.0) == ob.PlannerStatus.EXACT_SOLUTION
    stats = planner.last_run_stats()
    assert path_passes_motion_checks(si, ss.getSolutionPath())
    assert stats["best_cost"] <= stats["raw_cost"] < math.inf
    assert ss.getSolutionPath().length() == pytest.approx(stats["best_cost"])


def test_an_inner_planner_on_another_space_information_is_refused(robot):
    si = make_simple_setup(robot).getSpaceInformation()
    other = make_simple_setup(robot).getSpaceInformation()
    with pytest.raises(ValueError, match="another SpaceInformation"):
        SimplifiedPlanner(si, og.RRTConnect(other))
    with pytest.raises(ValueError, match="si must be"):
        SimplifiedPlanner(make_simple_setup(robot), og.RRTConnect(si))


def test_a_problem_without_a_start_state_is_invalid_start_not_a_crash(robot):
    ss = make_simple_setup(robot)  # no start, no goal
    si = ss.getSpaceInformation()
    planner = SimplifiedPlanner(si, og.RRTConnect(si))
    planner.setProblemDefinition(ss.getProblemDefinition())
    assert planner.solve(0.1) == ob.PlannerStatus.INVALID_START


def test_the_simplifier_starts_no_pass_after_the_termination_condition(robot, monkeypatch):
    """OMPL's simplify(path, ptc) finishes one whole pass past ptc unless told atLeastOnce=False."""
    calls = []
    real = og.PathSimplifier.simplify

    class Recording(og.PathSimplifier):
        def simplify(self, path, ptc, at_least_once=True):
            calls.append(at_least_once)
            return real(self, path, ptc, at_least_once)

    monkeypatch.setattr(og, "PathSimplifier", Recording)
    q = load_queries("planning_necessary")[0]
    ss = make_simple_setup(robot, q.start, q.goal)
    si = ss.getSpaceInformation()
    ss.setPlanner(SimplifiedPlanner(si, og.RRTConnect(si)))
    assert ss.solve(5.0) == ob.PlannerStatus.EXACT_SOLUTION and calls == [False]


def test_a_new_start_and_goal_without_clear_are_answered_not_the_old_query():
    """RRTConnect keeps its trees across solves: after ss.setStartAndGoalStates the wrapper posted the old query's
    path as an exact solution (it passes checkMotion, it just joins other states)."""
    from tpee_ompl.examples.planar_arm import make_planar_arm_setup

    ss = make_planar_arm_setup()
    si = ss.getSpaceInformation()
    ss.setPlanner(SimplifiedPlanner(si, og.RRTConnect(si)))
    assert ss.solve(2.0) == ob.PlannerStatus.EXACT_SOLUTION
    start, goal = si.allocState(), si.allocState()
    for k, (a, b) in enumerate(zip((0.4, 0.0, 0.0, 0.0), (-0.5, 0.2, 0.1, 0.0))):
        start[k], goal[k] = a, b
    ss.setStartAndGoalStates(start, goal)
    assert ss.solve(2.0) == ob.PlannerStatus.EXACT_SOLUTION
    W = path_to_array(ss.getSolutionPath(), 4)
    np.testing.assert_allclose(W[0], (0.4, 0.0, 0.0, 0.0))
    np.testing.assert_allclose(W[-1], (-0.5, 0.2, 0.1, 0.0))
