"""Figures for the closing note: DimensionRRT time and path length on TPEE queries, batched vs not,
the time split (collision checking vs Python overhead) and RRT* at equal samples.

    .venv/bin/python experiments/dimension_rrt_profile.py --reps 2 --samples 500 2500 --rrtstar
    .venv/bin/python experiments/dimension_rrt_profile.py --queries planning_necessary --reps 2 --samples 500 2500

Prints one table row per (samples, batch) and writes ``--out`` (JSON rows) when given.
"""

from __future__ import annotations

import argparse
import gc
import json
import statistics
import time

from _common import summary
import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.files import atomic_write_text, check_output_path
from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.examples.tpee_queries import cross_sector_query
from tpee_ompl.model.sectors import SECTOR_PAIRS
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.model.wearer_arm import WearerArm


def get_argument_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--reps", type=int, default=2, help="queries per pair type (12 pair types)")
    p.add_argument("--samples", type=int, nargs="+", default=[500, 2500])
    p.add_argument("--margin", type=float, default=0.02, help="security margin (m)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--rrtstar", action="store_true", help="also time og.RRTstar at equal iterations")
    p.add_argument("--out", default=None, help="JSON file for the rows (not replaced without --force)")
    p.add_argument("--force", action="store_true", help="replace the --out file if it exists")
    p.add_argument("--queries", default=None,
                   help="stored query set (e.g. planning_necessary): its first --reps queries of each pair type")
    return p


class _TimedRobot:
    """Wraps ``are_valid`` to measure time spent in collision checking."""

    def __init__(self, robot: WearerArm) -> None:
        self.robot = robot
        self.seconds = 0.0
        self._orig = robot.are_valid

    def __enter__(self) -> _TimedRobot:
        def timed(Q):
            t = time.perf_counter()
            try:
                return self._orig(Q)
            finally:
                self.seconds += time.perf_counter() - t

        self.robot.are_valid = timed  # type: ignore[method-assign]
        return self

    def __exit__(self, *exc) -> None:
        del self.robot.are_valid


def run(args: argparse.Namespace) -> list[dict]:
    ou.setLogLevel(ou.LOG_WARN)
    robot = WearerArm(security_margin=args.margin)
    rng = np.random.default_rng(args.seed)
    if args.queries:
        from tpee_ompl.model.queries import load_queries

        stored = load_queries(args.queries, robot if args.margin == 0.02 else None)
        queries = [(q.from_sector, q.to_sector, np.asarray(q.start), np.asarray(q.goal)) for i, j in SECTOR_PAIRS
                   for q in [q for q in stored if (q.from_sector, q.to_sector) == (i, j)][: args.reps]]
    else:
        queries = [(i, j, *cross_sector_query(robot, i, j, rng)) for _ in range(args.reps) for i, j in SECTOR_PAIRS]
    rows = []
    for n in args.samples:
        for batch in (True, False):
            times, lengths, check_s, checks, solved = [], [], [], [], 0
            for k, (i, j, q0, q1) in enumerate(queries):
                ss = make_simple_setup(robot, q0, q1)
                planner = tpee_dimension_rrt(ss.getSpaceInformation(), i, j, max_samples=n, seed=k, batch=batch)
                ss.setPlanner(planner)
                with _TimedRobot(robot) as tr:
                    t0 = time.perf_counter()
                    status = ss.solve(60.0)
                    dt = time.perf_counter() - t0
                st = planner.last_run_stats()
                solved += status == ob.PlannerStatus.EXACT_SOLUTION
                times.append(dt)
                lengths.append(st["best_cost"])
                check_s.append(tr.seconds)
                checks.append(st["collision_checks"])
            rows.append(
                {
                    "planner": "DimensionRRT",
                    "samples": n,
                    "batch": batch,
                    "queries": len(queries),
                    "solved": solved,
                    "median_time_s": statistics.median(times),
                    "median_length": statistics.median(lengths),
                    "median_checks": statistics.median(checks),
                    "check_time_share": sum(check_s) / sum(times),
                    "python_us_per_sample": 1e6 * (sum(times) - sum(check_s)) / (n * len(queries)),
                }
            )
            print(rows[-1], flush=True)
        if args.rrtstar:
            times, lengths, solved = [], [], 0
            for i, j, q0, q1 in queries[:: max(1, len(queries) // 6)]:
                ss = make_simple_setup(robot, q0, q1)
                r = og.RRTstar(ss.getSpaceInformation())
                ss.setPlanner(r)
                ss.setup()
                t0 = time.perf_counter()
                ob.Planner.solve(r, lambda: r.numIterations() >= n, 0.0)
                times.append(time.perf_counter() - t0)
                ok = ss.haveExactSolutionPath()
                solved += ok
                lengths.append(ss.getSolutionPath().length() if ok else float("inf"))
            rows.append(
                {"planner": "RRTstar", "samples": n, "queries": len(times), "solved": solved,
                 "median_time_s": statistics.median(times), "median_length": statistics.median(lengths)}
            )
            print(rows[-1], flush=True)
    return rows


def main(argv: list[str] | None = None) -> None:
    ap = get_argument_parser()
    args = ap.parse_args(argv)
    if args.out:
        try:
            check_output_path(args.out, force=args.force, what="--out file")
        except (OSError, ValueError) as exc:
            ap.error(str(exc))
    rows = run(args)
    if args.out:
        atomic_write_text(args.out, json.dumps(rows, indent=1), force=args.force)


if __name__ == "__main__":
    main()
    gc.collect()
