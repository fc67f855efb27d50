"""The problems a campaign can run: the wearer (the default), the generic problems, and a robot-checker hook.

A :class:`Problem` names its queries (plain dicts: ``id``, ``start``, ``goal``, plus its own keys
such as the wearer's sectors), builds its ``SimpleSetup`` inside the worker process
(:meth:`Problem.make_setup`; a task carries only the problem's NAME, OMPL objects cannot be
pickled), builds its dimension-RRT, and says which planners and motion validators apply.

Importing this module imports no OMPL (:mod:`tpee_ompl.bench.config` and the command-line parser
read :data:`PROBLEM_NAMES` from it); each problem imports what it needs when it is used.

Motion validators (``CampaignConfig.checkers``): ``batched`` checks each motion in batched calls through
the robot's checker, screened by clearance balls (:func:`tpee_ompl.planning.setup.make_simple_setup`),
``dense`` the same validator checking every state (the same verdicts), ``certified`` the
clearance-certificate validator (:mod:`tpee_ompl.planning.certified`: a few Coal distances per motion,
dense batched checks near contact), ``discrete`` OMPL's ``DiscreteMotionValidator`` calling the
validity checker per state.  The generic problems have
plain Python validity checkers and OMPL's default validator, so ``discrete`` is their only one.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .config import ANYTIME_PLANNERS, CHECKERS
from .generic_problems import GENERIC_PROBLEMS, GenericProblem, generic_queries, make_generic_setup

__all__ = ["DEFAULT_PROBLEM", "PROBLEM_NAMES", "Problem", "get_problem", "problem_table"]

DEFAULT_PROBLEM = "wearer"
_GENERIC_PLANNERS = ("DimensionRRT", "RRTstar", "RRTConnect", "RRTConnectSimplify", "AORRTC", "BITstar")
"""The anytime planners of the problems without the wearer's library (InformedRRTstar may be named too)."""


@dataclass(frozen=True)
class Problem:
    """One benchmark problem.  Callables import their dependencies when called (in the worker)."""

    name: str
    description: str
    dimension: int
    load_queries: Callable[[str | None, bool], tuple[str, list[dict]]]
    """``(query set or None, check_model) -> (query-set name, rows)``; None = the problem's own set."""
    build: Callable[[dict, str, int | None], tuple[Any, Any]]
    """``(query, motion validator name, n_threads) -> (og.SimpleSetup, checker)``; the checker counts
    ``collision_checks`` and has ``model_hash``."""
    build_dimension_rrt: Callable[[Any, Any], Any]
    """``(si, PlannerContext) -> DimensionRRT`` with the problem's grouping."""
    groups: tuple[tuple[int, ...], ...]
    """Grouping of dimension-RRT; the first group's length is ``length_dof12``, the rest's ``length_dof34``."""
    planners: tuple[str, ...] = _GENERIC_PLANNERS
    """The planners of its default anytime comparison."""
    checkers: tuple[str, ...] = ("discrete",)
    """Motion validators it has, the first being its headline one."""
    library: bool = False
    """LibraryDimensionRRT applies (the wearer's DMP path library)."""
    unsupported: tuple[str, ...] = ()
    """Planners that cannot run on its state space (refused with :attr:`unsupported_reason`)."""
    unsupported_reason: str = ""
    query_sets: bool = False
    """It reads query sets (``--queries``); the others have built-in queries."""
    default_queries: str | None = None

    def make_setup(self, query: dict, validator: str, n_threads: int | None = None) -> tuple[Any, Any]:
        """``(og.SimpleSetup, checker)`` for one query with the named motion validator (one of
        :attr:`checkers`), in this process; ``checker.collision_checks`` counts."""
        if validator not in self.checkers:
            raise ValueError(f"problem {self.name}: motion validator {validator!r} is not one of {self.checkers}")
        return self.build(query, validator, n_threads)

    def queries(self, name_or_path: str | None = None, check_model: bool = True) -> tuple[str, list[dict]]:
        """The query-set name and its rows (plain, JSON-able dicts).

        ``check_model``: refuse a set made for another model (loads the model); False only counts them.
        """
        return self.load_queries(name_or_path, check_model)

    def check_planner(self, name: str) -> None:
        """Raise ValueError when planner ``name`` does not apply to this problem."""
        if name == "LibraryDimensionRRT" and not self.library:
            raise ValueError(f"LibraryDimensionRRT does not apply to problem {self.name} (its DMP library is the wearer's)")
        if name in self.unsupported:
            raise ValueError(f"{name} does not apply to problem {self.name} ({self.unsupported_reason})")


# ----------------------------------------------------------------- the wearer
def _wearer_queries(default: str) -> Callable[[str | None, bool], tuple[str, list[dict]]]:
    def load(name_or_path: str | None, check_model: bool) -> tuple[str, list[dict]]:
        from ..model.wearer_arm import default_robot
        from .campaign import query_rows

        return query_rows(name_or_path or default, default_robot() if check_model else None)

    return load


def _wearer_setup(query: dict, validator: str, n_threads: int | None) -> tuple[Any, Any]:
    import numpy as np

    from ..planning.setup import make_simple_setup

    robot = _wearer_robot(n_threads)
    ss = make_simple_setup(robot, np.asarray(query["start"], float), np.asarray(query["goal"], float),
                           motion_validator=validator)
    return ss, robot


@functools.lru_cache(maxsize=2)
def _wearer_robot(n_threads: int | None):
    """One wearer model per process (loading the URDF takes a while)."""
    from ..model.wearer_arm import WearerArm

    return WearerArm(n_threads=n_threads)


def _wearer_dimension_rrt(si, ctx):
    from ..planning.tpee import tpee_dimension_rrt

    q = ctx.query
    return tpee_dimension_rrt(si, int(q["from_sector"]), int(q["to_sector"]), max_samples=ctx.max_samples,
                              seed=ctx.seed, stall_samples=ctx.stall_samples, **dict(ctx.dimension_rrt_overrides))


def _wearer(name: str, queries: str, what: str) -> Problem:
    return Problem(name=name, description=f"TPEE wearer's 4-DOF arm, query set {queries} ({what})", dimension=4,
                   load_queries=_wearer_queries(queries), build=_wearer_setup,
                   build_dimension_rrt=_wearer_dimension_rrt, groups=((0, 1), (2, 3)), planners=ANYTIME_PLANNERS,
                   checkers=CHECKERS, library=True, query_sets=True, default_queries=queries)


# ----------------------------------------------------------------- generic problems
def _generic(spec: GenericProblem) -> Problem:
    name = spec.name

    def load(name_or_path: str | None, check_model: bool) -> tuple[str, list[dict]]:
        if name_or_path is not None:
            raise ValueError(f"queries: problem {name} has built-in queries (give no query set)")
        return name, _generic_queries(name)

    def build(query: dict, validator: str, n_threads: int | None) -> tuple[Any, Any]:
        return make_generic_setup(spec, query["start"], query["goal"], validator != "discrete")

    def dimension_rrt(si, ctx):
        from ..planning.dimension_rrt import DimensionRRT

        return DimensionRRT(si, groups=spec.groups, max_samples=ctx.max_samples, seed=ctx.seed,
                            stall_samples=ctx.stall_samples, **dict(ctx.dimension_rrt_overrides))

    extra = _SO2_COMPOUND if spec.kind == "arm-so2" else {}
    return Problem(name=name, description=spec.description, dimension=spec.n, load_queries=load, build=build,
                   build_dimension_rrt=dimension_rrt, groups=spec.groups, **extra)


_NEEDS_INFORMED_SAMPLER = ("InformedRRTstar", "AORRTC", "BITstar")
"""OMPL planners whose set-up needs ``PathLengthDirectInfSampler`` (RealVector, SE2, SE3, Dubins, Reeds-Shepp only)."""
_SO2_COMPOUND: dict[str, Any] = {
    "unsupported": _NEEDS_INFORMED_SAMPLER,
    "unsupported_reason": "OMPL's informed sampler does not support compound SO2 spaces",
    "planners": tuple(n for n in _GENERIC_PLANNERS if n not in _NEEDS_INFORMED_SAMPLER),
}
"""The :class:`Problem` fields of a problem on a compound space with SO2 joints: the planners it leaves out."""


@functools.lru_cache(maxsize=None)
def _generic_queries_cached(name: str) -> str:
    return json.dumps(generic_queries(GENERIC_PROBLEMS[name]))


def _generic_queries(name: str) -> list[dict]:
    """A fresh copy of the problem's queries (drawn once per process)."""
    return json.loads(_generic_queries_cached(name))


# ----------------------------------------------------------------- robot-checker problems (hook)
def _robot_problem(name: str, dimension: int, description: str, robot: str, query_set: str,
                   groups: tuple[tuple[int, ...], ...], continuous: bool = False) -> Problem:
    """A problem on a :class:`~tpee_ompl.model.robot_checker.RobotChecker` made by a function of
    :mod:`tpee_ompl.model.robots`, its joint query set and ``make_simple_setup``: one entry per robot in
    :data:`PROBLEMS`.  ``groups``: dimension-RRT's grouping, a copy of the robot's constant in
    :mod:`~tpee_ompl.model.robots` (not imported here: listing the problems loads no Pinocchio; a test keeps them equal);
    ``continuous``: the robot has continuous joints (an SO2 compound: no certified validator, no informed sampler)."""

    def modules():
        from ..model import joint_queries, robots  # lazy: the robots need the optional 'robots' extra

        return robots, joint_queries

    @functools.lru_cache(maxsize=2)
    def checker(n_threads: int | None):
        robots, _ = modules()
        return getattr(robots, robot)(n_threads=n_threads)

    def load(name_or_path: str | None, check_model: bool) -> tuple[str, list[dict]]:
        _, joint_queries = modules()
        queries, header = joint_queries.load_joint_query_set(name_or_path or query_set, checker(None))
        rows = [{"id": q.id, "label": str(q.label), "start": [float(x) for x in q.start],
                 "goal": [float(x) for x in q.goal]} for q in queries]
        return str(header.get("name") or query_set), rows

    def build(query: dict, validator: str, n_threads: int | None) -> tuple[Any, Any]:
        from ..planning.setup import make_simple_setup

        c = checker(n_threads)
        return make_simple_setup(c, query["start"], query["goal"], motion_validator=validator), c

    def dimension_rrt(si, ctx):
        from ..planning.dimension_rrt import DimensionRRT

        return DimensionRRT(si, groups=groups, max_samples=ctx.max_samples, seed=ctx.seed,
                            stall_samples=ctx.stall_samples, **dict(ctx.dimension_rrt_overrides))

    extra = _SO2_COMPOUND if continuous else {}
    checkers = tuple(c for c in CHECKERS if c != "certified") if continuous else CHECKERS
    return Problem(name=name, description=description, dimension=dimension, load_queries=load, build=build,
                   build_dimension_rrt=dimension_rrt, groups=groups, checkers=checkers, query_sets=True,
                   default_queries=query_set, **extra)


PROBLEMS: dict[str, Problem] = {p.name: p for p in (
    _wearer("wearer", "planning_necessary", "cross-sector queries that need planning"),
    _wearer("wearer-random", "paper_random", "the paper's random queries"),
    *(_generic(spec) for spec in GENERIC_PROBLEMS.values()),
    _robot_problem("panda-shelf", 7, "Franka Panda reaching into a shelf (Pinocchio + Coal checker)",
                   robot="panda_shelf", query_set="panda_shelf",
                   groups=((0, 1, 2), (3, 4, 5, 6))),
    _robot_problem("kinova-posts", 6, "Kinova Jaco2 arm, 3 continuous joints (SO2), between two posts (convex hulls)",
                   robot="kinova_posts", query_set="kinova_posts",
                   groups=((0, 1, 2), (3, 4, 5)), continuous=True),
)}
"""Every problem by name; the wearer first (the default)."""
PROBLEM_NAMES: tuple[str, ...] = tuple(PROBLEMS)


def get_problem(name: str) -> Problem:
    """The problem called ``name``; ValueError (one line, listing the names) for an unknown one."""
    try:
        return PROBLEMS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown problem {name!r}: choose from {', '.join(PROBLEM_NAMES)}") from None


def problem_table() -> list[dict]:
    """One row per problem: ``name``, ``dimension``, ``queries`` (count, or None when they cannot be loaded
    here, with ``note`` saying why) and ``description``."""
    rows = []
    for p in PROBLEMS.values():
        row = {"name": p.name, "dimension": p.dimension, "queries": None, "description": p.description, "note": ""}
        try:
            row["queries"] = len(p.queries(check_model=False)[1])
        except (ImportError, OSError, ValueError) as exc:
            row["note"] = " ".join(str(exc).split())
        rows.append(row)
    return rows
