"""What every Python planner of the package shares: OMPL's solve contract, per-run statistics, the query's ends.

OMPL calls ``solve`` with a termination condition (a Python caller may pass seconds) and expects a
``PlannerStatus`` back, never an exception: one escaping into ``ot.Benchmark`` aborts the whole
benchmark.  :class:`PythonPlanner` wraps a subclass's ``_solve`` in that contract, keeps its
``last_run_stats()``, and reads the start and the single goal state the way the bindings allow
(``pdef.getStartState(i)`` frees a state the problem definition owns: never call it).
"""

from __future__ import annotations

import logging
import math
import numbers
import sys
from collections.abc import Callable
from typing import Any

from ompl import base as ob

__all__ = ["PythonPlanner", "check_space_information", "finite_state", "fixed_attribute", "planner_status",
           "status_text", "validator_mismatch"]

log = logging.getLogger(__name__)


def fixed_attribute(name: str, get: Callable[[Any], Any], doc: str, given: str | None = None) -> property:
    """A planner's read-only attribute (a setting fixed when it is built) whose assignment says where it is set
    (``given``: how the constructor takes it; default ``name=...`` or ``DimensionRRTOptions``)."""
    def refuse(self: Any, value: Any) -> None:
        kind = type(self).__name__
        raise AttributeError(f"{kind}.{name} is fixed when the planner is built: pass "
                             f"{given or f'{name}=... (or DimensionRRTOptions)'} to {kind}(si, ...)")
    return property(get, refuse, doc=doc)


def problem_objective(pdef: ob.ProblemDefinition) -> ob.OptimizationObjective | None:
    """The problem's optimization objective, or None when it has none (a plain ``og.SimpleSetup``)."""
    return pdef.getOptimizationObjective() if pdef.hasOptimizationObjective() else None


def finite_state(si: ob.SpaceInformation, state: ob.State) -> bool:
    """Whether every value of ``state`` is finite: its distance to itself is 0, not NaN, in any space
    (``si.satisfiesBounds`` lets NaN through, and a NaN state would reach the checker)."""
    return math.isfinite(si.distance(state, state))


def check_space_information(si: object) -> ob.SpaceInformation:
    """``si`` if it is an ``ob.SpaceInformation`` (a planner's first argument); ValueError naming what it is otherwise
    (the bindings' own TypeError says nothing a user can act on)."""
    if not isinstance(si, ob.SpaceInformation):
        raise ValueError(f"si must be an ompl.base.SpaceInformation, got {type(si).__name__}")
    return si


def planner_status(code: Any) -> ob.PlannerStatus:
    """An ``ob.PlannerStatus`` object (OMPL needs the object, not the enum value)."""
    return ob.PlannerStatus(code)


def validator_mismatch(si: ob.SpaceInformation) -> str | None:
    """Why ``si.checkMotion`` would pass states ``si.isValid`` rejects, or None: the validators of
    :func:`~tpee_ompl.planning.setup.make_simple_setup` check with the robot (or the checker their setup was given),
    and a checker set on ``si`` itself (which :class:`~tpee_ompl.planning.setup.RobotSimpleSetup` cannot follow) is
    not the one they consult."""
    if f"{__package__}.motion_validator" not in sys.modules:  # none can exist; importing it loads Pinocchio (0.4 s)
        return None
    from .motion_validator import BatchedMotionValidator
    from .setup import checks_as_robot

    mv = si.getMotionValidator()
    if not isinstance(mv, BatchedMotionValidator):
        return None
    svc = si.getStateValidityChecker()
    if svc is mv.checker if mv.checker is not None else checks_as_robot(svc, mv.robot):
        return None
    return ("the motion validator does not check states with the state validity checker set now (set with "
            "si.setStateValidityChecker?): set checkers with the setStateValidityChecker of the setup "
            "make_simple_setup returned, which tells its motion validator")


_UNNAMED = {ob.PlannerStatus.ABORT: "Abort", ob.PlannerStatus.INFEASIBLE: "Infeasible"}


def status_text(status: ob.PlannerStatus) -> str:
    """What ``str(status)`` says, except for ABORT and INFEASIBLE, which the bindings print as "Unknown status"."""
    return _UNNAMED.get(status.getStatus(), str(status))


class PythonPlanner(ob.Planner):
    """Base of the package's ``ob.Planner`` subclasses: subclasses implement ``_solve(ptc)``.

    A subclass validates its arguments BEFORE calling ``super().__init__`` (an exception after
    ``ob.Planner.__init__`` leaves a half-built nanobind trampoline that crashes at collection), and
    extends :meth:`_empty_stats` with its own counters.
    """

    def __init__(self, si: ob.SpaceInformation, name: str) -> None:
        super().__init__(si, name)
        self._stats: dict[str, Any] = self._empty_stats()
        self._say_start_choice = True  # off for a planner run inside another that said it already

    @staticmethod
    def _empty_stats() -> dict[str, Any]:
        return {"first_solution_time": None, "best_cost": math.inf, "progress": []}

    def last_run_stats(self) -> dict[str, Any]:
        """Statistics of the last solve (a copy): at least ``first_solution_time`` (s or None),
        ``best_cost`` (inf if none) and ``progress`` [(time_s, best_cost, samples), ...]; ``error``, the
        exception's repr, when the solve failed (status CRASH)."""
        out = dict(self._stats)
        out["progress"] = list(self._stats["progress"])
        return out

    def clear(self) -> None:
        """Forget the last run."""
        super().clear()
        self._stats = self._empty_stats()

    def _start_run(self) -> None:
        """Reset per-run state before ``_solve`` (statistics; subclasses may add)."""
        self._stats = self._empty_stats()

    def solve(self, ptc: ob.PlannerTerminationCondition | float) -> ob.PlannerStatus:
        """Run ``_solve`` under ``ptc`` (or that many seconds); an exception is logged and becomes CRASH.  A ``ptc``
        that is neither is the caller's error: TypeError, as OMPL's own planners raise."""
        if isinstance(ptc, numbers.Real) and not isinstance(ptc, bool):  # p.solve(1.0) from Python
            ptc = ob.timedPlannerTerminationCondition(float(ptc))
        elif not isinstance(ptc, ob.PlannerTerminationCondition):  # (a str was called as the condition: CRASH)
            raise TypeError("ptc must be an ompl.base.PlannerTerminationCondition or a number of seconds, "
                            f"got {type(ptc).__name__} {ptc!r:.80}")
        self._start_run()
        try:
            if self.getProblemDefinition() is None:
                log.error("%s: no problem definition; call setProblemDefinition(pdef) or solve through "
                          "og.SimpleSetup", self.getName())
                return planner_status(ob.PlannerStatus.ABORT)
            if not self.getSpaceInformation().isSetup():  # solved without setup(): set it up, as OMPL's planners do
                self.setup()
            if (why := validator_mismatch(self.getSpaceInformation())) is not None:
                log.error("%s: %s", self.getName(), why)
                return planner_status(ob.PlannerStatus.ABORT)
            return self._solve(ptc)
        except Exception as exc:  # an exception escaping into ot.Benchmark would abort the whole benchmark
            log.exception("%s.solve failed", self.getName())
            self._stats["error"] = repr(exc)
            return planner_status(ob.PlannerStatus.CRASH)

    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        raise NotImplementedError

    def _start(self) -> ob.State | ob.PlannerStatus:
        """The next valid start state within bounds (the problem's first on a new run), or INVALID_START."""
        pis = self.getPlannerInputStates()
        if pis.getSeenStartStatesCount() > 0:  # solve() again without clear(): the start states were handed out
            pis.restart()  # (before nextStart, which warns about an invalid start: once, not twice)
        start = pis.nextStart()
        if start is None:  # nextStart() skips start states out of bounds or invalid (OMPL checks them itself)
            return planner_status(ob.PlannerStatus.INVALID_START)
        count = self.getProblemDefinition().getStartStateCount()
        if count > 1 and self._say_start_choice:  # RRTConnect grows a tree from each; these search from one start
            log.warning("%s plans from one start state: the first valid of the %d given", self.getName(), count)
        if not finite_state(self.getSpaceInformation(), start):  # OMPL's bounds check lets NaN through
            log.error("%s: the start state has NaN or inf values", self.getName())
            return planner_status(ob.PlannerStatus.INVALID_START)
        return start

    def _goal_state(self) -> ob.State | ob.PlannerStatus:
        """The goal's state, within bounds and valid; else INVALID_GOAL, or UNRECOGNIZED_GOAL_TYPE (logged)
        when the goal is not an ``ob.GoalState``."""
        si, goal = self.getSpaceInformation(), self.getProblemDefinition().getGoal()
        if not isinstance(goal, ob.GoalState):
            log.error("%s needs a goal that is a single state, got %s", self.getName(), type(goal).__name__)
            return planner_status(ob.PlannerStatus.UNRECOGNIZED_GOAL_TYPE)
        gstate = goal.getState()
        if not finite_state(si, gstate):
            log.error("%s: the goal state has NaN or inf values", self.getName())
            return planner_status(ob.PlannerStatus.INVALID_GOAL)
        if not si.satisfiesBounds(gstate):
            log.error("%s: the goal state is outside the space's bounds", self.getName())
            return planner_status(ob.PlannerStatus.INVALID_GOAL)
        if not si.isValid(gstate):
            log.error("%s: the goal state is invalid (the state validity checker rejects it)", self.getName())
            return planner_status(ob.PlannerStatus.INVALID_GOAL)
        return gstate

    def _endpoints(self) -> tuple[ob.State, ob.State] | ob.PlannerStatus:
        """The start and the goal state, both within bounds and valid, or the status saying which is not."""
        start = self._start()
        if isinstance(start, ob.PlannerStatus):
            return start
        gstate = self._goal_state()
        if isinstance(gstate, ob.PlannerStatus):
            return gstate
        return start, gstate
