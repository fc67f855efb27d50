"""One motion checked without clearance balls: in bisection order up to the first invalid state, or every state at once.

    PYTHONPATH=. .venv/bin/python experiments/single_motion_checks.py                 # xArm7, 10 queries x 3, ~1 min
    PYTHONPATH=. .venv/bin/python experiments/single_motion_checks.py --queries 20 --reps 5

The xArm7 of example-robot-data with its shipped SRDF, a table and a wall (boxes), as a user would set it up: on
this robot the clearance-ball screen does not pay, so the default motion validator checks a motion's states
themselves.  For random valid start/goal pairs whose straight motion collides (numpy seed 0), RRTConnect's time
to its first exact path with the default validator as it is (one motion: ``RobotChecker.first_invalid`` on its
states in bisection order, stopping at the first invalid one, as OMPL's ``DiscreteMotionValidator``), with every
state of the motion checked in one batch (the validator before 2026-11-26, switched back in this process), and with
OMPL's ``motion_validator="discrete"``; the three alternate query by query.  RRTConnect is seeded once
(``--ompl-seed``), so the runs differ by their place in OMPL's random stream only.  Prints the median first-path
time and collision checks of each, the ratios of the medians, and every query's times.
"""

from __future__ import annotations

import argparse
import statistics
import time

from _common import summary
import numpy as np
from mesh_robots import robot_files
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl import Obstacle, RobotChecker, make_simple_setup
from tpee_ompl.planning import setup as setup_module

VARIANTS = ("bisection", "all at once", "discrete")


def _all_at_once(self, chunks, probes=0):
    """The batched validator's ``all_valid`` before the change: every state of every chunk in one batch (no probes)."""
    if not chunks:
        return np.zeros(0, dtype=bool)
    ok = self.robot.are_valid(np.concatenate(chunks))
    bounds = np.cumsum([0] + [len(c) for c in chunks])
    return np.array([ok[bounds[k] : bounds[k + 1]].all() for k in range(len(chunks))], dtype=bool)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", type=int, default=10)
    ap.add_argument("--reps", type=int, default=3, help="runs per query and variant")
    ap.add_argument("--limit", type=float, default=3.0, help="time limit per run, s")
    ap.add_argument("--ompl-seed", type=int, default=1)
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(args.ompl_seed)
    urdf, srdf, package_dirs = robot_files("xarm7", None)
    obstacles = [Obstacle("table", "box", (0.6, 0.6, 0.05), (0.45, 0.0, 0.2)),
                 Obstacle("wall", "box", (0.05, 0.6, 0.4), (0.3, 0.3, 0.35))]
    robot = RobotChecker(urdf, srdf, package_dirs=package_dirs, obstacles=obstacles)
    rng = np.random.default_rng(0)
    probe = make_simple_setup(robot).getSpaceInformation()
    queries: list[tuple[np.ndarray, np.ndarray]] = []
    while len(queries) < args.queries:
        Q = rng.uniform(robot.lower, robot.upper, size=(200, robot.nq))
        free = Q[robot.are_valid(Q)]
        for a, b in zip(free[0::2], free[1::2]):
            s1, s2 = probe.allocState(), probe.allocState()
            for k in range(robot.nq):
                s1[k], s2[k] = float(a[k]), float(b[k])
            if len(queries) < args.queries and not probe.checkMotion(s1, s2):
                queries.append((a, b))
    real = setup_module.BatchedMotionValidator.all_valid
    times: dict[str, list[float]] = {v: [] for v in VARIANTS}
    checks: dict[str, list[int]] = {v: [] for v in VARIANTS}
    for qi, (a, b) in enumerate(queries):
        row = []
        for _ in range(args.reps):
            for variant in VARIANTS:
                setup_module.BatchedMotionValidator.all_valid = _all_at_once if variant == "all at once" else real
                ss = make_simple_setup(robot, a, b, motion_validator="discrete" if variant == "discrete" else "batched")
                ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
                ptc = ob.plannerOrTerminationCondition(ob.timedPlannerTerminationCondition(args.limit),
                                                       ob.exactSolnPlannerTerminationCondition(ss.getProblemDefinition()))
                c0, t0 = robot.collision_checks, time.perf_counter()
                ss.solve(ptc)
                dt = time.perf_counter() - t0
                times[variant].append(dt if ss.haveExactSolutionPath() else float("inf"))
                checks[variant].append(robot.collision_checks - c0)
                row.append(f"{variant} {1e3 * dt:.1f}")
        setup_module.BatchedMotionValidator.all_valid = real
        print(f"query {qi}: " + ", ".join(row) + " ms", flush=True)
    med = {v: statistics.median(times[v]) for v in VARIANTS}
    for v in VARIANTS:
        solved = sum(np.isfinite(times[v]))
        print(f"{v:12s} median first path {1e3 * med[v]:7.1f} ms, median checks {statistics.median(checks[v]):8.0f}, "
              f"solved {solved}/{len(times[v])}")
    print(f"bisection / all at once: {med['bisection'] / med['all at once']:.2f}; "
          f"bisection / discrete: {med['bisection'] / med['discrete']:.2f}")


if __name__ == "__main__":
    main()
