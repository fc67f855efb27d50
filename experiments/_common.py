"""Helpers shared by the experiment scripts (imported as ``_common``: a script's own folder is on ``sys.path``)."""

from __future__ import annotations

import time
from pathlib import Path

from ompl import base as ob
from ompl import geometric as og

from tpee_ompl import PathLibrary, WearerArm
from tpee_ompl.bench.campaign import query_rows, stratified_subset
from tpee_ompl.resources import default_library_path


def summary(doc: str | None) -> str:
    """A script's ``--help`` description: its docstring's first paragraph on one line (its first line alone was cut
    mid-sentence where the paragraph wraps)."""
    return " ".join((doc or "").strip().split("\n\n")[0].split())


HELDOUT_HINT = ("make it with: PYTHONPATH=. python experiments/make_queries.py --seed 777 --n-per-pair 3 "
                "--out /tmp/heldout")
"""How the held-out query sets some scripts default to (``/tmp/heldout/*.json``) are made."""


def missing_query_files(queries: list[str] | str) -> str | None:
    """The first of ``queries`` that names a JSON file that is not there, with how to make the held-out sets; else
    None (a set's name, such as ``planning_necessary``, is the package's own)."""
    for q in [queries] if isinstance(queries, str) else queries:
        if q.endswith(".json") and not Path(q).is_file():
            return f"--queries: {q} not found; {HELDOUT_HINT}" if "/heldout/" in q else f"--queries: {q} not found"
    return None


def length_after(ss: og.SimpleSetup, planner: ob.Planner, seconds: float) -> float:
    """The length of ``planner``'s exact path after ``ss.solve(seconds)`` from a cleared setup (NaN if none)."""
    ss.clear()
    ss.setPlanner(planner)
    ss.solve(seconds)
    return ss.getSolutionPath().length() if ss.haveExactSolutionPath() else float("nan")


def first_path_time(ss: og.SimpleSetup, planner: ob.Planner, limit: float) -> float | None:
    """Seconds ``ss.solve`` takes ``planner`` (from a cleared setup) to its first exact path, stopped by
    ``exactSolnPlannerTerminationCondition`` or after ``limit`` s; None when it found none."""
    ss.clear()
    ss.setPlanner(planner)
    ptc = ob.plannerOrTerminationCondition(ob.exactSolnPlannerTerminationCondition(ss.getProblemDefinition()),
                                           ob.timedPlannerTerminationCondition(limit))
    t = time.perf_counter()
    ss.solve(ptc)
    dt = time.perf_counter() - t
    return dt if ss.haveExactSolutionPath() else None


def wearer_library_queries(queries: str, max_queries: int,
                           n_threads: int | None = None) -> tuple[WearerArm, PathLibrary, list[dict]]:
    """The wearer (``n_threads`` for its checks, default the checker's), its default path library and the stratified
    ``max_queries`` of a query set (name or JSON file)."""
    robot = WearerArm() if n_threads is None else WearerArm(n_threads=n_threads)
    library = PathLibrary.load(default_library_path(), robot)
    _, rows = query_rows(queries, robot)
    return robot, library, stratified_subset(rows, max_queries)

