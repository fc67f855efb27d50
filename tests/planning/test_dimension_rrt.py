"""DimensionRRT on the TPEE problem: validity on all 12 pair types, anytime, seeding, statuses, Benchmark."""

from __future__ import annotations

import contextlib
import io
import math
import sqlite3

import numpy as np
import pytest
from ompl import base as ob
from ompl import tools as ot

from tpee_ompl.examples.planar_arm import make_planar_arm_setup
from tpee_ompl.examples.tpee_queries import cross_sector_query
from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.sectors import SECTOR_PAIRS
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.paths import path_passes_motion_checks, path_to_array
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.planning.tpee import tpee_dimension_rrt

SAMPLES = 300


def _solve(robot: WearerArm, i: int, j: int, q0: np.ndarray, q1: np.ndarray, **kw):
    ss = make_simple_setup(robot, q0, q1)
    planner = tpee_dimension_rrt(ss.getSpaceInformation(), i, j, **kw)
    ss.setPlanner(planner)
    status = ss.solve(30.0)
    return ss, planner, status


def test_valid_paths_on_all_12_pair_types(robot: WearerArm) -> None:
    rng = np.random.default_rng(7)
    for i, j in SECTOR_PAIRS:
        q0, q1 = cross_sector_query(robot, i, j, rng)
        ss, planner, status = _solve(robot, i, j, q0, q1, max_samples=SAMPLES, seed=3)
        assert status == ob.PlannerStatus.EXACT_SOLUTION, (i, j)
        path = ss.getSolutionPath()
        assert path_passes_motion_checks(ss.getSpaceInformation(), path), (i, j)
        W = path_to_array(path, 4)
        assert W.shape == (7, 4)
        np.testing.assert_allclose(W[0], q0)
        np.testing.assert_allclose(W[-1], q1)
        np.testing.assert_allclose(W[:, :2], planner.prescribed[0])  # DOF1/DOF2 follow Table 3
        stats = planner.last_run_stats()
        assert stats["samples"] == SAMPLES and stats["collision_checks"] > 0
        assert stats["best_cost"] == pytest.approx(path.length())
        costs = [c for _, c, _ in stats["progress"]]
        assert all(b <= a for a, b in zip(costs, costs[1:])), "best cost increased"
        times = [t for t, _, _ in stats["progress"]]
        assert times == sorted(times)


def test_cost_never_increases_and_improves(robot: WearerArm) -> None:
    q0, q1 = cross_sector_query(robot, 1, 4, np.random.default_rng(1))
    _, planner, _ = _solve(robot, 1, 4, q0, q1, max_samples=800, seed=0)
    prog = planner.last_run_stats()["progress"]
    costs = np.array([c for _, c, _ in prog])
    finite = costs[np.isfinite(costs)]
    assert len(finite) > 1 and np.all(np.diff(finite) <= 0) and finite[-1] < finite[0]
    assert prog[-1][2] == 800


def test_same_seed_and_sample_cap_give_identical_path(robot: WearerArm) -> None:
    q0, q1 = cross_sector_query(robot, 4, 1, np.random.default_rng(2))
    paths = [path_to_array(_solve(robot, 4, 1, q0, q1, max_samples=200, seed=11)[0].getSolutionPath(), 4) for _ in range(2)]
    np.testing.assert_array_equal(paths[0], paths[1])


def test_valid_initial_waypoints_are_the_first_solution_and_only_get_shorter(robot: WearerArm) -> None:
    q0, q1 = cross_sector_query(robot, 1, 3, np.random.default_rng(5))
    ss, _, _ = _solve(robot, 1, 3, q0, q1, max_samples=SAMPLES, seed=2)
    W = path_to_array(ss.getSolutionPath(), 4)
    ss2, planner2, status = _solve(robot, 1, 3, q0, q1, max_samples=1, seed=9, initial_waypoints=W)
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    stats = planner2.last_run_stats()
    assert stats["first_solution_time"] is not None and stats["progress"][0][1] == pytest.approx(ss.getSolutionPath().length())
    assert ss2.getSolutionPath().length() <= ss.getSolutionPath().length() + 1e-12
    assert planner2.settings()["initial_waypoints"] == "set"


def test_invalid_initial_waypoints_are_checked_not_trusted(robot: WearerArm) -> None:
    q0, q1 = cross_sector_query(robot, 4, 2, np.random.default_rng(6))
    ss = make_simple_setup(robot, q0, q1)
    planner = tpee_dimension_rrt(ss.getSpaceInformation(), 4, 2, max_samples=SAMPLES, seed=1)
    W = planner.grouped.initial_waypoints(q0, q1)
    W[1:-1, 2:] = 0.0  # pan/tilt straight ahead at every intermediate step, through whatever is there
    planner.set_initial_waypoints(W)
    ss.setPlanner(planner)
    assert ss.solve(30.0) == ob.PlannerStatus.EXACT_SOLUTION
    assert path_passes_motion_checks(ss.getSpaceInformation(), ss.getSolutionPath())
    np.testing.assert_allclose(path_to_array(ss.getSolutionPath(), 4)[:, :2], planner.prescribed[0])
    planner.set_initial_waypoints(None)
    assert planner.settings()["initial_waypoints"] == "none"


def test_batched_and_per_state_checks_agree(robot: WearerArm) -> None:
    q0, q1 = cross_sector_query(robot, 2, 3, np.random.default_rng(3))
    a = _solve(robot, 2, 3, q0, q1, max_samples=150, seed=5)[0].getSolutionPath()
    b = _solve(robot, 2, 3, q0, q1, max_samples=150, seed=5, batch=False)[0].getSolutionPath()
    np.testing.assert_array_equal(path_to_array(a, 4), path_to_array(b, 4))


def test_screened_motion_checks_give_the_same_path_with_fewer_checks(robot: WearerArm) -> None:
    q0, q1 = cross_sector_query(robot, 2, 3, np.random.default_rng(3))
    out = []
    for levels in ((2.0, 1.0), ()):
        ss = make_simple_setup(robot, q0, q1)
        ss.getSpaceInformation().getMotionValidator().screen_levels = levels
        ss.setPlanner(tpee_dimension_rrt(ss.getSpaceInformation(), 2, 3, max_samples=300, seed=5))
        c0 = robot.collision_checks
        assert ss.solve(30.0) == ob.PlannerStatus.EXACT_SOLUTION
        out.append((path_to_array(ss.getSolutionPath(), 4), robot.collision_checks - c0))
    np.testing.assert_array_equal(out[0][0], out[1][0])
    assert out[0][1] < out[1][1]


def test_runs_inside_ompl_benchmark(robot: WearerArm, tmp_path) -> None:
    q0, q1 = cross_sector_query(robot, 3, 2, np.random.default_rng(4))
    ss = make_simple_setup(robot, q0, q1)
    planner = tpee_dimension_rrt(ss.getSpaceInformation(), 3, 2, max_samples=150, seed=1)
    bench = ot.Benchmark(ss, "dimension_rrt")
    bench.addPlanner(planner)
    req = ot.Request(maxTime=5.0, maxMem=1000.0, runCount=3, displayProgress=False, saveConsoleOutput=False, simplify=False)
    bench.benchmark(req)
    log = tmp_path / "b.log"
    bench.saveResultsToFile(str(log))
    db = tmp_path / "b.db"
    with contextlib.redirect_stdout(io.StringIO()):
        ot.readBenchmarkLog(str(db), [str(log)], False)
    with sqlite3.connect(db) as con:
        rows = con.execute("SELECT correct_solution, solved FROM runs").fetchall()
    assert rows == [(1, 1)] * 3


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"groups": [[0, 1], [1, 2, 3]]}, "more than one group"),
        ({"groups": [[0, 1], [2]]}, "in no group"),
        ({"groups": [[0, 1], [2, 7]]}, "out of range"),
        ({"groups": [[0, 1], []]}, "non-empty"),
        ({"h": 2}, "h"),
        ({"max_samples": 0}, "max_samples"),
        ({"narrowing": 0.0}, "narrowing"),
        ({"narrowing": 1.5}, "narrowing"),
        ({"narrow_after": -1}, "narrow_after"),
        ({"range_": -0.1}, "range_"),
        ({"shortcuts": "yes"}, "shortcuts"),
        ({"seed": -3}, "seed"),
        ({"prescribed": {0: np.zeros((5, 2))}}, "shape"),
        ({"prescribed": {4: np.zeros((7, 2))}}, "not a group index"),
        ({"initial_waypoints": np.zeros((5, 4))}, "initial_waypoints must have shape"),
        ({"initial_waypoints": np.full((7, 4), np.nan)}, "NaN"),
        ({"initial_waypoints": np.full((7, 4), 100.0)}, "outside the state space bounds"),
    ],
)
def test_bad_parameters_raise(robot: WearerArm, kwargs: dict, match: str) -> None:
    ss = make_simple_setup(robot)
    with pytest.raises(ValueError, match=match):
        DimensionRRT(ss.getSpaceInformation(), **kwargs)


def _status_of(ss, planner) -> ob.PlannerStatus:
    ss.setPlanner(planner)
    return ss.solve(5.0)


def test_invalid_start_and_goal_statuses(robot: WearerArm) -> None:
    q0, q1 = cross_sector_query(robot, 1, 2, np.random.default_rng(5))
    bad = np.array([0.0, 0.0, 0.0, 0.0])  # arm folded into the wearer
    assert not robot.is_valid(bad)
    for start, goal, want in ((bad, q1, ob.PlannerStatus.INVALID_START), (q0, bad, ob.PlannerStatus.INVALID_GOAL)):
        ss = make_simple_setup(robot, start, goal, check_endpoints=False)
        planner = DimensionRRT(ss.getSpaceInformation(), max_samples=10)
        assert _status_of(ss, planner) == want
        assert not ss.haveSolutionPath()


def test_an_invalid_start_is_reported_by_ompl_once(robot: WearerArm, capfd) -> None:
    """OMPL's "Skipping invalid start state" warning came twice: the start states were restarted after it."""
    from ompl import util as ou

    q0, q1 = cross_sector_query(robot, 1, 2, np.random.default_rng(5))
    ss = make_simple_setup(robot, np.zeros(4), q1, check_endpoints=False)
    level = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_WARN)
    try:
        capfd.readouterr()
        assert _status_of(ss, DimensionRRT(ss.getSpaceInformation(), max_samples=10)) == ob.PlannerStatus.INVALID_START
        assert capfd.readouterr().err.count("Skipping invalid start state") == 1
    finally:
        ou.setLogLevel(level)


def test_a_path_as_short_as_the_start_goal_distance_ends_the_search() -> None:
    """Nothing is shorter than the straight start-goal distance: start = goal, or a free direct motion without a
    prescribed group, used the whole time budget (0.3 of 0.3 s, where RRTConnect returns at once)."""
    for start, goal in (((0.3, 0.2, 0, 0), (0.3, 0.2, 0, 0)), ((0.3, 0.2, 0, 0), (0.5, 0.1, 0.2, 0))):
        ss = make_planar_arm_setup(start=start, goal=goal, obstacles=((5.0, 5.0, 0.1),))  # far out of reach
        planner = DimensionRRT(ss.getSpaceInformation(), seed=0)
        ss.setPlanner(planner)
        assert ss.solve(30.0) == ob.PlannerStatus.EXACT_SOLUTION
        assert planner.last_run_stats()["samples"] == 0
        assert ss.getSolutionPath().length() == pytest.approx(np.linalg.norm(np.subtract(goal, start)), abs=1e-12)


def test_start_off_the_prescribed_trajectory_is_invalid_start(robot: WearerArm) -> None:
    q0, q1 = cross_sector_query(robot, 1, 2, np.random.default_rng(6))
    ss = make_simple_setup(robot, q0, q1)
    planner = tpee_dimension_rrt(ss.getSpaceInformation(), 3, 2, max_samples=10)  # wrong Table 3 row
    assert _status_of(ss, planner) == ob.PlannerStatus.INVALID_START


def test_no_solution_times_out_without_a_path() -> None:
    # planar arm whose prescribed joint-0 trajectory puts link 1 through an obstacle at step 3
    ss = make_planar_arm_setup(start=(-1.0, 0, 0, 0), goal=(1.0, 0, 0, 0), obstacles=((0.25, 0.0, 0.05),))
    prescribed = {0: np.c_[np.linspace(-1.0, 1.0, 7), np.zeros(7)]}
    planner = DimensionRRT(ss.getSpaceInformation(), prescribed=prescribed, max_samples=100, seed=0)
    ss.setPlanner(planner)
    assert ss.solve(10.0) == ob.PlannerStatus.TIMEOUT
    assert not ss.haveSolutionPath()
    stats = planner.last_run_stats()
    assert stats["best_cost"] == math.inf and stats["first_solution_time"] is None
    assert stats["samples"] == 100


def test_settings_and_stats_shape(robot: WearerArm) -> None:
    ss = make_simple_setup(robot)
    planner = tpee_dimension_rrt(ss.getSpaceInformation(), 1, 2, max_samples=500, seed=2)
    settings = planner.settings()
    assert settings["h"] == "7" and settings["max_samples"] == "500" and settings["groups"] == "[[0, 1], [2, 3]]"
    assert all(isinstance(v, str) for v in settings.values())
    assert set(planner.last_run_stats()) == {
        "samples", "h", "collision_checks", "first_solution_time", "best_cost", "iterations", "progress",
        "solutions_posted", "released_at", "goals", "restarts",
    }
    assert settings["max_h"] == "None"


def test_stall_samples_stop_a_converged_run_before_its_cap(robot: WearerArm) -> None:
    q = load_queries("planning_necessary")[0]
    ss = make_simple_setup(robot, q.start, q.goal)
    planner = tpee_dimension_rrt(ss.getSpaceInformation(), q.from_sector, q.to_sector, max_samples=20000, seed=3,
                                 stall_samples=200)
    ss.setPlanner(planner)
    assert ss.solve(60.0) == ob.PlannerStatus.EXACT_SOLUTION
    stats = planner.last_run_stats()
    improvements = [n for (_, c0, _), (_, c1, n) in zip(stats["progress"], stats["progress"][1:]) if c1 < c0]
    assert stats["samples"] < 20000
    assert stats["samples"] == max(improvements, default=0) + 200  # exactly `stall` samples after the last gain
    with pytest.raises(ValueError, match="stall_samples"):
        tpee_dimension_rrt(ss.getSpaceInformation(), 1, 2, stall_samples=0)


def test_released_wearer_search_gives_one_path_whatever_the_call_sizes_and_the_hits_check(
        robot: WearerArm, monkeypatch: pytest.MonkeyPatch) -> None:
    """The released search on the wearer (one group of every DOF, the lone candidates' screens, the hits'
    states checked ahead, sweeps): the same capped path with one sample per call, with sample checkpoints
    every 37 samples and with the hits' check off."""
    from tpee_ompl.planning import goal_loop, search_draws

    q = load_queries("planning_necessary")[1]
    ss = make_simple_setup(robot, q.start, q.goal)

    def path(checkpoints: bool = False) -> np.ndarray:
        planner = tpee_dimension_rrt(ss.getSpaceInformation(), q.from_sector, q.to_sector, max_samples=2500,
                                     seed=2, release_after=50)
        if checkpoints:
            planner.set_sample_checkpoints(range(37, 2500, 37))
        ss.clear()
        ss.setPlanner(planner)
        assert ss.solve(60.0) == ob.PlannerStatus.EXACT_SOLUTION
        assert planner.last_run_stats()["released_at"] is not None
        return path_to_array(ss.getSolutionPath(), robot.nq)

    ref = path()
    np.testing.assert_array_equal(path(checkpoints=True), ref)
    with monkeypatch.context() as m:
        m.setattr(search_draws.SampleDraws, "_hit_states", lambda self, S, last: {})
        np.testing.assert_array_equal(path(), ref)
    with monkeypatch.context() as m:
        m.setattr(goal_loop, "PASS_BATCH", 1)
        np.testing.assert_array_equal(path(), ref)


def test_a_condition_on_samples_drawn_stops_the_connect_trees_at_that_sample() -> None:
    """The connect trees ask the termination condition before each sample, but samples_drawn() was counted only
    after their batch: ``samples_drawn() >= 1`` let 47 samples through (a plain 2-D wall problem)."""
    from ompl import geometric as og

    space = ob.RealVectorStateSpace(2)
    space.setBounds(-1.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: not (-0.1 < s[0] < 0.1 and s[1] > -0.6))
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = -0.8, 0.8, 0.8, 0.8
    ss.setStartAndGoalStates(start, goal)
    for n in (1, 3, 10):
        planner = DimensionRRT(ss.getSpaceInformation(), seed=1)
        ss.clear()
        ss.setPlanner(planner)
        seen: list[int] = []
        ptc = ob.PlannerTerminationCondition(lambda: seen.append(planner.samples_drawn()) or seen[-1] >= n)
        assert ss.solve(ptc) == ob.PlannerStatus.TIMEOUT  # (the wall needs more samples)
        assert planner.last_run_stats()["samples"] == n and seen == sorted(seen) and seen[-1] == n


def test_termination_condition_is_asked_at_each_sample_checkpoint_and_between_batches(robot: WearerArm) -> None:
    q = load_queries("planning_necessary")[1]
    ss = make_simple_setup(robot, q.start, q.goal)
    planner = tpee_dimension_rrt(ss.getSpaceInformation(), q.from_sector, q.to_sector, max_samples=1500, seed=4)
    planner.set_sample_checkpoints([300, 777, 1000])
    ss.setPlanner(planner)
    seen: list[int] = []
    ptc = ob.PlannerTerminationCondition(lambda: seen.append(planner.samples_drawn()) or False)
    assert ss.solve(ptc) == ob.PlannerStatus.EXACT_SOLUTION
    assert {300, 777, 1000} <= set(seen) and seen == sorted(seen)
    assert len(seen) < 1500 and planner.samples_drawn() == 1500  # rejected samples are passed over in batches
    cost = planner.last_run_stats()["best_cost"]
    same = tpee_dimension_rrt(ss.getSpaceInformation(), q.from_sector, q.to_sector, max_samples=1500, seed=4)
    ss.clear()
    ss.setPlanner(same)
    ss.solve(30.0)
    assert same.last_run_stats()["best_cost"] == cost  # the stops change nothing
    with pytest.raises(ValueError, match="sample checkpoint"):
        planner.set_sample_checkpoints([0])


@pytest.mark.parametrize("connect", [True, False], ids=["connect-trees", "layered-trees"])
def test_the_first_path_does_not_depend_on_how_the_planned_dofs_are_grouped(connect: bool) -> None:
    """The feasibility phase varies every planned DOF at once; its samples take the DOFs in index order, so
    the same seed finds the same first path whether the groups are [[0, 1], [2, 3]], [[0, 2], [1, 3]] or one."""
    paths = []
    for groups in ([[0, 1], [2, 3]], [[0, 2], [1, 3]], [[3, 1], [2, 0]], [[0, 1, 2, 3]]):
        ss = make_planar_arm_setup()
        planner = DimensionRRT(ss.getSpaceInformation(), groups=groups, seed=4, connect=connect, max_samples=3000)
        ss.setPlanner(planner)
        assert ss.solve(ob.exactSolnPlannerTerminationCondition(ss.getProblemDefinition()))
        paths.append(path_to_array(ss.getSolutionPath(), 4))
        assert planner.last_run_stats()["solutions_posted"] == 1
    for W in paths[1:]:
        np.testing.assert_array_equal(W, paths[0])


def test_settings_fixed_at_construction_refuse_assignment_instead_of_being_ignored() -> None:
    """p.h = 4 changed settings() (what a benchmark records) while the search went on with h = 7; p.range_ = 0.05
    (a number, as DimensionRRTOptions takes it) made every solve CRASH, p.narrowing = 5.0 overflowed mid-run, and
    p.batch = "x" was recorded as it was."""
    ss = make_planar_arm_setup()
    planner = DimensionRRT(ss.getSpaceInformation(), seed=3)
    for name, value in (("h", 4), ("seed", 5), ("groups", [[0, 1, 2, 3]]), ("prescribed", {}),
                        ("options", planner.options), ("range_", 0.05), ("narrowing", 5.0), ("narrow_after", -5),
                        ("batch", "x"), ("shortcuts", "x")):
        with pytest.raises(AttributeError, match=f"pass {name}="):
            setattr(planner, name, value)
    with pytest.raises(ValueError, match="read-only"):
        planner.range_[:] = 0.0  # (it changed the planner's own array)
    with pytest.raises(ValueError, match="max_samples"):
        planner.max_samples = -5  # was a silent TIMEOUT with 0 samples
    assert planner.h == 7 and planner.seed == 3 and planner.settings()["h"] == "7"
    planner.max_samples = 50  # read at every solve: honoured
    ss.setPlanner(planner)
    ss.solve(10.0)
    assert planner.last_run_stats()["samples"] <= 50


def test_a_run_ended_by_a_raising_validity_checker_still_reports_what_it_posted() -> None:
    """The statistics were written after the loop only: a crash left 'nothing posted' beside an exact path in pdef."""
    ss = make_planar_arm_setup()
    checker = ss.getStateValidityChecker()
    calls = {"n": 0}

    class Failing(ob.StateValidityChecker):
        def isValid(self, state):  # noqa: N802 (OMPL override)
            calls["n"] += 1
            if calls["n"] > 3000:
                raise RuntimeError("the checker broke")
            return checker.isValid(state)

    si = ss.getSpaceInformation()
    failing = Failing(si)
    ss.setStateValidityChecker(failing)
    planner = DimensionRRT(si, seed=0, batch=False)
    ss.setPlanner(planner)
    status = ss.solve(30.0)
    stats = planner.last_run_stats()
    assert status == ob.PlannerStatus.CRASH and ss.haveExactSolutionPath()  # a path was posted before the crash
    assert stats["solutions_posted"] >= 1 and stats["first_solution_time"] is not None
    assert stats["best_cost"] == pytest.approx(ss.getProblemDefinition().getSolutionPath().length())


@pytest.mark.parametrize("options", ["x", 3, {"h": 7}])
def test_tpee_options_that_are_not_an_options_object_are_named_in_the_error(robot: WearerArm, options) -> None:
    ss = make_simple_setup(robot)
    with pytest.raises(ValueError, match="^options must be a DimensionRRTOptions"):
        tpee_dimension_rrt(ss.getSpaceInformation(), 1, 2, options=options)
