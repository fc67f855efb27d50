"""Helpers shared by the experiment scripts (imported as ``_common``: a script's own folder is on ``sys.path``)."""

from __future__ import annotations

from ompl import base as ob
from ompl import geometric as og


def length_after(ss: og.SimpleSetup, planner: ob.Planner, seconds: float) -> float:
    """The length of ``planner``'s exact path after ``ss.solve(seconds)`` from a cleared setup (NaN if none)."""
    ss.clear()
    ss.setPlanner(planner)
    ss.solve(seconds)
    return ss.getSolutionPath().length() if ss.haveExactSolutionPath() else float("nan")
