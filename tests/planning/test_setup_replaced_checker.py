"""A state validity checker replaced after make_simple_setup (a user's added constraint): motions are checked through it,
and a checker the motion validator cannot know of makes the package's planners refuse rather than pass bad paths."""

from __future__ import annotations

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.model.queries import load_queries
from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.paths import motion_states, path_to_array
from tpee_ompl.planning.planner_base import validator_mismatch
from tpee_ompl.planning.setup import make_simple_setup, motion_check_step


def _keep_out(own: ob.StateValidityChecker):
    """The robot's checks plus a box in the pan / tilt joints that the robot alone allows."""
    return lambda s: own.isValid(s) and not (-2.8 < s[2] < -2.4 and -1.0 < s[3] < 0.6)


@pytest.fixture
def query(robot):
    return load_queries("planning_necessary", robot)[0]


def _into_the_box(si: ob.SpaceInformation, q) -> tuple[ob.State, ob.State, np.ndarray, np.ndarray]:
    a, x = si.allocState(), si.allocState()
    A, X = np.array(q.start, dtype=float), np.array(q.start, dtype=float)
    X[2:] = -2.6, 0.0
    for i in range(4):
        a[i], x[i] = float(A[i]), float(X[i])
    return a, x, A, X


@pytest.mark.parametrize("kind", ["batched", "dense", "certified"])
def test_a_checker_set_on_the_setup_is_the_one_its_motions_are_checked_with(robot, query, kind):
    ss = make_simple_setup(robot, query.start, query.goal, motion_validator=kind)
    si = ss.getSpaceInformation()
    own, mv = si.getStateValidityChecker(), si.getMotionValidator()
    a, x, A, X = _into_the_box(si, query)
    assert si.checkMotion(a, x)  # the robot alone lets the motion through
    ss.setStateValidityChecker(_keep_out(own))
    assert not si.isValid(x)
    assert not si.checkMotion(a, x)
    assert not mv.check_motions(A[None], X[None])[0]  # the batched call dimension-RRT makes, too
    assert validator_mismatch(si) is None
    ss.setStateValidityChecker(own)  # the robot's own checker: the robot's checks again
    assert mv.checker is None and si.checkMotion(a, x)


@pytest.mark.parametrize("planner", [lambda si: DimensionRRT(si, seed=1, max_samples=3000), og.RRTConnect])
def test_exact_paths_keep_every_checked_state_valid_under_the_replaced_checker(robot, query, planner):
    ss = make_simple_setup(robot, query.start, query.goal)
    si = ss.getSpaceInformation()
    ss.setStateValidityChecker(_keep_out(si.getStateValidityChecker()))
    ss.setPlanner(planner(si))
    assert ss.solve(5.0) == ob.PlannerStatus.EXACT_SOLUTION
    W = path_to_array(ss.getSolutionPath(), 4)
    step, s = motion_check_step(ss), si.allocState()
    for a, b in zip(W[:-1], W[1:]):
        for q in motion_states(a, b, step):
            for i in range(4):
                s[i] = float(q[i])
            assert si.isValid(s)


def test_a_checker_set_on_the_space_information_makes_the_packages_planners_refuse(robot, query):
    ss = make_simple_setup(robot, query.start, query.goal)
    si = ss.getSpaceInformation()
    si.setStateValidityChecker(_keep_out(si.getStateValidityChecker()))  # the setup cannot see this one
    assert "si.setStateValidityChecker" in validator_mismatch(si)
    ss.setPlanner(DimensionRRT(si, seed=1))
    assert ss.solve(1.0) == ob.PlannerStatus.ABORT
    assert not ss.haveExactSolutionPath()


def test_a_function_answering_a_numpy_bool_is_taken_as_a_bool(robot, query):
    """OMPL's bindings raise std::bad_cast on a numpy bool (a test of the continuous-joint set-up met it)."""
    ss = make_simple_setup(robot, query.start, query.goal)
    si = ss.getSpaceInformation()
    own = si.getStateValidityChecker()
    ss.setStateValidityChecker(lambda s: np.bool_(own.isValid(s)) & np.bool_(s[3] < 5.0))
    a, x, _, _ = _into_the_box(si, query)
    assert si.isValid(x) is True and si.checkMotion(a, x)

