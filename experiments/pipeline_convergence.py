"""How far the library pipeline is from its own limit: its median cost over longer and longer budgets.

    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py                 # 0.1, 1, 10 s: ~4.5 min
    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py --budgets 0.1 1
    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py --only 1 9 --seeds 6 --budgets 0.1 1   # the median's two queries

``LibraryDimensionRRT`` (its defaults: rows released, shortcuts) on the stratified 24 queries of a
named set, one seed per query (the query's index), each budget a separate run.  Prints per budget the
median and mean final cost and the median number of samples, then per query how far each budget's
path is above the shortest of them (so with 10 s in the list: how far 0.1 s is from where the search
converges), to set beside AORRTC's median in the anytime campaign.  ``--only`` runs some of the queries
(positions in the stratified set) and ``--seeds`` runs each with that many seeds (seed = 100 * s + position),
printing every run's cost and samples: the spread between runs of one query.
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import summary, wearer_library_queries
from ompl import util as ou

from tpee_ompl import make_simple_setup
from tpee_ompl.library.planner import LibraryDimensionRRT


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", default="planning_necessary", help="query-set name or JSON file")
    ap.add_argument("--max-queries", type=int, default=24)
    ap.add_argument("--budgets", type=float, nargs="+", default=[0.1, 1.0, 10.0])
    ap.add_argument("--only", type=int, nargs="+", default=None, help="positions of the queries to run (default: all)")
    ap.add_argument("--seeds", type=int, default=1, help="runs per query and budget, each with its own seed")
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    if args.seeds < 1:
        ap.error(f"--seeds must be at least 1, got {args.seeds}")
    if args.seeds > 1 or args.only:
        _spread(args, ap)
        return
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


def _spread(args: argparse.Namespace, ap: argparse.ArgumentParser) -> None:
    """Every run of the chosen queries x seeds x budgets: per query and budget the cost range, then each run."""
    robot, lib, rows = wearer_library_queries(args.queries, args.max_queries)
    if args.only and not all(0 <= k < len(rows) for k in args.only):
        ap.error(f"--only takes positions 0..{len(rows) - 1} of the stratified set, got {args.only}")
    for k in args.only if args.only else range(len(rows)):
        q = rows[k]
        ss = make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"]))
        for b in args.budgets:
            runs = []
            for s in range(args.seeds):
                planner = LibraryDimensionRRT(ss.getSpaceInformation(), lib, q["from_sector"], q["to_sector"],
                                              seed=100 * s + k)
                ss.clear()
                ss.setPlanner(planner)
                ss.solve(b)
                runs.append((ss.getSolutionPath().length() if ss.haveExactSolutionPath() else np.nan,
                             planner.last_run_stats()["samples"]))
            c = [r[0] for r in runs]
            print(f"query {k} at {b:g} s: cost {np.nanmin(c):.5f} .. {np.nanmax(c):.5f} (median {np.nanmedian(c):.5f}); "
                  f"samples {min(r[1] for r in runs)} .. {max(r[1] for r in runs)}; runs "
                  + ", ".join(f"{r[0]:.5f} ({r[1]})" for r in runs), flush=True)


if __name__ == "__main__":
    main()
