"""One run per anytime ladder: the rows of the shorter time budgets read at time checkpoints of the longest.

OMPL's planners and dimension-RRT do not know their time budget: they evaluate the termination condition
once per iteration and do the same work until it is true.  So the state of a run at the moment its clock
passes b is the state a run with budget b has at its deadline.  (``Benchmark`` checks its own deadline in a
thread only every 0.1 s, so every run is also told its budget by its :class:`RecordingPlanner`: a separate
run at b and the ladder's run at its longest budget stop at their budget, not up to 0.1 s later.)
The anytime ladder (0.1, 0.5, 1, 2 s) of one query and validator is run once, at the longest budget, each
planner inside :class:`TimeCheckpointPlanner`, which reads at each shorter budget b what the planner would
return if stopped there (:data:`ANYTIME_READ`):

* **RRT\\*, Informed RRT\\*** (``tree``): the best path rebuilt from ``getPlannerData`` (the goal vertex's chain
  of parents, else the approximate solution), as :mod:`~tpee_ompl.bench.ladder` does for iteration caps.
* **RRTConnect** (``first``): it stops at its first solution.  A run that finished by b gives the same row;
  at a budget before its finish a separate run stopped at b returns an *approximate* solution built from
  an internal candidate (the last start-tree motion of each connect phase) that its planner data cannot
  reproduce, so that budget runs separately.
* **dimension-RRT** (``posted``): its last posted path (intermediate-solution callback) when it is the best
  it found; when the best was still waiting to be posted (posting is throttled), that budget runs separately.

Everything else runs separately per budget: RRTConnectSimplify (its simplification uses the time left: it
knows its budget), AORRTC (it simplifies each new path in place with ``PathSimplifier.simplify(path, ptc)``,
whose first pass runs to its end even after the deadline, so its answer at b is not the problem
definition's path at b), BIT* (not verified), LibraryDimensionRRT (no intermediate-solution callback) and
``module:function`` planners.  A separate run is an ordinary ``Benchmark`` experiment at budget b of only
those planners, merged into the budget's log in the planners' order.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from ompl import base as ob
from ompl import tools as ot

from .database import log_text
from .ladder import CheckpointPlanner, DeriveContext, derive_planner_runs, run_seconds
from .planners import PlannerContext, RecordingPlanner
from .results import format_value, planner_name

__all__ = ["ANYTIME_READ", "AnytimeLadder", "TimeCheckpointPlanner", "copy_planner", "group_anytime_ladders"]

log = logging.getLogger(__name__)

ANYTIME_READ: dict[str, str] = {"RRTstar": "tree", "InformedRRTstar": "tree", "RRTConnect": "first",
                                "DimensionRRT": "posted"}
"""Planner name -> how its answer at a time checkpoint is read (tests/bench/test_anytime_ladder.py)."""


def group_anytime_ladders(groups: list[list[dict]], enabled: bool) -> list[list[dict]]:
    """``groups`` with the single anytime experiments of one validator merged into one ladder (by budget),
    placed where its first budget was; unchanged when ``enabled`` is False."""
    if not enabled:
        return groups
    ladders: dict[str, list[dict]] = {}
    out: list[list[dict]] = []
    for g in groups:
        if len(g) == 1 and g[0]["comparison"] == "anytime" and g[0]["budget"] is not None:
            if g[0]["checker"] not in ladders:
                ladders[g[0]["checker"]] = []
                out.append(ladders[g[0]["checker"]])
            ladders[g[0]["checker"]].append(g[0])
        else:
            out.append(g)
    return [sorted(g, key=lambda s: s["budget"]) if g[0]["comparison"] == "anytime" else g for g in out]


def copy_planner(pl: ot.PlannerExperiment) -> ot.PlannerExperiment:
    """A detached copy of a recorded planner (``ot.PlannerExperiment``), to outlive its benchmark."""
    new = ot.PlannerExperiment()
    new.name = pl.name
    common = ot.RunProperties()
    for k, v in pl.common.to_dict().items():
        common[k] = v
    new.common = common
    new.progressPropertyNames = list(pl.progressPropertyNames)
    runs = []
    for run in pl.runs:
        r = ot.RunProperties()
        for k, v in run.to_dict().items():
            r[k] = v
        runs.append(r)
    new.runs = runs
    new.runsProgressData = [[dict(p) for p in prog] for prog in pl.runsProgressData]
    return new


class TimeCheckpointPlanner(CheckpointPlanner):
    """A :class:`CheckpointPlanner` whose checkpoints are times (s since its ``solve`` began).

    ``mode`` is the planner's :data:`ANYTIME_READ` entry.  A snapshot is :class:`CheckpointPlanner`'s, with
    ``pending`` True when the budget must run separately (RRTConnect still running; dimension-RRT's best
    path not posted yet).
    """

    def __init__(self, si: ob.SpaceInformation, inner: ob.Planner, checkpoints: list[float],
                 context: tuple[str, PlannerContext], mode: str, checker: Any = None,
                 read: Callable[[ob.State], object] | None = None, renew: Callable[[], ob.Planner] | None = None,
                 deadline: float | None = None) -> None:
        self._check_inner(inner, mode == "posted")
        RecordingPlanner.__init__(self, si, inner, max_iterations=None, read=read, renew=renew, deadline=deadline)
        self._init_checkpoints(si, context, checker, python=mode == "posted")
        self.checkpoints = sorted({float(c) for c in checkpoints})
        self.mode = mode

    def _count(self) -> int | None:
        if self.python or hasattr(self.inner, "numIterations"):
            return super()._count()
        return None

    def _sample_stops(self) -> list[int]:
        return []  # the checkpoints are times

    def _due(self, n: int | None, now: float) -> list:
        return [b for b in sorted(self._run["todo"]) if now >= b]

    def _snapshot(self, n: int | None, now: float) -> dict:
        if self.mode != "first":
            return super()._snapshot(n, now)
        # RRTConnect still running at b: a run stopped at b returns an approximate path not readable here
        return {"time": now, "iterations": n, "checks": self._checks(), "pending": True}


SeparateRun = Callable[[dict, list[str]], tuple[list, dict, str | None]]
"""``(spec, planner names) -> (detached recorded planners, extras, error)``: an ordinary experiment at
``spec``'s budget with only those planners."""


class AnytimeLadder:
    """One anytime ladder run at its longest budget: wraps the planners, then derives the shorter budgets' logs."""

    def __init__(self, specs: list[dict], run_separate: SeparateRun) -> None:
        self.specs = sorted(specs, key=lambda s: s["budget"])
        self.budget = self.specs[-1]["budget"]
        self.checkpoints = [s["budget"] for s in self.specs[:-1]]
        self.run_separate = run_separate
        self.wrappers: dict[str, RecordingPlanner] = {}
        self.names: dict[str, str] = {}
        """Wrapper (recorded) name -> the configuration's planner name."""
        self.separate: set[str] = set()
        """Wrapper names of the planners that run separately at every shorter budget."""
        self.derived: list[tuple[str, dict, str | None]] = []

    @property
    def spec(self) -> dict:
        """The spec of the run itself (the longest budget)."""
        return self.specs[-1]

    def wrap(self, si: ob.SpaceInformation, inner: ob.Planner, cap: int | None, pname: str, ctx: PlannerContext,
             checker: Any = None, read: Callable[[ob.State], object] | None = None,
             renew: Callable[[], ob.Planner] | None = None) -> RecordingPlanner:
        """The recording wrapper of one planner: a :class:`TimeCheckpointPlanner` when its answer at a
        time can be read (:data:`ANYTIME_READ`), else a plain :class:`RecordingPlanner` run separately
        (``renew``: :class:`RecordingPlanner`'s).  ``cap`` is ignored (the anytime ladder has time budgets, not
        caps): it is there so a caller wraps with either ladder the same way
        (:meth:`~tpee_ompl.bench.ladder.Ladder.wrap`)."""
        mode = ANYTIME_READ.get(pname)
        if mode == "posted" and not hasattr(inner, "set_intermediate_solution_callback"):
            mode = None
        if mode is None:
            w = RecordingPlanner(si, inner, max_iterations=None, read=read, checker=checker, renew=renew,
                                 deadline=self.budget)
            self.separate.add(w.getName())
        else:
            w = TimeCheckpointPlanner(si, inner, self.checkpoints, (pname, ctx), mode, checker=checker, read=read,
                                      renew=renew, deadline=self.budget)
        self.wrappers[w.getName()] = w
        self.names[w.getName()] = pname
        return w

    def _needs_separate(self, b: float) -> set[str]:
        out = set(self.separate)
        for name, w in self.wrappers.items():
            if isinstance(w, TimeCheckpointPlanner) and any(s.get(b, {}).get("pending") for s in w.snapshots):
                out.add(name)
        return out

    def derive(self, bench: ot.Benchmark, name: str, records: dict,
               ctx: DeriveContext) -> list[tuple[str, dict, str | None]]:
        """One ``(log text, extras, error)`` per shorter budget, ascending (edits the recorded data in place:
        call after the longest budget's log is saved)."""
        ed = bench.getRecordedExperimentData()
        ctx.ss.getProblemDefinition().clearSolutionPaths()
        base = [copy_planner(pl) for pl in ed.planners]
        order = [planner_name(pl.name) for pl in base]
        separate = {}
        for spec in self.specs[:-1]:
            need = self._needs_separate(spec["budget"])
            if need:
                log.info("%s at %gs: run separately: %s", name, spec["budget"], ", ".join(sorted(need)))
                planners, extras, error = self.run_separate(spec, [self.names[n] for n in order if n in need])
                separate[spec["budget"]] = ({planner_name(p.name): p for p in planners}, extras, error)
        out = []
        tag = f"_T{self.budget:g}s_"
        for spec in self.specs[:-1]:
            b = spec["budget"]
            sep, sep_extras, error = separate.get(b, ({}, {}, None))
            ed.name = name.replace(tag, f"_T{b:g}s_")
            params = dict(ed.parameters)
            params["time_budget REAL"] = format_value(b)
            ed.parameters = params
            ed.maxTime = float(b)
            extras, total, planners = {}, 0.0, []
            for pl0 in base:
                pname = planner_name(pl0.name)
                if pname in sep:
                    pl = sep[pname]
                    extras[pname] = sep_extras.get(pname, [])
                    total += sum(run_seconds(r.to_dict()) for r in pl.runs)
                    planners.append(pl)
                    continue
                pl = copy_planner(pl0)
                extras[pname], seconds = derive_planner_runs(pl0, pl, self.wrappers[pname], records.get(pname, []), b, ctx)
                total += seconds
                planners.append(pl)
            ed.planners = planners
            ed.totalDuration = total
            out.append((log_text(bench), extras, error))
        return out
