"""Dimension-RRT's path lengths under sample caps on benchmark problems: deterministic, so two versions compare exactly.

    PYTHONPATH=. .venv/bin/python experiments/capped_lengths.py --save /tmp/new.json
    git worktree add /tmp/old ee04ede
    PYTHONPATH=/tmp/old .venv/bin/python experiments/capped_lengths.py --save /tmp/old.json
    PYTHONPATH=. .venv/bin/python experiments/capped_lengths.py --compare /tmp/old.json /tmp/new.json

Each query of each problem (the first --max-queries) is solved by ``DimensionRRT`` with the problem's grouping,
seed = query index + 1 and each cap of --samples (the run stops at the cap, so a version's lengths repeat bit for
bit); the campaign's headline validator (batched on robot problems, OMPL's discrete one on the generic ones).
``--compare`` prints per problem and cap the mean length of each file and how many queries got shorter or longer
(by more than 0.1 %).  The script imports ``tpee_ompl`` from ``PYTHONPATH``, so an older commit's package can be
measured with it.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from _common import summary
import numpy as np


def measure(problems: list[str], caps: list[int], max_queries: int) -> dict[str, list[list[float]]]:
    """{problem: [[cap, query index, length or NaN], ...]}."""
    from ompl import util as ou

    from tpee_ompl.bench.problems import get_problem
    from tpee_ompl.planning.dimension_rrt import DimensionRRT

    ou.setLogLevel(ou.LOG_NONE)
    out: dict[str, list[list[float]]] = {}
    for name in problems:
        problem = get_problem(name)
        _, rows = problem.queries()
        checker = problem.checkers[0]  # the headline validator
        found = []
        for qi, q in enumerate(rows[:max_queries]):
            for cap in caps:
                ss, _ = problem.make_setup(q, checker)
                si = ss.getSpaceInformation()
                ss.setPlanner(DimensionRRT(si, groups=problem.groups, seed=qi + 1, max_samples=cap))
                ss.solve(600.0)
                found.append([cap, qi, ss.getSolutionPath().length() if ss.haveExactSolutionPath() else math.nan])
            print(f"{name} query {qi}: done", file=sys.stderr, flush=True)
        out[name] = found
    return out


def compare(old: dict, new: dict) -> None:
    """Per problem and cap: mean length old / new and the queries shorter / longer / equal within 0.1 %."""
    for name in old:
        if name not in new:
            continue
        for cap in sorted({int(r[0]) for r in old[name]}):
            a = {int(r[1]): r[2] for r in old[name] if int(r[0]) == cap}
            b = {int(r[1]): r[2] for r in new[name] if int(r[0]) == cap}
            keys = sorted(k for k in a if k in b and math.isfinite(a[k]) and math.isfinite(b[k]))
            if not keys:
                print(f"{name:14s} cap {cap:5d}  no query solved in both files")
                continue
            r = np.array([b[k] / a[k] for k in keys])
            mean_a, mean_b = np.mean([a[k] for k in keys]), np.mean([b[k] for k in keys])
            print(f"{name:14s} cap {cap:5d}  queries {len(keys):3d}  mean length {mean_a:.4f} -> {mean_b:.4f}  "
                  f"per query new/old mean {r.mean():.4f}  shorter {(r < 0.999).sum()}  longer {(r > 1.001).sum()}  "
                  f"same {(abs(r - 1) <= 0.001).sum()}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--problems", nargs="+", default=["arm5-so2", "kinova-posts"])
    ap.add_argument("--samples", nargs="+", type=int, default=[500, 2500])
    ap.add_argument("--max-queries", type=int, default=10)
    ap.add_argument("--save", metavar="FILE", help="write the lengths to this JSON file (not replaced if it exists)")
    ap.add_argument("--compare", nargs=2, metavar=("OLD", "NEW"), help="compare two saved files instead of measuring")
    args = ap.parse_args(argv)
    if args.compare:
        try:
            old, new = (json.loads(Path(p).read_text()) for p in args.compare)
        except (OSError, ValueError) as exc:
            ap.error(f"--compare: {exc}")
        compare(old, new)
        return 0
    if args.save and Path(args.save).exists():
        ap.error(f"--save file {args.save} exists")
    if min(args.samples) < 1 or args.max_queries < 1:
        ap.error("--samples and --max-queries must be positive")
    found = measure(args.problems, args.samples, args.max_queries)
    text = json.dumps(found)
    if args.save:
        Path(args.save).write_text(text)
        print(f"lengths written to {args.save}")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
