"""The paper's real-time pipeline as one OMPL planner: a library path at once, then dimension-RRT while time remains.

:class:`LibraryDimensionRRT` answers a cross-sector query with the DMP path library (section 4.2:
the closest demonstrations' blended DMP paths, each checked with ``si.checkMotion`` over the whole
path) and reports the first valid one as an exact solution; then it keeps improving with
dimension-RRT (section 4.1) seeded by the closest demonstration's DMP path at the fake-time steps,
sharing the problem definition, so the best path either found is the answer.  When no library path
is valid it tries Table 3's straight motion, then plans.  Before all that it checks the direct
joint-space motion from start to goal (a colliding one mostly at a few probe states, :data:`DIRECT_PROBES`):
when that is free it is the shortest path in the space's metric, so it is posted and the run ends (on the
paper's random queries, 100 of 120).  It is an ordinary ``ob.Planner``: ``og.SimpleSetup``,
``ot.Benchmark`` and the benchmark campaigns use it like any other.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..model.queries import straight_motion
from ..model.sectors import check_sector, infer_sector, posture_preset
from ..planning.dimension_rrt import RELEASE_AFTER, DimensionRRT, DimensionRRTOptions, shortcuts_on
from ..planning.motion_validator import BatchedMotionValidator
from ..planning.paths import array_to_path, path_passes_motion_checks, state_to_array
from ..planning.planner_base import (PythonPlanner, check_space_information, fixed_attribute, planner_status,
                                     problem_objective)
from ..planning.tpee import tpee_dimension_rrt, tpee_options
from ..validation import sub_seed
from .path_library import PathLibrary

__all__ = ["LibraryDimensionRRT", "infer_sector"]

log = logging.getLogger(__name__)

DIRECT_PROBES = 15
"""States of the direct motion checked plainly before the rest (its end, then the middles breadth first, up to the first
invalid one): a colliding direct motion is mostly found there, for a few checks instead of a screened motion's 100 or
more.  The 120 ``planning_necessary`` queries' direct motions all collide: 115 are found at one of these states
(median 5 checked); ``paper_random``'s 20 colliding ones all within two (``experiments/library_coverage.py``)."""

class LibraryDimensionRRT(PythonPlanner):
    """A validated library path in milliseconds, refined by dimension-RRT until the termination condition.

    Parameters
    ----------
    si : ob.SpaceInformation
        The wearer arm's space (``make_simple_setup``): RealVector(4).
    library : PathLibrary
        The DMP path library (e.g. ``PathLibrary.load(default_library_path(), robot)``); its own
        fallback planner is not used (this planner plans under the termination condition instead).
    from_sector, to_sector : int, optional
        The sector pair; by default inferred at each solve from the start's and goal's DOF1/DOF2
        (the Table-1 presets, :func:`infer_sector`).  A query whose start and goal are not at two
        different presets has no demonstrations and no Table 3 row: it is planned without the library
        (its direct motion when free, else :class:`DimensionRRT` over every DOF, nothing prescribed).
        Given, the start and goal must be at their presets (else INVALID_START / INVALID_GOAL, logged), as
        for :func:`~tpee_ompl.planning.tpee.tpee_dimension_rrt`.
    options : DimensionRRTOptions, optional
        Settings of the refining dimension-RRT (its ``name`` is ignored; this planner's is ``name``).
        Left out: the defaults with ``release_after=RELEASE_AFTER`` (Table 3's rows released once the
        path converged on them); given: used as given (``release_after`` None keeps the rows).
    name : str
        Planner name (``geometric_<name>`` in a Benchmark database).
    **overrides
        Fields of :class:`DimensionRRTOptions` replacing those of ``options``.

    Every exact path passed ``si.checkMotion`` over the whole path (the library path here, the
    dimension-RRT path in :class:`DimensionRRT`); the problem definition keeps the cheaper.  A goal that
    is not one state (``GoalStates``, a sampleable region) is planned by :class:`DimensionRRT` alone (on the
    given pair's Table 3 row): the library's paths end at one state.  Bad ``options`` (groups, ``h``,
    ``range_``, a ``restart_after``: no restarts on Table 3's rows) and a space without usable bounds raise ValueError here, not at the first solve.
    """

    def __init__(
        self,
        si: ob.SpaceInformation,
        library: PathLibrary,
        from_sector: int | None = None,
        to_sector: int | None = None,
        options: DimensionRRTOptions | None = None,
        *,
        name: str = "LibraryDimensionRRT",
        **overrides: Any,
    ) -> None:
        # everything is checked before ob.Planner.__init__ (an exception after it crashes at GC)
        if not isinstance(library, PathLibrary):
            raise ValueError(f"library must be a PathLibrary, got {type(library).__name__}")
        check_space_information(si)
        robot = getattr(si.getStateValidityChecker(), "robot", None)  # a make_simple_setup set-up's robot
        if robot is not None:
            library.check_robot(robot)
        space, nq = si.getStateSpace(), library.robot.nq
        if not isinstance(space, ob.RealVectorStateSpace) or space.getDimension() != nq:
            raise ValueError(f"LibraryDimensionRRT plans in the library robot's joint space, a RealVectorStateSpace({nq}) "
                             f"(make_simple_setup); got {type(space).__name__} of dimension {space.getDimension()}")
        if (from_sector is None) != (to_sector is None):
            raise ValueError("give both from_sector and to_sector, or neither (inferred from start and goal)")
        pair = None if from_sector is None else (check_sector(from_sector), check_sector(to_sector))
        if pair is not None and pair[0] == pair[1]:
            raise ValueError(f"({pair[0]}, {pair[1]}) is not a cross-sector motion")
        opts = options if options is not None else DimensionRRTOptions(release_after=RELEASE_AFTER)
        if not isinstance(opts, DimensionRRTOptions):
            raise ValueError(f"options must be a DimensionRRTOptions, got {type(opts).__name__}")
        opts = dataclasses.replace(opts, name=name, **overrides)
        DimensionRRT.checked_setup(si, opts)  # the refining planner is built at solve time: its settings are checked now
        tpee_options(opts)  # groups, h and restart_after that tpee_dimension_rrt refuses at solve time, refused now
        super().__init__(si, name)
        self._library, self._pair, self._options = library, pair, opts
        self._inner: DimensionRRT | None = None
        self._refinements = 0

    library = fixed_attribute("library", lambda self: self._library, "The path library (``PathLibrary``).", "library")
    pair = fixed_attribute("pair", lambda self: self._pair, "The sector pair, or None: inferred at each solve.",
                           "from_sector and to_sector")
    options = fixed_attribute("options", lambda self: self._options,
                              "Settings of the refining dimension-RRT (``DimensionRRTOptions``).", "options=...")

    # ------------------------------------------------------------------ reporting
    def settings(self) -> dict[str, str]:
        """Parameter name -> value as text (for the benchmark's ``plannerConfigs``)."""
        lib = self.library
        return {
            "pair": "inferred" if self.pair is None else f"{self.pair[0]}->{self.pair[1]}",
            "library_demos": str(len(lib)),
            "library_model_hash": str(lib.robot.model_hash),
            "n_candidates": str(lib.n_candidates),
            "query_stride": str(lib.query_stride),
            "max_samples": str(self.options.max_samples),
            "seed": str(self.options.seed),
            "release_after": str(self.options.release_after),
            "shortcuts": str(shortcuts_on(self.options, prescribed=True)),  # Table 3 prescribes DOF1/DOF2
        }

    @staticmethod
    def _empty_stats() -> dict[str, Any]:
        return {**PythonPlanner._empty_stats(), "samples": 0, "iterations": 0, "collision_checks": 0,
                "library_outcome": None, "candidates_tried": 0, "library_seconds": None, "direct_motion": False,
                "released_at": None}

    def last_run_stats(self) -> dict[str, Any]:
        """Statistics of the last solve: ``library_outcome`` (how the first path came: "dmp": the closest
        demonstration's DMP path, "repaired": a later candidate's, "straight": Table 3's straight motion,
        "direct": the direct joint-space motion, "planned": dimension-RRT's, "failed"), ``direct_motion``
        (the direct motion was free, so the run ended with it: no path is shorter), ``candidates_tried``,
        ``library_seconds``, and those of :class:`DimensionRRT`
        (samples, first_solution_time, best_cost, progress [(time_s, best_cost, samples), ...], released_at)."""
        return super().last_run_stats()

    def clear(self) -> None:
        """Forget the last run (not the seed's stream: the next run draws other samples, as OMPL's planners do)."""
        super().clear()
        self._inner = None

    def _run_seed(self) -> int | None:
        """The refining dimension-RRT's seed: ``options.seed`` in the first refinement, then one derived from it
        and the refinement's number (a benchmark's runs of one planner are different runs, as OMPL's are)."""
        k, self._refinements = self._refinements, self._refinements + 1
        return self.options.seed if self.options.seed is None or k == 0 else sub_seed(self.options.seed, k)

    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        t0 = time.perf_counter()
        si, pdef = self.getSpaceInformation(), self.getProblemDefinition()
        goal = pdef.getGoal()
        if goal is not None and not isinstance(goal, ob.GoalState):  # the library's paths end at one state
            log.info("LibraryDimensionRRT: the goal is a %s, not one state: planned by dimension-RRT without the "
                     "library", type(goal).__name__)
            self._stats["library_outcome"] = "planned"
            return self._refine(ptc, t0, self.pair, None, False, read_ends=False)
        ends = self._endpoints()
        if isinstance(ends, ob.PlannerStatus):
            return ends
        n = si.getStateDimension()
        start, goal = state_to_array(ends[0], n), state_to_array(ends[1], n)
        if self.pair is not None:  # as dimension-RRT on the pair's Table 3 row: the ends must be at its presets
            for end, q, k in (("start", start, self.pair[0]), ("goal", goal, self.pair[1])):
                if infer_sector(q) != k:
                    log.error("LibraryDimensionRRT: the %s's DOF1/DOF2 %s is not sector %d's Table-1 preset %s "
                              "(from_sector=%d, to_sector=%d)", end, q[:2], k, posture_preset(k), *self.pair)
                    return planner_status(ob.PlannerStatus.INVALID_START if end == "start" else ob.PlannerStatus.INVALID_GOAL)
        i, j = self.pair if self.pair is not None else (infer_sector(start), infer_sector(goal))
        cross = i is not None and j is not None and i != j
        if not cross:  # no demonstration and no Table 3 row: the direct motion, else dimension-RRT over every DOF
            log.info("LibraryDimensionRRT: start and goal are not at two different Table-1 posture presets "
                     "(start DOF1/DOF2 %s, goal %s): planned without the library", start[:2], goal[:2])
        stats, progress = self._stats, self._stats["progress"]
        opt = problem_objective(pdef)  # asked with its own cost of a path; the costs here are lengths
        best_path = None
        lib = self.library
        have_exact = False
        seed = None

        def post(path: og.PathGeometric, outcome: str) -> None:
            """Add a proven path to the problem definition; the first one posted names the outcome."""
            pdef.addSolutionPath(path, False, 0.0, self.getName())
            now, cost = time.perf_counter() - t0, path.length()
            if stats["first_solution_time"] is None:
                stats.update(library_outcome=outcome, first_solution_time=now)
            stats["best_cost"] = cost
            progress.append((now, cost, 0))

        # the direct joint-space motion, when free, is the shortest path there is: nothing to look up or refine
        if self._direct_free(si, start, goal):
            post(array_to_path(si, np.stack([start, goal])), "direct")
            stats.update(direct_motion=True, library_seconds=time.perf_counter() - t0)
            return planner_status(ob.PlannerStatus.EXACT_SOLUTION)
        if cross and (i, j) in lib.pairs and len(lib.pairs[(i, j)].starts):
            closest = None
            for rank, k, W in lib.candidate_paths(start, goal, i, j):
                if rank > 0 and ptc():  # the closest demonstration's path is always tried: it is the answer in ms
                    break
                stats["candidates_tried"] += 1
                closest = k if closest is None else closest
                if path_passes_motion_checks(si, W, check_first=False, in_bounds=True):  # (the start: _endpoints)
                    best_path, have_exact = array_to_path(si, W), True
                    post(best_path, "dmp" if rank == 0 else "repaired")
                    break
            seed = lib.generate(start, goal, i, j, closest, stride=lib.per_step)
            # near the space's bounds (the joint limits) a DMP seed can leave them; it is only a head start: clip it
            bounds = si.getStateSpace().getBounds()
            seed = np.clip(seed, np.array(bounds.low, dtype=float), np.array(bounds.high, dtype=float))
        if not have_exact and ptc():  # time is up before the straight motion and the planning
            stats.update(library_outcome="failed", library_seconds=time.perf_counter() - t0)
            return planner_status(ob.PlannerStatus.TIMEOUT)
        if cross and not have_exact:  # Table 3's straight motion: often free when the library's paths are not
            W = straight_motion(start, goal, i, j)
            if path_passes_motion_checks(si, W, check_first=False, in_bounds=True):
                best_path, have_exact = array_to_path(si, W), True
                post(best_path, "straight")
        stats["library_seconds"] = time.perf_counter() - t0
        if have_exact and (ptc() or (opt is not None and opt.isSatisfied(best_path.cost(opt)))):
            return planner_status(ob.PlannerStatus.EXACT_SOLUTION)
        if stats["library_outcome"] is None:
            stats["library_outcome"] = "planned"
        return self._refine(ptc, t0, (i, j) if cross else None, seed, have_exact)

    @staticmethod
    def _direct_free(si: ob.SpaceInformation, start: np.ndarray, goal: np.ndarray) -> bool:
        """Whether the direct motion start -> goal (valid ends within the bounds) passes ``si.checkMotion``: through the
        project's validator with :data:`DIRECT_PROBES` of its states checked first."""
        mv = si.getMotionValidator()
        if isinstance(mv, BatchedMotionValidator):
            return mv.check_motion_values(start, goal, DIRECT_PROBES)
        return path_passes_motion_checks(si, array_to_path(si, np.stack([start, goal])), check_first=False)

    def _refine(self, ptc: ob.PlannerTerminationCondition, t0: float, pair: tuple[int, int] | None,
                seed: np.ndarray | None, have_exact: bool, read_ends: bool = True) -> ob.PlannerStatus:
        """Dimension-RRT on the same problem definition until ``ptc`` (on the pair's Table 3 row, from the DMP
        ``seed`` when given), its progress merged into this run's statistics; ``read_ends``: this planner read the
        start already (and said which of several it takes)."""
        si, pdef = self.getSpaceInformation(), self.getProblemDefinition()
        stats, progress = self._stats, self._stats["progress"]
        opts = dataclasses.replace(self.options, seed=self._run_seed())
        inner = None
        if pair is not None:
            try:
                inner = tpee_dimension_rrt(si, *pair, opts, initial_waypoints=seed if seed is not None
                                           and seed.shape[0] == self.options.h else None)
            except ValueError as e:  # e.g. a space whose bounds the Table 3 row leaves
                log.warning("LibraryDimensionRRT: planned over every DOF, without Table 3's row: %s", e)
        if inner is None:
            try:
                inner = DimensionRRT(si, opts)
            except ValueError as e:  # e.g. bounds changed since this planner was made: every DOF of zero width
                log.error("LibraryDimensionRRT: no refinement: %s", e)
                return planner_status(ob.PlannerStatus.EXACT_SOLUTION if have_exact else ob.PlannerStatus.ABORT)
        inner._say_start_choice = not read_ends  # noqa: SLF001 (the pipeline said which start it took)
        inner._known_cost = stats["best_cost"] if have_exact else math.inf  # noqa: SLF001 (only shorter paths posted)
        inner.setProblemDefinition(pdef)
        self._inner = inner
        t_inner = time.perf_counter() - t0
        status = inner.solve(ptc)
        s = inner.last_run_stats()
        stats.update(samples=s["samples"], iterations=s["iterations"], collision_checks=s["collision_checks"],
                     released_at=s["released_at"])
        posted = s["best_cost"]  # what the inner planner added to the problem definition
        for t, cost, samples in s["progress"]:
            if math.isfinite(cost) and posted <= cost < stats["best_cost"]:
                if stats["first_solution_time"] is None:
                    stats["first_solution_time"] = t_inner + t
                stats["best_cost"] = cost
                progress.append((t_inner + t, cost, samples))
        stats["best_cost"] = min(stats["best_cost"], posted)
        progress.append((time.perf_counter() - t0, stats["best_cost"], stats["samples"]))
        if have_exact or status == ob.PlannerStatus.EXACT_SOLUTION:
            return planner_status(ob.PlannerStatus.EXACT_SOLUTION)
        stats["library_outcome"] = "failed"
        return status

