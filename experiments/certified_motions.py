"""Certified (clearance-certificate) vs batched (dense) motion checking, side by side in one run.

For the wearer and the Panda shelf:
1. random motions (valid starts, 0.05-0.6 rad): µs per motion, boolean checks and distance
   evaluations per motion, and disagreements (the certified validator must never accept a motion
   the dense check rejects);
2. the motions RRT* asks for in 500 iterations on the first queries, replayed through both (the
   cache sees the planner's repeated endpoints);
3. planner level: RRTConnect (first solution), RRT* and dimension-RRT (500 iterations / samples)
   with each validator, in one worker process per validator with the same OMPL seed.

    PYTHONPATH=. python experiments/certified_motions.py [--motions 300] [--queries 8]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time

from _common import summary
import numpy as np


def _robot(name: str):
    if name == "wearer":
        from tpee_ompl.model.wearer_arm import default_robot

        return default_robot()
    from tpee_ompl.model.robots import panda_shelf

    return panda_shelf()


def _queries(name: str, robot, n: int) -> list[tuple[np.ndarray, np.ndarray]]:
    if name == "wearer":
        from tpee_ompl.model.queries import load_queries

        return [(q.start, q.goal) for q in load_queries("planning_necessary", robot)[:n]]
    from tpee_ompl.model.joint_queries import load_joint_query_set

    qs, _ = load_joint_query_set("panda_shelf", robot)
    return [(q.start, q.goal) for q in qs[:n]]


def _replay(robot, motions: np.ndarray, label: str) -> None:
    """Check each motion once with a fresh batched and a fresh certified validator, interleaved."""
    from tpee_ompl.planning.setup import make_simple_setup

    mb = make_simple_setup(robot).getSpaceInformation().getMotionValidator()
    mc = make_simple_setup(robot, motion_validator="certified").getSpaceInformation().getMotionValidator()
    tb = tc = 0.0
    cb = cc = 0
    vb, vc = [], []
    for a, b in motions:
        c0 = robot.collision_checks
        t0 = time.perf_counter()
        vb.append(mb.check_motions(a[None], b[None])[0])
        t1 = time.perf_counter()
        c1 = robot.collision_checks
        vc.append(mc.check_motions(a[None], b[None])[0])
        t2 = time.perf_counter()
        tb, tc, cb, cc = tb + t1 - t0, tc + t2 - t1, cb + c1 - c0, cc + robot.collision_checks - c1
    vb, vc = np.array(vb), np.array(vc)
    n = len(motions)
    print(f"  {label}: {n} motions, {vb.mean():.0%} valid (dense)")
    print(f"    batched   {tb / n * 1e6:8.0f} us/motion  {cb / n:6.1f} checks/motion")
    print(f"    certified {tc / n * 1e6:8.0f} us/motion  {cc / n:6.1f} checks/motion  "
          f"{mc.distance_evaluations / n:5.2f} distance evaluations/motion ({len(mc.groups.pair_groups)} groups)  "
          f"cache hits {mc.cache_hits}  fallbacks {mc.fallbacks}")
    print(f"    ratio batched/certified time {tb / tc:.2f}; certified accepts what dense rejects: {int(np.sum(vc & ~vb))}, "
          f"certified rejects what dense accepts: {int(np.sum(~vc & vb))}")


def _random_motions(robot, n: int, rng: np.random.Generator) -> np.ndarray:
    A = rng.uniform(robot.lower, robot.upper, (3 * n, robot.nq))
    A = A[robot.are_valid(A)][:n]
    D = rng.normal(size=A.shape)
    D /= np.linalg.norm(D, axis=1)[:, None]
    B = np.clip(A + D * rng.uniform(0.05, 0.6, (len(A), 1)), robot.lower, robot.upper)
    return np.stack([A, B], axis=1)


def _planner_motions(robot, queries, iterations: int) -> np.ndarray:
    """The motions RRT* checks in ``iterations`` iterations on each query."""
    from ompl import base as ob
    from ompl import geometric as og

    from tpee_ompl.planning.paths import state_to_array
    from tpee_ompl.planning.setup import BatchedMotionValidator, make_simple_setup

    out = []

    class Recording(BatchedMotionValidator):
        def checkMotion(self, s1, s2):  # noqa: N802
            out.append((state_to_array(s1, robot.nq), state_to_array(s2, robot.nq)))
            return super().checkMotion(s1, s2)

    for start, goal in queries:
        ss = make_simple_setup(robot, start, goal)
        si = ss.getSpaceInformation()
        mv = Recording(si, robot, robot.max_joint_step())
        si.setMotionValidator(mv)
        planner = og.RRTstar(si)
        ss.setPlanner(planner)
        ss.setup()
        ss.solve(ob.PlannerTerminationCondition(lambda p=planner: p.numIterations() >= iterations))
    return np.array(out)


def _planner_worker(robot_name: str, validator: str, n_queries: int, iterations: int) -> None:
    """One process per validator: the same OMPL seed gives the same planner seeds in each."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    from tpee_ompl.planning.dimension_rrt import DimensionRRT
    from tpee_ompl.planning.setup import make_simple_setup

    ou.RNG.setSeed(7)
    ou.setLogLevel(ou.LOG_ERROR)
    robot = _robot(robot_name)
    groups = ((0, 1), (2, 3)) if robot_name == "wearer" else ((0, 1, 2), (3, 4, 5, 6))
    rows = {"RRTConnect": [], "RRTstar": [], "DimensionRRT": []}
    for k, (start, goal) in enumerate(_queries(robot_name, robot, n_queries)):
        for name in rows:
            ss = make_simple_setup(robot, start, goal, motion_validator=validator)
            si = ss.getSpaceInformation()
            if name == "RRTConnect":
                planner = og.RRTConnect(si)
                ptc = ob.plannerOrTerminationCondition(ob.exactSolnPlannerTerminationCondition(ss.getProblemDefinition()),
                                                       ob.timedPlannerTerminationCondition(5.0))
            elif name == "RRTstar":
                planner = og.RRTstar(si)
                ptc = ob.PlannerTerminationCondition(lambda p=planner: p.numIterations() >= iterations)
            else:
                planner = DimensionRRT(si, groups=groups, max_samples=iterations, seed=k + 1)
                ptc = ob.timedPlannerTerminationCondition(30.0)
            ss.setPlanner(planner)
            ss.setup()
            c0 = robot.collision_checks
            t0 = time.perf_counter()
            ss.solve(ptc)
            dt = time.perf_counter() - t0
            solved = ss.haveExactSolutionPath()
            cost = ss.getSolutionPath().length() if solved else float("inf")
            rows[name].append((dt, robot.collision_checks - c0, solved, cost))
    for name, r in rows.items():
        t, c, s, cost = (np.array(x) for x in zip(*r))
        print(f"RESULT {robot_name} {validator} {name} median_s {np.median(t):.3f} total_s {t.sum():.2f} "
              f"checks {int(c.sum())} solved {int(s.sum())}/{len(s)} median_length {np.median(cost):.3f}")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--motions", type=int, default=300, help="random motions per robot")
    parser.add_argument("--queries", type=int, default=8, help="queries per robot for the planner comparison")
    parser.add_argument("--iterations", type=int, default=500, help="RRT* iterations / dimension-RRT samples")
    parser.add_argument("--robots", default="wearer,panda")
    parser.add_argument("--worker", nargs=2, metavar=("ROBOT", "VALIDATOR"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        _planner_worker(args.worker[0], args.worker[1], args.queries, args.iterations)
        return
    rng = np.random.default_rng(1)
    for name in args.robots.split(","):
        robot = _robot(name)
        print(f"== {name}: joint step {robot.max_joint_step():.4f} rad, {len(robot.gmodel.collisionPairs)} pairs")
        _replay(robot, _random_motions(robot, args.motions, rng), "random motions")
        _replay(robot, _planner_motions(robot, _queries(name, robot, 2), args.iterations), "RRT* motions (2 queries)")
        for validator in ("batched", "certified"):
            cmd = [sys.executable, __file__, "--worker", name, validator, "--queries", str(args.queries),
                   "--iterations", str(args.iterations)]
            res = subprocess.run(cmd, capture_output=True, text=True, check=True)
            print("\n".join(line[7:] for line in res.stdout.splitlines() if line.startswith("RESULT ")))


if __name__ == "__main__":
    main()
