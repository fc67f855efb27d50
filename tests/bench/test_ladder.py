"""One run per iteration ladder: checkpoint rows equal separate capped runs (fresh processes, same seeds)."""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import multiprocessing as mp
import sqlite3
from pathlib import Path

import pytest
from helpers.bench_databases import assert_same_shape
from helpers.bench_standins import write_query_file
from helpers.planning_spaces import free_so2_space
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.bench.campaign import query_rows, run_campaign, stratified_subset
from tpee_ompl.bench.config import CampaignConfig
from tpee_ompl.bench.database import build_database
from tpee_ompl.bench.experiment import run_query_task
from tpee_ompl.bench.ladder import _tree_path, group_ladders


def _spec(cap=None, checker="batched", budget=None, **kw) -> dict:
    comparison = "iterations" if cap is not None else "anytime"
    return {"comparison": comparison, "checker": checker, "cap": cap, "budget": budget, **kw}


# --------------------------------------------------------------------------- grouping
def test_iteration_caps_of_one_validator_form_one_ladder_and_anytime_runs_stay_separate():
    specs = [_spec(500), _spec(2500), _spec(500, "discrete"), _spec(1000), _spec(budget=0.1)]
    groups = group_ladders(specs, True, ("DimensionRRT", "RRTstar"))
    assert [[s["cap"] for s in g] for g in groups] == [[500, 1000, 2500], [500], [None]]
    assert groups[1][0]["checker"] == "discrete" and groups[2][0]["budget"] == 0.1


def test_ladders_are_off_when_disabled_or_a_planner_is_not_verified():
    specs = [_spec(500), _spec(1000)]
    assert group_ladders(specs, False, ("DimensionRRT", "RRTstar")) == [[specs[0]], [specs[1]]]
    assert group_ladders(specs, True, ("DimensionRRT", "InformedRRTstar")) == [[specs[0]], [specs[1]]]


# --------------------------------------------------------------------------- RRT*'s path from its planner data
def _rrtstar_2d(goal_x: float, wall_top: float):
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: not (0.3 < s[0] < 0.6 and s[1] < wall_top))
    a, b = space.allocState(), space.allocState()
    a[0], a[1], b[0], b[1] = 0.1, 0.1, goal_x, 0.1
    ss.setStartAndGoalStates(a, b, 1e-9)
    si = ss.getSpaceInformation()
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    r = og.RRTstar(si)
    ss.setPlanner(r)
    ss.setup()
    return ss, si, r


@pytest.mark.parametrize("iterations, exact", [(600, True), (8, False)])
def test_rrtstar_solution_is_rebuilt_from_its_planner_data(iterations, exact):
    ss, si, r = _rrtstar_2d(0.9, 0.8)
    status = r.solve(ob.PlannerTerminationCondition(lambda: r.numIterations() >= iterations))
    pdef = ss.getProblemDefinition()
    assert bool(pdef.hasExactSolution()) == exact and bool(status)
    pd = ob.PlannerData(si)
    r.getPlannerData(pd)
    W, got_exact, diff = _tree_path(pd, si, pdef.getGoal().getState(), 2)
    ref = [[s[0], s[1]] for s in pdef.getSolutionPath().getStates()]
    assert got_exact == exact
    assert W.tolist() == ref
    assert diff == (0.0 if exact else pytest.approx(pdef.getSolutionDifference(), rel=1e-12))


# --------------------------------------------------------------------------- fresh processes
_LADDER_PLANNERS = ("DimensionRRT", "RRTstar", "DimensionRRTReleased", "DimensionRRTNoShortcuts")


def _task(q: dict, specs: list[dict], ladder: bool, caps: tuple[int, ...]) -> dict:
    cfg = dataclasses.asdict(CampaignConfig(sample_caps=caps, anytime_budgets=(), checkers=("batched",), workers=0,
                                            one_run_per_ladder=ladder, iteration_planners=_LADDER_PLANNERS))
    return {"config": cfg, "query": q, "qpos": 0, "query_set": "planning_necessary", "seed": 11, "n_threads": 1,
            "specs": specs}


def _in_fresh_process(task: dict) -> dict:
    with cf.ProcessPoolExecutor(1, mp_context=mp.get_context("spawn")) as ex:
        return ex.submit(run_query_task, task).result()


def _rows(logs: dict, tmp: Path) -> dict[tuple[int, str], dict]:
    paths = []
    for name, text in logs.items():
        paths.append(tmp / name)
        paths[-1].write_text(text)
    db, bad = build_database(paths, tmp / "x.db")
    assert not bad
    con = sqlite3.connect(db)
    con.row_factory = sqlite3.Row
    rows = con.execute("SELECT e.sample_cap, p.name AS planner, r.* FROM runs r JOIN experiments e ON r.experimentid = e.id "
                       "JOIN plannerConfigs p ON r.plannerid = p.id").fetchall()
    return {(r["sample_cap"], r["planner"].split("_", 1)[1]): dict(r) for r in rows}


EXACT_COLUMNS = ("best_cost", "raw_length", "length_dof12", "length_dof34", "solution_length", "solution_segments",
                 "iterations", "samples", "status", "solved", "approximate_solution", "correct_solution",
                 "correct_solution_strict", "path_valid_dense", "reaches_goal", "graph_states", "graph_motions")


@pytest.mark.slow
def test_checkpoint_rows_equal_separate_capped_runs(tmp_path):
    """RRT* and dimension-RRT (and its benchmark variants) at 500 read from a run capped at 1500 = a run
    capped at 500 (same seeds)."""
    _, queries = query_rows("planning_necessary")
    q = stratified_subset(queries, 2)[1]
    caps = (500, 1500)
    ladder = _in_fresh_process(_task(q, [_spec(c) for c in caps], True, caps))
    separate = _in_fresh_process(_task(q, [_spec(500, seed_tag=1500)], False, (500,)))
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    a, b = _rows(ladder["logs"], tmp_path / "a"), _rows(separate["logs"], tmp_path / "b")
    for planner in _LADDER_PLANNERS:
        ra, rb = a[(500, planner)], b[(500, planner)]
        assert ra["solved"] == 1 and ra["path_valid_dense"] == 1
        assert {c: ra[c] for c in EXACT_COLUMNS} == {c: rb[c] for c in EXACT_COLUMNS}, planner
        assert a[(1500, planner)]["iterations"] == 1500
        assert set(ra) == set(rb)


@pytest.mark.slow
def test_one_run_ladders_give_the_database_of_separate_runs(tmp_path, robot):
    """Same tables, columns and rows; equal iterations and validity, and the same runs at the largest cap."""
    qfile = write_query_file(tmp_path / "q.json", robot, n=1)
    dbs = {}
    for ladder in (True, False):
        cfg = CampaignConfig(name=f"l{int(ladder)}", queries=str(qfile), sample_caps=(60, 120, 180),
                             iteration_planners=("DimensionRRT", "RRTstar"), checkers=("batched",),
                             anytime_budgets=(), workers=1, seed=3, out=str(tmp_path / "out"),
                             one_run_per_ladder=ladder)
        res = run_campaign(cfg, progress_bar=False, report=False)
        assert res.database is not None and not res.failed_tasks
        dbs[ladder] = sqlite3.connect(res.database)

    assert_same_shape(dbs[True], dbs[False])
    query = ("SELECT e.sample_cap, p.name, r.iterations, r.solved, r.path_valid_dense, r.reaches_goal, r.best_cost "
             "FROM runs r JOIN experiments e ON r.experimentid = e.id JOIN plannerConfigs p ON r.plannerid = p.id "
             "ORDER BY e.sample_cap, p.name")
    rows = {k: dbs[k].execute(query).fetchall() for k in dbs}
    assert [r[:5] for r in rows[True]] == [r[:5] for r in rows[False]]
    assert all(r[2] == r[0] for r in rows[True])
    largest = [[r for r in rows[k] if r[0] == 180] for k in dbs]
    assert largest[0] == largest[1]  # the ladder's one run is the separate run at its largest cap: the same seeds


@pytest.mark.slow
def test_a_resumed_ladder_member_holds_the_rows_of_the_uninterrupted_campaign(tmp_path, robot):
    """A resume ran the missing cap alone, seeded by its own cap: RRT*'s N=60 row became another run (7.97 -> 6.11
    in a helper's arm4 campaign).  The ladder runs whole now, and only the missing log is written."""
    from tpee_ompl.bench.campaign import resume_campaign

    qfile = write_query_file(tmp_path / "q.json", robot, n=1)
    cfg = CampaignConfig(name="rs", queries=str(qfile), sample_caps=(60, 120),
                         iteration_planners=("DimensionRRT", "RRTstar"), checkers=("batched",), anytime_budgets=(),
                         workers=0, seed=3, out=str(tmp_path / "out"))
    res = run_campaign(cfg, progress_bar=False, report=False)
    query = ("SELECT e.sample_cap, p.name, " + ", ".join(f"r.{c}" for c in EXACT_COLUMNS) + " FROM runs r JOIN "
             "experiments e ON r.experimentid = e.id JOIN plannerConfigs p ON r.plannerid = p.id "
             "ORDER BY e.sample_cap, p.name")
    before = sqlite3.connect(res.database).execute(query).fetchall()
    (small,) = [p for p in res.logs if p.name.endswith("_N60.log")]
    (large,) = [p for p in res.logs if p.name.endswith("_N120.log")]
    kept = large.read_bytes()
    small.unlink()
    again = resume_campaign(res.directory, progress_bar=False, report=False)
    assert sqlite3.connect(again.database).execute(query).fetchall() == before
    assert large.read_bytes() == kept  # the member that had a log is left as it was


def test_checkpoint_columns_write_waypoints_of_a_compound_so2_space():
    from tpee_ompl.bench.ladder import Ladder

    si = free_so2_space()
    pdef = ob.ProblemDefinition(si)
    snap = {"waypoints": [[3.0, -3.0], [-3.0, 3.0]], "exact": True, "time": 0.1, "valid_fraction": 1.0,
            "difference": 0.0}
    row = Ladder._ompl_columns(si, pdef, {}, snap, simplify=False)
    short_way = 2 * (2 * 3.141592653589793 - 6.0)  # each joint wraps round through pi
    assert float(row["solution length REAL"]) == pytest.approx(short_way)
    assert row["correct solution BOOLEAN"] in ("1", "True", "true")


def test_a_checkpoints_progress_never_holds_a_row_from_after_it():
    """The planner's clock starts a little after the wrapper's: a row at 0.09999 s (66,701 samples) came after the
    0.10002-s checkpoint (66,665), and the database's iterations went down."""
    from tpee_ompl.bench.ladder import progress_until

    progress = [(0.05, 3.0, 30000), (0.09, 2.9, 60000), (0.09999, 2.8, 66701), (0.2, 2.7, 130000)]
    snap = {"time": 0.10002, "best_cost": 2.9, "iterations": 66665}
    rows = progress_until(progress, snap)
    assert rows == [(0.05, 3.0, 30000), (0.09, 2.9, 60000), (0.10002, 2.9, 66665)]
    assert [r[2] for r in rows] == sorted(r[2] for r in rows)
