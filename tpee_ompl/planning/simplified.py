"""A planner followed by OMPL's path simplifier, as one planner: the pipeline most OMPL and MoveIt users run.

``SimplifiedPlanner(si, og.RRTConnect(si))`` plans with RRTConnect until its first exact path, then
shortens it with ``og.PathSimplifier.simplify`` until the simplifier converges or the termination
condition ends it.  An inner planner that returns only at the termination condition (an anytime one such as
RRT*) leaves the simplifier no time.  The simplification is part of the planner's time (so a benchmark compares it at
equal time with an anytime planner), and the simplified path is added to the problem definition
after it passed ``si.checkMotion`` over the whole path.
"""

from __future__ import annotations

import logging
import math
import time
from typing import Any

from ompl import base as ob
from ompl import geometric as og

from .paths import path_passes_motion_checks
from .planner_base import PythonPlanner, check_space_information, planner_status, problem_objective

__all__ = ["SimplifiedPlanner"]

log = logging.getLogger(__name__)


class SimplifiedPlanner(PythonPlanner):
    """``inner`` until its first exact solution, then OMPL's ``PathSimplifier`` in the remaining time.

    Parameters
    ----------
    si : ob.SpaceInformation
    inner : ob.Planner
        The planner that finds the first path (e.g. ``og.RRTConnect(si)``), on the same ``si``.
    name : str, optional
        Planner name (default ``<inner name>Simplify``, e.g. ``RRTConnectSimplify``).
    """

    def __init__(self, si: ob.SpaceInformation, inner: ob.Planner, name: str | None = None) -> None:
        check_space_information(si)
        if not isinstance(inner, ob.Planner):
            raise ValueError(f"inner must be an ompl.base.Planner, got {type(inner).__name__}")
        if inner.getSpaceInformation() is not si:  # its paths would be checked against another space's validity
            raise ValueError(f"inner planner {inner.getName()} is built on another SpaceInformation than si")
        if name is not None and (not isinstance(name, str) or not name):
            raise ValueError(f"name must be a non-empty string, got {name!r}")
        super().__init__(si, name or f"{inner.getName()}Simplify")
        self.inner = inner
        self._inner_setup = False

    @staticmethod
    def _empty_stats() -> dict[str, Any]:
        return {**PythonPlanner._empty_stats(), "raw_cost": math.inf, "simplify_time": 0.0}

    def settings(self) -> dict[str, str]:
        """Parameter name -> value as text (for the benchmark's ``plannerConfigs``)."""
        return {"inner": self.inner.getName(), "simplifier": "PathSimplifier.simplify(path, ptc, atLeastOnce=False)"}

    def last_run_stats(self) -> dict[str, Any]:
        """first_solution_time (s, the inner planner's exact path), raw_cost, best_cost (after
        simplifying), simplify_time (s), progress [(time_s, best_cost, None), ...] (no iteration count: RRTConnect
        reports none)."""
        return super().last_run_stats()

    def clear(self) -> None:
        """Forget the last run (and the inner planner's)."""
        super().clear()
        self.inner.clear()

    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        t0 = time.perf_counter()
        si, pdef = self.getSpaceInformation(), self.getProblemDefinition()
        missing = "start state" if pdef.getStartStateCount() == 0 else "goal" if pdef.getGoal() is None else None
        if missing:  # the inner planner would throw (a CRASH with a traceback)
            log.error("%s: the problem has no %s", self.getName(), missing)
            return planner_status(ob.PlannerStatus.INVALID_START if missing == "start state"
                                  else ob.PlannerStatus.INVALID_GOAL)
        self.inner.setProblemDefinition(pdef)
        if not self._inner_setup:  # the bindings expose setup() but not isSetup()
            self.inner.setup()
            self._inner_setup = True
        status = self.inner.solve(ptc)
        if pdef.hasExactSolution() and not _answers(pdef):
            # native planners keep their trees across solves: after a new start or goal without clear(), RRTConnect
            # answered the old query's path as an exact solution
            pdef.clearSolutionPaths()
            self.inner.clear()
            status = self.inner.solve(ptc)
        if not pdef.hasExactSolution():
            return status
        # a plain og.SimpleSetup has no objective: the raw and simplified paths are compared by length
        stats, opt = self._stats, problem_objective(pdef) or ob.PathLengthOptimizationObjective(si)
        raw = og.PathGeometric(pdef.getSolutionPath())
        now = time.perf_counter() - t0
        stats.update(first_solution_time=now, raw_cost=float(raw.cost(opt).value()))
        stats["best_cost"] = stats["raw_cost"]
        stats["progress"].append((now, stats["raw_cost"], None))  # no iteration count
        if ptc():
            return planner_status(ob.PlannerStatus.EXACT_SOLUTION)
        path = og.PathGeometric(raw)
        t1 = time.perf_counter()
        # atLeastOnce=False: no pass started after ptc holds (the bindings' default finishes one whole pass past it)
        og.PathSimplifier(si, pdef.getGoal(), opt).simplify(path, ptc, False)
        stats["simplify_time"] = time.perf_counter() - t1
        cost = float(path.cost(opt).value())
        if cost < stats["raw_cost"] and path_passes_motion_checks(si, path):
            pdef.addSolutionPath(path, False, 0.0, self.getName())
            stats["best_cost"] = cost
        stats["progress"].append((time.perf_counter() - t0, stats["best_cost"], None))
        return planner_status(ob.PlannerStatus.EXACT_SOLUTION)


def _answers(pdef: ob.ProblemDefinition) -> bool:
    """Whether the problem definition's solution path runs from one of its start states into its goal."""
    states = pdef.getSolutionPath().getStates()  # the path's own states (never pdef.getStartState: it frees them)
    return bool(states) and pdef.hasStartState(states[0], 0) and pdef.getGoal().isSatisfied(states[-1])
