"""Where dimension-RRT converges on one query over many seeds: one local optimum, or several.

    PYTHONPATH=. .venv/bin/python experiments/seed_spread.py --index 0     # query 0 (1->2), 20 seeds, ~30 s

``tpee_dimension_rrt`` (Table 3's row kept, the paper's planner) on query ``--index`` of the stratified
24 of ``--queries``, once per seed 0 .. ``--seeds`` - 1, capped at ``--samples`` samples; prints the
final lengths, sorted.  With ``--release`` the rows are released after ``RELEASE_AFTER`` samples
without a shorter path (``DimensionRRTReleased``).  Used to check whether a query that stays more than
5 % above the best found keeps doing so for every seed (a class of paths the row cannot leave) or only
for some (luck of the samples).
"""

from __future__ import annotations

import argparse

from _common import summary
import numpy as np
from ompl import util as ou

from tpee_ompl import WearerArm, make_simple_setup
from tpee_ompl.bench.campaign import query_rows, stratified_subset
from tpee_ompl.planning.dimension_rrt import RELEASE_AFTER
from tpee_ompl.planning.tpee import tpee_dimension_rrt


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", default="planning_necessary", help="query-set name or JSON file")
    ap.add_argument("--index", type=int, default=0, help="index into the 24 stratified queries")
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--samples", type=int, default=5000)
    ap.add_argument("--release", action="store_true", help="release the rows (release_after=RELEASE_AFTER)")
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    robot = WearerArm()
    _, rows = query_rows(args.queries, robot)
    q = stratified_subset(rows, 24)[args.index]
    ss = make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"]))
    lengths = []
    for seed in range(args.seeds):
        planner = tpee_dimension_rrt(ss.getSpaceInformation(), q["from_sector"], q["to_sector"], seed=seed,
                                     max_samples=args.samples, release_after=RELEASE_AFTER if args.release else None)
        ss.clear()
        ss.setPlanner(planner)
        ss.solve(60.0)
        lengths.append(ss.getSolutionPath().length() if ss.haveExactSolutionPath() else float("nan"))
    print(f"query {args.index} ({q['from_sector']}->{q['to_sector']}), {args.seeds} seeds, {args.samples} samples"
          f"{', rows released' if args.release else ''}: lengths {np.round(np.sort(lengths), 4).tolist()}")


if __name__ == "__main__":
    main()
