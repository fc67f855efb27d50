"""Where the library pipeline's samples go once its path has converged: what limits its length at 0.1 s.

    PYTHONPATH=. .venv/bin/python experiments/converged_search.py                  # 24 queries at 0.1 s, ~5 s
    PYTHONPATH=. .venv/bin/python experiments/converged_search.py --budget 1 --queries paper_random

Runs ``LibraryDimensionRRT`` (seed = query index) on the stratified queries of a set, each solved once to
warm up and once measured, with counting wrappers around the search's steps (the paths are the
planner's own: the wrappers only count).  Prints per query and in total: samples drawn; samples that
reach the paper's rule, i.e. would shorten the path at some step (the others are passed over in one
vectorised test); how many of those were accepted; shortcut sweeps; the final path's intermediate
waypoints that bend (their two segments longer than the chord between their neighbours by more than
1e-4 of the path's length; the others lie on that chord or within 1e-4 of it); and the time in
Pinocchio's batched collision calls (``computeCollisionsInParallel``, which the search checks through)
against the rest of the run.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import pinocchio as pin
from _common import summary, wearer_library_queries
from ompl import util as ou

from tpee_ompl import make_simple_setup
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.model import robot_checker
from tpee_ompl.planning import dimension_search, waypoint_shortcuts
from tpee_ompl.planning.paths import path_to_array

_COUNTS = {"rule": 0, "accepted": 0, "sweeps": 0, "pin_calls": 0, "pin_time": 0.0}


def _instrument() -> None:
    """Counting wrappers around the paper's rule, the sweeps and Pinocchio's batched collision call."""
    improve, sweep, collide = dimension_search.Search._improve, waypoint_shortcuts.shortcut_waypoints, pin.computeCollisionsInParallel

    def counted_improve(self, gi, c):
        n = improve(self, gi, c)
        _COUNTS["rule"] += 1
        _COUNTS["accepted"] += bool(n)
        return n

    def counted_sweep(*args):
        _COUNTS["sweeps"] += 1
        return sweep(*args)

    def timed_collide(*args):
        t = time.perf_counter()
        out = collide(*args)
        _COUNTS["pin_time"] += time.perf_counter() - t
        _COUNTS["pin_calls"] += 1
        return out

    dimension_search.Search._improve = counted_improve
    waypoint_shortcuts.shortcut_waypoints = counted_sweep  # each sweep, also those sweep_until_settled repeats
    robot_checker.pin.computeCollisionsInParallel = timed_collide


def _bends(W: np.ndarray) -> int:
    L = np.linalg.norm(np.diff(W, axis=0), axis=1)
    excess = L[:-1] + L[1:] - np.linalg.norm(W[2:] - W[:-2], axis=1)
    return int((excess > 1e-4 * L.sum()).sum())


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--queries", default="planning_necessary")
    ap.add_argument("--max-queries", type=int, default=24)
    ap.add_argument("--budget", type=float, default=0.1, help="time per run, s")
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    robot, lib, rows = wearer_library_queries(args.queries, args.max_queries)
    _instrument()
    print("query  length   samples  to the rule  accepted  sweeps  bends/interior  Pinocchio / rest (ms)")
    totals = {"samples": 0, "rule": 0, "accepted": 0, "sweeps": 0, "pin": 0.0, "rest": 0.0}
    bends = []
    for k, q in enumerate(rows):
        ss = make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"]))
        for _ in range(2):  # the first solve warms the process up
            _COUNTS.update(rule=0, accepted=0, sweeps=0, pin_calls=0, pin_time=0.0)
            planner = LibraryDimensionRRT(ss.getSpaceInformation(), lib, q["from_sector"], q["to_sector"], seed=k)
            ss.clear()
            ss.setPlanner(planner)
            t0 = time.perf_counter()
            ss.solve(args.budget)
            wall = time.perf_counter() - t0
        stats = planner.last_run_stats()
        W = path_to_array(ss.getSolutionPath(), robot.nq)
        bends.append(_bends(W))
        rest = wall - _COUNTS["pin_time"]
        print(f"{k:5d}  {stats['best_cost']:.4f}  {stats['samples']:7d}  {_COUNTS['rule']:11d}  {_COUNTS['accepted']:8d}  "
              f"{_COUNTS['sweeps']:6d}  {bends[-1]:6d}/{len(W) - 2:<7d}  {1e3 * _COUNTS['pin_time']:5.1f} / {1e3 * rest:5.1f}")
        totals["samples"] += stats["samples"]
        totals["rule"] += _COUNTS["rule"]
        totals["accepted"] += _COUNTS["accepted"]
        totals["sweeps"] += _COUNTS["sweeps"]
        totals["pin"] += _COUNTS["pin_time"]
        totals["rest"] += rest
    n = totals["samples"]
    print(f"\nall {len(rows)} queries at {args.budget} s: {n} samples; {totals['rule']} reach the paper's rule "
          f"({100 * totals['rule'] / n:.1f} %), {totals['accepted']} accepted ({100 * totals['accepted'] / max(1, totals['rule']):.1f} % "
          f"of those); {totals['sweeps']} sweeps; bending waypoints per path median {statistics.median(bends)}; "
          f"time in Pinocchio's batched collision calls {100 * totals['pin'] / (totals['pin'] + totals['rest']):.0f} %")


if __name__ == "__main__":
    main()
