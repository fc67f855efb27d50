"""What Table 3 costs: per query of an anytime campaign, the shortest length any path along the prescribed
DOF1/DOF2 row can have, against the best path any planner found.

    PYTHONPATH=. .venv/bin/python experiments/table3_bound.py results/<stamp>_pn_anytime/benchmark.db
    PYTHONPATH=. .venv/bin/python experiments/table3_bound.py DB --planner DimensionRRT --reference RRTConnectSimplify
    PYTHONPATH=. .venv/bin/python experiments/table3_bound.py DB --end-motions   # + the end-motion bound (13 s)

Dimension-RRT's TPEE case keeps DOF1/DOF2 on the paper's Table 3 row (unless ``release_after`` is set;
the library pipeline sets it, and its DMP and direct-motion paths leave the row anyway); AORRTC,
RRTConnect and RRT* move them freely.  ``cross_sector_length_bound`` (hypot of the row's length and the other joints' straight
distance, obstacles ignored) is a lower bound for every path along the row, so a query whose bound exceeds
1.05 x the best found cannot be within 5 % for any planner that keeps the row.  Prints, per query, the
bound / best found and each budget's length / best found of ``--planner`` and ``--reference``; then how many
queries the row rules out, and the median bound against the reference's median cost at its largest budget.

``--end-motions`` tightens the bound of each query the row alone does not rule out and that ``--planner``
misses at its largest budget, with obstacles: the paper's path has 7 waypoints on the row, and its first and
last motions (start -> waypoint 1, waypoint 5 -> goal) must be valid.  With x the free joints (DOF3/DOF4) of
waypoint 5, Minkowski's inequality over the first five motions gives length >= hypot(P - a5, |x - start|) +
hypot(a5, |goal - x|) (a5 the row's last step); the least of that over the x on a grid (``--grid`` rad over the
joint limits) whose motion to the goal passes the setup's motion validator bounds every such path, and the
same for waypoint 1 and the start; the larger of the two is printed.  Only the grid points whose bound is
within 10 % of the best found are checked, so a bound above that reads "> 1.100".  A sampled bound: a
valid region thinner than the grid could be missed.  Dimension-RRT keeps the 7 waypoints (``max_h`` unset, as
in the campaigns; its shortcut sweeps move the free joints of the waypoints, not the row).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
from collections import defaultdict
from pathlib import Path

from _common import summary
import numpy as np
from ompl import util as ou

from tpee_ompl.bench.report import WITHIN_BEST, best_found, load_runs
from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.sectors import cross_sector_length_bound, cross_sector_trajectory
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.setup import make_simple_setup


_END_LIMIT = 1.10
"""--end-motions checks the grid points whose bound is at most this times the best found (a bound above it: inf)."""


def end_motion_bound(robot: WearerArm, q, limit: float, grid: float) -> float:
    """The larger of the first- and last-motion bounds (module docstring) of query q, inf when no grid point
    whose bound is at most ``limit`` has a valid motion (then no path along the row is that short)."""
    start, goal = np.asarray(q.start, dtype=float), np.asarray(q.goal, dtype=float)
    row = cross_sector_trajectory(q.from_sector, q.to_sector)
    steps = np.linalg.norm(np.diff(row, axis=0), axis=1)
    mv = make_simple_setup(robot, start, goal).getSpaceInformation().getMotionValidator()
    lo, hi = robot.lower[2:], robot.upper[2:]
    X = np.stack(np.meshgrid(*(np.arange(a, b + 1e-9, grid) for a, b in zip(lo, hi)), indexing="ij"), -1)
    X = X.reshape(-1, len(lo))
    bounds = []
    for k, end, other, a in ((len(row) - 2, goal, start, steps[-1]), (1, start, goal, steps[0])):
        lb = np.hypot(steps.sum() - a, np.linalg.norm(X - other[2:], axis=1)) + np.hypot(a, np.linalg.norm(X - end[2:], axis=1))
        near = np.flatnonzero(lb <= limit)
        W = np.column_stack([np.broadcast_to(row[k], (len(near), 2)), X[near]])
        if len(near):  # the motions only from the valid waypoints
            valid = robot.are_valid(W)
            near, W = near[valid], W[valid]
        E = np.broadcast_to(end, W.shape)
        ok = np.zeros(len(near), dtype=bool)
        for i in range(0, len(near), 20000):  # the motion as the path runs it: start -> waypoint 1, waypoint 5 -> goal
            A, B = (W[i : i + 20000], E[i : i + 20000]) if k > 1 else (E[i : i + 20000], W[i : i + 20000])
            ok[i : i + 20000] = mv.check_motions(A, B)
        bounds.append(float(lb[near[ok]].min()) if ok.any() else math.inf)
    return max(bounds)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("db", type=Path, help="a campaign's benchmark.db with an anytime comparison")
    ap.add_argument("--planner", default="DimensionRRT", help="a planner that keeps the Table 3 row (one run per "
                    "query and budget, as the anytime comparison has)")
    ap.add_argument("--reference", default="AORRTC", help="a planner that moves DOF1/DOF2 freely")
    ap.add_argument("--end-motions", action="store_true", help="tighten the bound with the first and last motions "
                    "on the queries --planner misses (module docstring)")
    ap.add_argument("--grid", type=float, default=0.005, help="rad: grid of DOF3/DOF4 for --end-motions")
    args = ap.parse_args(argv)
    if not 0.002 <= args.grid <= 0.5:  # (finer: a grid over the whole joint box of several GB)
        print(f"table3_bound.py: --grid must be within [0.002, 0.5] rad, got {args.grid:g}", file=sys.stderr)
        return 2
    if not args.db.is_file():
        print(f"table3_bound.py: no such database: {args.db}", file=sys.stderr)
        return 2
    ou.setLogLevel(ou.LOG_WARN)
    runs = [r for r in load_runs(args.db) if r["comparison"] == "anytime" and r["motion_validator"] in (None, "batched")]
    if not runs:
        print(f"table3_bound.py: {args.db} has no anytime runs", file=sys.stderr)
        return 2
    best = best_found(runs)
    robot = WearerArm()
    queries = {}
    for name in {r["query_set"] for r in runs}:
        queries.update({(name, str(q.id)): q for q in load_queries(name, robot)})
    budgets = sorted({float(r["time_budget"]) for r in runs})
    length: dict[tuple, float] = {}  # (planner, budget, query id) -> raw length of a successful run
    for r in runs:
        if r["success"] and r["planner"] in (args.planner, args.reference):
            key = (r["planner"], float(r["time_budget"]), r["query_id"])
            if key in length:
                print(f"table3_bound.py: {args.db} has several runs of {key[0]} on query {key[2]} at {key[1]:g} s; "
                      "give a campaign with one run each", file=sys.stderr)
                return 2
            length[key] = float(r["solution_length"])
    rows = []
    for qid in sorted(best, key=lambda q: min(r["query_index"] for r in runs if r["query_id"] == q)):
        r0 = next(r for r in runs if r["query_id"] == qid)
        q = queries[(r0["query_set"], str(qid))]
        bound = cross_sector_length_bound(q.start, q.goal, q.from_sector, q.to_sector)
        x = length.get((args.planner, budgets[-1], qid))
        if args.end_motions and bound <= WITHIN_BEST * best[qid] and (x is None or x > WITHIN_BEST * best[qid]):
            bound = max(bound, end_motion_bound(robot, q, _END_LIMIT * best[qid], args.grid))
        rows.append((qid, q.from_sector, q.to_sector, bound, best[qid]))
    cols = "".join(f"  {p[:6]:>6s}@{b:g}" for p in (args.planner, args.reference) for b in budgets)
    print(f"{'query':>6s} pair  bound/best{cols}   (length / best found; '-': not solved)")
    within = defaultdict(int)
    for qid, i, j, bound, b in rows:
        cells = []
        for p in (args.planner, args.reference):
            for t in budgets:
                x = length.get((p, t, qid))
                cells.append(f"  {'-' if x is None else f'{x / b:.3f}':>{len(p[:6]) + len(f'{t:g}') + 1}s}")
                within[(p, t)] += x is not None and x <= WITHIN_BEST * b
        flag = "  row rules out 5 %" if bound > WITHIN_BEST * b else ""
        print(f"{qid!s:>6s} {i}->{j}  {'   > 1.100' if math.isinf(bound) else f'{bound / b:10.3f}'}{''.join(cells)}{flag}")
    ruled_out = sum(bound > WITHIN_BEST * b for _, _, _, bound, b in rows)
    n = len(rows)
    print(f"\n{n} queries; the Table 3 row rules out 'within {100 * (WITHIN_BEST - 1):.0f} % of the best found' on "
          f"{ruled_out}: at most {n - ruled_out} of {n} for a planner that keeps it")
    for p in (args.planner, args.reference):
        print(f"within {100 * (WITHIN_BEST - 1):.0f} %: {p} " + ", ".join(f"{within[(p, t)]}/{n} at {t:g} s" for t in budgets))
    t = budgets[-1]
    ref = [length[(args.reference, t, qid)] for qid, *_ in rows if (args.reference, t, qid) in length]
    bounds = [min(bound, b) for _, _, _, bound, b in rows]  # (an end-motion bound above the best is no lower bound of it)
    if ref:
        print(f"median cost: Table 3 bound {statistics.median(bounds):.3f}, {args.reference} at {t:g} s "
              f"{statistics.median(ref):.3f} ({len(ref)}/{n} solved)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
