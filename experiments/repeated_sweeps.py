"""Shortcut sweeps until settled against one sweep per improvement: the paper's dimension-RRT at sample caps and budgets.

    PYTHONPATH=. .venv/bin/python experiments/repeated_sweeps.py                    # caps 500 and 2500, ~25 s
    PYTHONPATH=. .venv/bin/python experiments/repeated_sweeps.py --queries /tmp/fresh/planning_necessary.json
    PYTHONPATH=. .venv/bin/python experiments/repeated_sweeps.py --budgets 0.01 0.1 --planner library

After each sample that shortened the path, the rows' search (Table 3's rows kept, as Table 4's planner)
sweeps its waypoints towards their shortest points again while a sweep still gains
``SWEEP_MIN_GAIN`` of the length, at most ``MAX_SWEEPS`` times (``waypoint_shortcuts.sweep_until_settled``);
before 2026-11-26 it swept once.  This runs both settings (``MAX_SWEEPS`` set in-process; 1 is the
earlier code) on the stratified queries of a set x ``--seeds`` seeds, alternating which goes first, and
prints per cap (or budget) the mean length of each, the mean of the per-run ratios, the runs more than
0.1 % shorter / longer, the median run time and the mean of the per-run time ratios (Table 4's
time column is a mean of per-query ratios, so this is how the setting moves it).  At a sample cap both draw the same samples; a budget
gives each what it reaches in that time.  ``--planner library``: ``LibraryDimensionRRT`` (its released
search sweeps once either way, so only its rows phase changes).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _common import summary, wearer_library_queries
from ompl import util as ou

from tpee_ompl import make_simple_setup
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.planning import waypoint_shortcuts
from tpee_ompl.planning.tpee import tpee_dimension_rrt


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", default="planning_necessary", help="query-set name or JSON file")
    ap.add_argument("--max-queries", type=int, default=24)
    ap.add_argument("--seeds", type=int, default=4, help="runs per query and setting, each with its own seed")
    ap.add_argument("--samples", type=int, nargs="+", default=[500, 2500], help="sample caps (ignored with --budgets)")
    ap.add_argument("--budgets", type=float, nargs="+", default=None, help="time budgets in s instead of caps")
    ap.add_argument("--planner", choices=("paper", "library"), default="paper")
    args = ap.parse_args(argv)
    if args.seeds < 1:
        ap.error(f"--seeds must be at least 1, got {args.seeds}")
    ou.setLogLevel(ou.LOG_NONE)
    robot, lib, rows = wearer_library_queries(args.queries, args.max_queries)
    limits = [("s", b) for b in args.budgets] if args.budgets else [("samples", n) for n in args.samples]
    settings = {"settled": waypoint_shortcuts.MAX_SWEEPS, "once": 1}
    length = {(lim, s): [] for lim in limits for s in settings}
    seconds = {(lim, s): [] for lim in limits for s in settings}
    try:
        for k, q in enumerate(rows):
            ss = make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"]))
            si = ss.getSpaceInformation()
            for seed in range(args.seeds):
                for lim in limits:
                    order = list(settings) if (k + seed) % 2 == 0 else list(settings)[::-1]
                    for name in order:
                        waypoint_shortcuts.MAX_SWEEPS = settings[name]
                        cap = {"max_samples": lim[1]} if lim[0] == "samples" else {}
                        s = 1000 * seed + k
                        planner = (tpee_dimension_rrt(si, q["from_sector"], q["to_sector"], seed=s, **cap)
                                   if args.planner == "paper"
                                   else LibraryDimensionRRT(si, lib, q["from_sector"], q["to_sector"], seed=s, **cap))
                        ss.clear()
                        ss.setPlanner(planner)
                        t = time.perf_counter()
                        ss.solve(lim[1] if lim[0] == "s" else 60.0)
                        seconds[(lim, name)].append(time.perf_counter() - t)
                        length[(lim, name)].append(ss.getSolutionPath().length() if ss.haveExactSolutionPath() else np.nan)
    finally:
        waypoint_shortcuts.MAX_SWEEPS = settings["settled"]
    print(f"{args.planner} on {args.queries}, {len(rows)} queries x {args.seeds} seeds "
          f"(settled: at most {settings['settled']} sweeps while each gains {waypoint_shortcuts.SWEEP_MIN_GAIN:g})")
    for lim in limits:
        a, b = np.array(length[(lim, "settled")]), np.array(length[(lim, "once")])
        r = a / b
        print(f"{lim[1]:g} {lim[0]}: mean length once {np.nanmean(b):.4f} settled {np.nanmean(a):.4f}, mean ratio "
              f"{np.nanmean(r):.4f}, runs shorter / longer by > 0.1 %: {int(np.sum(r < 0.999))} / {int(np.sum(r > 1.001))} "
              f"of {len(r)}, solved {int(np.isfinite(b).sum())} / {int(np.isfinite(a).sum())}, median time once "
              f"{1e3 * np.median(seconds[(lim, 'once')]):.1f} ms settled {1e3 * np.median(seconds[(lim, 'settled')]):.1f} ms, "
              f"mean time ratio settled / once {np.mean(np.array(seconds[(lim, 'settled')]) / seconds[(lim, 'once')]):.3f}, "
              f"longest run once {1e3 * max(seconds[(lim, 'once')]):.1f} ms settled {1e3 * max(seconds[(lim, 'settled')]):.1f} ms",
              flush=True)


if __name__ == "__main__":
    main()
