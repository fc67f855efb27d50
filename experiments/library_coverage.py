"""Library coverage and independence on the named query sets, and the pipeline at 0.01 s (issue 17's report).

For every query of ``planning_necessary`` and ``paper_random``, per ordered sector pair: how often the
library's closest demonstration's DMP path is valid (every motion through ``si.checkMotion``), how often a later
candidate's is, and how often none is (then Table 3's straight motion, or planning).  That is the library's
own coverage, whatever the planner does first.  Then the LibraryDimensionRRT planner is run on each query with
a 0.01 s budget: how many are solved, the time to the first exact path, and what that path was ("direct": the
direct joint-space motion, free, checked first; "dmp" / "repaired": a library path; "straight"; "planned";
"failed"), and what the direct motions cost: how many are free, and of the colliding ones how many were found
at one of the planner's ``DIRECT_PROBES`` probe states.
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
from tpee_ompl.library.planner import DIRECT_PROBES, LibraryDimensionRRT
from tpee_ompl.model.queries import straight_motion
from tpee_ompl.planning.paths import path_passes_motion_checks
from tpee_ompl.resources import default_library_path

OUTCOMES = ("direct", "dmp", "repaired", "straight", "planned", "failed")


def main(argv: list[str] | None = None) -> None:
    """Print per-pair library coverage, the planner's outcomes at the budget and the query-to-demo distances,
    as Markdown and JSON."""
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
        coverage: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
        outcomes: collections.Counter = collections.Counter()
        nearest, first, solved, direct = [], [], 0, []
        for q in load_queries(name, robot):
            pair = (q.from_sector, q.to_sector)
            pd = lib.pairs[pair]
            d = np.linalg.norm(np.hstack([pd.starts, pd.goals]) - np.r_[q.start, q.goal], axis=1)
            nearest.append(float(d.min()))
            ss = make_simple_setup(robot, q.start, q.goal)
            si = ss.getSpaceInformation()
            si.setup()
            coverage[f"{pair[0]}->{pair[1]}"][_library_answer(si, lib, q)] += 1
            before = robot.collision_checks
            direct.append((LibraryDimensionRRT._direct_free(si, q.start, q.goal), robot.collision_checks - before))
            planner = LibraryDimensionRRT(si, lib, seed=1)
            ss.setPlanner(planner)
            ss.solve(args.budget)
            stats = planner.last_run_stats()
            outcomes[stats["library_outcome"]] += 1
            if ss.haveExactSolutionPath():
                solved += 1
                first.append(stats["first_solution_time"])
        total = sum(coverage.values(), collections.Counter())
        first_ms = np.array(first) * 1e3
        colliding = [c for free, c in direct if not free]
        report["sets"][name] = {
            "library_per_pair": {k: dict(v) for k, v in sorted(coverage.items())}, "library_total": dict(total),
            "nearest_demo_rad": {"min": min(nearest), "median": float(np.median(nearest))},
            "solved": solved, "first_path_ms": {"median": float(np.median(first_ms)),
                                                "p95": float(np.percentile(first_ms, 95))},
            "planner_outcomes": dict(outcomes),
            "direct_motions": {"free": len(direct) - len(colliding), "colliding": len(colliding),
                               "colliding_found_at_a_probe": sum(c <= DIRECT_PROBES for c in colliding),
                               "colliding_median_checks": float(np.median(colliding)) if colliding else None}}
        print(f"\n## {name}: {len(direct)} queries\n\nThe library alone (every query):\n")
        print("| pair | first candidate valid | later candidate | none: straight motion free | none |\n|---|---|---|---|---|")
        for k, v in sorted(coverage.items()):
            print(f"| {k} | {v['first']} | {v['later']} | {v['straight']} | {v['none']} |")
        print(f"| all | {total['first']} | {total['later']} | {total['straight']} | {total['none']} |")
        print(f"\nThe pipeline at {args.budget} s: {solved} solved; time to the first exact path median "
              f"{np.median(first_ms):.2f} ms, p95 {np.percentile(first_ms, 95):.2f} ms; first path "
              + ", ".join(f"{o} {outcomes[o]}" for o in OUTCOMES if outcomes[o]) + ".")
        print(f"Direct motions: {len(direct) - len(colliding)} free; of the {len(colliding)} colliding, "
              f"{sum(c <= DIRECT_PROBES for c in colliding)} found at one of the {DIRECT_PROBES} probe states"
              + (f" (median {np.median(colliding):.0f} states checked)." if colliding else "."))
        print(f"Closest demonstration to a query's (start, goal): min {min(nearest):.3f} rad, "
              f"median {np.median(nearest):.3f} rad (0 would mean the query is in the library).")
    if args.json:
        print(json.dumps(report, indent=1))


def _library_answer(si, lib: PathLibrary, q) -> str:
    """What the library answers for query q on its own: its first candidate's path valid ("first"), a later one's
    ("later"), none but Table 3's straight motion is free ("straight"), or nothing ("none")."""
    for rank, _, W in lib.candidate_paths(q.start, q.goal, q.from_sector, q.to_sector):
        if path_passes_motion_checks(si, W, in_bounds=True):
            return "first" if rank == 0 else "later"
    W = straight_motion(q.start, q.goal, q.from_sector, q.to_sector)
    return "straight" if path_passes_motion_checks(si, W, in_bounds=True) else "none"


if __name__ == "__main__":
    main()
