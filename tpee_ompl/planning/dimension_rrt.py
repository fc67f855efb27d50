"""Dimension-RRT (Zou et al. 2022, sec. 4.1.2) as an OMPL planner.

The path is ``h`` fake-time waypoints (see :mod:`tpee_ompl.planning.grouped_space`).  Groups of DOFs are
handled in order; a prescribed group (Table 3 for DOF1/DOF2) is taken as given.  For a planned group
each iteration draws ONE ``k_i``-dimensional sample ``c`` and tries it at every intermediate step
``t``: the candidate waypoint is ``W[t]`` with the group's values replaced by ``c``.

Improvement (the paper's rule, on a valid path): ``W[t]`` is replaced by the candidate iff the
path gets shorter, the candidate is valid and both motions to ``W[t-1]`` and ``W[t+1]`` are valid.
The cost test (``|W[t-1]-c| + |c-W[t+1]| < |W[t-1]-W[t]| + |W[t]-W[t+1]|`` in the space's metric)
runs first and costs no collision check.  Steps are tried in turn ``t = 1 .. h-2``; two neighbouring
steps are never both replaced by one sample (the motion between them was not checked).

Feasibility phase (before the first valid path; the paper leaves it open): a forward tree from the
start and a backward tree from the goal whose depth-t nodes are waypoints of step t.  The trees vary
ALL planned groups jointly (their DOFs in index order: the grouping does not change the first path) and are
built once, so progress in one group is never lost when the
improvement phase's group turns over (a per-group feasibility phase stalled on a 6-joint arm split
in three groups).  They are seeded with the valid prefix and suffix of the initial path.  Every node
is a valid waypoint; motions are checked lazily, as in LazyRRT: the step whose motions from the
nearest forward node and to the nearest backward node are shortest completes a candidate path, and
only then are its unchecked motions checked (every 16th state of all of them first, in bisection
order, longest unchecked stretch first, stopping at the first failure with the checker's
``first_invalid``; then in full with ``si.checkMotion``'s verdict).  A failed motion kills the node
it leads into with its subtree.  Without prescribed groups a node also serves later (forward) or
earlier (backward) steps by staying put; the repeated waypoints of the path are spread along its
segments before the next sample.  Without prescribed groups the samples are uniform over the planned
DOFs' bounds; with them (the TPEE case) 90 % come from the box the trees' initial path sweeps, padded by
a quarter of each DOF's range and the padding doubled every 16 samples, so a detour stays near the
blocked line while a near one exists (a departure from the paper's uniform samples: on the
120 ``planning_necessary`` queries 15 % fewer checks and a 17 % shorter first path; the rest uniform,
so any detour is still reached; :mod:`~tpee_ompl.planning.search_draws`).  What each
choice measured: ``docs/dimension_rrt.md`` and ``docs/first_path.md``.

Without prescribed groups (``connect=True``, the default) the first path is searched differently:
a waypoint's configuration then does not depend on its step, so two trees grow as OMPL's RRTConnect
grows them (:mod:`tpee_ompl.planning.connect_trees`: uniform samples from the planner's own seeded
generator, steps of at most 0.2 x the space's maximum extent, every motion checked in full), from
the start and the goal alone (with ``initial_waypoints``: from their valid prefix and suffix; the
straight line's prefix would pin the trees to the obstacle it ends at).  Once they meet, their path
through every tree node (each motion checked) is posted at once, as RRTConnect's would be; then its turning
points (a connect's collinear steps are one segment, checked again as one motion) are fitted to the ``h``
steps: while there are more than ``h``, the interior point whose shortcut saves most and passes is
dropped; the points are held (repeated) to fill the steps, the path is posted when shorter, and the next
sample first spreads the held points over its segments (kept when that path passes the checker).  The fit
asks the termination condition before each check, so a run stopped at its first path checks nothing more.  A
path that cannot be fitted seeds the layered trees above with its points at ``h`` evenly spaced places (the
trees' path stays the answer until a shorter one fits).
With a prescribed group (the TPEE case) the layered trees stay: its values depend on the step.

Raising h (sec. 4.1.3: with ``h`` fixed, an obstacle that needs more than ``h - 1`` segments is never
bridged): with ``max_h`` set, after 500 samples without a first path, or at once when the connect
trees' path has more turns than steps, ``h`` becomes ``2h - 1`` while that is at most ``max_h`` and the
layered trees start again; a prescribed row keeps its polyline, sampled at more steps.  By default
``h`` stays fixed, as in the paper; ``last_run_stats()["h"]`` reports the steps used.

Narrowing: once a valid path exists and the group has drawn ``narrow_after`` samples, 90 % of the
samples come from the bounding box of the current path's group values (released: of one waypoint's),
padded by ``max(range_, span * narrowing ** (m / 100))`` (``m``: samples since narrowing started), clipped
to the bounds (an SO2 angle's box is the arc the path sweeps, wrapping round +-pi); 10 % stay uniform.  The paper
gives no numbers; the defaults (200, 0.5): ``docs/dimension_rrt.md``.

Releasing the prescribed rows (``release_after``; off by default, as in the paper, which fixes
DOF1/DOF2 on Table 3's rows "to simplify the calculation"): a converged path along a row can be
longer than one that leaves it (``experiments/table3_bound.py``).  Once a valid path exists and
``release_after`` samples in a row brought no shorter one, the search goes on from the current path
with all DOFs in one planned group, its narrowed samples drawn around one waypoint at a time (a path
pressed against an obstacle shortens only by moving a waypoint in all DOFs at once; its passed motions
are not checked again; ``stall_samples`` counts on across the release).  ``last_run_stats()["released_at"]``
gives the sample count.  ``LibraryDimensionRRT`` sets it (:data:`RELEASE_AFTER`).

Restarts (``restart_after``; off by default, as in the paper; without a prescribed group only): the paper's rule
shortens a path where it lies, so the first path's way round an obstacle, or round a continuous joint's circle,
is kept.  Once ``restart_after`` samples in a row brought no shorter path, a fresh search of the goal (a *twin*)
takes turns with the converged one (25 samples to its 100 while it is the longer); the longer twin is started
again whenever it too found nothing shorter in as many samples.  Every shorter path of either is posted.
``last_run_stats()["restarts"]`` counts the fresh searches (:data:`RESTART_AFTER`: a measured value).

Shortcuts (``shortcuts``; by default on when a group is prescribed): after each sample that improved the
path (and on a new path), every intermediate waypoint's values of the sample's group move towards the point
shortest between its neighbours, as far as its checks allow, sweep after sweep while each gains 0.3 % when
the rows are kept to the end (else once); once released, a collapsed waypoint's step also goes to the longest
segment (:mod:`tpee_ompl.planning.waypoint_shortcuts`).  Off without a prescribed group: a waypoint on its
neighbours' segment never moves again by the paper's rule.

Batching: a sample's candidate waypoints and their motions go through the checker's batched
``are_valid(Q)`` when it has one (candidates plus every 16th interior motion state, then the rest for
the survivors; a lone candidate first, then every 4th state of its motions in bisection order up to the
first failure), else ``si.isValid`` / ``si.checkMotion``; motion states are those OMPL's discrete
validator checks, and a motion that passed ``si.checkMotion`` is not checked again when posted.  Up to
64 samples the cost test rejects are passed over per call, by a vectorised test run ahead and kept while
the path stays (:mod:`tpee_ompl.planning.search_draws`; the same paths as one at a time); the
termination condition is asked between calls and at :meth:`DimensionRRT.set_sample_checkpoints`.

Stopping like an OMPL planner: each improved path is added to the problem definition as it is found
(so ``ob.exactSolnPlannerTerminationCondition(pdef)`` stops at the first), after every segment not
already checked in an earlier posted path passed ``si.checkMotion``
(:func:`~tpee_ompl.planning.paths.path_passes_motion_checks`); after the first, improvements are
posted while posting costs at most 10 % of the run time and the best one always at the end.  The
planner stops once ``opt.isSatisfied(cost)`` (a cost threshold of ``inf`` = first solution; with an
objective other than path length, which the search still minimises, its own cost of the path), and once its
path is as short as the straight start-goal distance (nothing is shorter).  The termination condition is asked
between batches of samples and, in the shortcut sweeps, before each batch of candidates;
:meth:`DimensionRRT.set_intermediate_solution_callback` stands in for OMPL's (refused from Python).

Goal regions: a goal that is not one state (``GoalStates``, e.g. several IK solutions, or any other
``GoalSampleableRegion``) gives its ``max_goals`` valid goal states nearest the start (of a region: of
``max_goals`` drawn), and each gets its own search
(:mod:`tpee_ompl.planning.goal_runs`), nearest to the start first, in turns of 100 samples (a search with no
path after 500 samples gives its place to the next of the other goal states, its own goal going to the back of
that queue, so a goal sealed off does not hold the solve for good); every
search's shorter paths go to the same problem definition, and a goal whose start-goal distance is no
shorter than the best path found stops.  A goal off a prescribed row is skipped.  Of several start states
the first valid one is planned from (OMPL's RRTConnect grows its start tree from all of them).

Spaces: bounded RealVector, SO2 (the short way round, like ``SO2StateSpace``) and compounds of them;
the bounds are read again at each solve (as OMPL's samplers read them).  No approximate solutions: a
solve without an exact path ends with TIMEOUT and adds nothing to the problem definition.
Here: the planner; its settings (:class:`DimensionRRTOptions`) are in :mod:`tpee_ompl.planning.dimension_rrt_options`,
the search in :mod:`tpee_ompl.planning.dimension_search`, the goal states in :mod:`tpee_ompl.planning.goal_runs`,
the solve's loop over them in :mod:`tpee_ompl.planning.goal_loop`.
"""

from __future__ import annotations

import atexit
import logging
import math
import time
import weakref
from collections.abc import Callable, Iterable, Mapping
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..validation import check_int
from .dimension_rrt_options import (RELEASE_AFTER, RESTART_AFTER, DimensionRRTOptions, resolve_options,
                                     shortcuts_on)
from .dimension_search import Search, SearchSettings
from .goal_loop import GoalLoop, LoopLimits
from .goal_runs import GoalRun, goal_states
from .grouped_space import GroupedSpace
from .planner_base import PythonPlanner, check_space_information, fixed_attribute, planner_status
from .search_checker import Checker
from .solution_posting import SolutionPoster

__all__ = ["RELEASE_AFTER", "RESTART_AFTER", "DimensionRRT", "DimensionRRTOptions", "shortcuts_on"]

log = logging.getLogger(__name__)

_WITH_CALLBACKS: weakref.WeakSet[DimensionRRT] = weakref.WeakSet()
"""Planners holding an intermediate-solution callback.  A callback defined in a script refers to the
script's globals, which hold the planner: that cycle outlived the bindings at exit, and nanobind
printed "leaked instances" warnings; :func:`_drop_callbacks` breaks it first."""


@atexit.register
def _drop_callbacks() -> None:
    for planner in list(_WITH_CALLBACKS):
        planner._callback = None


def _read_only(a: np.ndarray) -> np.ndarray:
    """A view of ``a`` that cannot be written through (``p.range_[:] = 0`` changed the planner's own array)."""
    v = a.view()
    v.flags.writeable = False
    return v


class DimensionRRT(PythonPlanner):
    """Dimension-RRT (paper sec. 4.1.2): anytime, fake-time, DOF-grouped path optimisation.

    Parameters
    ----------
    si : ob.SpaceInformation
        A bounded RealVector space, an SO2 space, or a compound of them.
    options : DimensionRRTOptions, optional
        The planner's settings (defaults if omitted).
    prescribed : dict {group index: array (h, k_i)}, optional
        Group trajectories taken as given, start and goal rows included (``{0: Table 3 row}``).
    initial_waypoints : array (h, n), optional
        A first guess of the path (e.g. a DMP path from :mod:`tpee_ompl.library.path_library`): the
        planned groups' intermediate waypoints start there instead of on the straight line
        (see :meth:`set_initial_waypoints`).
    **overrides
        Fields of :class:`DimensionRRTOptions` replacing those of ``options`` (``DimensionRRT(si, seed=1)``).

    Raises
    ------
    ValueError
        Overlapping, missing or out-of-range DOF indices, ``h < 3``, ``max_samples < 1``, ``max_h < h``,
        ``max_goals < 1``, bad ``narrowing``/``narrow_after``/``range_``, a space type other than
        RealVector/SO2/compound (named in the message), or a RealVector space without bounds.
    TypeError
        An override that is not a field of :class:`DimensionRRTOptions` (named).
    """

    def __init__(
        self,
        si: ob.SpaceInformation,
        options: DimensionRRTOptions | None = None,
        *,
        prescribed: Mapping[int, np.ndarray] | None = None,
        initial_waypoints: np.ndarray | None = None,
        **overrides: Any,
    ) -> None:
        # Validate everything BEFORE super().__init__: an exception raised after it leaves a
        # half-constructed nanobind trampoline whose collection crashed the interpreter.
        opts = resolve_options(options, overrides)
        grouped, rng_full = self.checked_setup(si, opts, prescribed)
        initial = grouped.check_initial(initial_waypoints)
        super().__init__(si, opts.name)
        self._options = opts
        self.grouped = grouped
        self.max_samples = opts.max_samples
        self._range = rng_full
        self._rng = np.random.default_rng(opts.seed)
        self._initial = initial
        self._callback: Callable[[ob.Planner, list[ob.State], ob.Cost], object] | None = None
        self._callback_failed = False
        self._sample_checkpoints: tuple[int, ...] = ()
        self._samples_drawn = 0
        self._known_cost = math.inf  # set by a planner running this one after it posted a path of that cost

    # fixed at construction (the groups, the steps and the random generator are built from them): read-only, so that
    # an assignment cannot change settings() while the search goes on with the old value (``range_ = 0.05`` made
    # every solve CRASH, ``narrowing = 5.0`` overflowed mid-run)
    h = fixed_attribute("h", lambda self: self.grouped.h, "Fake-time steps (``DimensionRRTOptions.h``).")
    groups = fixed_attribute("groups", lambda self: self.grouped.groups,
                             "The DOF groups (``DimensionRRTOptions.groups``).")
    prescribed = fixed_attribute("prescribed", lambda self: self.grouped.prescribed,
                                 "Groups with a prescribed trajectory.")
    seed = fixed_attribute("seed", lambda self: self.options.seed, "The seed of the planner's random generator.")
    options = fixed_attribute("options", lambda self: self._options,
                              "The settings it was built with (``DimensionRRTOptions``).")
    narrow_after = fixed_attribute("narrow_after", lambda self: self._options.narrow_after,
                          "Samples before the sampling region narrows (``DimensionRRTOptions.narrow_after``).")
    narrowing = fixed_attribute("narrowing", lambda self: self._options.narrowing,
                       "The narrowing factor (``DimensionRRTOptions.narrowing``).")
    range_ = fixed_attribute("range_", lambda self: _read_only(self._range),
                    "The narrowed region's least padding per DOF (``DimensionRRTOptions.range_``, for these bounds).")
    batch = fixed_attribute("batch", lambda self: self._options.batch,
                   "Whether the checker's batched calls are used (``DimensionRRTOptions.batch``).")
    shortcuts = fixed_attribute("shortcuts", lambda self: shortcuts_on(self._options, bool(self.grouped.prescribed)),
                       "Whether the search takes shortcuts between waypoints (``DimensionRRTOptions.shortcuts``).")

    @property
    def max_samples(self) -> int | None:
        """Sample cap of a solve (None: none); read at every solve, so it may be changed between solves."""
        return self._max_samples

    @max_samples.setter
    def max_samples(self, value: int | None) -> None:
        self._max_samples = check_int("max_samples", value, minimum=1, optional=True)

    @classmethod
    def checked_setup(cls, si: ob.SpaceInformation, opts: DimensionRRTOptions,
                      prescribed: Mapping[int, np.ndarray] | None = None) -> tuple[GroupedSpace, np.ndarray]:
        """The grouped space and the per-DOF ``range_`` these options give on ``si``; ValueError (naming the
        setting or the space) where the constructor would raise one.  For planners that build a DimensionRRT
        only at solve time (the library pipeline), to refuse bad settings when they are made."""
        check_space_information(si)
        grouped = GroupedSpace(si, opts.groups, opts.h, prescribed)
        if opts.restart_after is not None and grouped.prescribed:  # (a fresh search on the rows: never measured)
            raise ValueError("restart_after: restarts are for problems without a prescribed group (Table 3's rows "
                             "are released with release_after instead)")
        return grouped, cls._full_range(opts, grouped)

    @staticmethod
    def _full_range(opts: DimensionRRTOptions, grouped: GroupedSpace) -> np.ndarray:
        """``range_`` per DOF: as given, or 2 % of each bound width."""
        layout = grouped.layout
        if opts.range_ is None:
            return 0.02 * (layout.upper - layout.lower)
        arr = np.asarray(opts.range_, dtype=float)
        if arr.ndim > 1 or (arr.ndim == 1 and len(arr) != layout.n):
            raise ValueError(f"range_ must be a positive number or array of {layout.n}, got {opts.range_!r}")
        return np.broadcast_to(arr, (layout.n,)).copy()

    def _follow_bounds(self) -> ob.PlannerStatus | None:
        """Take the space's bounds as they are now, as OMPL's planners do (their samplers read them at each
        solve): when they changed since this planner was built, the groups, ``range_`` and the initial
        waypoints are set up again for them.  None when the planner can go on, else ABORT (the reason logged)."""
        try:
            grouped = self._regrouped()
            if grouped is None:
                return None
            initial = grouped.check_initial(self._initial)
        except ValueError as e:
            log.error("%s: the space's bounds changed and %s", self.getName(), e)
            return planner_status(ob.PlannerStatus.ABORT)
        self.grouped, self._range, self._initial = grouped, self._full_range(self.options, grouped), initial
        return None

    def _regrouped(self) -> GroupedSpace | None:
        """The grouped space for the space's bounds and weights as they are now, or None when they have not changed."""
        space, old = self.getSpaceInformation().getStateSpace(), self.grouped
        if not old.layout.layout_changed(space):
            return None
        return GroupedSpace(space, old.groups, old.h, old.prescribed)

    def _ranges(self, grouped: GroupedSpace) -> dict[int, np.ndarray]:
        """Group index -> the smallest narrowed padding of its DOFs (``range_``), for ``grouped``'s groups."""
        return {gi: self.range_[grouped.group_dims(gi)] for gi in range(len(grouped.groups))}

    def set_initial_waypoints(self, W: np.ndarray | None) -> None:
        """Start the next solves from the waypoints W (h, n) instead of the straight line; None to unset.

        Only the planned groups' intermediate waypoints are taken from W: start, goal and the
        prescribed groups always come from the problem.  Nothing in W is trusted: its waypoints and
        motions are checked like any other, and an invalid W only gives the feasibility phase a head
        start (its valid prefix and suffix seed the layered trees).  Kept across :meth:`clear`.
        """
        grouped = self._regrouped() or self.grouped  # checked against the bounds as they are now
        self._initial = grouped.check_initial(W)
        if grouped is not self.grouped:
            self.grouped, self._range = grouped, self._full_range(self.options, grouped)

    def set_intermediate_solution_callback(
        self, callback: Callable[[ob.Planner, list[ob.State], ob.Cost], object] | None
    ) -> None:
        """Call ``callback(planner, states, cost)`` for each path added to the problem definition.

        The arguments of OMPL's intermediate-solution callback (which the 2.0.1 bindings do not accept
        from Python).  ``states`` are the path's states (copies), ``cost`` its ``ob.Cost``.  An
        exception in the callback is logged and the callback is not called again in that solve.
        None removes it.
        """
        if callback is not None and not callable(callback):
            raise ValueError(f"callback must be callable or None, got {type(callback).__name__}")
        self._callback = callback
        if callback is not None:
            _WITH_CALLBACKS.add(self)

    def set_sample_checkpoints(self, counts: Iterable[int]) -> None:
        """Make the termination condition be asked exactly when the run has drawn each of ``counts``
        samples (the loop otherwise asks it once per batch of samples the cost test rejects, see
        :meth:`Search.iterate <tpee_ompl.planning.dimension_search.Search.iterate>`); a condition that
        reads :meth:`samples_drawn` then sees the search as a run capped there would end.  The path
        found does not depend on it."""
        if isinstance(counts, (str, bytes, Mapping)) or not isinstance(counts, Iterable):
            raise ValueError(f"counts must be a sequence of sample counts, got {counts!r}")
        self._sample_checkpoints = tuple(sorted({check_int("sample checkpoint", c, minimum=1) for c in counts}))

    def samples_drawn(self) -> int:
        """Samples drawn so far in the current (or last) solve: what the termination condition sees."""
        return self._samples_drawn

    def _set_samples_drawn(self, n: int) -> None:
        self._samples_drawn = n

    def _notify(self, path: og.PathGeometric, cost: float) -> None:
        cb = self._callback
        if cb is None or self._callback_failed:
            return
        si = self.getSpaceInformation()
        states = [si.allocState() for _ in range(path.getStateCount())]  # copies: the posted path stays as checked
        for c, s in zip(states, path.getStates()):
            si.copyState(c, s)
        try:
            cb(self, states, ob.Cost(cost))
        except Exception:
            log.exception("DimensionRRT: the intermediate-solution callback raised; not called again in this solve")
            self._callback_failed = True

    # ------------------------------------------------------------------ reporting
    def settings(self) -> dict[str, str]:
        """Parameter name -> value as text (for the benchmark's ``plannerConfigs``)."""
        return {
            "groups": str(self.groups),
            "prescribed_groups": str(sorted(self.prescribed)),
            "h": str(self.h),
            "max_samples": str(self.max_samples),
            "seed": str(self.seed),
            "narrow_after": str(self.narrow_after),
            "narrowing": str(self.narrowing),
            "range": str([round(float(v), 6) for v in self.range_]),
            "batch": str(self.batch),
            "stall_samples": str(self.options.stall_samples),
            "max_h": str(self.options.max_h),
            "release_after": str(self.options.release_after),
            "connect": str(self.options.connect),
            "shortcuts": str(self.shortcuts),
            "initial_waypoints": "none" if self._initial is None else "set",
            "max_goals": str(self.options.max_goals),
            "restart_after": str(self.options.restart_after),
        }

    @staticmethod
    def _empty_stats() -> dict[str, Any]:
        return {
            "samples": 0,
            "h": 0,
            "collision_checks": 0,
            "first_solution_time": None,
            "best_cost": math.inf,
            "iterations": 0,
            "progress": [],
            "solutions_posted": 0,
            "released_at": None,
            "restarts": 0,
            "goals": 0,
        }

    def last_run_stats(self) -> dict[str, Any]:
        """Statistics of the last solve: samples, h (fake-time steps at the end; with several goal states the
        most any goal's search used), collision_checks, first_solution_time (s or None),
        best_cost (inf if none), iterations, progress [(time_s, best_cost, samples), ...],
        solutions_posted (paths added to the problem definition), released_at (samples at which the
        prescribed rows were first released, or None), goals (goal states planned to), restarts (fresh searches
        started by ``restart_after``)."""
        return super().last_run_stats()

    def _start_run(self) -> None:
        super()._start_run()
        self._samples_drawn = 0
        self._callback_failed = False

    def _ends(self, ptc: ob.PlannerTerminationCondition) -> tuple[np.ndarray, list[np.ndarray]] | ob.PlannerStatus:
        """The start and the goal states to plan to (on the prescribed trajectory, nearest first), or the status
        saying why there are none."""
        layout, grouped = self.grouped.layout, self.grouped
        start = self._start()
        Q1 = start if isinstance(start, ob.PlannerStatus) else goal_states(self, ptc, self.options.max_goals, layout.read)
        if isinstance(Q1, ob.PlannerStatus):
            return Q1
        q0 = layout.read(start)
        fits = [q1 for q1 in Q1 if grouped.endpoint_mismatch(q0, q1) is None]
        if not fits:
            mismatch = grouped.endpoint_mismatch(q0, Q1[0])
            log.error("the %s state is not on the prescribed trajectory", mismatch)
            return planner_status(ob.PlannerStatus.INVALID_START if mismatch == "start" else ob.PlannerStatus.INVALID_GOAL)
        if len(fits) < len(Q1):
            log.info("DimensionRRT: %d of %d goal states are off the prescribed trajectory", len(Q1) - len(fits), len(Q1))
        if len(fits) > 1:
            fits.sort(key=lambda q1: float(layout.distance(q0, q1)))  # nearest first (stable)
        if len(fits) > self.options.max_goals:
            log.info("%s plans to the %d goal states nearest the start, of %d (max_goals); the others take the place "
                     "of one that found no path", self.getName(), self.options.max_goals, len(fits))
        return q0, fits

    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        t0 = time.perf_counter()
        moved = self._follow_bounds()
        if moved is not None:
            return moved
        ends = self._ends(ptc)
        if isinstance(ends, ob.PlannerStatus):
            return ends
        q0, fits = ends
        si, pdef = self.getSpaceInformation(), self.getProblemDefinition()
        layout, grouped = self.grouped.layout, self.grouped
        checker = Checker(si, layout, self.batch, probe=q0)
        checks0 = checker.counter() - checker.probe_checks  # (the probe's check is this solve's: counted)
        release = self.options.release_after if grouped.prescribed and grouped.planned else None

        settings = SearchSettings(self.narrow_after, self.narrowing, self.options.connect, self.shortcuts,
                                  settle=release is None)

        def new_search(grouped_: GroupedSpace, goal: np.ndarray, initial: np.ndarray | None,
                       turns: np.ndarray | None = None, local: bool = False) -> Search:
            return Search(grouped_, checker, self._rng, q0, goal, settings, self._ranges(grouped_), initial, turns,
                          local=local)

        def new_run(q1: np.ndarray) -> GoalRun:
            return GoalRun(q1, grouped, new_search(grouped, q1, self._initial), release, float(layout.distance(q0, q1)))

        runs = []  # each search checks its initial path: the termination condition is asked between them
        for q1 in fits[: self.options.max_goals]:
            if runs and ptc():
                break
            runs.append(new_run(q1))
        poster = SolutionPoster(self, si, pdef, t0, grouped.to_path, self._notify, checker.passed, self._known_cost)
        limits = LoopLimits(self.max_samples if grouped.planned else 0, self.options.max_h or 0,
                            self.options.stall_samples, self._sample_checkpoints,
                            restart=None if grouped.prescribed else self.options.restart_after)
        loop = GoalLoop(runs, poster, new_search, q0, limits, self._stats, t0, self._set_samples_drawn,
                        waiting=fits[self.options.max_goals :], new_run=new_run)
        try:
            loop.run(ptc)
        finally:  # also when the user's validity checker raised: the paths posted before it are in the problem
            self._stats.update(
                h=max(run.grouped.h for run in runs),
                samples=loop.drawn,
                iterations=loop.drawn,
                collision_checks=checker.counter() - checks0,
                first_solution_time=poster.first_time,
                best_cost=poster.best_cost,
                solutions_posted=poster.posted,
                goals=loop.tried,
            )
        return planner_status(ob.PlannerStatus.EXACT_SOLUTION if poster.posted else ob.PlannerStatus.TIMEOUT)
