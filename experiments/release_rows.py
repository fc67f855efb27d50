"""What releasing Table 3's rows buys: dimension-RRT and the library pipeline with and without
``release_after``, at equal time, against AORRTC given 1 s.

    PYTHONPATH=. .venv/bin/python experiments/release_rows.py                       # both named sets, 24 each, ~2 min
    PYTHONPATH=. .venv/bin/python experiments/release_rows.py --queries /tmp/heldout/planning_necessary.json \\
        --max-queries 36 --release 0 100 300 1000 --planners library                # how RELEASE_AFTER was chosen

For each query (the first --max-queries of each set, round-robin over sector pairs as ``tpee-ompl
bench --max-queries`` takes them), AORRTC runs once for 1 s; then each planner (``dimension-rrt``:
``tpee_dimension_rrt``, seed = the query's position; ``library``: ``LibraryDimensionRRT`` with the
packaged library) runs once per budget and per ``release_after`` value (0 = never, the paper's
behaviour).  Prints per set, budget, planner and value: the median raw cost, the mean length / best
found (the shortest path any run of this script found for the query) and the queries within 5 % of it.
The held-out set is drawn with ``python experiments/make_queries.py --seed 777 --n-per-pair 3 --out
/tmp/heldout`` (not the benchmark sets).
"""

from __future__ import annotations

import argparse
import statistics

from _common import summary
import numpy as np
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl import PathLibrary, WearerArm, make_simple_setup
from tpee_ompl.bench.campaign import query_rows, stratified_subset
from tpee_ompl.bench.report import WITHIN_BEST
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.planning.dimension_rrt import RELEASE_AFTER, DimensionRRTOptions
from tpee_ompl.planning.paths import path_passes_motion_checks, path_to_array
from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.resources import default_library_path


def _proven_length(ss: og.SimpleSetup, start: np.ndarray, goal: np.ndarray) -> float:
    """Length of the setup's exact path if it runs from start to goal and passes ``si.checkMotion``, else NaN
    (AORRTC's path can be the goal alone when the direct motion is free: ompl/ompl#1420)."""
    if not ss.haveExactSolutionPath():
        return float("nan")
    path = ss.getSolutionPath()
    W = path_to_array(path, len(start))
    if len(W) < 2 or not (np.allclose(W[0], start) and np.allclose(W[-1], goal)):
        return float("nan")
    return float(path.length()) if path_passes_motion_checks(ss.getSpaceInformation(), path) else float("nan")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", nargs="+", default=["planning_necessary", "paper_random"],
                    help="named query sets or query-set JSON files")
    ap.add_argument("--max-queries", type=int, default=24)
    ap.add_argument("--budgets", type=float, nargs="+", default=[0.01, 0.1])
    ap.add_argument("--release", type=int, nargs="+", default=[0, RELEASE_AFTER],
                    help="release_after values (0: never)")
    ap.add_argument("--planners", nargs="+", choices=["dimension-rrt", "library"], default=["dimension-rrt", "library"])
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    robot = WearerArm()
    lib = PathLibrary.load(default_library_path(), robot) if "library" in args.planners else None
    for name in args.queries:
        set_name, rows = query_rows(name, robot)
        rows = stratified_subset(rows, args.max_queries)
        keys = [(p, r, t) for p in args.planners for r in args.release for t in args.budgets]
        cost: dict[tuple, list[float]] = {k: [] for k in keys}
        ref: list[float] = []
        for k, q in enumerate(rows):
            start, goal, i, j = np.array(q["start"]), np.array(q["goal"]), q["from_sector"], q["to_sector"]
            ss = make_simple_setup(robot, start, goal)
            si = ss.getSpaceInformation()
            ss.setPlanner(og.AORRTC(si))
            ss.solve(1.0)
            ref.append(_proven_length(ss, start, goal))
            for planner, release, budget in keys:
                opts = DimensionRRTOptions(seed=k, release_after=release or None)
                ss.clear()
                ss.setPlanner(tpee_dimension_rrt(si, i, j, opts) if planner == "dimension-rrt"
                              else LibraryDimensionRRT(si, lib, i, j, opts))
                ss.solve(budget)
                cost[(planner, release, budget)].append(_proven_length(ss, start, goal))
        ref_a = np.array(ref)
        best = np.nanmin(np.vstack([ref_a] + [np.array(v) for v in cost.values()]), axis=0)
        print(f"{set_name}: {len(rows)} queries; AORRTC at 1 s: median cost {np.nanmedian(ref_a):.4f}, "
              f"{int(np.sum(ref_a <= WITHIN_BEST * best))} within 5 % of the best found, "
              f"{int(np.sum(~np.isnan(ref_a)))} solved", flush=True)
        for planner, release, budget in keys:
            a = np.array(cost[(planner, release, budget)])
            ok = ~np.isnan(a)
            med = statistics.median(a[ok].tolist()) if ok.any() else float("nan")
            print(f"  {budget:g} s  {planner:13s} release_after {release or 'never':>5}:  median cost {med:.4f}  "
                  f"length / best {np.mean(a[ok] / best[ok]):.4f} (mean)  within 5 % {int(np.sum(a <= WITHIN_BEST * best))}"
                  f"/{len(a)}  solved {int(ok.sum())}", flush=True)


if __name__ == "__main__":
    main()
