"""States a candidate path's screen checks before it finds a failure, for three orders of the screened states.

    PYTHONPATH=. .venv/bin/python experiments/screen_order.py            # ~10 s

Runs dimension-RRT (``tpee_dimension_rrt``, seed = query index) to its first path on every query of a
named set, keeps every bisection screen of a candidate path (``Checker.first_failing_motion`` with
``bisect=True``: every 16th interior state of the path's unchecked motions), checks all of those states,
and counts, per screen, the states an in-order checker (``first_invalid``) would check before the first
invalid one (all of them when none is), for:

- by level: every motion's middle state, then every motion's quarter points, ... (the order before 2026-11-25);
- longest stretch first: within a motion the same bisection, across motions the state that halves the
  longest unchecked stretch (length / 2^(level+1)) first (the planner's order now);
- motion by motion: all of one motion's states (in bisection order) before the next motion's.

The screens are those of the planner's own run, so they depend on its order; the counts compare the
orders on the same screens.
"""

from __future__ import annotations

import argparse

from _common import summary
import numpy as np
from ompl import util as ou

from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning import search_checker
from tpee_ompl.planning.search_checker import _COARSE_STRIDE, _longest_stretch_key, _screen_levels
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.planning.tpee import tpee_dimension_rrt


def _states_to_failure(order: np.ndarray, ok: np.ndarray) -> int:
    bad = np.flatnonzero(~ok[order])
    return int(bad[0]) + 1 if len(bad) else len(order)


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--queries", default="planning_necessary")
    p.add_argument("--limit", type=float, default=1.0, help="time limit per first-path run, s")
    args = p.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    robot = WearerArm()
    screens: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
    original = search_checker.Checker.first_failing_motion

    def recording(self, A, B, bisect, starts=False):
        if bisect:
            S, idx, _ = self.interior(A, B, _COARSE_STRIDE)
            if len(idx):
                level = _screen_levels(idx, len(A))
                screens.append((idx, level, self.layout.distance(A, B)[idx], robot.are_valid(S)))
        return original(self, A, B, bisect, starts)

    search_checker.Checker.first_failing_motion = recording
    try:
        from ompl import base as ob

        for k, q in enumerate(load_queries(args.queries, robot)):
            ss = make_simple_setup(robot, q.start, q.goal)
            ss.setPlanner(tpee_dimension_rrt(ss.getSpaceInformation(), q.from_sector, q.to_sector, seed=k))
            first = ob.exactSolnPlannerTerminationCondition(ss.getProblemDefinition())
            ss.solve(ob.plannerOrTerminationCondition(first, ob.timedPlannerTerminationCondition(args.limit)))
    finally:
        search_checker.Checker.first_failing_motion = original
    counts: dict[str, list[int]] = {"by level": [], "longest stretch first": [], "motion by motion": []}
    for idx, level, length, ok in screens:
        counts["by level"].append(_states_to_failure(np.lexsort((idx, level)), ok))
        stretch_first = np.lexsort((idx, _longest_stretch_key(level, length)))
        counts["longest stretch first"].append(_states_to_failure(stretch_first, ok))
        counts["motion by motion"].append(_states_to_failure(np.lexsort((level, idx)), ok))
    failing = sum(int((~ok).any()) for *_, ok in screens)
    print(f"{args.queries}: {len(screens)} screens, {failing} with an invalid state")
    for name, v in counts.items():
        print(f"  {name:22s} states checked to the first failure: mean {np.mean(v):5.2f}, median {np.median(v):4.1f}")


if __name__ == "__main__":
    main()
