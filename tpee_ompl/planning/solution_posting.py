"""Posting dimension-RRT's improved paths to OMPL as they are found: checked, throttled, with a callback."""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from .paths import path_passes_motion_checks
from .planner_base import problem_objective

__all__ = ["SolutionPoster", "without_repeats"]

log = logging.getLogger("tpee_ompl.planning.dimension_rrt")

_POST_SHARE = 0.1
"""After the first, improvements are posted as found while posting costs at most this share of the run time."""


def without_repeats(W: np.ndarray) -> np.ndarray:
    """The waypoints W without one equal to the waypoint before it (start == goal, or waypoints the released search
    collapsed): OMPL's planners post no zero-length segment, and time parametrisations downstream divide by the
    segment's length.  The path still runs from the first row to the last row's values, with two rows at least."""
    moves = np.any(W[1:] != W[:-1], axis=1)
    if moves.all():
        return W
    keep = np.concatenate(([True], moves))
    return W[keep] if keep.sum() >= 2 else W[[0, -1]]


def _is_path_length(opt: ob.OptimizationObjective) -> bool:
    """Whether ``opt`` costs a path by its length: OMPL's objective, or a subclass overriding none of its costs."""
    costs = ("motionCost", "stateCost", "combineCosts", "identityCost", "motionCostHeuristic", "costToGo")
    base = ob.PathLengthOptimizationObjective
    return isinstance(opt, base) and all(getattr(type(opt), c, None) is getattr(base, c, None) for c in costs)


class SolutionPoster:
    """Hands improved paths to OMPL as they are found (see :mod:`tpee_ompl.planning.dimension_rrt`, "Stopping").

    An improvement is checked with ``si.checkMotion`` and added to the problem definition at once
    when it is the first, when it satisfies the objective, or while posting has cost at most
    ``_POST_SHARE`` of the time so far; otherwise it waits for the next post or :meth:`flush`.
    """

    def __init__(self, planner: ob.Planner, si: ob.SpaceInformation, pdef: ob.ProblemDefinition, t0: float,
                 to_path: Callable[[ob.SpaceInformation, np.ndarray], og.PathGeometric],
                 notify: Callable[[og.PathGeometric, float], None], passed: set[bytes] | None = None,
                 known_cost: float = math.inf) -> None:
        """``known_cost``: a path of that cost is in the problem definition already (posted by the planner this one
        runs inside): only shorter ones are posted."""
        self.planner, self.si, self.pdef, self.t0 = planner, si, pdef, t0
        self.to_path, self.notify = to_path, notify
        self.opt = problem_objective(pdef)
        self._own_cost = self.opt is not None and not _is_path_length(self.opt)
        """The objective is not path length: whether a path satisfies it is asked with its own cost of the path."""
        if self._own_cost:
            log.warning("%s minimises path length; the objective '%s' only says when a path is good enough",
                        planner.getName(), self.opt.getDescription() or type(self.opt).__name__)
        self.found_cost = known_cost  # best cost the search found
        self.best_cost = known_cost  # best cost posted (checked by si.checkMotion)
        self.first_time: float | None = None
        self.posted = 0
        self.satisfied = False
        self._pending: tuple[np.ndarray, float] | None = None
        self._spent = 0.0
        self.rejected = 0
        """Paths the search accepted that ``si.checkMotion`` or the bounds rejected (said once per solve)."""
        self._passed: set[bytes] = set() if passed is None else passed
        """Segments (two waypoint rows as bytes) that already passed ``si.checkMotion``, shared with the
        search's checker so a motion it checked that way is not checked again."""

    def offer(self, W: np.ndarray, cost: float, now: float) -> None:
        self.found_cost = cost
        self._pending = (W.copy(), cost)
        if self._own_cost:
            sat = bool(self.opt.isSatisfied(self.to_path(self.si, W).cost(self.opt)))
        else:
            sat = self.opt is not None and bool(self.opt.isSatisfied(ob.Cost(cost)))
        if self.posted == 0 or sat or self._spent <= _POST_SHARE * (now - self.t0):
            self.flush()
            self.satisfied = sat and self.posted > 0 and self.best_cost == cost

    def flush(self) -> None:
        """Post the pending improvement, if any (after ``si.checkMotion`` over the whole path)."""
        if self._pending is None:
            return
        t = time.perf_counter()
        W, cost = self._pending
        W = without_repeats(W)
        self._pending = None
        planner = self.planner
        path = self.to_path(self.si, W)
        # the start state was checked when it was read (OMPL's nextStart); a segment that already passed si.checkMotion
        # (same two waypoints in an earlier posted path) is not checked again
        keys = [W[k : k + 2].tobytes() for k in range(len(W) - 1)]
        states = path.getStates()
        todo = [k for k, key in enumerate(keys) if key not in self._passed]
        if path_passes_motion_checks(self.si, states, check_first=False, segments=todo, in_bounds=True):
            self._passed.update(keys)
            self.pdef.addSolutionPath(path, False, 0.0, planner.getName())
            self.posted += 1
            self.best_cost = cost
            if self.first_time is None:
                self.first_time = time.perf_counter() - self.t0
            self.notify(path, cost)
        else:
            self.rejected += 1
            if self.rejected == 1:  # (one per improvement when the checker's batched call disagrees with isValid)
                log.warning("DimensionRRT: si.checkMotion or the bounds rejected a path the search accepted; not "
                            "reported (later ones in this solve are not logged: is the checker's are_valid the same "
                            "test as its isValid?)")
            self.found_cost = self.best_cost  # not found after all: the loop must not stop on its cost
        self._spent += time.perf_counter() - t
