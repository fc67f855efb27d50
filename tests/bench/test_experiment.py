"""One query's experiments: path metrics, the experiment list and log names."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from ompl import base as ob

from tpee_ompl.bench.config import CampaignConfig
from tpee_ompl.bench.experiment import experiment_specs, group_lengths, log_name


def test_group_lengths_split_the_joint_space_path():
    W = np.array([[0, 0, 0, 0], [3, 4, 0, 0], [3, 4, 1, 0]], dtype=float)
    assert group_lengths(W) == pytest.approx((6.0, 5.0, 1.0))
    with pytest.raises(ValueError, match="shape"):
        group_lengths(np.zeros((3, 2)))


def test_alternative_checkers_and_anytime_run_on_the_first_queries_only():
    cfg = dataclasses.asdict(CampaignConfig(sample_caps=(10, 20), alt_checker_queries=1, alt_checker_caps=(10,),
                                            anytime_budgets=(0.5,), anytime_queries=1))
    first, second = experiment_specs(cfg, 0), experiment_specs(cfg, 1)
    assert [(s["comparison"], s["checker"], s["cap"], s["budget"]) for s in first] == [
        ("iterations", "batched", 10, None), ("iterations", "batched", 20, None),
        ("iterations", "discrete", 10, None), ("anytime", "batched", None, 0.5)]
    assert [(s["checker"], s["cap"]) for s in second] == [("batched", 10), ("batched", 20)]
    names = [log_name({"id": 7}, 3, s) for s in first]
    assert names[0] == "q003_iterations_batched_N10.log" and names[-1] == "q003_anytime_batched_T0.5s.log"
    assert len(set(names)) == len(names)


def test_anytime_without_validators_uses_the_problems_headline_validator():
    cfg = dataclasses.asdict(CampaignConfig.for_problem("arm4", sample_caps=(), checkers=(), anytime_budgets=(0.5,)))
    assert [s["checker"] for s in experiment_specs(cfg, 0)] == ["discrete"]
    wearer = dataclasses.asdict(CampaignConfig(sample_caps=(), checkers=(), anytime_budgets=(0.5,)))
    assert [s["checker"] for s in experiment_specs(wearer, 0)] == ["batched"]


def test_every_run_starts_from_the_experiments_cost_threshold_whatever_the_planner_before_left(tmp_path, robot):
    # OMPL's AORRTC leaves the shared objective's threshold at its own cost; BIT*, run next, then stopped at once
    import sqlite3

    from helpers.bench_standins import tiny_config, write_query_file

    from tpee_ompl.bench.campaign import run_campaign

    lowers, honours = "helpers.bench_standins:make_lowers_threshold", "helpers.bench_standins:make_honours_threshold"
    cfg = tiny_config(write_query_file(tmp_path / "q.json", robot, n=2), tmp_path, sample_caps=(30,),
                      iteration_planners=(lowers, honours), anytime_budgets=())
    res = run_campaign(cfg, report=False, progress_bar=False)
    with sqlite3.connect(res.database) as db:
        rows = db.execute("SELECT plannerConfigs.name, runs.iterations FROM runs JOIN plannerConfigs "
                          "ON runs.plannerid = plannerConfigs.id").fetchall()
    assert sorted(name.rsplit("_", 1)[-1] for name, _ in rows) == ["HonoursThreshold"] * 2 + ["LowersThreshold"] * 2
    assert [it for _, it in rows] == [30] * 4  # HonoursThreshold drew its 30 samples: the threshold was 0 again


def test_a_one_state_answer_short_of_the_goal_has_no_path_columns_and_one_at_the_goal_has(robot):
    """AORRTC answers a timeout with its start state alone, which OMPL records as a correct solution of length 0."""
    from tpee_ompl.bench.experiment import _path_properties
    from tpee_ompl.model.sectors import posture_preset
    from tpee_ompl.planning.space_layout import RealVectorLayout
    from tpee_ompl.planning.setup import make_simple_setup

    start, goal = np.r_[posture_preset(1), 0.0, 0.0], np.r_[posture_preset(4), 0.0, 0.0]
    si = make_simple_setup(robot, start, goal).getSpaceInformation()
    layout = RealVectorLayout(si.getStateSpace())
    rec = {"waypoints": start[None, :], "best_cost": None}
    assert _path_properties(si, rec, start, goal, (0, 1), layout) == {}
    at_goal = _path_properties(si, rec, start, start, (0, 1), layout)  # a query whose goal is its start
    assert at_goal["raw_length REAL"] == 0.0 and at_goal["path_valid_dense INTEGER"] == 1
    two = _path_properties(si, {"waypoints": np.array([start, goal]), "best_cost": None}, start, goal, (0, 1), layout)
    assert two["reaches_goal INTEGER"] == 1 and two["raw_length REAL"] > 0
    assert two["best_cost REAL"] == two["raw_length REAL"]  # a planner without bestCost() (RRTConnect): its length


def test_a_zero_length_path_short_of_the_goal_has_no_path_columns_and_an_approximate_path_no_best_cost(robot):
    """AORRTC's "zero-length path" (ompl/ompl#1420: status invalid goal, its start twice, bestCost() 0) was
    recorded with best_cost 0, raw_length 0 and path_valid_dense 1: Planner Arena showed it as a perfect path."""
    from tpee_ompl.bench.experiment import _path_properties
    from tpee_ompl.model.sectors import posture_preset
    from tpee_ompl.planning.space_layout import RealVectorLayout
    from tpee_ompl.planning.setup import make_simple_setup

    start, goal = np.r_[posture_preset(1), 0.0, 0.0], np.r_[posture_preset(4), 0.0, 0.0]
    si = make_simple_setup(robot, start, goal).getSpaceInformation()
    layout = RealVectorLayout(si.getStateSpace())
    assert _path_properties(si, {"waypoints": np.array([start, start]), "best_cost": 0.0}, start, goal, (0, 1), layout) == {}
    half = 0.5 * (start + goal)
    approx = _path_properties(si, {"waypoints": np.array([start, half]), "best_cost": 0.0}, start, goal, (0, 1), layout)
    assert approx["reaches_goal INTEGER"] == 0 and approx["raw_length REAL"] > 0 and approx["best_cost REAL"] is None
    exact = _path_properties(si, {"waypoints": np.array([start, goal]), "best_cost": float("inf")}, start, goal, (0, 1),
                             layout)
    assert exact["best_cost REAL"] == exact["raw_length REAL"] > 0  # no finite bestCost(): the path's length


def test_a_run_whose_path_stops_short_of_the_goal_has_no_first_solution_time(robot):
    """A native planner's first solution time is read from a finite bestCost(); AORRTC's is 0 without a path."""
    from tpee_ompl.bench.experiment import _run_properties, _Setup
    from tpee_ompl.bench.problems import get_problem
    from tpee_ompl.model.sectors import posture_preset
    from tpee_ompl.planning.space_layout import RealVectorLayout
    from tpee_ompl.planning.setup import make_simple_setup

    start, goal = np.r_[posture_preset(1), 0.0, 0.0], np.r_[posture_preset(4), 0.0, 0.0]
    ss = make_simple_setup(robot, start, goal)
    si = ss.getSpaceInformation()
    setup = _Setup(get_problem("wearer"), ss, si, robot, RealVectorLayout(si.getStateSpace()), start, goal)
    rec = {"waypoints": np.array([start, start]), "best_cost": 0.0, "first_solution_time": 0.001, "iterations": 5,
           "samples": 5, "error": None, "checks_end": None}
    props = _run_properties(setup, rec, robot.collision_checks)
    assert props["first_solution_time REAL"] is None and props["best_cost REAL"] is None
    assert props["reaches_goal INTEGER"] == 0 and props["path_valid_dense INTEGER"] is None
    rec.update(waypoints=np.array([start, goal]), best_cost=float(np.linalg.norm(goal - start)))
    assert _run_properties(setup, rec, robot.collision_checks)["first_solution_time REAL"] == 0.001


def test_an_exact_answer_short_of_the_goal_is_an_unsolved_run_without_solution_columns_or_zero_costs(tmp_path, robot):
    """OMPL records AORRTC's start-only answer (ompl/ompl#1420) as solved with length 0, and its bestCost() 0
    went into the progress rows: Planner Arena and OMPL's bestPlannerConfigs ranked it the best planner."""
    import sqlite3

    from helpers.bench_standins import STANDIN, tiny_config, write_query_file

    from tpee_ompl.bench.campaign import run_campaign

    stops = "helpers.bench_standins:make_stops_at_start"
    cfg = tiny_config(write_query_file(tmp_path / "q.json", robot, n=2), tmp_path, sample_caps=(30,),
                      iteration_planners=(stops, STANDIN), anytime_budgets=())
    res = run_campaign(cfg, report=False, progress_bar=False)
    with sqlite3.connect(res.database) as db:
        rows = db.execute("SELECT plannerConfigs.name, runs.status, runs.solved, runs.solution_length, "
                          "runs.correct_solution, runs.approximate_solution, runs.reaches_goal, runs.id, "
                          "runs.solution_clearance FROM runs "
                          "JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id").fetchall()
        costs = dict(db.execute("SELECT runid, MIN(best_cost) FROM progress GROUP BY runid").fetchall())
    stopped = [r for r in rows if r[0].endswith("StopsAtStart")]
    others = [r for r in rows if not r[0].endswith("StopsAtStart")]
    assert len(stopped) == len(others) == 2
    invalid_goal = int(ob.PlannerStatus.INVALID_GOAL.value)
    assert [r[1:7] for r in stopped] == [(invalid_goal, 0, None, None, None, 0)] * 2
    assert all(costs.get(r[7]) is None or costs[r[7]] > 0 for r in stopped)  # its cost-0 row is gone (inf stays)
    assert all(r[2] == 1 and r[3] > 0 and r[4] == 1 and r[6] == 1 for r in others)  # a real path keeps its columns
    assert all(r[8] > 0 for r in others)  # the checker's clearance, metres from the margins (OMPL's default: 0)


@pytest.mark.slow
def test_an_ompl_planners_runs_do_not_depend_on_the_planners_run_before_it(robot):
    """RRT* allocates its sampler at its first solve after ``clear()``; before each run was seeded, its samples came
    from wherever the seed generator stood then: OMPL's simplification of dimension-RRT's path before it draws
    seeds as that path asks, so RRT*'s rows differed between a ladder and a separate capped run."""
    from tpee_ompl.bench.campaign import query_rows, stratified_subset
    from tpee_ompl.bench.experiment import _run_experiment

    _, queries = query_rows("planning_necessary")
    cfg = dataclasses.asdict(CampaignConfig(sample_caps=(1500,), anytime_budgets=(), checkers=("batched",), runs=2,
                                            iteration_planners=("DimensionRRT", "RRTstar")))
    task = {"config": cfg, "query": stratified_subset(queries, 2)[1], "qpos": 0, "query_set": "planning_necessary",
            "seed": 11, "n_threads": 1}
    spec = {"comparison": "iterations", "checker": "batched", "cap": 1500, "budget": None}
    columns = ("raw_length", "graph states", "graph motions", "collision_checks")
    rows = {}
    for only in (None, ["RRTstar"]):
        _, extras, error = _run_experiment(cfg, task, spec, only=only)
        assert error is None
        (name,) = [n for n in extras if n.endswith("RRTstar")]
        rows[only is None] = [tuple(run[c] for c in columns) for run in extras[name]]
    assert rows[True] == rows[False]  # with dimension-RRT run before it, or alone
    assert rows[True][0] != rows[True][1]  # each run its own seed


def test_a_renewed_single_use_planner_is_made_from_its_runs_seed(monkeypatch: pytest.MonkeyPatch):
    """AORRTC gets a fresh instance for each run after the first; it was made at ``clear()``, before the run was
    seeded, so its own random numbers came from whatever the run before left (its path's simplification draws
    seeds as that path asks: dimension-RRT's at 1500 samples here).  Made after the seed now: the same whether OMPL
    simplified the path or not."""
    from helpers import bench_standins

    from tpee_ompl.bench import experiment
    from tpee_ompl.bench.campaign import query_rows, stratified_subset

    name = "helpers.bench_standins:make_construction_recorder"
    monkeypatch.setattr(experiment, "SINGLE_USE_PLANNERS", (name,))
    _, queries = query_rows("planning_necessary")
    draws = {}
    for simplify in (True, False):
        cfg = dataclasses.asdict(CampaignConfig(sample_caps=(1500,), anytime_budgets=(), checkers=("batched",), runs=3,
                                                iteration_planners=(name,), simplify=simplify))
        task = {"config": cfg, "query": stratified_subset(queries, 2)[1], "qpos": 0,
                "query_set": "planning_necessary", "seed": 11, "n_threads": 1}
        bench_standins.CONSTRUCTION_DRAWS.clear()
        _, _, error = experiment._run_experiment(cfg, task, {"comparison": "iterations", "checker": "batched",
                                                             "cap": 1500, "budget": None})
        assert error is None
        draws[simplify] = list(bench_standins.CONSTRUCTION_DRAWS)
    assert draws[True][1:3] == draws[False][1:3]
    assert len(draws[True]) == 3 and len(set(draws[True])) == 3  # made once, renewed twice, each its own seed
