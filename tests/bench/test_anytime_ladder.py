"""One run per anytime ladder: rows read at time checkpoints are what the planner returns when stopped there."""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing as mp
import sqlite3

import pytest
from helpers.bench_databases import assert_same_shape
from helpers.bench_standins import write_query_file
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.bench.anytime_ladder import AnytimeLadder, TimeCheckpointPlanner, group_anytime_ladders
from tpee_ompl.bench.campaign import run_campaign
from tpee_ompl.bench.config import CampaignConfig
from tpee_ompl.bench.planners import PlannerContext, RecordingPlanner


def _spec(budget=None, checker="batched", cap=None) -> dict:
    comparison = "iterations" if cap is not None else "anytime"
    return {"comparison": comparison, "checker": checker, "cap": cap, "budget": budget}


# --------------------------------------------------------------------------- grouping
def test_anytime_budgets_of_one_validator_form_one_ladder_sorted_by_budget():
    groups = [[_spec(cap=500)], [_spec(2.0)], [_spec(0.1)], [_spec(0.5, "discrete")], [_spec(1.0)]]
    out = group_anytime_ladders(groups, True)
    assert [[s["budget"] for s in g] for g in out] == [[None], [0.1, 1.0, 2.0], [0.5]]
    assert group_anytime_ladders(groups, False) == groups


# --------------------------------------------------------------------------- a 2-D problem
def _setup_2d(goal_x: float, enclosed: bool = False):
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)

    def valid(s) -> bool:
        if enclosed:  # the goal sits in a closed box: no planner can reach it
            return not (0.7 < s[0] < 0.98 and 0.02 < s[1] < 0.3 and not (0.72 < s[0] < 0.96 and 0.04 < s[1] < 0.28))
        return not (0.3 < s[0] < 0.6 and s[1] < 0.8)

    ss.setStateValidityChecker(valid)
    a, b = space.allocState(), space.allocState()
    a[0], a[1], b[0], b[1] = 0.1, 0.1, goal_x, 0.1
    ss.setStartAndGoalStates(a, b, 1e-9)
    si = ss.getSpaceInformation()
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    return ss, si


def _checkpointed(ss, si, name: str, checkpoints: list[float]) -> tuple[AnytimeLadder, RecordingPlanner]:
    ladder = AnytimeLadder([_spec(b) for b in (*checkpoints, 9.0)], lambda spec, names: ([], {}, None))
    inner = getattr(og, name)(si)
    w = ladder.wrap(si, inner, None, name, PlannerContext(query={}, max_samples=None, seed=1), checker=None)
    ss.setPlanner(w)
    ss.setup()
    return ladder, w


def test_rrtconnect_finished_before_a_budget_gives_its_own_row_there():
    ss, si = _setup_2d(0.9)
    ladder, w = _checkpointed(ss, si, "RRTConnect", [0.5])
    assert isinstance(w, TimeCheckpointPlanner)
    assert ss.solve(2.0) and ss.haveExactSolutionPath()
    assert w.snapshots == [{}]  # it returned before 0.5 s: the run itself is the 0.5 s row
    assert ladder._needs_separate(0.5) == set()


def test_rrtconnect_still_running_at_a_budget_is_run_separately_there():
    ss, si = _setup_2d(0.85, enclosed=True)
    ladder, w = _checkpointed(ss, si, "RRTConnect", [0.05])
    ss.solve(0.2)
    assert not ss.haveExactSolutionPath()
    assert w.snapshots[0][0.05]["pending"] and w.snapshots[0][0.05]["time"] >= 0.05
    assert ladder._needs_separate(0.05) == {"RRTConnect"}


@pytest.mark.parametrize("name", ["RRTConnectSimplify", "AORRTC", "BITstar", "LibraryDimensionRRT"])
def test_planners_that_know_their_budget_or_are_unverified_run_separately(name):
    _, si = _setup_2d(0.9)
    ladder = AnytimeLadder([_spec(0.1), _spec(1.0)], lambda spec, names: ([], {}, None))
    # the choice goes by the configuration's planner name (a cheap inner planner stands in)
    w = ladder.wrap(si, og.RRTConnect(si), None, name, PlannerContext(query={}, max_samples=None, seed=1))
    assert type(w) is RecordingPlanner and ladder._needs_separate(0.1) == {w.getName()}
    assert ladder.names[w.getName()] == name


def test_every_anytime_run_is_told_its_own_budget(tmp_path, robot, monkeypatch):
    """The ladder's run its longest budget, a planner run separately at a shorter budget that budget (OMPL's
    ``Benchmark`` alone would let each run on until its thread's next check, up to 0.1 s later)."""
    told: list[tuple[str, float | None]] = []
    init = RecordingPlanner.__init__

    def recording_init(self, si, inner, *args, **kwargs):
        init(self, si, inner, *args, **kwargs)
        told.append((inner.getName(), self.deadline))

    monkeypatch.setattr(RecordingPlanner, "__init__", recording_init)
    cfg = CampaignConfig(name="deadlines", queries=str(write_query_file(tmp_path / "q.json", robot, n=1)),
                         sample_caps=(), anytime_budgets=(0.02, 0.05), anytime_planners=("RRTConnect", "AORRTC"),
                         workers=0, seed=3, out=str(tmp_path / "out"))
    res = run_campaign(cfg, progress_bar=False, report=False)
    assert res.database is not None and not res.failed_tasks
    # RRTConnect runs separately at 0.02 s only when it was still running there (it usually stops sooner)
    assert set(told) - {("RRTConnect", 0.02)} == {("AORRTC", 0.02), ("AORRTC", 0.05), ("RRTConnect", 0.05)}


# --------------------------------------------------------------------------- RRT*: the path at a time checkpoint
def _rrt_at_time(name: str, t: float) -> tuple[int, list]:
    """Fresh process: the planner's checkpoint at t s of a longer run (iterations, path)."""
    from ompl import util as ou

    ou.RNG.setSeed(5)
    ss, si = _setup_2d(0.9)
    _, w = _checkpointed(ss, si, name, [t])
    ss.solve(t + 0.3)
    snap = w.snapshots[0][t]
    return snap["iterations"], snap["exact"], snap["waypoints"].tolist()


def _rrt_stopped_at(name: str, n: int) -> tuple[bool, list]:
    """Fresh process, same seed: the planner's own solution when stopped after n iterations."""
    from ompl import util as ou

    ou.RNG.setSeed(5)
    ss, si = _setup_2d(0.9)
    _, w = _checkpointed(ss, si, name, [100.0])  # same wrapper and allocations, no checkpoint reached
    w.inner.setProblemDefinition(ss.getProblemDefinition())
    ss.setup()
    r = w.inner
    r.solve(ob.PlannerTerminationCondition(lambda: r.numIterations() >= n))
    pdef = ss.getProblemDefinition()
    return bool(pdef.hasExactSolution()), [[s[0], s[1]] for s in pdef.getSolutionPath().getStates()]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["RRTstar", "InformedRRTstar"])
def test_path_read_at_a_time_checkpoint_is_the_path_the_planner_returns_when_stopped_there(name):
    ctx = mp.get_context("spawn")
    with cf.ProcessPoolExecutor(1, mp_context=ctx) as ex:
        n, exact, W = ex.submit(_rrt_at_time, name, 0.05).result()
    with cf.ProcessPoolExecutor(1, mp_context=ctx) as ex:
        ref_exact, ref = ex.submit(_rrt_stopped_at, name, n).result()
    assert n > 0 and exact == ref_exact
    assert W == ref


# --------------------------------------------------------------------------- a campaign, both ways
@pytest.mark.slow
def test_anytime_ladder_gives_the_database_of_separate_runs(tmp_path, robot):
    """Same tables, columns, experiments and run keys; RRTConnect (done in milliseconds) the same status."""
    qfile = write_query_file(tmp_path / "q.json", robot, n=1)
    planners = ("DimensionRRT", "RRTstar", "InformedRRTstar", "RRTConnect", "BITstar")
    dbs = {}
    for ladder in (True, False):
        cfg = CampaignConfig(name=f"a{int(ladder)}", queries=str(qfile), sample_caps=(), anytime_budgets=(0.1, 0.3),
                             anytime_planners=planners, workers=1, seed=3, out=str(tmp_path / "out"),
                             one_run_per_anytime_ladder=ladder)
        res = run_campaign(cfg, progress_bar=False, report=False)
        assert res.database is not None and not res.failed_tasks
        dbs[ladder] = sqlite3.connect(res.database)

    assert_same_shape(dbs[True], dbs[False])
    assert [r[0] for r in dbs[True].execute("SELECT name FROM experiments ORDER BY name")] == \
        [r[0] for r in dbs[False].execute("SELECT name FROM experiments ORDER BY name")]
    query = ("SELECT e.time_budget, e.timelimit, p.name, r.status, r.solved, r.time "
             "FROM runs r JOIN experiments e ON r.experimentid = e.id JOIN plannerConfigs p ON r.plannerid = p.id "
             "ORDER BY e.time_budget, p.name")
    rows = {k: dbs[k].execute(query).fetchall() for k in dbs}
    assert [r[:3] for r in rows[True]] == [r[:3] for r in rows[False]]
    assert all(r[0] == r[1] for r in rows[True])  # the experiment's time limit is its budget
    longest = {r[2]: r[5] for r in rows[True] if r[0] == 0.3}
    for a, b in zip(rows[True], rows[False]):
        if a[2].endswith("RRTConnect"):
            assert a[3:5] == b[3:5] == (6, 1)
        if a[2].endswith("RRTstar") and a[0] < 0.3:  # derived at 0.1 s
            # read at the first termination check past its budget, during the 0.3 s run (no wall-clock bound:
            # a loaded machine delays that check)
            assert a[0] <= a[5] <= longest[a[2]]
