"""One run per iteration ladder: the rows of the smaller sample caps read at checkpoints of the largest.

Under a fixed seed and an iteration cap, the run capped at 500 is the prefix of the run capped at 2500
(RRT* and dimension-RRT do not know their cap).  So a ladder (500, 1000, ..., 2500) of one planner,
query and motion validator is run once, at 2500, inside :class:`CheckpointPlanner`, which snapshots
at each smaller cap N what a run stopped there would have returned:

* **RRT*** (``og.RRTstar``): its termination condition is evaluated once per iteration, before the
  next one; when ``numIterations()`` is N, ``inner.getPlannerData(pd)`` gives the tree and the goal
  vertex RRT* marks (its best goal motion).  The path is the goal vertex's chain of parents (each
  vertex of the tree has one incoming edge); without a goal vertex it is RRT*'s approximate solution,
  the vertex nearest the goal (solution difference = that distance).  ``best_cost`` is ``bestCost()``.
* **dimension-RRT** (a Python planner): its loop evaluates the termination condition between batches
  of samples, and exactly after sample N when N is one of its ``set_sample_checkpoints``; the call
  that sees ``samples_drawn() == N`` sees the search after N samples.  Its best path is the last one it posted
  (its intermediate-solution callback) when that is the best it found (the last cost of its progress
  trace); when the best was still waiting to be posted (posting is throttled by time), the row comes
  from a separate run of a fresh planner capped at N with the same seed, after the benchmark.

:func:`derive_checkpoint_logs` then writes one OMPL log per smaller cap, in the schema of a separate
run (same experiment name pattern and parameters, ``sample_cap`` = N): OMPL's columns (status,
solved, lengths, ``correct_solution``/``_strict``, graph size, simplified columns from OMPL's own
``PathSimplifier.simplifyMax``, which is randomized) recomputed for the checkpoint path, and this
package's columns (collision checks, iterations, lengths, dense validity) as the post-run event would.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import tools as ot

from ..planning.paths import states_to_array
from ..planning.setup import motion_counts, valid_motion_fraction
from ..planning.space_layout import RealVectorLayout
from .database import NO_PATH_COLUMNS, SOLUTION_KEYS, log_text, progress_rows
from .planners import PlannerContext, RecordingPlanner, planner_factory
from .results import format_value, planner_name

__all__ = ["LADDER_PLANNERS", "CheckpointPlanner", "DeriveContext", "Ladder", "group_ladders", "progress_until"]

log = logging.getLogger(__name__)

LADDER_PLANNERS = ("DimensionRRT", "DimensionRRTReleased", "DimensionRRTNoShortcuts", "RRTstar")
"""Planners whose checkpoint rows are verified to equal separate capped runs (tests/bench/test_ladder.py)."""


def group_ladders(specs: list[dict], enabled: bool, planners: tuple[str, ...] | list[str]) -> list[list[dict]]:
    """The experiments in run order, those of one iteration ladder (same validator) grouped.

    A group of several specs is run once at its largest cap (:class:`Ladder`); a spec alone is a
    separate run.  Nothing is grouped when ``enabled`` is False or a planner is not in
    :data:`LADDER_PLANNERS`.
    """
    if not enabled or any(p not in LADDER_PLANNERS for p in planners):
        return [[s] for s in specs]
    groups: dict[str, list[dict]] = {}
    out: list[list[dict]] = []
    for s in specs:
        if s["comparison"] == "iterations" and s["cap"] is not None:
            if s["checker"] not in groups:
                groups[s["checker"]] = []
                out.append(groups[s["checker"]])
            groups[s["checker"]].append(s)
        else:
            out.append([s])
    return [sorted(g, key=lambda s: s["cap"]) for g in out]


def _ompl_text(v) -> str:
    """A value as OMPL's ``Benchmark`` writes it (``ompl::toString``: C++ stream defaults, 6 significant digits);
    '' (NULL in the database) for None."""
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_, int, np.integer)):
        return str(int(v))
    return f"{float(v):.6g}"


def _tree_path(pd, si, goal_state, dim: int, read=None) -> tuple[np.ndarray | None, bool, float]:
    """RRT*'s solution from its planner data: (waypoints, exact, solution difference)."""
    if pd.numVertices() == 0:
        return None, False, math.inf
    if pd.numGoalVertices() > 0:
        v, exact, diff = pd.getGoalIndex(0), True, 0.0
    else:  # approximate: the tree vertex nearest the goal (RRT*'s approxGoalMotion)
        best = (math.inf, None)
        for i in range(pd.numVertices()):
            if not pd.isStartVertex(i):
                d = si.distance(pd.getVertex(i).getState(), goal_state)
                if d < best[0]:
                    best = (d, i)
        if best[1] is None:
            return None, False, math.inf
        diff, v, exact = best[0], best[1], False
    chain = [v]
    while not pd.isStartVertex(chain[-1]):
        parents = pd.getIncomingEdges(chain[-1])
        if len(parents) != 1:
            raise RuntimeError(f"vertex {chain[-1]} has {len(parents)} parents: not a tree")
        chain.append(parents[0])
    return states_to_array([pd.getVertex(i).getState() for i in reversed(chain)], dim, read=read), exact, diff


@dataclasses.dataclass(frozen=True)
class DeriveContext:
    """What deriving a ladder's rows takes from its experiment: the set-up, the query's ends, OMPL's ``simplify``
    request, the safety time limit of a separate run, and ``path_properties(si, record, start, goal)``, which
    measures a path as the post-run event does (with the problem's groups and state layout)."""

    ss: og.SimpleSetup
    start: np.ndarray
    goal: np.ndarray
    simplify: bool
    max_time: float
    path_properties: Callable[..., dict]


class CheckpointPlanner(RecordingPlanner):
    """A :class:`RecordingPlanner` that also snapshots, at each checkpoint below its cap, what a run
    capped there would have returned.

    After each ``solve``, :attr:`snapshots` gains one ``{cap: snapshot}`` for the run: ``time`` (s),
    ``iterations``, ``best_cost``, ``waypoints`` ((K, n) or None), ``exact``, ``difference``,
    ``graph_states``/``graph_motions``, ``checks`` (the problem checker's counter), ``valid_fraction`` (the
    motion validator's), ``pending`` (dimension-RRT's best path was not posted yet: no waypoints).
    """

    def __init__(self, si: ob.SpaceInformation, inner: ob.Planner, max_iterations: int, checkpoints: list[int],
                 context: tuple[str, PlannerContext], checker: Any = None,
                 read: Callable[[ob.State], object] | None = None,
                 renew: Callable[[], ob.Planner] | None = None) -> None:
        python = hasattr(inner, "last_run_stats")
        if not python and type(inner) is not og.RRTstar:
            raise ValueError(f"{inner.getName()}: checkpoint rows are verified for og.RRTstar only")
        self._check_inner(inner, python)
        super().__init__(si, inner, max_iterations=None if python else max_iterations, read=read, renew=renew)
        self._init_checkpoints(si, context, checker, python)
        self.checkpoints = sorted({int(c) for c in checkpoints if int(c) < max_iterations})

    @staticmethod
    def _check_inner(inner: ob.Planner, python: bool) -> None:
        """Raise ValueError when checkpoints cannot be read from ``inner`` (before ``ob.Planner.__init__``: an
        exception after it leaves a half-built trampoline)."""
        if python and not hasattr(inner, "set_intermediate_solution_callback"):
            raise ValueError(f"{inner.getName()}: no intermediate-solution callback, no checkpoints")

    def _init_checkpoints(self, si, context: tuple[str, PlannerContext], checker, python: bool) -> None:
        """What every checkpoint planner holds besides its checkpoints (they are caps here, times in the anytime
        ladder); ``python``: the inner planner is one of this package's, read through its posted paths."""
        self.context = context
        self.python = python
        self.checker = checker if checker is not None else getattr(si.getStateValidityChecker(), "robot", None)
        """The problem's checker: its ``collision_checks`` counter gives each checkpoint's checks."""
        self.snapshots: list[dict] = []
        self.start_checks: list[int] = []
        self._run: dict = {}

    def _checks(self) -> int:
        return int(self.checker.collision_checks) if self.checker is not None else 0

    def _on_solution(self, planner, states, cost) -> None:
        # copied at once: the states belong to the posted path (holding them past its life corrupts the heap)
        self._run["posted"] = (states_to_array(states, self.getSpaceInformation().getStateDimension(), read=self._read),
                               float(cost.value()))

    def _count(self) -> int | None:
        """The search's position at this termination check: samples so far (Python) or RRT*'s iterations."""
        if self.python:
            drawn = getattr(self.inner, "samples_drawn", None)
            if callable(drawn):  # dimension-RRT asks once per batch of samples, so count them, not the calls
                return int(drawn())
            self._run["calls"] += 1
            return self._run["calls"] - 1
        return self.inner.numIterations()

    def _sample_stops(self) -> list[int]:
        """The sample counts at which a Python planner must ask the termination condition."""
        return self.checkpoints

    def _due(self, n: int | None, now: float) -> list:
        """The checkpoints reached at this termination check."""
        return [n] if n in self._run["todo"] else []

    def _watch(self) -> bool:
        run = self._run
        n = self._count()
        now = time.perf_counter() - run["t0"]
        for key in self._due(n, now):
            run["todo"].discard(key)
            try:
                run["snaps"][key] = self._snapshot(n, now)
            except Exception:  # noqa: BLE001 (an exception would abort the benchmark)
                log.exception("checkpoint %s of %s failed", key, self.inner.getName())
        return False

    def _snapshot(self, n: int, now: float) -> dict:
        si = self.getSpaceInformation()
        dim = si.getStateDimension()
        snap = {"time": now, "iterations": n, "checks": self._checks(), "pending": False,
                "valid_fraction": valid_motion_fraction(self._run["motions0"], motion_counts(si.getMotionValidator()))}
        if self.python:
            progress = self.inner.last_run_stats()["progress"]
            found = progress[-1][1] if progress else math.inf
            posted = self._run.get("posted")
            W = None
            if posted is not None and posted[1] == found:
                W = posted[0].copy()
            snap.update(best_cost=found, waypoints=W, exact=W is not None, difference=0.0,
                        graph_states=None, graph_motions=None, pending=W is None and math.isfinite(found))
            return snap
        pd = ob.PlannerData(si)
        self.inner.getPlannerData(pd)
        goal = self.getProblemDefinition().getGoal().getState()
        W, exact, diff = _tree_path(pd, si, goal, dim, self._read)
        snap.update(best_cost=self.inner.bestCost().value(), waypoints=W, exact=exact, difference=diff,
                    graph_states=int(pd.numVertices()), graph_motions=int(pd.numEdges()))
        return snap

    def solve(self, ptc):  # noqa: D102 (OMPL override)
        self.renew_if_used()  # (before the inner planner is read below)
        self.start_checks.append(self._checks())
        self._run = {"t0": time.perf_counter(), "calls": 0, "todo": set(self.checkpoints), "snaps": {}, "motions0": None}
        with contextlib.suppress(Exception):  # nothing may escape to OMPL (it would abort the benchmark)
            self._run["motions0"] = motion_counts(self.getSpaceInformation().getMotionValidator())
        if self.python:
            self.inner.set_intermediate_solution_callback(self._on_solution)
            if callable(getattr(self.inner, "set_sample_checkpoints", None)):
                self.inner.set_sample_checkpoints(self._sample_stops())
        watched = ob.plannerOrTerminationCondition(ptc, ob.PlannerTerminationCondition(self._watch))
        try:
            return super().solve(watched)
        finally:
            if self.python:
                self.inner.set_intermediate_solution_callback(None)
                if callable(getattr(self.inner, "set_sample_checkpoints", None)):
                    self.inner.set_sample_checkpoints([])
            self.snapshots.append(self._run["snaps"])


class Ladder:
    """One iteration ladder run at its largest cap: wraps the planners, then derives the other caps' logs."""

    def __init__(self, specs: list[dict]) -> None:
        self.specs = sorted(specs, key=lambda s: s["cap"])
        self.cap = self.specs[-1]["cap"]
        self.checkpoints = [s["cap"] for s in self.specs[:-1]]
        self.wrappers: dict[str, CheckpointPlanner] = {}
        self.derived: list[tuple[str, dict, None]] = []
        """The smaller caps' (log text, extras, None), ascending, after the run."""

    @property
    def spec(self) -> dict:
        """The spec of the run itself (the largest cap)."""
        return self.specs[-1]

    def wrap(self, si: ob.SpaceInformation, inner: ob.Planner, cap: int, pname: str, ctx: PlannerContext,
             checker: Any = None, read: Callable[[ob.State], object] | None = None,
             renew: Callable[[], ob.Planner] | None = None) -> CheckpointPlanner:
        """The recording wrapper of one planner of the run (``checker``: the problem's, whose checks are
        counted; ``read``: the state reader of a non-RealVector space; ``renew``: :class:`RecordingPlanner`'s)."""
        w = CheckpointPlanner(si, inner, cap, self.checkpoints, (pname, ctx), checker=checker, read=read, renew=renew)
        self.wrappers[w.getName()] = w
        return w

    def derive(self, bench: ot.Benchmark, name: str, records: dict, ctx: DeriveContext) -> list[tuple[str, dict, None]]:
        """One ``(log text, extras, None)`` per smaller cap, ascending (edits the recorded data in place:
        call after the largest cap's log is saved)."""
        ed = bench.getRecordedExperimentData()
        self._run_pending(ctx.ss, ctx.max_time)
        out = []
        for n in self.checkpoints:
            ed.name = name.replace(f"_N{self.cap}_", f"_N{n}_")
            params = dict(ed.parameters)
            params["sample_cap INTEGER"] = str(n)
            ed.parameters = params
            extras, total = {}, 0.0
            for pl in ed.planners:
                pname = planner_name(pl.name)
                extras[pname], seconds = derive_planner_runs(pl, pl, self.wrappers[pname], records.get(pname, []), n, ctx)
                total += seconds
                pl.common["iteration_cap"] = str(n)
                if "planner.max_samples" in pl.common.to_dict():  # our planners' own cap: the row's, as a run capped at n
                    pl.common["planner.max_samples"] = str(n)
            ed.totalDuration = total
            out.append((log_text(bench), extras, None))
        return out

    def _run_pending(self, ss, max_time: float) -> None:
        """Checkpoints where dimension-RRT's best path was not posted yet: a separate run capped there."""
        si, pdef = ss.getSpaceInformation(), ss.getProblemDefinition()
        for w in self.wrappers.values():
            for snaps in w.snapshots:
                for n, snap in snaps.items():
                    if not snap["pending"]:
                        continue
                    pname, ctx = w.context
                    p = planner_factory(pname)(si, dataclasses.replace(ctx, max_samples=n))
                    pdef.clearSolutionPaths()
                    p.setProblemDefinition(pdef)
                    p.setup()
                    c0, t0, m0 = w._checks(), time.perf_counter(), motion_counts(si.getMotionValidator())
                    p.solve(ob.timedPlannerTerminationCondition(max_time))
                    elapsed = time.perf_counter() - t0
                    snap["valid_fraction"] = valid_motion_fraction(m0, motion_counts(si.getMotionValidator()))
                    stats = p.last_run_stats()
                    W = None
                    if pdef.hasExactSolution():
                        W = states_to_array(pdef.getSolutionPath().getStates(), si.getStateDimension(), read=w._read)
                    snap.update(time=elapsed, waypoints=W, exact=W is not None, best_cost=stats["best_cost"],
                                own_checks=w._checks() - c0, pending=False, iterations=stats["samples"],
                                first_solution_time=stats["first_solution_time"],
                                progress=[(float(t), float(c), int(k)) for t, c, k in stats["progress"]])
                    log.info("%s: checkpoint %d re-run separately (its best path was not posted yet)", pname, n)
        pdef.clearSolutionPaths()

    @staticmethod
    def _ompl_columns(si, pdef, row: dict, snap: dict, simplify: bool) -> dict:
        """OMPL's run columns for the checkpoint path, computed as ``Benchmark`` does."""
        row = {k: v for k, v in row.items() if not k.startswith(SOLUTION_KEYS)}
        W = snap["waypoints"]
        st = ob.PlannerStatus.EXACT_SOLUTION if snap["exact"] else (
            ob.PlannerStatus.APPROXIMATE_SOLUTION if W is not None else ob.PlannerStatus.TIMEOUT)
        row.update({"time REAL": _ompl_text(snap["time"]), "status ENUM": str(st.value),
                    "solved BOOLEAN": _ompl_text(bool(snap["exact"])),
                    "valid segment fraction REAL": _ompl_text(snap["valid_fraction"])})
        if snap.get("graph_states") is not None:
            row["graph states INTEGER"] = str(snap["graph_states"])
            row["graph motions INTEGER"] = str(snap["graph_motions"])
        if W is None:
            return row
        space = si.getStateSpace()
        path = RealVectorLayout(space).to_path(si, W)  # SO2 compounds too
        factor = space.getValidSegmentCountFactor()

        def describe(p: og.PathGeometric, prefix: str) -> dict:
            out = {f"{prefix}solution length REAL": p.length(), f"{prefix}solution smoothness REAL": p.smoothness(),
                   f"{prefix}solution clearance REAL": p.clearance(),
                   f"{prefix}solution segments INTEGER": p.getStateCount() - 1}
            ok = p.check()
            space.setValidSegmentCountFactor(factor * 4)
            try:
                strict = p.check()
            finally:
                space.setValidSegmentCountFactor(factor)
            key = "simplified correct solution" if prefix else "correct solution"
            out.update({f"{key} BOOLEAN": bool(ok), f"{key} strict BOOLEAN": bool(strict)})
            return out

        cols = {"approximate solution BOOLEAN": not snap["exact"], "solution difference REAL": snap["difference"],
                **describe(path, "")}
        if simplify:
            t0 = time.perf_counter()
            og.PathSimplifier(si, pdef.getGoal(), pdef.getOptimizationObjective()).simplifyMax(path)
            cols["simplification time REAL"] = time.perf_counter() - t0
            cols.update(describe(path, "simplified "))
        row.update({k: _ompl_text(v) for k, v in cols.items()})
        return row

    @staticmethod
    def _our_columns(si, props: dict, snap: dict, checks, start, goal, path_properties) -> dict:
        """This package's run columns for the checkpoint, as the post-run event computes them."""
        first = snap.get("first_solution_time", props.get("first_solution_time REAL"))
        if "first_solution_time" not in snap and (first is None or first == "" or float(first) > snap["time"]):
            first = None
        out = dict(props)
        out.update({"collision_checks INTEGER": checks, "iterations INTEGER": snap["iterations"],
                    "samples INTEGER": snap["iterations"], "first_solution_time REAL": first, **NO_PATH_COLUMNS})
        if snap.get("graph_states") is not None:
            out["graph states INTEGER"] = snap["graph_states"]
            out["graph motions INTEGER"] = snap["graph_motions"]
        out["valid segment fraction REAL"] = snap["valid_fraction"]
        rec = {"waypoints": snap["waypoints"], "best_cost": snap["best_cost"]}
        out.update(path_properties(si, rec, start, goal))
        if snap["waypoints"] is None and math.isfinite(float(snap["best_cost"])):
            out["best_cost REAL"] = snap["best_cost"]
        return out


def derived_run(ctx: DeriveContext, w: CheckpointPlanner, i: int, row: dict, rec: dict,
                snap: dict | None) -> tuple[dict, list, dict]:
    """Run ``i``'s (OMPL row, progress, our columns) at one checkpoint: the recorded run itself when
    ``snap`` is None (the run ended before the checkpoint), else the snapshot's columns."""
    if snap is None:
        return row, rec["progress"], rec["props"]
    si = ctx.ss.getSpaceInformation()
    row = Ladder._ompl_columns(si, ctx.ss.getProblemDefinition(), row, snap, ctx.simplify)
    checks = snap.get("own_checks", snap["checks"] - w.start_checks[i])  # the search's, as a full run's
    props = Ladder._our_columns(si, rec["props"], snap, checks, ctx.start, ctx.goal, ctx.path_properties)
    row.update({k: format_value(v) for k, v in props.items()})
    prog = snap.get("progress")
    if prog is None:
        prog = progress_until(rec["progress"], snap)
    return row, prog, props


def progress_until(progress: list[tuple[float, float, int | None]], snap: dict) -> list[tuple[float, float, int | None]]:
    """A run's progress rows as they stood at a checkpoint snapshot, ending with the snapshot's own row.

    The planner times its rows from its own start and the snapshot from the wrapper's, a little earlier, so a row
    a few microseconds before the snapshot's time can come after it: rows past the snapshot's iterations are
    left out too (a row of 66,701 samples was followed by the checkpoint's 66,665)."""
    n = snap["iterations"]
    out = [p for p in progress if p[0] <= snap["time"] and (n is None or p[2] is None or p[2] <= n)]
    return out + [(snap["time"], snap["best_cost"], n)]


def derive_planner_runs(source: ot.PlannerExperiment, target: ot.PlannerExperiment, w: CheckpointPlanner,
                        recs: list[dict], key: float, ctx: DeriveContext) -> tuple[list[dict], float]:
    """Write into ``target`` (an ``ot.PlannerExperiment``) the runs of ``source`` as they stood at checkpoint
    ``key`` (a cap or a budget; :func:`derived_run` per run); return the runs' extra columns and their seconds."""
    rows, progress, extras = [], [], []
    for i, run in enumerate(source.runs):
        snap = w.snapshots[i].get(key) if i < len(w.snapshots) else None
        rec = recs[i] if i < len(recs) else {"props": {}, "progress": []}
        row, prog, props = derived_run(ctx, w, i, run.to_dict(), rec, snap)
        rows.append(row)
        progress.append(prog)
        extras.append({k.rsplit(" ", 1)[0]: v for k, v in props.items()})
    set_runs(target, rows, progress)
    return extras, sum(run_seconds(r) for r in rows)


def run_seconds(row: dict) -> float:
    """A run's planning plus simplification time (s), from its OMPL row."""
    return float(row.get("time REAL") or 0) + float(row.get("simplification time REAL") or 0)


def set_runs(pl: ot.PlannerExperiment, rows: list[dict], progress: list[list]) -> None:
    """Replace a recorded planner's runs and progress (``pl``: an ``ot.PlannerExperiment``)."""
    runs = []
    for row in rows:
        new = ot.RunProperties()
        for k, v in row.items():
            new[k] = v
        runs.append(new)
    pl.runs = runs
    pl.runsProgressData = [progress_rows(p) for p in progress]
