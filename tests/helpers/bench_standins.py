"""Stand-in planners and tiny campaigns for the benchmark tests (``tests/bench/``, ``tests/cli/``).

Campaign configurations name planner factories as ``module:function`` strings that worker
processes import, so the factories live here, in an importable module:
``"helpers.bench_standins:make_standin"`` (``tests/`` is on ``sys.path``: conftest.py puts it there,
spawned workers inherit it, Dask subprocesses get it through the task's ``sys_path``).
"""

from __future__ import annotations

import json
import os
import signal
import time
from pathlib import Path

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.bench.config import CampaignConfig
from tpee_ompl.bench.planners import PlannerContext
from tpee_ompl.model.sectors import posture_preset
from tpee_ompl.planning.planner_base import PythonPlanner

STANDIN = "helpers.bench_standins:make_standin"
"""The stand-in's planner name in a campaign configuration."""


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
    """Planner factory of the stand-in (:data:`STANDIN`)."""
    return StandInPlanner(si, max_samples=ctx.max_samples, seed=ctx.seed)


class LowersThreshold(StandInPlanner):
    """Leaves the shared objective's cost threshold at a cost every path meets after its run, as OMPL's AORRTC
    leaves it at its own path's cost."""

    def solve(self, ptc):
        status = super().solve(ptc)
        self.getProblemDefinition().getOptimizationObjective().setCostThreshold(ob.Cost(1e9))
        return status


class HonoursThreshold(StandInPlanner):
    """Stops after one sample when the objective is already satisfied by any path, as BIT* stops once it is."""

    def solve(self, ptc):
        if self.getProblemDefinition().getOptimizationObjective().isSatisfied(ob.Cost(1e6)):
            self.max_samples = 1
        return super().solve(ptc)


def make_lowers_threshold(si, ctx: PlannerContext):
    planner = LowersThreshold(si, max_samples=ctx.max_samples, seed=ctx.seed)
    planner.setName("LowersThreshold")
    return planner


def make_honours_threshold(si, ctx: PlannerContext):
    planner = HonoursThreshold(si, max_samples=ctx.max_samples, seed=ctx.seed)
    planner.setName("HonoursThreshold")
    return planner


class StopsAtStart(StandInPlanner):
    """Answers as OMPL 2.0.1's AORRTC does on a query whose direct motion is free (ompl/ompl#1420): an "exact"
    path of its start twice, bestCost() 0, status invalid goal."""

    def solve(self, ptc):
        si, pdef = self.getSpaceInformation(), self.getProblemDefinition()
        start = self.getPlannerInputStates().nextStart()  # (pdef.getStartState(0) would be freed twice)
        path = og.PathGeometric(si)
        for _ in range(2):
            s = si.allocState()
            s[0:4] = [start[i] for i in range(4)]
            path.append(s)
        pdef.addSolutionPath(path, False, 0.0, self.getName())
        self._stats = {"samples": 1, "iterations": 1, "best_cost": 0.0, "collision_checks": 0,
                       "first_solution_time": 0.0, "progress": [(0.001, float("inf"), 0), (0.002, 0.0, 1)]}
        return ob.PlannerStatus(ob.PlannerStatus.INVALID_GOAL)


def make_stops_at_start(si, ctx: PlannerContext):
    planner = StopsAtStart(si, max_samples=ctx.max_samples, seed=ctx.seed)
    planner.setName("StopsAtStart")
    return planner


# --------------------------------------------------------------------------- planners that fail
class SolveRaises(StandInPlanner):
    """Raises inside ``solve`` (called by OMPL's Benchmark from C++)."""

    def __init__(self, si, max_samples=None, seed=None):
        super().__init__(si, max_samples, seed)
        self.setName("SolveRaises")

    def solve(self, ptc):
        raise ValueError("solve exploded")


class SetupRaises(StandInPlanner):
    """Raises inside ``setup``."""

    def __init__(self, si, max_samples=None, seed=None):
        super().__init__(si, max_samples, seed)
        self.setName("SetupRaises")

    def setup(self):
        raise ValueError("setup exploded")


class PackagePlannerRaises(PythonPlanner):
    """One of the package's planners (:class:`~tpee_ompl.planning.planner_base.PythonPlanner`, as DimensionRRT)
    raising in ``_solve``: its solve() logs the exception and returns CRASH."""

    def __init__(self, si):
        super().__init__(si, "PackagePlannerRaises")

    def _solve(self, ptc):
        raise ValueError("_solve exploded")


class _RaisingMotionValidator(ob.MotionValidator):
    def __init__(self, si):
        super().__init__(si)

    def checkMotion(self, s1, s2):  # noqa: N802 (OMPL override)
        raise RuntimeError("motion validator exploded")


class AbortsBenchmark(StandInPlanner):
    """Solves, then leaves a raising Python motion validator: OMPL's own path check aborts ``benchmark()``."""

    def solve(self, ptc):
        status = super().solve(ptc)
        si = self.getSpaceInformation()
        si.setMotionValidator(_RaisingMotionValidator(si))
        return status


def make_solve_raises(si, ctx: PlannerContext):
    return SolveRaises(si, max_samples=ctx.max_samples, seed=ctx.seed)


def make_setup_raises(si, ctx: PlannerContext):
    return SetupRaises(si, max_samples=ctx.max_samples, seed=ctx.seed)


def make_package_planner_raises(si, ctx: PlannerContext):
    return PackagePlannerRaises(si)


def make_aborts_benchmark(si, ctx: PlannerContext):
    return AbortsBenchmark(si, max_samples=ctx.max_samples, seed=ctx.seed)


KILL_MARKER_ENV = "TPEE_TEST_KILL_MARKER"
"""Environment variable naming the marker file of :func:`make_worker_killer`."""


def make_worker_killer(si, ctx: PlannerContext):
    """First call anywhere: kill the Dask worker running this task (our parent process); then a stand-in."""
    marker = Path(os.environ[KILL_MARKER_ENV])
    try:
        fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return StandInPlanner(si, max_samples=ctx.max_samples, seed=ctx.seed)
    os.write(fd, str(os.getppid()).encode())
    os.close(fd)
    os.kill(os.getppid(), signal.SIGKILL)
    time.sleep(30)  # PR_SET_PDEATHSIG ends this process with its worker
    raise RuntimeError("worker was not killed")


# --------------------------------------------------------------------------- tiny campaigns
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


def tiny_config(query_file: Path, out: Path, **kw) -> CampaignConfig:
    """A seconds-long campaign on ``query_file``: the stand-in vs RRT*, caps 30/60, budget 0.05 s, in-process."""
    base = dict(name="smoke", queries=str(query_file), sample_caps=(30, 60),
                iteration_planners=(STANDIN, "RRTstar"), checkers=("batched",),
                anytime_budgets=(0.05,), anytime_planners=(STANDIN, "RRTstar", "RRTConnect"),
                workers=0, seed=3, out=str(out))
    base.update(kw)
    return CampaignConfig(**base)


SELF_KILL_ENV = "TPEE_TEST_SELF_KILL"
"""Environment variable of :func:`make_self_killer`: JSON ``{"dir", "query_id", "cap", "times"}``."""


def make_self_killer(si, ctx: PlannerContext):
    """SIGKILL this worker process (like a segfault or the OOM killer) in one experiment; else a stand-in.

    The experiment is query ``query_id`` at cap ``cap``; the process dies the first ``times`` times
    it gets there, counted by one file ``killed-<pid>`` per death in ``dir``.
    """
    spec = json.loads(os.environ[SELF_KILL_ENV])
    folder = Path(spec["dir"])
    if ctx.query["id"] == spec["query_id"] and ctx.max_samples == spec["cap"]:
        if len(list(folder.glob("killed-*"))) < int(spec["times"]):
            (folder / f"killed-{os.getpid()}").write_text(str(ctx.max_samples))
            os.kill(os.getpid(), signal.SIGKILL)
    return StandInPlanner(si, max_samples=ctx.max_samples, seed=ctx.seed)


def make_broken_factory(si, ctx: PlannerContext):
    """A planner factory that raises (its query's task fails in the worker: a runtime failure, not bad input)."""
    raise RuntimeError("this planner factory always fails")


CONSTRUCTION_DRAWS: list[float] = []
"""The first number each :func:`make_construction_recorder` planner drew from OMPL's seed generator when made."""


def make_construction_recorder(si, ctx: PlannerContext):
    """The problem's dimension-RRT, after noting the first number a new OMPL ``RNG`` draws at that moment (it takes the
    generator's next seed, as a native planner's own RNGs do when it is made): as a single-use stand-in it shows which
    seed a renewed planner got."""
    from ompl import util as ou

    from tpee_ompl.bench.problems import get_problem

    CONSTRUCTION_DRAWS.append(ou.RNG().uniform01())
    return get_problem(ctx.problem).build_dimension_rrt(si, ctx)
