"""DimensionRRT stops the way OMPL planners stop, and plans foreign set-ups (several planned groups, SO2)."""

from __future__ import annotations

import logging
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from tests.helpers.planning_arms import planar_arm_setup
from tests.helpers.planning_spaces import LengthTimes100, PathLengthTimes100
from tpee_ompl.bench.problems import get_problem
from tpee_ompl.examples.planar_arm import make_planar_arm_setup
from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.paths import path_passes_motion_checks, set_state

CAP = 3000


def _run(ss, ptc=None, **kw):
    planner = DimensionRRT(ss.getSpaceInformation(), **kw)
    ss.clear()
    ss.setPlanner(planner)
    status = ss.solve(ob.timedPlannerTerminationCondition(60.0) if ptc is None else ptc)
    return planner, status


def test_exact_solution_termination_stops_at_the_first_path() -> None:
    ss = make_planar_arm_setup()
    full = _run(ss, seed=3, max_samples=CAP)[0].last_run_stats()  # before ss.clear() resets it
    ptc = ob.plannerOrTerminationCondition(ob.exactSolnPlannerTerminationCondition(ss.getProblemDefinition()),
                                           ob.timedPlannerTerminationCondition(60.0))
    planner, status = _run(ss, ptc, seed=3, max_samples=CAP)
    stats = planner.last_run_stats()
    assert status == ob.PlannerStatus.EXACT_SOLUTION and ss.haveExactSolutionPath()
    assert stats["solutions_posted"] == 1 and stats["samples"] < full["samples"] == CAP
    assert path_passes_motion_checks(ss.getSpaceInformation(), ss.getSolutionPath())


def test_connect_trees_path_is_posted_as_found_before_it_is_fitted_to_the_steps() -> None:
    ss = make_planar_arm_setup()
    checker = ss.getStateValidityChecker()
    at_post = []

    def callback(planner, states, cost):
        at_post.append((checker.collision_checks, len(states)))

    ptc = ob.plannerOrTerminationCondition(ob.exactSolnPlannerTerminationCondition(ss.getProblemDefinition()),
                                           ob.timedPlannerTerminationCondition(60.0))
    planner = DimensionRRT(ss.getSpaceInformation(), seed=8, max_samples=CAP, batch=False)
    planner.set_intermediate_solution_callback(callback)
    ss.clear()
    ss.setPlanner(planner)
    assert ss.solve(ptc) == ob.PlannerStatus.EXACT_SOLUTION
    assert len(at_post) == 1 and at_post[0][0] == checker.collision_checks  # nothing checked after the post
    # every tree node on the way (9 here): more than the h = 7 steps a fitted path has
    assert at_post[0][1] == ss.getSolutionPath().getStateCount() > planner.last_run_stats()["h"] == 7
    assert path_passes_motion_checks(ss.getSpaceInformation(), ss.getSolutionPath())


def _arm6_query1(cap: int, checkpoints: list[int] | None = None, ptc=None) -> tuple[DimensionRRT, og.SimpleSetup]:
    """The generic problem arm6, query 1, seed 1 (its connect trees meet at sample 38 with one straight run)."""
    problem = get_problem("arm6")
    ss = problem.make_setup(problem.queries()[1][1], "discrete")[0]
    planner = DimensionRRT(ss.getSpaceInformation(), groups=problem.groups, seed=1, max_samples=cap)
    if checkpoints:
        planner.set_sample_checkpoints(checkpoints)
    ss.setPlanner(planner)
    assert ss.solve(ob.timedPlannerTerminationCondition(60.0) if ptc is None else ptc(planner))
    return planner, ss


def test_progress_row_of_the_connect_trees_path_counts_the_samples_that_found_it() -> None:
    planner, _ = _arm6_query1(300)
    n = next(samples for _, cost, samples in planner.last_run_stats()["progress"] if math.isfinite(cost))
    assert _arm6_query1(n)[0].last_run_stats()["solutions_posted"] >= 1
    problem = get_problem("arm6")
    ss = problem.make_setup(problem.queries()[1][1], "discrete")[0]
    before = DimensionRRT(ss.getSpaceInformation(), groups=problem.groups, seed=1, max_samples=n - 1)
    ss.setPlanner(before)
    assert ss.solve(60.0) == ob.PlannerStatus.TIMEOUT


@pytest.mark.parametrize("connect", [True, False])
def test_no_progress_row_shows_a_path_before_the_first_solution_time(connect: bool) -> None:
    for seed in range(4):
        ss = make_planar_arm_setup()
        planner = DimensionRRT(ss.getSpaceInformation(), seed=seed, max_samples=400, connect=connect)
        ss.setPlanner(planner)
        assert ss.solve(60.0) == ob.PlannerStatus.EXACT_SOLUTION
        stats = planner.last_run_stats()
        first_row = next(t for t, cost, _ in stats["progress"] if math.isfinite(cost))
        assert first_row >= stats["first_solution_time"]


def test_a_fit_that_only_merges_the_trees_steps_is_not_posted_again() -> None:
    planner, ss = _arm6_query1(38)
    stats = planner.last_run_stats()
    assert stats["solutions_posted"] == 1 and stats["best_cost"] == pytest.approx(ss.getSolutionPath().length())


def test_sample_checkpoint_at_the_trees_meeting_sees_what_a_run_capped_there_returns() -> None:
    seen = []

    def ptc(planner):
        def watch() -> bool:
            if planner.samples_drawn() == 38 and not seen:
                seen.append(planner.last_run_stats()["progress"][-1][1])
            return False
        return ob.plannerOrTerminationCondition(ob.timedPlannerTerminationCondition(60.0),
                                                ob.PlannerTerminationCondition(watch))

    _arm6_query1(138, [38], ptc)
    capped, _ = _arm6_query1(38)
    assert seen == [capped.last_run_stats()["best_cost"]]


def test_infinite_cost_threshold_means_first_solution() -> None:
    ss = make_planar_arm_setup()
    ss.getProblemDefinition().getOptimizationObjective().setCostThreshold(ob.Cost(math.inf))
    planner, status = _run(ss, seed=4, max_samples=CAP)
    stats = planner.last_run_stats()
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    assert stats["solutions_posted"] == 1 and stats["samples"] < CAP
    assert ss.getSolutionPath().length() == pytest.approx(stats["best_cost"])


def test_finite_cost_threshold_stops_once_satisfied() -> None:
    ss = make_planar_arm_setup()
    progress = _run(ss, seed=5, max_samples=CAP)[0].last_run_stats()["progress"]
    costs = [c for _, c, _ in progress if math.isfinite(c)]
    threshold = 0.5 * (costs[0] + costs[-1])  # halfway between the first and the final path
    ss.getProblemDefinition().getOptimizationObjective().setCostThreshold(ob.Cost(threshold))
    planner, status = _run(ss, seed=5, max_samples=CAP)
    stats = planner.last_run_stats()
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    assert stats["best_cost"] <= threshold and stats["samples"] < CAP


@pytest.mark.parametrize("objective", [LengthTimes100, PathLengthTimes100])
def test_another_objectives_threshold_is_asked_with_its_own_cost(objective, caplog: pytest.LogCaptureFixture) -> None:
    ss = make_planar_arm_setup()
    first = _run(ss, seed=5, max_samples=400)[0].last_run_stats()["progress"]
    length = next(c for _, c, _ in first if math.isfinite(c))
    opt = objective(ss.getSpaceInformation())
    opt.setCostThreshold(ob.Cost(2.0 * length))  # any path's length is below it; no path's cost (100 x length) is
    ss.setOptimizationObjective(opt)
    with caplog.at_level(logging.WARNING):
        planner, status = _run(ss, seed=5, max_samples=400)
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    assert planner.last_run_stats()["samples"] == 400  # never satisfied: the whole budget, not the first path
    assert "minimises path length" in caplog.text
    opt.setCostThreshold(ob.Cost(200.0 * length))  # the first path's cost satisfies this one
    planner, status = _run(ss, seed=5, max_samples=400)
    assert status == ob.PlannerStatus.EXACT_SOLUTION and planner.last_run_stats()["samples"] < 400


def test_callback_sees_every_posted_path_checked_and_improving() -> None:
    ss = make_planar_arm_setup()
    si = ss.getSpaceInformation()
    seen = []

    def callback(planner, states, cost):
        assert isinstance(planner, DimensionRRT) and isinstance(cost, ob.Cost)
        seen.append((cost.value(), path_passes_motion_checks(si, states)))

    planner = DimensionRRT(si, seed=6, max_samples=1500)
    planner.set_intermediate_solution_callback(callback)
    ss.setPlanner(planner)
    assert ss.solve(60.0) == ob.PlannerStatus.EXACT_SOLUTION
    stats = planner.last_run_stats()
    assert len(seen) == stats["solutions_posted"] >= 1
    assert all(ok for _, ok in seen)
    costs = [c for c, _ in seen]
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    assert costs[-1] == pytest.approx(stats["best_cost"]) == pytest.approx(ss.getSolutionPath().length())


def test_a_planner_run_after_a_path_was_posted_posts_only_shorter_ones() -> None:
    """The library pipeline runs dimension-RRT after posting its library path (``_known_cost``): the same search, its
    longer paths not posted (they were, 1 of 24 queries at 0.1 s, one 1.4x the library path's length)."""
    runs = []
    for known in (math.inf, None):
        ss = make_planar_arm_setup()
        costs = []
        planner = DimensionRRT(ss.getSpaceInformation(), seed=6, max_samples=1500)
        planner.set_intermediate_solution_callback(lambda p, states, cost: costs.append(cost.value()))
        if known is None:
            known = planner._known_cost = runs[0][0][len(runs[0][0]) // 2]  # noqa: SLF001
        ss.setPlanner(planner)
        assert ss.solve(60.0) == ob.PlannerStatus.EXACT_SOLUTION
        runs.append((costs, planner.last_run_stats()["best_cost"]))
    (all_costs, best), (shorter, best_again) = runs
    # (which intermediate paths are posted depends on the time posting took: 10 % of the run at most)
    assert len(all_costs) >= 3 and all_costs[0] > known and shorter and max(shorter) < known and best_again == best


def test_raising_callback_is_logged_and_planning_goes_on(caplog) -> None:
    ss = make_planar_arm_setup()
    calls = []

    def callback(*args):
        calls.append(args)
        raise RuntimeError("boom")

    planner = DimensionRRT(ss.getSpaceInformation(), seed=6, max_samples=800)
    planner.set_intermediate_solution_callback(callback)
    ss.setPlanner(planner)
    with caplog.at_level(logging.ERROR):
        assert ss.solve(60.0) == ob.PlannerStatus.EXACT_SOLUTION
    assert len(calls) == 1 and "callback raised" in caplog.text
    with pytest.raises(ValueError, match="callable"):
        planner.set_intermediate_solution_callback(3)


def test_solve_without_problem_definition_is_a_clear_abort(caplog) -> None:
    ss = make_planar_arm_setup()
    planner = DimensionRRT(ss.getSpaceInformation(), max_samples=10)
    with caplog.at_level(logging.ERROR):
        status = ob.Planner.solve(planner, 1.0)
    assert status == ob.PlannerStatus.ABORT
    assert "no problem definition" in caplog.text and "Traceback" not in caplog.text
    assert all(r.exc_info is None for r in caplog.records)


def test_unbounded_real_vector_space_is_refused_at_construction() -> None:
    si = ob.SpaceInformation(ob.RealVectorStateSpace(2))
    with pytest.raises(ValueError, match="bounds"):
        DimensionRRT(si)


@pytest.mark.parametrize("groups", [[[0, 1], [2, 3], [4, 5]], [[0, 1, 2], [3, 4, 5]], [[5, 0], [1, 4], [2], [3]]])
def test_six_joint_arm_with_several_planned_groups_gets_a_path(groups) -> None:
    ss = planar_arm_setup(6)
    si = ss.getSpaceInformation()
    pdef = ss.getProblemDefinition()
    assert not si.checkMotion(*ss.endpoint_states)  # the straight motion is blocked
    ptc = ob.plannerOrTerminationCondition(ob.exactSolnPlannerTerminationCondition(pdef),
                                           ob.timedPlannerTerminationCondition(60.0))
    planner, status = _run(ss, ptc, groups=groups, seed=0, max_samples=2000)
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    assert path_passes_motion_checks(si, ss.getSolutionPath())


def test_continuous_joints_plan_across_plus_minus_pi() -> None:
    # start and goal either side of +-pi: the short way (0.6 rad) crosses the wrap, the long way 5.7 rad
    ss = planar_arm_setup(3, start=(2.9, 0.2, 0.0), goal=(-2.9, 0.2, 0.0), obstacles=((5.0, 5.0, 0.1),),
                          continuous=True)
    planner, status = _run(ss, seed=0, max_samples=200)
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    path = ss.getSolutionPath()
    assert path_passes_motion_checks(ss.getSpaceInformation(), path)
    assert path.length() == pytest.approx(2 * math.pi - 5.8, abs=1e-9)
    assert planner.last_run_stats()["best_cost"] == pytest.approx(path.length())


def test_continuous_joints_with_a_prescribed_row_are_shortcut_the_short_way_round() -> None:
    # joint 0 prescribed across +-pi (2.9 -> -2.9, 0.58 rad the short way), joints 1 and 2 planned from a
    # guess with a detour, free space: the shortcuts take the path close to the shortest along the row
    ss = planar_arm_setup(3, start=(2.9, 0.8, -0.5), goal=(-2.9, -0.6, 0.7), obstacles=((5.0, 5.0, 0.1),),
                          continuous=True)
    step = 2 * math.pi - 5.8
    row = np.mod(2.9 + np.linspace(0.0, step, 7) + math.pi, 2 * math.pi) - math.pi
    guess = np.column_stack([row, np.linspace(0.8, -0.6, 7), np.linspace(-0.5, 0.7, 7)])
    guess[2:5, 1] += 0.5  # a detour of joint 1
    planner, status = _run(ss, seed=0, max_samples=300, groups=[[0], [1, 2]], prescribed={0: row[:, None]},
                           initial_waypoints=guess)
    assert status == ob.PlannerStatus.EXACT_SOLUTION and planner.settings()["shortcuts"] == "True"
    path = ss.getSolutionPath()
    assert path_passes_motion_checks(ss.getSpaceInformation(), path)
    values = np.array([[s[k].value for k in range(3)] for s in path.getStates()])
    assert np.all((values >= -math.pi) & (values < math.pi))
    bound = step + 1.4 + 1.2  # the compound's metric: the sum of the joints' distances
    assert planner.last_run_stats()["progress"][0][1] > bound + 0.5  # the guess, posted first
    assert bound - 1e-9 < path.length() < bound + 0.05  # the detour's 0.53 rad nearly gone (seeds 0-4 of the
    # paper's rule alone leave 0-0.33)


def test_solved_without_setup_it_sets_the_space_up_as_ompls_planners_do() -> None:
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: not (0.4 < s[0] < 0.6 and s[1] < 0.7))
    si = ss.getSpaceInformation()
    ss.setStartAndGoalStates(set_state(si.allocState(), (0.1, 0.1)), set_state(si.allocState(), (0.9, 0.1)))
    assert not si.isSetup()
    planner = DimensionRRT(si, seed=3, max_samples=300)
    planner.setProblemDefinition(ss.getProblemDefinition())
    assert ob.Planner.solve(planner, 10.0) == ob.PlannerStatus.EXACT_SOLUTION
    assert si.isSetup()
    assert path_passes_motion_checks(si, ss.getProblemDefinition().getSolutionPath())


def test_max_h_below_h_is_refused_naming_it() -> None:
    ss = make_planar_arm_setup()
    with pytest.raises(ValueError, match="max_h must be at least h"):
        DimensionRRT(ss.getSpaceInformation(), h=7, max_h=5)



def _wall_checker_setup(are_valid) -> og.SimpleSetup:
    """A 2-D wall problem whose checker has a method named ``are_valid`` (given) beside ``isValid``."""
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)

    class Checker(ob.StateValidityChecker):
        def isValid(self, s: ob.State) -> bool:
            return not (0.4 < s[0] < 0.6 and s[1] < 0.7)

    Checker.are_valid = are_valid
    si = ss.getSpaceInformation()
    ss._checker = Checker(si)  # referenced from Python, or it is collected
    ss.setStateValidityChecker(ss._checker)
    ss.setStartAndGoalStates(set_state(si.allocState(), (0.1, 0.1)), set_state(si.allocState(), (0.9, 0.1)))
    return ss


@pytest.mark.parametrize("are_valid", [
    lambda self, states: all(self.isValid(s) for s in states),  # "are all of these valid?": one bool
    lambda self, states: [self.isValid(s) for s in states if isinstance(s, ob.State)],  # for OMPL states only
    lambda self, Q: np.zeros(len(Q), dtype=bool),  # disagrees with isValid on the start
    lambda self, Q, margin: np.ones(len(Q), dtype=bool),  # other arguments
], ids=["all-valid", "ompl-states", "disagrees", "arguments"])
def test_a_checker_method_named_are_valid_that_is_not_the_batched_call_is_passed_over_with_a_warning(
        are_valid, caplog: pytest.LogCaptureFixture) -> None:
    """A user's checker with a helper of that name meaning something else made every solve CRASH (the name alone
    made the search take it for the batched call): it is asked once, on the start, and passed over with a warning
    naming it; the states are then checked one by one, as RRTConnect checks them."""
    ss = _wall_checker_setup(are_valid)
    with caplog.at_level(logging.WARNING):
        planner, status = _run(ss, seed=0, max_samples=300)
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    assert caplog.text.count("the validity checker's are_valid (Checker)") == 1
    assert path_passes_motion_checks(ss.getSpaceInformation(), ss.getSolutionPath().getStates())


@pytest.mark.parametrize("answer", [lambda ok: ok.astype(np.int8), lambda ok: ok.tolist(), lambda ok: ok.astype(int)])
def test_a_batched_call_answering_zeros_and_ones_is_taken_and_asked_once_per_checker(answer, caplog,
                                                                                     monkeypatch) -> None:
    """The probe wanted a bool array: an int8 or 0/1 answer, which the search reads as booleans, was refused with a
    warning on every solve (and the states checked one by one)."""
    from tpee_ompl.planning import search_checker

    probes: list[bool] = []
    real = search_checker._answers_per_row
    monkeypatch.setattr(search_checker, "_answers_per_row", lambda *a: probes.append(real(*a)) or probes[-1])

    def are_valid(self, Q):
        Q = np.atleast_2d(Q)
        calls.append(len(Q))
        return answer(~((0.4 < Q[:, 0]) & (Q[:, 0] < 0.6) & (Q[:, 1] < 0.7)))

    calls: list[int] = []
    ss = _wall_checker_setup(are_valid)
    with caplog.at_level(logging.WARNING):
        for _ in range(2):
            assert _run(ss, seed=0, max_samples=300)[1] == ob.PlannerStatus.EXACT_SOLUTION
    assert probes == [True] and "are_valid" not in caplog.text and len(calls) > 10  # taken; asked once


def test_a_batched_call_that_passes_what_is_valid_rejects_is_said_once_per_solve(
        caplog: pytest.LogCaptureFixture) -> None:
    """An are_valid that says True to everything (right for the start) had the search accept paths si.checkMotion
    then rejected, each logged: over 100 warnings in 0.3 s.  One per solve now, naming the likely cause; every
    path posted passed si.checkMotion all the same."""
    ss = _wall_checker_setup(lambda self, Q: np.ones(len(Q), dtype=bool))
    with caplog.at_level(logging.WARNING):
        planner, status = _run(ss, seed=0, max_samples=2000)
    assert caplog.text.count("rejected a path the search accepted") == 1
    assert "is the checker's are_valid the same test as its isValid?" in caplog.text
    if status == ob.PlannerStatus.EXACT_SOLUTION:
        assert path_passes_motion_checks(ss.getSpaceInformation(), ss.getSolutionPath().getStates())


def test_a_batched_checker_answering_the_wrong_shape_later_is_named_in_the_error(
        caplog: pytest.LogCaptureFixture) -> None:
    """Right for the start alone, one answer too many for several states: the run ends in CRASH naming it."""
    ss = _wall_checker_setup(lambda self, Q: np.ones(len(Q) + (len(Q) > 1), dtype=bool))
    with caplog.at_level(logging.ERROR):
        status = _run(ss, seed=0, max_samples=50)[1]
    assert status == ob.PlannerStatus.CRASH
    assert "are_valid returned shape" in caplog.text


def _wall_setup(bound: float) -> og.SimpleSetup:
    """3-D box with a wall at x = 0 whose only way round lies at |y| or |z| > 1.2."""
    space = ob.RealVectorStateSpace(3)
    space.setBounds(-bound, bound)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: not (abs(s[0]) < 0.1 and abs(s[1]) < 1.2 and abs(s[2]) < 1.2))
    si = ss.getSpaceInformation()
    start, goal = si.allocState(), si.allocState()
    set_state(start, [-0.5, 0.0, 0.0])
    set_state(goal, [0.5, 0.0, 0.0])
    ss.setStartAndGoalStates(start, goal)
    return ss


def test_a_planner_built_before_the_bounds_widened_plans_in_the_new_bounds() -> None:
    ss = _wall_setup(1.0)  # no way round inside [-1, 1]^3
    planner = DimensionRRT(ss.getSpaceInformation(), seed=0, max_samples=CAP)
    ss.getStateSpace().setBounds(-2.0, 2.0)  # as OMPL's planners, it plans in the bounds of solve time
    ss.setPlanner(planner)
    assert ss.solve(ob.timedPlannerTerminationCondition(60.0)) == ob.PlannerStatus.EXACT_SOLUTION
    assert path_passes_motion_checks(ss.getSpaceInformation(), ss.getSolutionPath())
    assert np.max(np.abs(planner.grouped.layout.upper)) == 2.0


def test_bounds_that_leave_the_initial_waypoints_outside_abort_with_a_reason(caplog) -> None:
    ss = _wall_setup(2.0)
    W = np.linspace([-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], 7)
    W[1:-1, 1] = 1.5  # round the wall
    planner = DimensionRRT(ss.getSpaceInformation(), seed=0, max_samples=CAP, initial_waypoints=W)
    ss.getStateSpace().setBounds(-1.0, 1.0)
    ss.setPlanner(planner)
    with caplog.at_level(logging.ERROR):
        status = ss.solve(ob.timedPlannerTerminationCondition(5.0))
    assert status == ob.PlannerStatus.ABORT and not ss.haveSolutionPath()
    assert "bounds changed" in caplog.text and "initial_waypoints lie outside" in caplog.text


_CALLBACK_SCRIPT = """
import numpy as np
from ompl import base as ob, geometric as og
from tpee_ompl import WearerArm, make_simple_setup, posture_preset, tpee_dimension_rrt
robot = WearerArm()
ss = make_simple_setup(robot, np.r_[posture_preset(1), 0.0, 0.0], np.r_[posture_preset(4), 0.0, 0.0])
planner = og.RRTstar(ss.getSpaceInformation())
ss.setPlanner(planner)
ss.solve(ob.PlannerTerminationCondition(lambda: planner.numIterations() >= 20))
path = ss.getSolutionPath()
planner = tpee_dimension_rrt(ss.getSpaceInformation(), 1, 4, max_samples=100, seed=0)
ss.setPlanner(planner)
ss.solve(5.0)
planner.set_intermediate_solution_callback(lambda p, states, cost: None)
"""


def test_a_script_that_keeps_its_callback_set_exits_without_leak_warnings(tmp_path) -> None:
    # the callback refers to the script's globals, which hold the planner: nanobind used to report leaked
    # instances at exit (the README's example, run as a script after "In fifteen lines")
    script = tmp_path / "callback.py"
    script.write_text(_CALLBACK_SCRIPT)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120,
                          cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])})
    assert done.returncode == 0, done.stderr
    assert "leaked" not in done.stderr


def test_initial_waypoints_set_after_the_bounds_widened_are_checked_against_the_new_bounds() -> None:
    ss = _wall_setup(1.0)
    planner = DimensionRRT(ss.getSpaceInformation(), seed=0, max_samples=CAP)
    ss.getStateSpace().setBounds(-2.0, 2.0)
    W = np.linspace([-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], 7)
    W[1:-1, 1] = 1.5  # round the wall, outside the bounds the planner was built with
    planner.set_initial_waypoints(W)  # was refused: checked against the old bounds
    ss.setPlanner(planner)
    assert ss.solve(ob.timedPlannerTerminationCondition(60.0)) == ob.PlannerStatus.EXACT_SOLUTION


@pytest.mark.parametrize("groups", [None, [[0, 1, 2]], [[0], [1, 2]], [[2], [0, 1]]])
def test_a_dimension_locked_by_bounds_of_width_zero_keeps_its_value_for_every_grouping(groups) -> None:
    """Bounds of width 0 lock a joint for OMPL's planners (RRTConnect planned the space; DimensionRRT refused it):
    the locked dimension keeps its value on every waypoint, whether it is grouped with others or alone."""
    from tests.helpers.planning_spaces import locked_dimension_space

    ss = og.SimpleSetup(locked_dimension_space(3, 2, value=0.3))
    ss.setStateValidityChecker(lambda s: not (-0.1 < s[0] < 0.1 and s[1] > -0.6))
    si = ss.getSpaceInformation()
    ss.setStartAndGoalStates(set_state(si.allocState(), (-0.8, 0.8, 0.3)), set_state(si.allocState(), (0.8, 0.8, 0.3)))
    planner, status = _run(ss, seed=1, max_samples=600, **({} if groups is None else {"groups": groups}))
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    path = ss.getSolutionPath()
    assert path_passes_motion_checks(si, path.getStates(), in_bounds=True)
    assert all(s[2] == 0.3 for s in path.getStates())
    assert path.length() < 4.0  # round the wall's end (straight-line bound 3.1), not along the bounds
