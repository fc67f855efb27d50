"""What the shortcuts between fake-time waypoints buy: dimension-RRT with ``shortcuts`` on and off, same seeds.

    .venv/bin/python experiments/make_queries.py --seed 777 --n-per-pair 3 --out /tmp/heldout   # once
    PYTHONPATH=. .venv/bin/python experiments/waypoint_shortcuts.py                             # ~3 min

Three parts, each with the same seeds for both settings (so every difference is the shortcuts'):

* the wearer (``tpee_dimension_rrt``, Table 3's row prescribed) capped at ``--samples`` on the
  held-out queries (not the benchmark sets; ``--queries`` takes another set);
* the library pipeline (``LibraryDimensionRRT``, rows released after ``RELEASE_AFTER``) at each of
  ``--budgets`` seconds on the same queries;
* the plain-OMPL planar arms of ``experiments/foreign_problems.py`` (no prescribed group, so the
  shortcuts are off by default there) capped at ``--arm-samples``, with them forced on.

Prints per part and setting: mean and median final length, how many runs the shortcuts made more
than 1 % shorter / longer than the same seed without them, total time and mean collision checks.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from _common import missing_query_files, summary
from ompl import util as ou

from tpee_ompl import PathLibrary, WearerArm, make_simple_setup
from tpee_ompl.bench.campaign import query_rows, stratified_subset
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.planning.dimension_rrt import RELEASE_AFTER, DimensionRRT, DimensionRRTOptions
from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.resources import default_library_path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import foreign_problems  # noqa: E402 (the plain-OMPL problems, beside this script)


def _run(ss, planner, budget: float) -> tuple[float, float, int]:
    ss.clear()
    ss.setPlanner(planner)
    t = time.perf_counter()
    ss.solve(budget)
    dt = time.perf_counter() - t
    length = ss.getSolutionPath().length() if ss.haveExactSolutionPath() else float("nan")
    return length, dt, int(planner.last_run_stats()["collision_checks"])


def _report(label: str, res: dict[bool, list[tuple[float, float, int]]]) -> None:
    off = np.array([r[0] for r in res[False]])
    print(label, flush=True)
    for on in (False, True):
        a = np.array(res[on])
        ratio = a[:, 0] / off
        print(f"  shortcuts {'on ' if on else 'off'}: mean length {np.nanmean(a[:, 0]):.4f}  median {np.nanmedian(a[:, 0]):.4f}"
              f"  >1 % shorter / longer than off {int(np.sum(ratio < 0.99))} / {int(np.sum(ratio > 1.01))} of {len(a)}"
              f"  time {a[:, 1].sum():.2f} s  checks {a[:, 2].mean():.0f} (mean)  solved {int(np.sum(~np.isnan(a[:, 0])))}",
              flush=True)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", default="/tmp/heldout/planning_necessary.json", help="query-set name or JSON file")
    ap.add_argument("--max-queries", type=int, default=36)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--samples", type=int, default=500)
    ap.add_argument("--budgets", type=float, nargs="*", default=[0.01, 0.1])
    ap.add_argument("--arm-samples", type=int, default=2000)
    ap.add_argument("--arm-seeds", type=int, default=10)
    args = ap.parse_args(argv)
    if (missing := missing_query_files(args.queries)) is not None:
        ap.error(missing)
    ou.setLogLevel(ou.LOG_NONE)
    robot = WearerArm()
    lib = PathLibrary.load(default_library_path(), robot) if args.budgets else None
    _, rows = query_rows(args.queries, robot)
    rows = stratified_subset(rows, args.max_queries)
    parts = [("samples", args.samples)] + [("time", b) for b in args.budgets]
    res = {p: {False: [], True: []} for p in parts}
    for k, q in enumerate(rows):
        start, goal, i, j = np.array(q["start"]), np.array(q["goal"]), q["from_sector"], q["to_sector"]
        ss = make_simple_setup(robot, start, goal)
        si = ss.getSpaceInformation()
        for s in range(args.seeds):
            for part in parts:
                for on in (False, True):
                    if part[0] == "samples":
                        opts = DimensionRRTOptions(seed=1000 * s + k, max_samples=part[1], shortcuts=on)
                        res[part][on].append(_run(ss, tpee_dimension_rrt(si, i, j, opts), 60.0))
                    else:
                        opts = DimensionRRTOptions(seed=1000 * s + k, release_after=RELEASE_AFTER, shortcuts=on)
                        res[part][on].append(_run(ss, LibraryDimensionRRT(si, lib, i, j, opts), part[1]))
    n = f"{len(rows)} queries x {args.seeds} seeds"
    _report(f"wearer, dimension-RRT capped at {args.samples} samples ({n})", res[parts[0]])
    for part in parts[1:]:
        _report(f"wearer, library pipeline at {part[1]:g} s ({n})", res[part])
    for name, build, groupings in foreign_problems.problems():
        if not name.startswith("arm") or "so2" in name:
            continue
        ss = build()
        si = ss.getSpaceInformation()
        for groups in groupings:
            arm = {False: [], True: []}
            for seed in range(args.arm_seeds):
                for on in (False, True):
                    p = DimensionRRT(si, groups=groups, seed=seed, max_samples=args.arm_samples, shortcuts=on)
                    arm[on].append(_run(ss, p, 60.0))
            _report(f"{name} {groups}, capped at {args.arm_samples} samples ({args.arm_seeds} seeds)", arm)


if __name__ == "__main__":
    main()
