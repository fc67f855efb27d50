"""How far the library pipeline is from its own limit: its median cost over longer and longer budgets.

    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py                 # 0.1, 1, 10 s: ~4.5 min
    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py --budgets 0.1 1
    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py --only 1 9 --seeds 6 --budgets 0.1 1   # the median's two queries
    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py --aorrtc --seeds 3 --budgets 0.1 0.15 0.2 0.3  # ~4 min
    PYTHONPATH=. .venv/bin/python experiments/pipeline_convergence.py --only 9 --repeat 10 --budgets 0.1   # one run, again

``LibraryDimensionRRT`` (its defaults: rows released, shortcuts) on the stratified 24 queries of a
named set, one seed per query (the query's index), each budget a separate run.  Prints per budget the
median and mean final cost and the median number of samples, then per query how far each budget's
path is above the shortest of them (so with 10 s in the list: how far 0.1 s is from where the search
converges), to set beside AORRTC's median in the anytime campaign.  ``--only`` runs some of the queries
(positions in the stratified set) and ``--seeds`` runs each with that many seeds (seed = 100 * s + position),
printing every run's cost and samples: the spread between runs of one query.

``--aorrtc``: issue 17's comparison in one process instead of a campaign: each query and seed (``--seeds``) runs
the pipeline at every budget and OMPL's AORRTC (its defaults; OMPL seeded with 100 * s + position + 1 before it) for
1 s, one after the other on one checker thread (a campaign worker's); prints each budget's median cost over all runs against AORRTC's, and the median over the
queries of each query's median ratio.  ``--repeat N`` with one ``--only`` query: the same run (the same seed, so the
same samples in the same order) N times per budget, printing the samples each reached and its CPU time: how far
what a run reaches within its budget depends on how fast the machine is at that moment.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _common import length_after, summary, wearer_library_queries
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl import make_simple_setup
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.planning.setup import seed_ompl


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", default="planning_necessary", help="query-set name or JSON file")
    ap.add_argument("--max-queries", type=int, default=24)
    ap.add_argument("--budgets", type=float, nargs="+", default=[0.1, 1.0, 10.0])
    ap.add_argument("--only", type=int, nargs="+", default=None, help="positions of the queries to run (default: all)")
    ap.add_argument("--seeds", type=int, default=1, help="runs per query and budget, each with its own seed")
    ap.add_argument("--aorrtc", action="store_true", help="AORRTC for 1 s beside each query and seed (one thread)")
    ap.add_argument("--repeat", type=int, default=0, help="with one --only query: its first seed's run this many times")
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    if args.seeds < 1:
        ap.error(f"--seeds must be at least 1, got {args.seeds}")
    if args.repeat < 0 or args.repeat and (not args.only or len(args.only) != 1):
        ap.error("--repeat takes a count of at least 1 and exactly one --only query")
    if args.repeat:
        _repeat(args, ap)
        return
    if args.aorrtc:
        _versus_aorrtc(args, ap)
        return
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
    robot, lib, rows = _checked_rows(args, ap)
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


def _checked_rows(args: argparse.Namespace, ap: argparse.ArgumentParser, n_threads: int | None = None) -> tuple:
    """The robot, library and stratified rows, with ``--only`` checked against them."""
    robot, lib, rows = wearer_library_queries(args.queries, args.max_queries, n_threads)
    if args.only and not all(0 <= k < len(rows) for k in args.only):
        ap.error(f"--only takes positions 0..{len(rows) - 1} of the stratified set, got {args.only}")
    return robot, lib, rows


def _versus_aorrtc(args: argparse.Namespace, ap: argparse.ArgumentParser) -> None:
    """The pipeline at each budget and AORRTC at 1 s, query by query and seed by seed, in one process."""
    robot, lib, rows = _checked_rows(args, ap, n_threads=1)
    ks = args.only if args.only else list(range(len(rows)))
    setups = {k: make_simple_setup(robot, np.array(rows[k]["start"]), np.array(rows[k]["goal"])) for k in ks}
    cost = {b: np.full((args.seeds, len(ks)), np.nan) for b in args.budgets}
    ao = np.full((args.seeds, len(ks)), np.nan)
    for s in range(args.seeds):
        for i, k in enumerate(ks):
            q, ss = rows[k], setups[k]
            for b in args.budgets:
                planner = LibraryDimensionRRT(ss.getSpaceInformation(), lib, q["from_sector"], q["to_sector"],
                                              seed=100 * s + k)
                cost[b][s, i] = length_after(ss, planner, b)
            seed_ompl(100 * s + k + 1)  # AORRTC's own stream (OMPL refuses 0)
            ao[s, i] = length_after(ss, og.AORRTC(ss.getSpaceInformation()), 1.0)
        print(f"seed {s + 1} of {args.seeds} done", flush=True)
    ref = float(np.nanmedian(ao))
    print(f"AORRTC 1 s: median cost {ref:.5f} over {ao.size} runs; per seed "
          + " / ".join(f"{np.nanmedian(a):.5f}" for a in ao))
    for b in args.budgets:
        c = cost[b]
        med = float(np.nanmedian(c))
        ratio = np.nanmedian(c, axis=0) / np.nanmedian(ao, axis=0)
        print(f"pipeline {b:g} s: median cost {med:.5f} ({100 * (med / ref - 1):+.3f} % against AORRTC at 1 s); per seed "
              + " / ".join(f"{np.nanmedian(x):.5f}" for x in c)
              + f"; per query, median of the median ratios {np.nanmedian(ratio):.5f} ({int(np.sum(ratio <= 1))} of "
              f"{len(ks)} at or below 1)")


def _repeat(args: argparse.Namespace, ap: argparse.ArgumentParser) -> None:
    """One query's first-seed run, ``--repeat`` times at each budget: the same samples, at the machine's speed."""
    robot, lib, rows = _checked_rows(args, ap, n_threads=1)
    k = args.only[0]
    q = rows[k]
    ss = make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"]))
    for b in args.budgets:
        runs = []
        for _ in range(args.repeat):
            planner = LibraryDimensionRRT(ss.getSpaceInformation(), lib, q["from_sector"], q["to_sector"], seed=k)
            t = time.process_time()
            c = length_after(ss, planner, b)
            runs.append((c, planner.last_run_stats()["samples"], time.process_time() - t))
        n = [r[1] for r in runs]
        print(f"query {k} at {b:g} s, seed {k}, {args.repeat} times: samples {min(n)} .. {max(n)}, cost "
              f"{min(r[0] for r in runs):.5f} .. {max(r[0] for r in runs):.5f}; runs (cost, samples, CPU ms) "
              + ", ".join(f"{r[0]:.5f} {r[1]} {1000 * r[2]:.0f}" for r in runs), flush=True)


if __name__ == "__main__":
    main()
