"""Goal regions for dimension-RRT: the goal states a solve plans to, and one search per goal state.

OMPL problems state their goal as one state (``GoalState``), several (``GoalStates``: e.g. the inverse
kinematics solutions of one end-effector pose) or a region that can be sampled
(``GoalSampleableRegion``, ``GoalSpace``, ``GoalLazySamples``, a Python subclass).  Dimension-RRT's
search runs between two fixed configurations, so :func:`goal_states` takes up to ``max_goals`` valid goal
states from the region (OMPL's ``PlannerInputStates.nextGoal``, which checks bounds and validity), and
:class:`~tpee_ompl.planning.dimension_rrt.DimensionRRT` runs one :class:`GoalRun` per goal state, nearest
to the start first, in turns of :data:`GOAL_TURN` samples; every run's shorter paths go to the same
problem definition.  A region that cannot be sampled (a bare ``GoalRegion``) is refused.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from ompl import base as ob

from .planner_base import planner_status

if TYPE_CHECKING:  # pragma: no cover
    from .dimension_search import Search
    from .grouped_space import GroupedSpace

__all__ = ["GOAL_TURN", "GoalRun", "goal_states"]

log = logging.getLogger("tpee_ompl.planning.dimension_rrt")

GOAL_TURN = 100
"""Samples a goal's search draws before the next goal's takes its turn (with several goal states)."""
_GOAL_TRIES = 100
"""Draws from a goal region per goal state wanted before it counts as having no more valid ones."""


@dataclass
class GoalRun:
    """One goal state's search within a solve, and its counters.

    ``done`` counts the samples of this goal's earlier searches (before ``h`` was raised or the rows were
    released); ``improved_at`` is the search's sample count at its last shorter path (``stall_samples`` and
    ``release_after`` count from there); ``bound`` is the start-goal distance, which no path to this goal
    beats."""

    goal: np.ndarray
    grouped: GroupedSpace
    search: Search
    release: int | None
    bound: float
    done: int = 0
    improved_at: int = 0
    best: float = np.inf
    turn_end: int = 0
    stopped: bool = False

    @property
    def samples(self) -> int:
        return self.done + self.search.samples


def goal_states(planner: ob.Planner, ptc: ob.PlannerTerminationCondition, max_goals: int,
                read: Callable[[ob.State], np.ndarray]) -> list[np.ndarray] | ob.PlannerStatus:
    """The goal states of ``planner``'s problem to plan to (as ``read`` gives their values), or the status
    saying why there are none.

    A ``GoalState``: its state, INVALID_GOAL when it is out of bounds or invalid.  Any other
    ``GoalSampleableRegion``: up to ``max_goals`` valid states drawn from it (a ``GoalLazySamples`` with
    none yet: its first waited for until ``ptc``); INVALID_GOAL when none is found.  Another goal type: UNRECOGNIZED_GOAL_TYPE, with an error naming it."""
    si, goal = planner.getSpaceInformation(), planner.getProblemDefinition().getGoal()
    if isinstance(goal, ob.GoalState):
        state = goal.getState()
        if not (si.satisfiesBounds(state) and si.isValid(state)):
            return planner_status(ob.PlannerStatus.INVALID_GOAL)
        return [read(state)]
    if not isinstance(goal, ob.GoalSampleableRegion):
        log.error("%s needs a goal it can sample states from (GoalState, GoalStates or another GoalSampleableRegion), "
                  "got %s", planner.getName(), type(goal).__name__)
        return planner_status(ob.PlannerStatus.UNRECOGNIZED_GOAL_TYPE)
    pis = planner.getPlannerInputStates()
    if pis.getSampledGoalsCount() > 0:  # solve() again without clear(): the goal states were drawn already
        pis.restart()
    states: list[np.ndarray] = []
    tries = 0  # nextGoal() draws one state and returns None when it is invalid (nextGoal() reuses one state:
    # read at once); a region whose states are all invalid ends after _GOAL_TRIES per goal wanted
    while len(states) < max_goals and pis.haveMoreGoalStates() and tries < _GOAL_TRIES * max_goals and not (tries and ptc()):
        tries += 1
        state = pis.nextGoal()
        if state is not None:
            states.append(read(state))
    if not states and isinstance(goal, ob.GoalLazySamples):
        state = pis.nextGoal(ptc)  # a sampler thread may need time for its first goal: waited for until ptc
        if state is not None:
            states.append(read(state))
    if not states:
        log.error("%s: no valid goal state could be drawn from the goal region", planner.getName())
        return planner_status(ob.PlannerStatus.INVALID_GOAL)
    return states
