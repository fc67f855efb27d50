"""The planners a campaign runs: factories by name, their settings, and :class:`RecordingPlanner`.

A factory is ``(si, PlannerContext) -> ob.Planner``.  :data:`PLANNER_FACTORIES` holds the built-in
ones (dimension-RRT and OMPL's planners with their default settings); a name ``module:function``
is imported instead, so worker processes can build planners defined elsewhere (e.g. test stand-ins).

Every planner runs inside :class:`RecordingPlanner`, which keeps the planner's *raw* output path
(OMPL simplifies the solution in place before the benchmark's post-run event, so the event can only
see the simplified path), caps native planners' iterations and records progress.

This module imports OMPL; :mod:`tpee_ompl.bench.config` (the names) does not, so the command-line
parser is built without it.
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import inspect
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ..planning.paths import path_to_array
from ..planning.setup import motion_counts, quieter_ompl, valid_motion_fraction
from .config import KNOWN_PLANNERS

__all__ = [
    "PLANNER_FACTORIES",
    "PlannerContext",
    "PlannerFactory",
    "RecordingPlanner",
    "planner_factory",
    "planner_settings",
]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class PlannerContext:
    """What a planner factory may use: the query (plain dict), the cap, a seed and the problem's name."""

    query: dict
    max_samples: int | None
    seed: int
    problem: str = "wearer"
    """:data:`~tpee_ompl.bench.problems.PROBLEMS` name: dimension-RRT is built with its grouping."""
    stall_samples: int | None = None
    """Our planners stop after this many samples without a shorter path (None: the paper's behaviour,
    as in every campaign; ``tpee-ompl plan`` sets it so a converged run does not idle to its time limit)."""
    dimension_rrt_overrides: tuple[tuple[str, Any], ...] = ()
    """(field, value) pairs of ``DimensionRRTOptions`` a problem's dimension-RRT is built with (a variant's name
    and settings, e.g. ``DimensionRRTReleased``'s)."""
    library: str | None = None
    """``LibraryDimensionRRT``'s path library file (None: the packaged one, built for the packaged model)."""


PlannerFactory = Callable[[ob.SpaceInformation, PlannerContext], ob.Planner]


def _native(cls_name: str) -> PlannerFactory:
    def make(si, ctx: PlannerContext):
        return getattr(og, cls_name)(si)  # OMPL's defaults, never changed

    make.__name__ = f"make_{cls_name}"
    return make


def _dimension_rrt(si, ctx: PlannerContext):
    from .problems import get_problem

    return get_problem(ctx.problem).build_dimension_rrt(si, ctx)


def _dimension_rrt_released(si, ctx: PlannerContext):
    from ..planning.dimension_rrt import RELEASE_AFTER

    overrides = (("release_after", RELEASE_AFTER), ("name", "DimensionRRTReleased"))
    return _dimension_rrt(si, dataclasses.replace(ctx, dimension_rrt_overrides=overrides))


def _dimension_rrt_no_shortcuts(si, ctx: PlannerContext):
    overrides = (("shortcuts", False), ("name", "DimensionRRTNoShortcuts"))
    return _dimension_rrt(si, dataclasses.replace(ctx, dimension_rrt_overrides=overrides))


_LIBRARIES: dict[tuple[str, str], object] = {}
"""The path libraries LibraryDimensionRRT was built with, loaded once per process (by file and model hash)."""


def _library_dimension_rrt(si, ctx: PlannerContext):
    from ..library import LibraryDimensionRRT, PathLibrary
    from ..model.wearer_arm import default_robot
    from ..resources import default_library_path
    from .problems import get_problem

    get_problem(ctx.problem).check_planner("LibraryDimensionRRT")
    robot = getattr(si.getStateValidityChecker(), "robot", None) or default_robot()
    key = (str(ctx.library or default_library_path()), robot.model_hash)
    lib = _LIBRARIES.get(key)
    if lib is None:
        lib = _LIBRARIES[key] = PathLibrary.load(key[0], robot)
    q = ctx.query
    return LibraryDimensionRRT(si, lib, int(q["from_sector"]), int(q["to_sector"]), max_samples=ctx.max_samples,
                               seed=ctx.seed, stall_samples=ctx.stall_samples)


def _rrtconnect_simplify(si, ctx: PlannerContext):
    from ..planning.simplified import SimplifiedPlanner

    return SimplifiedPlanner(si, og.RRTConnect(si))


_OURS: dict[str, PlannerFactory] = {
    "DimensionRRT": _dimension_rrt,
    "DimensionRRTReleased": _dimension_rrt_released,
    "DimensionRRTNoShortcuts": _dimension_rrt_no_shortcuts,
    "LibraryDimensionRRT": _library_dimension_rrt,
    "RRTConnectSimplify": _rrtconnect_simplify,
}
PLANNER_FACTORIES: dict[str, PlannerFactory] = {
    **_OURS,
    **{n: _native(n) for n in KNOWN_PLANNERS if n not in _OURS},
}
"""Planner name -> factory ``(si, PlannerContext) -> ob.Planner``.  A name ``module:function`` is
imported instead (so worker processes can build planners defined elsewhere, e.g. test stand-ins)."""


SINGLE_USE_PLANNERS: tuple[str, ...] = ("AORRTC",)
"""Native planners that crash when solved again after ``clear()``: ompl 2.0.1's AORRTC segfaults in the second
run of a benchmark experiment (``--runs 2``; setup, solve, clear, solve).  :class:`RecordingPlanner` is given
a fresh one for each run after the first (``renew``).  An AORRTC freed without ever being set up segfaults too
(``og.AORRTC(si)`` then ``del``; ``clear()`` does not help): check everything before one is built."""


def planner_factory(name: str) -> PlannerFactory:
    """The factory of a planner name of :data:`PLANNER_FACTORIES`, or of a ``module:function`` name."""
    if name in PLANNER_FACTORIES:
        return PLANNER_FACTORIES[name]
    if ":" in name:
        mod, _, attr = name.partition(":")
        try:
            fn = getattr(importlib.import_module(mod), attr)
        except (ImportError, AttributeError) as exc:
            raise ValueError(f"planner {name!r}: cannot import {attr} from {mod} ({exc})") from None
        if not callable(fn):
            raise ValueError(f"planner {name!r}: {attr} is not a factory function")
        try:  # checked here, before any work: a wrong callable failed every query of a campaign, one by one
            inspect.signature(fn).bind(None, None)
        except TypeError:
            raise ValueError(f"planner {name!r}: {attr} cannot be called as factory(si, ctx) (a planner factory takes "
                             "the SpaceInformation and a PlannerContext and returns an ob.Planner)") from None
        except ValueError:  # no signature to read (some builtins): what it returns is checked when it is called
            pass
        return fn
    raise ValueError(f"unknown planner {name!r}: choose from {sorted(PLANNER_FACTORIES)} or give module:function")


def _parse_settings(text: str) -> dict[str, str]:
    out = {}
    for line in text.splitlines():
        k, sep, v = line.partition(" = ")
        if sep and k.strip() and " " not in k.strip():
            out[k.strip()] = v.strip()
    return out


def planner_settings(p: ob.Planner) -> dict[str, str]:
    """A planner's settings as text: its ``settings()`` (Python planners) or parsed ``printSettings()``."""
    if hasattr(p, "settings"):  # one line each: a log holds one setting per line (a newline made a log unreadable)
        return {" ".join(str(k).split()): " ".join(str(v).split()) for k, v in p.settings().items()}
    try:
        with quieter_ompl(ou.LOG_ERROR):  # printSettings reads BIT*'s deprecated options, each getter warns
            return _parse_settings(p.printSettings())
    except Exception:  # noqa: BLE001 (bindings differ per planner)
        return {}


class RecordingPlanner(ob.Planner):
    """Runs an inner planner, caps its iterations, keeps its raw path and records progress.

    Parameters
    ----------
    si : ob.SpaceInformation
    inner : ob.Planner
        Native OMPL planner or Python planner (``last_run_stats()`` is used when present).
    max_iterations : int or None
        Stop after this many ``inner.numIterations()`` (native planners only; Python planners
        get their cap through their factory).
    read : callable, optional
        ``state -> array (n,)`` for spaces other than RealVector (e.g. ``RealVectorLayout.read`` of an
        SO2 compound); n is the space's dimension.
    checker : object with a ``collision_checks`` counter, optional
        The problem's checker: its counter as ``solve`` returns is recorded (``checks_end``), so a
        run's checks exclude what OMPL's ``Benchmark`` does after it (simplification, path checks).
    renew : callable, optional
        ``() -> ob.Planner``: a fresh inner planner, built and set up before the next run (:meth:`renew_if_used`)
        instead of clearing the one that ran (:data:`SINGLE_USE_PLANNERS`).
    deadline : float, optional
        Seconds after ``solve`` began at which the inner planner is told to stop (an anytime run's budget).
        ``ot.Benchmark`` checks its own deadline in a thread only every 0.1 s, so without it a run with a
        0.01 s budget ran about 0.11 s and one with 1 s about 1.09 s; the inner planner now asks a timed
        condition of its own at every termination check, as ``ss.solve(seconds)`` does.

    After each ``solve``, :attr:`last` holds the run's record: ``waypoints`` (raw path, (K, n), or
    None), ``iterations``, ``samples``, ``best_cost``, ``first_solution_time``, ``progress``
    (list of (time, best cost, iterations)), ``checks_end`` (the checker's counter as ``solve``
    returned, or None), ``valid_fraction`` (the share of the motions the validator checked during ``solve``
    that were valid, :func:`~tpee_ompl.planning.setup.motion_counts`, None when it counted none: OMPL's own
    column reads 0 for a Python motion validator), ``graph_states`` / ``graph_motions`` (None for a Python planner, which keeps no OMPL graph)
    and ``error`` (None, or the exception's repr).  A native planner's
    ``first_solution_time`` is the first termination check that saw an exact solution (a finite
    ``bestCost()``, or one in the problem definition for planners without it, e.g. AORRTC), else the run's
    end when it returned one (RRTConnect stops at its first path).
    Exceptions never escape to OMPL (they would abort the whole benchmark): a failing ``solve``
    returns status *crash*.
    """

    progress_period = 0.05
    """Seconds between the progress rows of a native planner exposing ``bestCost``/``numIterations``."""

    def __init__(self, si: ob.SpaceInformation, inner: ob.Planner, max_iterations: int | None = None,
                 read: Callable[[ob.State], object] | None = None, checker: Any = None,
                 renew: Callable[[], ob.Planner] | None = None, deadline: float | None = None) -> None:
        # checked before ob.Planner.__init__: an exception after it leaves a half-built trampoline
        if max_iterations is not None and not hasattr(inner, "last_run_stats") and not hasattr(inner, "numIterations"):
            raise ValueError(f"{inner.getName()} has no numIterations(): it cannot be iteration-capped")
        super().__init__(si, inner.getName())
        self.checker = checker
        self.renew = renew
        self.deadline = deadline
        self._ran = False
        self._dim = int(si.getStateSpace().getDimension())
        self._read = read
        self.inner = inner
        self.max_iterations = max_iterations
        self._native = not hasattr(inner, "last_run_stats")
        """A native OMPL planner: watched at every termination check (cap, first solution, progress)."""
        self._setup_error: str | None = None
        self.last: dict = {}

    def setup(self) -> None:  # noqa: D102 (OMPL override)
        super().setup()
        self._setup_inner()

    def _setup_inner(self) -> None:
        self._setup_error = None
        try:  # an exception escaping to C++ would abort the whole benchmark
            self.inner.setProblemDefinition(self.getProblemDefinition())
            self.inner.setup()
        except Exception as exc:  # noqa: BLE001
            log.exception("planner %s: setup failed", self.inner.getName())
            self._setup_error = repr(exc)

    def clear(self) -> None:  # noqa: D102 (OMPL override)
        super().clear()
        if self.renew is not None and self._ran:
            return  # a used single-use planner is replaced before its next run (:meth:`renew_if_used`)
        try:
            self.inner.clear()
        except Exception:  # noqa: BLE001
            log.exception("planner %s: clear failed", self.inner.getName())

    def renew_if_used(self) -> None:
        """Replace a used single-use inner planner (``renew``) with a fresh one, set up.  ``ot.Benchmark``'s pre-run
        event calls it after seeding OMPL for the run (``bench/experiment.py``), so the new planner's random numbers
        come from that seed and not from what ran before; :meth:`solve` calls it when nothing did."""
        if self.renew is None or not self._ran:
            return
        try:
            self.inner = self.renew()
            self._ran = False
            self._setup_inner()  # Benchmark sets the wrapper up once, before the first run
        except Exception as exc:  # noqa: BLE001
            log.exception("planner %s: renewing it failed", self.inner.getName())
            self._setup_error = repr(exc)  # never solve a used single-use planner again: the run is a crash

    def solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:  # noqa: D102 (OMPL override)
        self.renew_if_used()
        inner, cap = self.inner, self.max_iterations
        pdef = self.getProblemDefinition()
        t0 = time.perf_counter()
        progress: list[tuple[float, float, int]] = []
        state = {"next": 0.0, "first": None}
        has_cost = hasattr(inner, "bestCost")
        has_iterations = hasattr(inner, "numIterations")

        def stop() -> bool:
            """Called at every termination check: the first exact solution's time, progress, the cap."""
            it = inner.numIterations() if has_iterations else None
            now = time.perf_counter() - t0
            if state["first"] is None and (math.isfinite(inner.bestCost().value()) if has_cost
                                           else pdef.hasExactSolution()):
                state["first"] = now
            if has_cost and now >= state["next"]:
                progress.append((now, inner.bestCost().value(), it))
                state["next"] = now + self.progress_period
            return cap is not None and it is not None and it >= cap

        error = self._setup_error
        self._ran = True
        mv, motions0 = self.getSpaceInformation().getMotionValidator(), None
        try:
            if self.deadline is not None:
                ptc = ob.plannerOrTerminationCondition(ptc, ob.timedPlannerTerminationCondition(self.deadline))
            motions0 = motion_counts(mv)
            if error is not None:
                raise RuntimeError(f"setup failed: {error}")
            if self._native:
                cond = ob.plannerOrTerminationCondition(ptc, ob.PlannerTerminationCondition(stop))
                status = inner.solve(cond)
            else:
                status = inner.solve(ptc)
        except Exception as exc:  # noqa: BLE001 (an exception would abort the whole benchmark)
            log.exception("planner %s failed", inner.getName())
            error = repr(exc)
            status = ob.PlannerStatus(ob.PlannerStatus.CRASH)
        elapsed = time.perf_counter() - t0
        if error is None and hasattr(inner, "last_run_stats"):  # a PythonPlanner turns its exceptions into CRASH
            with contextlib.suppress(Exception):
                error = inner.last_run_stats().get("error")
        checks_end = int(self.checker.collision_checks) if self.checker is not None else None
        waypoints = None
        if error is None and pdef.hasSolution():
            waypoints = path_to_array(pdef.getSolutionPath(), self._dim, read=self._read)
        if state["first"] is None and error is None and pdef.hasExactSolution():
            state["first"] = elapsed  # found as the planner returned (RRTConnect stops at its first path)
        fraction = None
        with contextlib.suppress(Exception):  # nothing may escape to OMPL (it would abort the benchmark)
            fraction = valid_motion_fraction(motions0, motion_counts(mv))
        self.last = {"waypoints": waypoints, "error": error, "checks_end": checks_end, "valid_fraction": fraction,
                     **self._run_stats(elapsed, progress, has_cost, state["first"]), **self._graph_size()}
        return status

    def _graph_size(self) -> dict:
        """The inner planner's graph: OMPL asks the wrapper (a Python planner) for planner data, which it
        cannot forward (a Python ``getPlannerData`` override aborts), so the counts are read here."""
        if hasattr(self.inner, "last_run_stats"):  # our Python planners keep no OMPL graph
            return {"graph_states": None, "graph_motions": None}
        try:
            pd = ob.PlannerData(self.getSpaceInformation())
            self.inner.getPlannerData(pd)
        except Exception:  # noqa: BLE001 (a planner without planner data)
            return {"graph_states": None, "graph_motions": None}
        if pd.numVertices() == 0:  # any graph a solve keeps holds its start: none is given (AORRTC's, 490 states)
            return {"graph_states": None, "graph_motions": None}
        return {"graph_states": int(pd.numVertices()), "graph_motions": int(pd.numEdges())}

    def _run_stats(self, elapsed: float, progress: list, has_cost: bool, first: float | None) -> dict:
        """Iterations, samples, best cost, first-solution time and progress of the run that just ended."""
        inner = self.inner
        if hasattr(inner, "last_run_stats"):
            stats: dict = {}
            with contextlib.suppress(Exception):
                stats = dict(inner.last_run_stats() or {})
            iterations = stats.get("iterations")
            return {
                "iterations": iterations,
                "samples": stats.get("samples", iterations),
                "best_cost": stats.get("best_cost"),
                "first_solution_time": stats.get("first_solution_time"),
                "progress": [(float(t), float(c), None if n is None else int(n))
                             for t, c, n in stats.get("progress", [])],
            }
        iterations = inner.numIterations() if hasattr(inner, "numIterations") else None
        best = inner.bestCost().value() if has_cost else None
        if has_cost:
            progress.append((elapsed, best, iterations))
        return {
            "iterations": iterations,
            "samples": iterations,
            "best_cost": best,
            "first_solution_time": first,
            "progress": progress,
        }
