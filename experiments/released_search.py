"""The released search, joint or per group: what planning every DOF as one group, sampled around one waypoint, buys.

    .venv/bin/python experiments/make_queries.py --seed 777 --n-per-pair 3 --out /tmp/heldout   # once
    PYTHONPATH=. .venv/bin/python experiments/released_search.py                                 # ~70 s
    PYTHONPATH=. .venv/bin/python experiments/released_search.py --budgets 0.01 0.1 1 --seeds 1

Once ``release_after`` samples brought no shorter path along the prescribed rows, the search goes on
with every DOF in one planned group and draws its narrowed samples around one intermediate waypoint
at a time (``GroupedSpace.released``, ``Search(local=True)``).  This script switches back in-process to
the search that followed before (the same groups as along the rows, every one planned, samples from
the box around the whole path) and runs, per query of each held-out set and each seed, the library
pipeline (``LibraryDimensionRRT``) and dimension-RRT with ``release_after=RELEASE_AFTER``
(``DimensionRRTReleased``) both ways, alternating which goes first, under the same seed.

Prints per set, planner and budget: mean and median final length both ways, how many runs were more
than 0.1 % shorter / longer jointly than per group, and how many are within 5 % of the shorter of the
two runs of their seed.
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import length_after, missing_query_files, summary
from ompl import util as ou

from tpee_ompl import PathLibrary, WearerArm, make_simple_setup
from tpee_ompl.bench.campaign import query_rows, stratified_subset
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.planning import dimension_rrt
from tpee_ompl.planning.dimension_rrt import RELEASE_AFTER
from tpee_ompl.planning.dimension_search import Search
from tpee_ompl.planning.grouped_space import GroupedSpace
from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.resources import default_library_path

_RELEASED = GroupedSpace.released


def _per_group_released(self: GroupedSpace) -> GroupedSpace:
    return GroupedSpace(self.layout.space, self.groups, self.h)  # the same groups, every one planned


class _BoxSearch(Search):
    def __init__(self, *args, **kwargs) -> None:
        kwargs["local"] = False
        super().__init__(*args, **kwargs)


def _joint(on: bool) -> None:
    GroupedSpace.released = _RELEASED if on else _per_group_released
    dimension_rrt.Search = Search if on else _BoxSearch


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", nargs="+", default=["/tmp/heldout/planning_necessary.json",
                                                     "/tmp/heldout/paper_random.json"])
    ap.add_argument("--max-queries", type=int, default=36)
    ap.add_argument("--budgets", type=float, nargs="+", default=[0.1])
    ap.add_argument("--seeds", type=int, default=3)
    args = ap.parse_args(argv)
    if (missing := missing_query_files(args.queries)) is not None:
        ap.error(missing)
    ou.setLogLevel(ou.LOG_NONE)
    robot = WearerArm()
    lib = PathLibrary.load(default_library_path(), robot)
    try:
        for name in args.queries:
            _, rows = query_rows(name, robot)
            rows = stratified_subset(rows, args.max_queries)
            res = {(who, b): {False: [], True: []} for who in ("pipeline", "released") for b in args.budgets}
            for k, q in enumerate(rows):
                start, goal, i, j = np.array(q["start"]), np.array(q["goal"]), q["from_sector"], q["to_sector"]
                ss = make_simple_setup(robot, start, goal)
                si = ss.getSpaceInformation()
                for b in args.budgets:
                    for s in range(args.seeds):
                        seed = k + 1000 * s
                        for on in ((False, True) if (k + s) % 2 else (True, False)):
                            _joint(on)
                            for who in ("pipeline", "released"):
                                planner = (LibraryDimensionRRT(si, lib, i, j, seed=seed) if who == "pipeline"
                                           else tpee_dimension_rrt(si, i, j, seed=seed, release_after=RELEASE_AFTER))
                                res[(who, b)][on].append(length_after(ss, planner, b))
            for (who, b), r in res.items():
                box, joint = np.array(r[False]), np.array(r[True])
                better = np.fmin(box, joint)
                print(f"{name.split('/')[-1]:26s} {who:9s} {b:g} s x {args.seeds} seeds: mean {np.nanmean(box):.4f} -> "
                      f"{np.nanmean(joint):.4f}  median {np.nanmedian(box):.4f} -> {np.nanmedian(joint):.4f}  "
                      f">0.1 % shorter / longer jointly {int(np.sum(joint < 0.999 * box))} / "
                      f"{int(np.sum(joint > 1.001 * box))} of {len(joint)}  within 5 % of the shorter "
                      f"{int(np.sum(box <= 1.05 * better))} -> {int(np.sum(joint <= 1.05 * better))}", flush=True)
    finally:
        _joint(True)


if __name__ == "__main__":
    main()
