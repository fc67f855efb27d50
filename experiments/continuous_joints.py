"""Arms with continuous joints planned as SO2 angles (the default since 2026-11-26) against the workaround before
it, the continuous joints given limits of +-pi in a copy of the URDF.

    PYTHONPATH=. .venv/bin/python experiments/continuous_joints.py            # about 40 s
    PYTHONPATH=. .venv/bin/python experiments/continuous_joints.py --queries 6 --seconds 0.2

The Kinova Jaco2 6-DOF arm of example-robot-data (joints 1, 4 and 6 continuous), set up as
``experiments/mesh_robots.py`` does (its user SRDF), with convex hulls (``convex_meshes=True``), between two posts
(6 cm square, 1.2 m tall, 0.3 m either side of the base: 63 % of random configurations free, the straight motion
blocked on 13 of 20 random free pairs).  Queries: pairs of random collision-free configurations (seeded), the same
for both set-ups; most have a continuous joint whose short way crosses pi.  Per set-up and planner: queries solved exactly, the median time to the first exact path
(``exactSolnPlannerTerminationCondition``, from a cleared setup; a query without one counts as the whole budget,
so a planner that fails the hard queries gains nothing in the median) and the median collision checks to it
(the robot's counter: what the machine's load does not change), and the median joint travel of the path the
planner ends with (the sum over segments and joints of each joint's change along the motion the set-up checks: the
short way round for an SO2 joint; radians, the same measure for both set-ups).  Planners: RRTConnect then OMPL's
path simplifier (``ss.simplifySolution``), and dimension-RRT (default groups) run for ``--seconds``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import first_path_time
from mesh_robots import robot_files, user_srdf
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl import DimensionRRT, RobotChecker, make_simple_setup
from tpee_ompl.model.obstacles import box
from tpee_ompl.planning.space_layout import RealVectorLayout

ROBOT = "kinova"
POSTS = (box("post1", (0.06, 0.06, 1.2), (0.3, 0.0, 0.4)), box("post2", (0.06, 0.06, 1.2), (-0.3, 0.0, 0.4)))


def queries(robot: RobotChecker, n: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` pairs of free configurations drawn uniformly within the joint limits."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        Q = rng.uniform(robot.lower, robot.upper, (64, robot.nq))
        free = Q[robot.are_valid(Q)]
        out.extend(zip(free[0::2], free[1::2]))
    return out[:n]


def travel(ss: og.SimpleSetup) -> float:
    """Joint travel of the setup's solution path (its space's own differences: SO2 the short way)."""
    layout = RealVectorLayout(ss.getSpaceInformation().getStateSpace())
    W = layout.from_path(ss.getSolutionPath())
    return float(np.abs(layout.delta(W[:-1], W[1:])).sum())


def run(robot: RobotChecker, rows: list, seconds: float) -> dict[str, tuple[int, list[float], list[int], list[float]]]:
    """Per planner: (solved, first-path times (the budget when none), checks to them, final travels)."""
    out: dict[str, tuple[int, list[float], list[int], list[float]]] = {}
    for name in ("RRTConnect+simplify", "dimension-RRT"):
        solved, times, checks, travels = 0, [], [], []
        for k, (a, b) in enumerate(rows):
            ss = make_simple_setup(robot, a, b)
            si = ss.getSpaceInformation()
            make = (lambda: og.RRTConnect(si)) if name.startswith("RRT") else (lambda: DimensionRRT(si, seed=k + 1))
            c0 = robot.collision_checks
            t = first_path_time(ss, make(), seconds)
            times.append(seconds if t is None else t)
            checks.append(robot.collision_checks - c0)
            if t is None:
                continue
            if name.startswith("RRT"):
                ss.simplifySolution(seconds)
            else:
                ss.clear()
                ss.setPlanner(make())
                ss.solve(seconds)
                if not ss.haveExactSolutionPath():
                    continue
            assert ss.getSolutionPath().check()
            solved += 1
            travels.append(travel(ss))
        out[name] = (solved, times, checks, travels)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--queries", type=int, default=24)
    parser.add_argument("--seconds", type=float, default=0.5)
    parser.add_argument("--seed", type=int, default=0, help="seeds the queries and OMPL's RNG")
    args = parser.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(args.seed + 1)  # once per process: RRTConnect's samples repeat from run to run
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        urdf, shipped, dirs = robot_files(ROBOT, folder)
        limited, _, _ = robot_files(ROBOT, folder, limited=True)
        srdf = user_srdf(urdf, shipped, dirs, folder / f"{ROBOT}.srdf")
        so2 = RobotChecker(urdf, srdf, package_dirs=dirs, convex_meshes=True, obstacles=POSTS)
        bounded = RobotChecker(limited, srdf, package_dirs=dirs, convex_meshes=True, obstacles=POSTS)
        rows = queries(so2, args.queries, args.seed)
        crossing = sum(bool((np.abs(b - a)[so2.circular] > np.pi).any()) for a, b in rows)
        print(f"{ROBOT}: {so2.nq} joints, continuous {[n for n, c in zip(so2.joint_names, so2.circular) if c]}; "
              f"{len(rows)} queries, {crossing} with a short way across pi; {args.seconds} s per solve", flush=True)
        for label, robot in (("SO2 (default)", so2), ("limited to +-pi", bounded)):
            for planner, (solved, times, checks, travels) in run(robot, rows, args.seconds).items():
                med_l = f"{statistics.median(travels):5.2f} rad" if travels else "    -    "
                print(f"  {label:16s} {planner:20s} solved {solved:2d}/{len(rows)}, first path median "
                      f"{statistics.median(times) * 1e3:6.1f} ms, {statistics.median(checks):7.0f} checks; "
                      f"joint travel median {med_l}", flush=True)
    print(f"({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
