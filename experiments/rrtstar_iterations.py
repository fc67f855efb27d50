"""RRT* capped at N iterations on the first queries of the wearer's default set: the time of each run.

Issue 18's measure of the motion checks' speed (``make_simple_setup``'s default validator).  It uses only
``tpee_ompl.bench.problems``, so it runs against another checkout too, side by side with this one:

    PYTHONPATH=. python experiments/rrtstar_iterations.py [--queries 4] [--iterations 2500] [--threads 2]
    git worktree add /tmp/before <commit> && PYTHONPATH=/tmp/before python experiments/rrtstar_iterations.py
"""

from __future__ import annotations

import argparse
import statistics
import time

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.bench.problems import get_problem


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--queries", type=int, default=4)
    ap.add_argument("--iterations", type=int, default=2500)
    ap.add_argument("--threads", type=int, default=2, help="threads of the batched checks (default setup: 2)")
    ap.add_argument("--validator", default="batched")
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_ERROR)
    ou.RNG.setSeed(1)
    problem = get_problem("wearer")
    _, queries = problem.load_queries(None, False)
    times = []
    for k, query in enumerate(queries[: args.queries]):
        ss, robot = problem.build(query, args.validator, args.threads)
        planner = og.RRTstar(ss.getSpaceInformation())
        ss.setPlanner(planner)
        ss.setup()
        c0 = robot.collision_checks
        t0 = time.perf_counter()
        status = ss.solve(ob.PlannerTerminationCondition(lambda: planner.numIterations() >= args.iterations))
        times.append(time.perf_counter() - t0)
        print(f"query {k}: {times[-1]:.2f} s, {status}, {robot.collision_checks - c0} collision checks")
    print(f"median {statistics.median(times):.2f} s over {len(times)} queries "
          f"(RRT* {args.iterations} iterations, {args.validator}, {args.threads} thread(s))")


if __name__ == "__main__":
    main()
