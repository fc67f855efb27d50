"""Posting dimension-RRT's paths: no zero-length segment reaches OMPL (:mod:`tpee_ompl.planning.solution_posting`)."""

from __future__ import annotations

import time

import numpy as np
from helpers.planning_spaces import box_problem
from ompl import base as ob

from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.paths import path_to_array, set_state
from tpee_ompl.planning.solution_posting import SolutionPoster, without_repeats


def test_repeated_waypoints_are_dropped_and_the_ends_kept():
    W = np.array([[0, 0], [0, 0], [1, 0], [1, 0], [1, 0], [2, 1], [2, 1]], dtype=float)
    np.testing.assert_array_equal(without_repeats(W), [[0, 0], [1, 0], [2, 1]])
    same = np.zeros((7, 2))
    np.testing.assert_array_equal(without_repeats(same), np.zeros((2, 2)))  # start == goal: two states, as OMPL's
    distinct = np.arange(14.0).reshape(7, 2)
    assert without_repeats(distinct) is distinct


def test_a_start_equal_to_the_goal_is_posted_as_two_states_not_seven():
    """A helper's probe: the path was 7 equal states (OMPL's planners post 2)."""
    si, _ = box_problem()
    pdef = ob.ProblemDefinition(si)
    start = set_state(si.allocState(), (-0.5, 0.5))
    pdef.setStartAndGoalStates(start, set_state(si.allocState(), (-0.5, 0.5)))
    planner = DimensionRRT(si, groups=[[0, 1]], seed=0, max_samples=10)
    planner.setProblemDefinition(pdef)
    assert planner.solve(1.0) == ob.PlannerStatus.EXACT_SOLUTION
    W = path_to_array(pdef.getSolutionPath(), 2)
    np.testing.assert_array_equal(W, [[-0.5, 0.5], [-0.5, 0.5]])


def test_a_path_refused_at_posting_does_not_count_as_found():
    """The loop stops once the found cost reaches the straight start-goal distance and ranks goals by it: a path that
    ``si.checkMotion`` or the bounds refused must not set it (the posted best cost stays what was found)."""
    si, _ = box_problem()
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(set_state(si.allocState(), (-0.5, 0.5)), set_state(si.allocState(), (0.5, 0.5)))
    pdef.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    planner = DimensionRRT(si, groups=[[0, 1]], seed=0, max_samples=10)
    poster = SolutionPoster(planner, si, pdef, time.perf_counter(), planner.grouped.to_path, lambda path, cost: None)
    outside = np.array([[-0.5, 0.5], [0.0, 5.0], [0.5, 0.5]])  # through a waypoint outside the box
    poster.offer(outside, 1.0, time.perf_counter())
    assert poster.posted == 0 and poster.found_cost == poster.best_cost == np.inf
    inside = np.array([[-0.5, 0.5], [0.0, 0.5], [0.5, 0.5]])
    poster.offer(inside, 1.0, time.perf_counter())
    assert poster.posted == 1 and poster.found_cost == poster.best_cost == 1.0
