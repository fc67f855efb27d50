"""Goal regions for dimension-RRT: the goal states a solve plans to, and one search per goal state.

OMPL problems state their goal as one state (``GoalState``), several (``GoalStates``: e.g. the inverse
kinematics solutions of one end-effector pose) or a region that can be sampled
(``GoalSampleableRegion``, ``GoalSpace``, ``GoalLazySamples``, a Python subclass).  Dimension-RRT's
search runs between two fixed configurations, so :func:`goal_states` reads the goal's valid states
(OMPL's ``PlannerInputStates.nextGoal``, which checks bounds and validity) and
:class:`~tpee_ompl.planning.dimension_rrt.DimensionRRT` keeps the ``max_goals`` nearest the start, runs
one :class:`GoalRun` per goal state, nearest first, in turns of :data:`GOAL_TURN` samples, and posts every
shorter path to the same problem definition.  ``max_samples`` counts the samples of all goals;
``stall_samples`` counts per goal (a goal with no path yet stops after that many samples once another
has one), so a converged solve ends at most one stall per goal after its last shorter path; a goal whose
start-goal distance is no shorter than the best path found stops at once.  A region that cannot be
sampled (a bare ``GoalRegion``) is refused.  A ``GoalLazySamples`` whose sampler is a Python function
cannot deliver while the planner waits for its first goal (the wait holds the interpreter; OMPL's
RRTConnect waits the same way from Python): give such a goal states up front (``GoalStates``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from ompl import base as ob

from .planner_base import finite_state, planner_status

if TYPE_CHECKING:  # pragma: no cover
    from .dimension_search import Search
    from .grouped_space import GroupedSpace
    from .planner_base import PythonPlanner

__all__ = ["GOAL_SWAP_AFTER", "GOAL_TURN", "MAX_GOAL_STATES", "GoalRun", "goal_states"]

log = logging.getLogger("tpee_ompl.planning.dimension_rrt")

GOAL_TURN = 100
"""Samples a goal's search draws before the next goal's takes its turn (with several goal states)."""
GOAL_SWAP_AFTER = 500
"""Samples of a goal's search without a path after which, at the end of its turn, the next goal state beyond the
``max_goals`` nearest takes its place (it goes to the back of that queue): the nearest goals sealed in a pocket
made the solve TIMEOUT for good while a farther one was reachable (RRTConnect found it in 2 ms)."""
_GOAL_TRIES = 100
"""Draws from a goal region per goal state wanted before it counts as having no more valid ones."""
MAX_GOAL_STATES = 1000
"""Most states of a ``GoalStates`` read to pick the nearest ``max_goals`` from."""


@dataclass(eq=False)  # (identity: the loop finds a run in its list, and a goal array has no truth value)
class GoalRun:
    """One goal state's search within a solve, and its counters.

    ``done`` counts the samples of this goal's earlier searches (before ``h`` was raised or the rows were
    released); ``improved_at`` is the search's sample count at its last shorter path (``stall_samples`` and
    ``release_after`` count from there); ``best`` is the length of its shortest path so far; ``bound`` is
    the start-goal distance, which no path to this goal beats; ``turn_end`` is the sample count at which
    its turn ends; ``stopped``: converged (``stall_samples``) or beaten (``bound``), it gets no more turns."""

    goal: np.ndarray
    grouped: GroupedSpace
    search: Search
    release: int | None
    bound: float
    done: int = 0
    improved_at: int = 0
    best: float = field(init=False)
    turn_end: int = 0
    stopped: bool = False
    twin: GoalRun | None = None
    """A second search of the same goal, taking turns with this one (``DimensionRRTOptions.restart_after``)."""

    @property
    def samples(self) -> int:
        return self.done + self.search.samples

    def __post_init__(self) -> None:
        self.best = self.search.cost if self.search.valid else np.inf

    def restart(self, grouped: GroupedSpace, search: Search) -> None:
        """Go on with a new search (``h`` raised, or the rows released); its samples count on from the last's."""
        self.done = self.samples
        self.grouped, self.search = grouped, search


def goal_states(planner: PythonPlanner, ptc: ob.PlannerTerminationCondition, max_goals: int,
                read: Callable[[ob.State], np.ndarray]) -> list[np.ndarray] | ob.PlannerStatus:
    """The distinct goal states of ``planner``'s problem (as ``read`` gives their values) that a solve may
    plan to, or the status saying why there are none.

    A ``GoalState``: its state (INVALID_GOAL when it is out of bounds or invalid).  ``GoalStates`` (and
    its subclass ``GoalLazySamples``): every valid one it holds, up to :data:`MAX_GOAL_STATES` (the caller
    keeps the ``max_goals`` nearest first, so below that cap the choice does not depend on OMPL's rotating sample
    position; a ``GoalLazySamples`` holding none yet: its first waited for until ``ptc``).  Any other
    ``GoalSampleableRegion``: the first ``max_goals`` valid states drawn from it (with OMPL's random
    numbers, not the planner's seed; drawn until ``ptc`` while none is valid, as RRTConnect's ``nextGoal(ptc)``,
    then at most :data:`_GOAL_TRIES` per goal state wanted); INVALID_GOAL when the goal has no more states to give
    and none was valid, TIMEOUT when ``ptc`` stopped the drawing first.  Another goal type: UNRECOGNIZED_GOAL_TYPE,
    with an error naming it."""
    goal = planner.getProblemDefinition().getGoal()
    if isinstance(goal, ob.GoalState):
        state = planner._goal_state()
        return state if isinstance(state, ob.PlannerStatus) else [read(state)]
    if not isinstance(goal, ob.GoalSampleableRegion):
        log.error("%s needs a goal it can sample states from (GoalState, GoalStates or another GoalSampleableRegion), "
                  "got %s", planner.getName(), type(goal).__name__)
        return planner_status(ob.PlannerStatus.UNRECOGNIZED_GOAL_TYPE)
    want = min(goal.maxSampleCount(), MAX_GOAL_STATES) if isinstance(goal, ob.GoalStates) else max_goals
    pis, si = planner.getPlannerInputStates(), planner.getSpaceInformation()
    if pis.getSampledGoalsCount() > 0:  # solve() again without clear(): the goal states were drawn already
        pis.restart()
    states: dict[bytes, np.ndarray] = {}  # distinct values, in the order drawn
    tries = 0  # nextGoal() draws one state, None when it is invalid; it reuses one state, so read at once
    region = not isinstance(goal, ob.GoalStates)  # drawn until a valid state comes (OMPL's nextGoal(ptc)) or ptc
    while (len(states) < want and pis.haveMoreGoalStates() and (tries < _GOAL_TRIES * want or region and not states)
           and not (tries and ptc())):
        tries += 1
        state = pis.nextGoal()
        if state is not None and finite_state(si, state):  # OMPL's bounds check lets NaN through
            q = read(state)
            states.setdefault(q.tobytes(), q)
    if not states and isinstance(goal, ob.GoalLazySamples):
        state = pis.nextGoal(ptc)  # a sampler thread may need time for its first goal: waited for until ptc
        if state is not None and finite_state(si, state):
            states[b""] = read(state)
    if not states:
        if ptc() and pis.haveMoreGoalStates():  # stopped drawing, not out of goals
            return planner_status(ob.PlannerStatus.TIMEOUT)
        log.error("%s: no valid goal state could be drawn from the goal region", planner.getName())
        return planner_status(ob.PlannerStatus.INVALID_GOAL)
    return list(states.values())
