"""First path on the campaign's generic problems: dimension-RRT against RRTConnect over many seeds, in one process.

    PYTHONPATH=. .venv/bin/python experiments/generic_first_path.py                 # 10 seeds, all seven, ~25 s
    PYTHONPATH=. .venv/bin/python experiments/generic_first_path.py --seeds 20 point4-hole narrow3

``make bench-generic`` runs each planner once per query (10 queries), so its median time to a first path is
the median of 10 runs, and on the point problems, where both planners need a few milliseconds and a
query's runs spread over an order of magnitude, it swings from one campaign to the next (narrow3: 2.5x
in one, 6.0x and 3.8x in two others).  Here each query of the problem (the campaign's own set-up:
``get_problem(name).make_setup``, Python checker, OMPL's motion validator) runs ``--seeds`` times, the two
planners alternating (dimension-RRT with the problem's grouping and the run's seed; RRTConnect after
OMPL's global seed is set to the same number), each stopped by ``exactSolnPlannerTerminationCondition``
or --limit s.  Prints per problem the median over all runs of each planner, their ratio, and the ratio
of the medians of the per-query medians (each query weighs the same).  Runs without a path count as the
limit.
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import first_path_time, summary
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.bench.generic_problems import GENERIC_PROBLEMS
from tpee_ompl.bench.problems import get_problem
from tpee_ompl.planning.dimension_rrt import DimensionRRT


def main(argv: list[str] | None = None) -> None:
    names = list(GENERIC_PROBLEMS)
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("problems", nargs="*", default=names, help=f"generic problems (default: all of {names})")
    ap.add_argument("--seeds", type=int, default=10, help="runs per query and planner")
    ap.add_argument("--limit", type=float, default=10.0, help="time limit per run, s")
    args = ap.parse_args(argv)
    if args.seeds < 1:
        ap.error(f"--seeds must be at least 1, got {args.seeds}")
    unknown = [p for p in args.problems if p not in names]
    if unknown:
        ap.error(f"unknown generic problem(s) {unknown}; choose from {names}")
    ou.setLogLevel(ou.LOG_NONE)
    print(f"{'problem':12s} {'runs':>5s}  {'D, ms':>7s} {'RC, ms':>7s} {'ratio':>6s}  per-query ratio  solved D / RC")
    for name in args.problems:
        problem = get_problem(name)
        _, rows = problem.queries()
        d_all, r_all, d_med, r_med = [], [], [], []
        for qi, q in enumerate(rows):
            ss, _ = problem.make_setup(q, "discrete")
            si = ss.getSpaceInformation()
            dq, rq = [], []
            for s in range(1, args.seeds + 1):
                seed = 1000 * s + qi
                ou.RNG.setSeed(seed)
                dq.append(first_path_time(ss, DimensionRRT(si, groups=problem.groups, seed=seed), args.limit))
                rq.append(first_path_time(ss, og.RRTConnect(si), args.limit))
            d_all += dq
            r_all += rq
            d_med.append(np.median([args.limit if t is None else t for t in dq]))
            r_med.append(np.median([args.limit if t is None else t for t in rq]))
        D = np.array([args.limit if t is None else t for t in d_all])
        R = np.array([args.limit if t is None else t for t in r_all])
        solved = f"{sum(t is not None for t in d_all)} / {sum(t is not None for t in r_all)}"
        print(f"{name:12s} {len(D):5d}  {1e3 * np.median(D):7.2f} {1e3 * np.median(R):7.2f} "
              f"{np.median(D) / np.median(R):6.2f}  {np.median(d_med) / np.median(r_med):15.2f}  {solved}")


if __name__ == "__main__":
    main()
