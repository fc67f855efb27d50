"""What Table 3 costs: per query of an anytime campaign, the shortest length any path along the prescribed
DOF1/DOF2 row can have, against the best path any planner found.

    PYTHONPATH=. .venv/bin/python experiments/table3_bound.py results/<stamp>_pn_anytime/benchmark.db
    PYTHONPATH=. .venv/bin/python experiments/table3_bound.py DB --planner DimensionRRT --reference RRTConnectSimplify

Dimension-RRT's TPEE case keeps DOF1/DOF2 on the paper's Table 3 row (unless ``release_after`` is set;
the library pipeline sets it, and its DMP and direct-motion paths leave the row anyway); AORRTC,
RRTConnect and RRT* move them freely.  ``cross_sector_length_bound`` (hypot of the row's length and the other joints' straight
distance, obstacles ignored) is a lower bound for every path along the row, so a query whose bound exceeds
1.05 x the best found cannot be within 5 % for any planner that keeps the row.  Prints, per query, the
bound / best found and each budget's length / best found of ``--planner`` and ``--reference``; then how many
queries the row rules out, and the median bound against the reference's median cost at its largest budget.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from collections import defaultdict
from pathlib import Path

from tpee_ompl.bench.report import WITHIN_BEST, best_found, load_runs
from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.sectors import cross_sector_length_bound
from tpee_ompl.model.wearer_arm import WearerArm


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("db", type=Path, help="a campaign's benchmark.db with an anytime comparison")
    ap.add_argument("--planner", default="DimensionRRT", help="a planner that keeps the Table 3 row (one run per "
                    "query and budget, as the anytime comparison has)")
    ap.add_argument("--reference", default="AORRTC", help="a planner that moves DOF1/DOF2 freely")
    args = ap.parse_args(argv)
    if not args.db.is_file():
        print(f"table3_bound.py: no such database: {args.db}", file=sys.stderr)
        return 2
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
        rows.append((qid, q.from_sector, q.to_sector, cross_sector_length_bound(q.start, q.goal, q.from_sector,
                                                                                 q.to_sector), best[qid]))
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
        print(f"{qid!s:>6s} {i}->{j}  {bound / b:10.3f}{''.join(cells)}{flag}")
    ruled_out = sum(bound > WITHIN_BEST * b for _, _, _, bound, b in rows)
    n = len(rows)
    print(f"\n{n} queries; the Table 3 row rules out 'within {100 * (WITHIN_BEST - 1):.0f} % of the best found' on "
          f"{ruled_out}: at most {n - ruled_out} of {n} for a planner that keeps it")
    for p in (args.planner, args.reference):
        print(f"within {100 * (WITHIN_BEST - 1):.0f} %: {p} " + ", ".join(f"{within[(p, t)]}/{n} at {t:g} s" for t in budgets))
    t = budgets[-1]
    ref = [length[(args.reference, t, qid)] for qid, *_ in rows if (args.reference, t, qid) in length]
    bounds = [bound for _, _, _, bound, _ in rows]
    if ref:
        print(f"median cost: Table 3 bound {statistics.median(bounds):.3f}, {args.reference} at {t:g} s "
              f"{statistics.median(ref):.3f} ({len(ref)}/{n} solved)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
