"""One dimension-RRT solve after its set-up: the goal runs' turns, releasing the prescribed rows, raising ``h``,
stopping on a stall, and each pass of samples with its improvements posted to OMPL.

:class:`~tpee_ompl.planning.dimension_rrt.DimensionRRT` builds the runs (one per goal state), the
:class:`~tpee_ompl.planning.solution_posting.SolutionPoster` and the way a new search is made, then hands them to
:class:`GoalLoop`; what each rule does and why is in the planner's module docstring ("Goal regions",
"Raising h", "Stopping like an OMPL planner", the release of the prescribed rows).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from ompl import base as ob

from .dimension_search import Search
from .goal_runs import GOAL_SWAP_AFTER, GOAL_TURN, GoalRun
from .grouped_space import GroupedSpace
from .solution_posting import SolutionPoster

__all__ = ["GoalLoop", "LoopLimits", "NewSearch"]

log = logging.getLogger("tpee_ompl.planning.dimension_rrt")

REFINE_AFTER = 500
"""Samples without a first path after which ``h`` is raised (when ``max_h`` allows, not while the connect trees
grow; see "Raising h")."""
PROGRESS_PERIOD = 0.01
"""Seconds between progress-trace entries (OMPL's benchmark records progress about as often)."""
PASS_BATCH = 64
"""Most samples per :meth:`Search.iterate` call on a valid path (those the cost test rejects are passed
over in one vectorised step; the termination condition is asked between calls) or in the connect
trees (which ask it before each sample, as RRTConnect does)."""

TWIN_TURN = 25
"""Samples of the longer twin's turn (``restart_after``; the shorter one's: :data:`GOAL_TURN`): a fresh search's
samples cost more than a converged one's, most of which the cost test turns down."""

NewSearch = Callable[..., Search]
"""``new_search(grouped, goal, initial, turns=None, local=False)``: a search of the solve's start to ``goal``."""


@dataclass(frozen=True)
class LoopLimits:
    """What ends a solve or a pass, besides the termination condition: ``cap`` samples of all goals (None: no
    cap), ``max_h`` fake-time steps at most when raising ``h``, ``stall`` samples without a shorter path (None:
    never), and the ``stops`` (sample counts) a pass ends at exactly; and ``restart``, when twins start."""

    cap: int | None
    max_h: int
    stall: int | None
    stops: tuple[int, ...]
    restart: int | None = None
    """``restart_after``: samples without a shorter path before a twin search starts (None: never)."""


class GoalLoop:
    """The loop of one solve over its goal runs (nearest goal first, in turns of :data:`GOAL_TURN` samples when
    there are several), until the objective is satisfied, the termination condition holds, the cap is reached, the
    path is as short as the nearest goal's straight distance, or every goal has stopped."""

    def __init__(self, runs: list[GoalRun], poster: SolutionPoster, new_search: NewSearch, q0: np.ndarray,
                 limits: LoopLimits, stats: dict[str, Any], t0: float,
                 on_drawn: Callable[[int], None], waiting: list[np.ndarray] | None = None,
                 new_run: Callable[[np.ndarray], GoalRun] | None = None) -> None:
        self.runs, self.poster, self.new_search, self.q0 = runs, poster, new_search, q0
        self.limits, self.stats, self.t0, self.on_drawn = limits, stats, t0, on_drawn
        self.waiting = list(waiting or []) if new_run is not None else []
        """Goal states beyond the ``max_goals`` nearest, in turn for a run's place (:data:`GOAL_SWAP_AFTER`)."""
        self.new_run = new_run
        self.tried = len(runs)
        """Goal states searched so far (a goal taken again after its turn in the queue counts again)."""
        self.several = len(runs) > 1 or bool(self.waiting)
        self.drawn = 0
        """Samples of every goal's searches so far."""
        self.turn = 0
        self._last_log = -math.inf
        runs[0].turn_end = GOAL_TURN

    def record(self, now: float, drawn: int | None = None) -> None:
        """A progress row: (seconds since the solve began, best cost found, samples; ``drawn``: within a pass)."""
        self.stats["progress"].append((now - self.t0, self.poster.found_cost, self.drawn if drawn is None else drawn))

    def _shorter(self, cost: float) -> bool:
        """Whether a path of this cost is worth offering: shorter than the best found by more than rounding (a
        fit that only merged the connect trees' collinear steps is the posted path again, its length summed
        another way)."""
        return cost < self.poster.found_cost * (1.0 - 1e-12)

    def run(self, ptc: ob.PlannerTerminationCondition) -> None:
        """Offer the runs' initial paths, loop, post what is pending."""
        poster = self.poster
        for run in self.runs:
            if self._shorter(run.best):
                poster.offer(run.search.W, run.best, time.perf_counter())
        self.record(time.perf_counter())
        cap = self.limits.cap
        shortest = min(run.bound for run in self.runs)  # no path is shorter than the straight start-goal distance
        while not poster.satisfied and not ptc() and (cap is None or self.drawn < cap):
            if poster.found_cost <= shortest * (1.0 + 1e-12) + 1e-12:  # reached it (start = goal, a free direct path)
                break
            if not self.step(ptc):
                break
        poster.flush()
        self.record(time.perf_counter())

    def step(self, ptc: ob.PlannerTerminationCondition) -> bool:
        """One step of the loop on the current goal's run; False when every goal has stopped."""
        run = self.runs[self.turn]
        if self.several:  # a goal no path to which beats the best found (its start-goal distance is no shorter) stops
            run.stopped |= run.bound >= self.poster.found_cost - 1e-12
            if run.stopped or run.samples >= run.turn_end:
                if not run.stopped and run.twin is not None:
                    self._restart_twin(run)
                elif (not run.stopped and self.waiting and not math.isfinite(run.best) and run.samples >= GOAL_SWAP_AFTER
                      and not self._can_raise_h(run)):  # (h first: a fresh run starts at the base h again)
                    self._swap(run)
                return self._next_turn()
        search, stall, restart = run.search, self.limits.stall, self.limits.restart
        if restart is not None and run.twin is None and search.valid and search.samples - run.improved_at >= restart:
            self._add_twin(run)
            return True
        if run.release is not None and search.valid and search.samples - run.improved_at >= run.release:
            self._release(run)
        elif stall is not None and math.isfinite(self.poster.found_cost) and search.samples - run.improved_at >= stall:
            run.stopped = True  # converged: nothing shorter in the last ``stall`` samples
            return not all(r.stopped for r in self.runs)
        elif (not search.valid and self._can_raise_h(run)
              and ((search.samples >= REFINE_AFTER and not search.connecting) or search.unfitted is not None)):
            self._raise_h(run)
        else:
            self._pass(run, ptc)
        return True

    def _can_raise_h(self, run: GoalRun) -> bool:
        """Whether ``max_h`` lets ``run``'s steps be doubled (h -> 2h - 1) once more."""
        return 2 * run.grouped.h - 1 <= self.limits.max_h

    def _add_twin(self, run: GoalRun) -> None:
        """``run`` found nothing shorter in ``restart_after`` samples: a fresh search of its goal (its *twin*) takes
        turns with it from now on (the paper's rule only shortens a path where it lies: the first path's way round an
        obstacle, or round a continuous joint's circle, was kept)."""
        twin = self.new_run(run.goal)
        run.twin, twin.twin = twin, run
        self.runs.insert(self.runs.index(run) + 1, twin)
        self.several = True
        run.turn_end = run.samples  # its turn ends here: the twin's begins
        self.stats["restarts"] += 1
        log.info("DimensionRRT: no shorter path in %d samples; a fresh search of the goal takes turns with it",
                 self.limits.restart)

    def _restart_twin(self, run: GoalRun) -> None:
        """At the end of ``run``'s turn: when it is the longer of two twins (or has no path) and found nothing
        shorter in ``restart_after`` samples, a fresh search takes its place."""
        other = run.twin
        worse = run.best >= other.best
        # not once the other has stopped (``stall_samples``): each fresh search would start the stall count again
        if (worse and not other.stopped and run.search.samples - run.improved_at >= self.limits.restart
                and (run.search.valid or not self._can_raise_h(run))):
            fresh = self.new_run(run.goal)
            fresh.twin, other.twin = other, fresh
            self.runs[self.runs.index(run)] = fresh
            self.stats["restarts"] += 1

    def _swap(self, run: GoalRun) -> None:
        """The next waiting goal state takes the place of ``run``, which found no path; its goal waits at the back."""
        fresh = self.new_run(self.waiting.pop(0))
        self.waiting.append(run.goal)
        self.runs[self.turn] = fresh
        self.tried += 1
        if math.isfinite(fresh.best) and self._shorter(fresh.best):  # its initial path is valid
            self.poster.offer(fresh.search.W, fresh.best, time.perf_counter())
            self.record(time.perf_counter())
        log.info("DimensionRRT: no path to a goal state after %d samples; the next of the goal states beyond "
                 "max_goals takes its place", run.samples)

    def _next_turn(self) -> bool:
        """Another goal's turn; False when none is left."""
        active = [k for k in range(len(self.runs)) if not self.runs[k].stopped]
        if not active:
            return False
        self.turn = next((k for k in active if k > self.turn), active[0])
        nxt = self.runs[self.turn]
        behind = nxt.twin is not None and nxt.best >= nxt.twin.best  # the longer twin: a shorter turn
        nxt.turn_end = nxt.samples + (TWIN_TURN if behind else GOAL_TURN)
        return True

    def _release(self, run: GoalRun) -> None:
        """Converged on the prescribed rows: from this path on, every DOF in one group, around one waypoint
        (``improved_at`` shifted so that ``stall`` counts on across the release)."""
        search = run.search
        released = run.grouped.released()
        run.restart(released, self.new_search(released, run.goal, search.W, local=True))
        run.release = None
        run.improved_at -= search.samples
        if self.stats["released_at"] is None:
            self.stats["released_at"] = self.drawn
        log.info("DimensionRRT: prescribed rows released after %d samples", self.drawn)

    def _raise_h(self, run: GoalRun) -> None:
        """No path yet, or a connect path with more turns than steps: twice the steps, the trees start again
        (that path is fitted to the new steps first)."""
        refined: GroupedSpace = run.grouped.refined(self.q0, run.goal)
        run.restart(refined, self.new_search(refined, run.goal, None, run.search.unfitted))
        run.best = run.search.cost if run.search.valid else math.inf
        if self._shorter(run.best):
            self.poster.offer(run.search.W, run.best, time.perf_counter())
            self.record(time.perf_counter())
        log.info("DimensionRRT: no path after %d samples, h raised to %d", run.done, run.grouped.h)

    def _found(self, W: np.ndarray, cost: float, drawn: int) -> None:
        """A valid path the search found after ``drawn`` samples, before it fits it to its steps (the connect
        trees' path, every motion checked): offered at once, so that a first path is posted as soon as
        RRTConnect's would be."""
        if self._shorter(cost):
            self.poster.offer(W, cost, time.perf_counter())
            self.record(time.perf_counter(), drawn)  # (after the post: no row shows a path before it is posted)

    def _pass(self, run: GoalRun, ptc: ob.PlannerTerminationCondition) -> None:
        """Samples until the next limit (a batch, the cap, the stall, the release, a stop, the goal's turn); a
        shorter path is offered to OMPL at once."""
        search, lim = run.search, self.limits
        limit = PASS_BATCH if lim.cap is None else min(PASS_BATCH, lim.cap - self.drawn)
        if lim.stall is not None:
            limit = min(limit, lim.stall - (search.samples - run.improved_at))
        if run.release is not None and search.valid:
            limit = min(limit, run.release - (search.samples - run.improved_at))
        if lim.stops and self.drawn < lim.stops[-1]:
            limit = min(limit, next(s for s in lim.stops if s > self.drawn) - self.drawn)
        if self.several:
            limit = min(limit, run.turn_end - run.samples)
        before = search.samples

        def stop() -> bool:  # asked within a call too (between connect-tree samples): the count as it is then
            n = self.drawn + search.samples - before
            self.on_drawn(n)
            if n in lim.stops:  # asked once this pass has ended there, so that it sees what a run capped there returns
                return self.poster.satisfied
            return self.poster.satisfied or bool(ptc())

        def found(W: np.ndarray, cost: float) -> None:  # ``stall`` counts from here (``best`` is its search's path)
            run.improved_at = search.samples
            self._found(W, cost, self.drawn + search.samples - before)

        accepted = search.iterate(max(1, limit), stop, found)
        self.drawn += search.samples - before
        self.on_drawn(self.drawn)
        now = time.perf_counter()
        if accepted and search.valid and search.cost < run.best:
            run.best, run.improved_at = search.cost, search.samples
            if self._shorter(search.cost):
                self.poster.offer(search.W, search.cost, now)
                self._last_log = time.perf_counter()
                self.record(self._last_log)
                return
        if now - self._last_log >= PROGRESS_PERIOD:
            self.record(now)
            self._last_log = now
