"""Benchmark harness: smoke campaign, interruption, isolation of campaigns, path metrics."""

from __future__ import annotations

import json
import sqlite3
import time
from pathlib import Path

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.bench.campaign import CampaignConfig, PlannerContext, group_lengths, load_query_set, run_campaign
from tpee_ompl.model.sectors import posture_preset


class StandInPlanner(ob.Planner):
    """A tiny sampling planner shaped like DimensionRRT: straight line, else one random via-point.

    Samples up to ``max_samples`` via-points (or until the time is up), keeps the shortest
    collision-free start-via-goal path; exposes ``settings()`` and ``last_run_stats()``.
    """

    def __init__(self, si, max_samples=None, seed=None):
        super().__init__(si, "StandIn")
        self.max_samples = max_samples
        self.rng = np.random.default_rng(seed)
        self._stats = {}

    def settings(self):
        return {"max_samples": str(self.max_samples), "kind": "via-point"}

    def last_run_stats(self):
        return dict(self._stats)

    def clear(self):
        super().clear()

    def solve(self, ptc):
        si, pdef = self.getSpaceInformation(), self.getProblemDefinition()
        t0 = time.perf_counter()
        pis = self.getPlannerInputStates()
        start = pis.nextStart()
        if start is None:
            start = pdef.getStartState(0)
        goal = pdef.getGoal().getState()
        a = np.array([start[i] for i in range(4)])
        b = np.array([goal[i] for i in range(4)])
        sampler = si.allocStateSampler()
        best, best_cost, samples, progress, first = None, np.inf, 0, [], None
        if si.checkMotion(start, goal):
            best, best_cost, first = [a, b], float(np.linalg.norm(b - a)), time.perf_counter() - t0
        while not ptc() and samples < (self.max_samples or 10**9):
            samples += 1
            s = si.allocState()
            sampler.sampleUniform(s)
            v = np.array([s[i] for i in range(4)])
            cost = np.linalg.norm(v - a) + np.linalg.norm(b - v)
            if cost < best_cost:
                if si.isValid(s) and si.checkMotion(start, s) and si.checkMotion(s, goal):
                    best, best_cost = [a, v, b], float(cost)
                    first = first if first is not None else time.perf_counter() - t0
            if samples % 20 == 0:
                progress.append((time.perf_counter() - t0, best_cost, samples))
        progress.append((time.perf_counter() - t0, best_cost, samples))
        self._stats = {"samples": samples, "iterations": samples, "best_cost": best_cost, "collision_checks": 0,
                       "first_solution_time": first, "progress": progress}
        if best is None:
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        path = og.PathGeometric(si)
        for w in best:
            s = si.allocState()
            s[0:4] = [float(x) for x in w]
            path.append(s)
        pdef.addSolutionPath(path, False, 0.0, self.getName())
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)


def make_standin(si, ctx: PlannerContext):
    """Planner factory used by the campaigns below (importable as ``test_benchmark:make_standin``)."""
    return StandInPlanner(si, max_samples=ctx.max_samples, seed=ctx.seed)


def write_query_file(path: Path, robot, n: int = 2, seed: int = 7) -> Path:
    """A tiny query set in the queries.py JSON format: sector presets with random valid pan/tilt."""
    rng = np.random.default_rng(seed)
    pairs = [(1, 2), (3, 4), (2, 4), (4, 1)][:n]
    queries = []
    for k, (i, j) in enumerate(pairs):
        ends = []
        for sector in (i, j):
            while True:
                q = np.r_[posture_preset(sector), rng.uniform(robot.lower[2:], robot.upper[2:])]
                if robot.is_valid(q):
                    ends.append(q)
                    break
        queries.append({"id": k, "from_sector": i, "to_sector": j, "target_a": [1.0, 0.0, 1.0],
                        "target_b": [0.0, 1.0, 1.0], "start": ends[0].tolist(), "goal": ends[1].tolist()})
    data = {"format_version": 1, "name": "tiny", "seed": seed, "model_hash": robot.model_hash, "queries": queries}
    path.write_text(json.dumps(data))
    return path


@pytest.fixture(scope="module")
def query_file(tmp_path_factory, robot) -> Path:
    return write_query_file(tmp_path_factory.mktemp("q") / "tiny.json", robot)


def tiny_config(query_file: Path, out: Path, **kw) -> CampaignConfig:
    base = dict(name="smoke", queries=str(query_file), sample_caps=(30, 60),
                iteration_planners=("test_benchmark:make_standin", "RRTstar"), checkers=("batched",),
                anytime_budgets=(0.05,), anytime_planners=("test_benchmark:make_standin", "RRTstar", "RRTConnect"),
                workers=0, seed=3, out=str(out))
    base.update(kw)
    return CampaignConfig(**base)


def test_group_lengths_split_the_joint_space_path():
    W = np.array([[0, 0, 0, 0], [3, 4, 0, 0], [3, 4, 1, 0]], dtype=float)
    assert group_lengths(W) == pytest.approx((6.0, 5.0, 1.0))
    with pytest.raises(ValueError, match="shape"):
        group_lengths(np.zeros((3, 2)))


def test_query_file_loads_as_plain_dicts(query_file):
    name, qs = load_query_set(str(query_file))
    assert name == "tiny" and len(qs) == 2
    assert qs[0]["from_sector"] == 1 and len(qs[0]["start"]) == 4


def test_smoke_campaign_fills_the_database(query_file, tmp_path):
    res = run_campaign(tiny_config(query_file, tmp_path), progress_bar=False)
    assert not res.interrupted
    assert res.directory.parent == tmp_path and res.directory.name.endswith("_smoke")
    assert len(res.logs) == 2 * 3 and all(p.suffix == ".log" for p in res.logs)
    con = sqlite3.connect(res.database)
    rows = con.execute(
        "SELECT plannerConfigs.name, runs.correct_solution, runs.best_cost, runs.iterations, runs.collision_checks, "
        "runs.length_dof12, runs.length_dof34, runs.path_valid_dense, runs.solution_length "
        "FROM runs JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id "
        "JOIN experiments ON runs.experimentid = experiments.id WHERE experiments.comparison = 'iterations'").fetchall()
    planners = {r[0] for r in rows}
    assert planners == {"geometric_StandIn", "geometric_RRTstar"}
    for name, correct, best, iters, checks, l12, l34, dense, length in rows:
        assert correct is not None and iters is not None and checks > 0  # filled for every run
        if length is not None:  # solved: every column of the raw path is there
            assert correct == 1 and dense == 1 and best == pytest.approx(length, rel=1e-4)
            assert l12 + l34 >= length - 1e-6  # triangle inequality per segment
    assert {r[0] for r in rows if r[8] is not None} == planners  # each planner solved something
    caps = dict(con.execute("SELECT sample_cap, COUNT(*) FROM experiments WHERE comparison='iterations' "
                            "GROUP BY sample_cap").fetchall())
    assert caps == {30: 2, 60: 2}
    rrt_iters = {r[0] for r in con.execute(
        "SELECT runs.iterations FROM runs JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id "
        "JOIN experiments ON runs.experimentid = experiments.id "
        "WHERE plannerConfigs.name='geometric_RRTstar' AND experiments.comparison='iterations'")}
    assert rrt_iters <= {30, 60}
    n_prog = con.execute(
        "SELECT COUNT(*) FROM progress JOIN runs ON progress.runid = runs.id "
        "JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id WHERE plannerConfigs.name='geometric_StandIn'"
    ).fetchone()[0]
    assert n_prog > 0
    settings = con.execute("SELECT settings FROM plannerConfigs WHERE name='geometric_StandIn'").fetchone()[0]
    assert "planner.kind" in settings and "iteration_cap" in settings
    params = con.execute("SELECT query_id, from_sector, to_sector, query_set FROM experiments").fetchall()
    assert ("0", 1, 2, "tiny") in params
    con.close()
    table = (res.directory / "table4.csv").read_text()
    assert table.splitlines()[0].endswith(",paper") and "length_dof12" in table
    assert "StandIn / RRTstar" in (res.directory / "report.md").read_text()
    assert res.plots and all(p.suffix == ".png" and p.stat().st_size > 0 for p in res.plots)
    meta = json.loads((res.directory / "campaign.json").read_text())
    assert meta["seed"] == 3 and "ompl" in meta["versions"]


def test_interrupted_campaign_keeps_finished_logs_and_builds_the_db(query_file, tmp_path):
    def stop_after_first(logs):
        raise KeyboardInterrupt

    cfg = tiny_config(query_file, tmp_path, sample_caps=(30,), anytime_budgets=())
    res = run_campaign(cfg, on_task_done=stop_after_first, progress_bar=False)
    assert res.interrupted
    assert len(res.logs) == 1 and res.logs[0].is_file()
    assert not list((res.directory / "logs").glob("*.part"))
    con = sqlite3.connect(res.database)
    assert con.execute("SELECT COUNT(*) FROM experiments").fetchone()[0] == 1
    con.close()
    success = (res.directory / "success.csv").read_text()
    assert "missing" in success.splitlines()[0]


def test_second_campaign_leaves_the_first_untouched(query_file, tmp_path):
    cfg = tiny_config(query_file, tmp_path, sample_caps=(20,), anytime_budgets=(), max_queries=1)
    first = run_campaign(cfg, progress_bar=False, report=False)
    before = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in first.directory.rglob("*") if p.is_file()}
    second = run_campaign(cfg, progress_bar=False, report=False)
    assert second.directory != first.directory
    after = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in first.directory.rglob("*") if p.is_file()}
    assert before == after


def test_bad_config_is_rejected():
    with pytest.raises(ValueError, match="motion validator"):
        CampaignConfig(checkers=("fast",))
    with pytest.raises(ValueError, match="caps"):
        CampaignConfig(sample_caps=(0,))
