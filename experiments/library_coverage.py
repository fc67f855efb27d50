"""Library coverage and independence on the named query sets (issue 17's report).

For every query of ``planning_necessary`` and ``paper_random`` the LibraryDimensionRRT planner is run with
a 0.01 s budget; per ordered sector pair the script counts how often the closest demonstration's DMP path
was valid ("dmp"), a later candidate's ("repaired"), Table 3's straight motion ("straight"), or the
planner had to plan ("planned"/"failed").
It also checks that no benchmark query is in the library: the library's demonstrations were drawn by its
own sampler (seed in its build parameters), and the distance from each query's (start, goal) to the
closest demonstration of its pair (8-D, radians) is reported; 0 would mean a query was a demonstration.

Usage: python experiments/library_coverage.py [--sets planning_necessary paper_random] [--budget 0.01]
"""

from __future__ import annotations

import argparse
import collections
import json

from _common import summary
import numpy as np
from ompl import util as ou

from tpee_ompl import PathLibrary, WearerArm, load_queries, make_simple_setup
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.resources import default_library_path


def main(argv: list[str] | None = None) -> None:
    """Print per-pair outcome counts and the query-to-demo distances, as Markdown and JSON."""
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--sets", nargs="+", default=["planning_necessary", "paper_random"])
    ap.add_argument("--budget", type=float, default=0.01, help="seconds per query")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_WARN)
    robot = WearerArm(n_threads=1)
    lib = PathLibrary.load(default_library_path(), robot)
    report = {"library": str(default_library_path()), "build_seed": lib.build_params.get("seed"), "sets": {}}
    for name in args.sets:
        counts: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
        nearest, first, solved = [], [], 0
        for q in load_queries(name, robot):
            pair = (q.from_sector, q.to_sector)
            pd = lib.pairs[pair]
            d = np.linalg.norm(np.hstack([pd.starts, pd.goals]) - np.r_[q.start, q.goal], axis=1)
            nearest.append(float(d.min()))
            ss = make_simple_setup(robot, q.start, q.goal)
            planner = LibraryDimensionRRT(ss.getSpaceInformation(), lib, seed=1)
            ss.setPlanner(planner)
            ss.solve(args.budget)
            stats = planner.last_run_stats()
            counts[f"{pair[0]}->{pair[1]}"][stats["library_outcome"]] += 1
            if ss.haveExactSolutionPath():
                solved += 1
                first.append(stats["first_solution_time"])
        total = sum(counts.values(), collections.Counter())
        first_ms = np.array(first) * 1e3
        report["sets"][name] = {"per_pair": {k: dict(v) for k, v in sorted(counts.items())}, "total": dict(total),
                                "nearest_demo_rad": {"min": min(nearest), "median": float(np.median(nearest))},
                                "solved": solved, "first_path_ms": {"median": float(np.median(first_ms)),
                                                                    "p95": float(np.percentile(first_ms, 95))}}
        print(f"\n## {name}: {sum(total.values())} queries, budget {args.budget} s: {solved} solved; "
              f"time to the first exact path median {np.median(first_ms):.2f} ms, p95 {np.percentile(first_ms, 95):.2f} ms")
        print("| pair | first candidate valid | later candidate | straight motion | planned | failed |\n|---|---|---|---|---|---|")
        for k, v in sorted(counts.items()):
            print(f"| {k} | {v['dmp']} | {v['repaired']} | {v['straight']} | {v['planned']} | {v['failed']} |")
        print(f"| all | {total['dmp']} | {total['repaired']} | {total['straight']} | {total['planned']} | {total['failed']} |")
        print(f"closest demonstration to a query's (start, goal): min {min(nearest):.3f} rad, "
              f"median {np.median(nearest):.3f} rad (0 would mean the query is in the library)")
    if args.json:
        print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
