"""How far the library pipeline is from its own limit: its median cost over longer and longer budgets.

    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py                 # 0.1, 1, 10 s: ~4.5 min
    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py --budgets 0.1 1

``LibraryDimensionRRT`` (its defaults: rows released, shortcuts) on the stratified 24 queries of a
named set, one seed per query (the query's index), each budget a separate run.  Prints per budget the
median and mean final cost and the median number of samples, then per query how far each budget's
path is above the shortest of them (so with 10 s in the list: how far 0.1 s is from where the search
converges), to set beside AORRTC's median in the anytime campaign.
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import wearer_library_queries
from ompl import util as ou

from tpee_ompl import make_simple_setup
from tpee_ompl.library.planner import LibraryDimensionRRT


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", default="planning_necessary", help="query-set name or JSON file")
    ap.add_argument("--max-queries", type=int, default=24)
    ap.add_argument("--budgets", type=float, nargs="+", default=[0.1, 1.0, 10.0])
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    robot, lib, rows = wearer_library_queries(args.queries, args.max_queries)
    cost = {b: [] for b in args.budgets}
    samples = {b: [] for b in args.budgets}
    for k, q in enumerate(rows):
        ss = make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"]))
        for b in args.budgets:
            planner = LibraryDimensionRRT(ss.getSpaceInformation(), lib, q["from_sector"], q["to_sector"], seed=k)
            ss.clear()
            ss.setPlanner(planner)
            ss.solve(b)
            cost[b].append(ss.getSolutionPath().length() if ss.haveExactSolutionPath() else np.nan)
            samples[b].append(planner.last_run_stats()["samples"])
    best = np.nanmin(np.array([cost[b] for b in args.budgets]), axis=0)
    for b in args.budgets:
        c = np.array(cost[b])
        print(f"{b:g} s: median cost {np.nanmedian(c):.4f}  mean {np.nanmean(c):.4f}  median samples "
              f"{np.median(samples[b]):.0f}  within 0.1 % of the shortest over the budgets "
              f"{int(np.sum(c <= 1.001 * best))}/{len(c)}", flush=True)
    for b in args.budgets:
        print(f"{b:g} s, % above the shortest, per query:", np.round(100 * (np.array(cost[b]) / best - 1), 2).tolist())


if __name__ == "__main__":
    main()
