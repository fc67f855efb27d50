"""What respreading collapsed waypoints buys the released search: on and off, same seeds, same queries.

    .venv/bin/python experiments/make_queries.py --seed 777 --n-per-pair 3 --out /tmp/heldout   # once
    PYTHONPATH=. .venv/bin/python experiments/collapsed_waypoints.py                            # ~2 min

Once the prescribed rows are released, two waypoints can collapse onto each other; the search then
gives the step to the longest segment (``waypoint_shortcuts.respread_candidate``).  This script
switches that step off in-process (``dimension_search.respread_candidate`` returning None) and runs,
per query of each held-out set, the library pipeline (``LibraryDimensionRRT``) and dimension-RRT
with ``release_after=RELEASE_AFTER`` (``DimensionRRTReleased``), with it and without it:

* capped at ``--samples`` samples, one seed per query (deterministic: every difference is the step's);
* at ``--budget`` s, ``--seeds`` seeds per query, on and off alternating query by query.

Prints per set, planner and part: mean and median final length, and how many runs were more than
0.5 % shorter / longer with the step than the same seed without it.
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import length_after, missing_query_files, summary
from ompl import util as ou

import tpee_ompl.planning.dimension_search as dimension_search
from tpee_ompl import PathLibrary, WearerArm, make_simple_setup
from tpee_ompl.bench.campaign import query_rows, stratified_subset
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.planning.dimension_rrt import RELEASE_AFTER
from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.resources import default_library_path

_RESPREAD = dimension_search.respread_candidate


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", nargs="+", default=["/tmp/heldout/planning_necessary.json",
                                                     "/tmp/heldout/paper_random.json"])
    ap.add_argument("--max-queries", type=int, default=36)
    ap.add_argument("--samples", type=int, default=3000)
    ap.add_argument("--budget", type=float, default=0.1)
    ap.add_argument("--seeds", type=int, default=3)
    args = ap.parse_args(argv)
    if (missing := missing_query_files(args.queries)) is not None:
        ap.error(missing)
    ou.setLogLevel(ou.LOG_NONE)
    robot = WearerArm()
    lib = PathLibrary.load(default_library_path(), robot)
    for name in args.queries:
        _, rows = query_rows(name, robot)
        rows = stratified_subset(rows, args.max_queries)
        parts = [("samples", None, 1), ("time", args.budget, args.seeds)]
        res = {(who, part): {False: [], True: []} for who in ("pipeline", "released") for part, _, _ in parts}
        for k, q in enumerate(rows):
            start, goal, i, j = np.array(q["start"]), np.array(q["goal"]), q["from_sector"], q["to_sector"]
            ss = make_simple_setup(robot, start, goal)
            si = ss.getSpaceInformation()
            for part, budget, seeds in parts:
                cap = args.samples if budget is None else None
                for s in range(seeds):
                    seed = k + 1000 * s
                    for on in ((False, True) if (k + s) % 2 else (True, False)):
                        dimension_search.respread_candidate = _RESPREAD if on else (lambda *a: None)
                        for who in ("pipeline", "released"):
                            planner = (LibraryDimensionRRT(si, lib, i, j, seed=seed, max_samples=cap) if who == "pipeline"
                                       else tpee_dimension_rrt(si, i, j, seed=seed, max_samples=cap,
                                                               release_after=RELEASE_AFTER))
                            res[(who, part)][on].append(length_after(ss, planner, 60.0 if budget is None else budget))
        dimension_search.respread_candidate = _RESPREAD
        for (who, part), r in res.items():
            off, on = np.array(r[False]), np.array(r[True])
            ratio = on / off
            what = f"{args.samples} samples" if part == "samples" else f"{args.budget} s x {args.seeds} seeds"
            print(f"{name.split('/')[-1]:26s} {who:9s} {what:18s} mean {np.nanmean(off):.4f} -> {np.nanmean(on):.4f}  "
                  f"median {np.nanmedian(off):.4f} -> {np.nanmedian(on):.4f}  >0.5 % shorter / longer with it "
                  f"{int(np.sum(ratio < 0.995))} / {int(np.sum(ratio > 1.005))} of {len(on)}", flush=True)


if __name__ == "__main__":
    main()
