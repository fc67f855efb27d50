"""Time to a first exact path: dimension-RRT vs RRTConnect at home, and dimension-RRT's per-sample overhead.

    PYTHONPATH=. .venv/bin/python experiments/first_path.py                       # both parts, ~2 min
    PYTHONPATH=. .venv/bin/python experiments/first_path.py --queries planning_necessary --max-queries 24
    PYTHONPATH=. .venv/bin/python experiments/first_path.py --skip-overhead --reps 5   # medians over 5 runs per query
    PYTHONPATH=. .venv/bin/python experiments/first_path.py --skip-home           # overhead only
    PYTHONPATH=. .venv/bin/python experiments/first_path.py --skip-overhead --split   # + time in Pinocchio vs the rest
    PYTHONPATH=. .venv/bin/python experiments/first_path.py --skip-overhead --reps 3 --ompl-seed 1 --save /tmp/fp/1.json
        # every run's time, for experiments/first_path_pooled.py (many of RRTConnect's seeds pooled)

Home: for every query of each named set (the wearer, ``make_simple_setup`` with its batched motion
validator), RRTConnect and dimension-RRT (``tpee_dimension_rrt``, seed = query index) run one after the
other in this process, each stopped by ``exactSolnPlannerTerminationCondition`` or --limit s; prints the
median and p95 time to the first exact path of each, the ratio of the medians and the median
number of configurations checked (dimension-RRT's is deterministic under its seed).

Overhead: dimension-RRT on a 6-D box with a wall and a hole (straight path blocked), a plain Python
validity checker that returns at once (no batched call), capped at --samples samples; prints the time
per sample outside the checker (planner overhead) and inside it, and the checker calls per sample.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import statistics
import time

import numpy as np
from _common import first_path_time, summary
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.files import atomic_write_text, check_output_path
from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.planning.tpee import tpee_dimension_rrt


def get_argument_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--queries", nargs="+", default=["planning_necessary", "paper_random"])
    p.add_argument("--max-queries", type=int, default=None, help="first N queries of each set")
    p.add_argument("--limit", type=float, default=1.0, help="time limit per first-path run, s")
    p.add_argument("--samples", type=int, default=2000, help="sample cap of the overhead run")
    p.add_argument("--reps", type=int, default=1,
                   help="runs per query and planner at home (RRTConnect is unseeded here: its times vary run to run)")
    p.add_argument("--skip-home", action="store_true")
    p.add_argument("--skip-overhead", action="store_true")
    p.add_argument("--ompl-seed", type=int, default=0,
                   help="OMPL's global seed, so RRTConnect's runs repeat (0: unseeded, as by default)")
    p.add_argument("--split", action="store_true",
                   help="time the collision calls (pinocchio.computeCollisions*) apart from the rest of each run")
    p.add_argument("--save", default=None, metavar="FILE",
                   help="write every home run (set, query, repetition, planner, seconds or null, checks) to this JSON file")
    p.add_argument("--force", action="store_true", help="replace the --save file if it exists")
    return p


def _p95(v: list[float]) -> float:
    return float(np.percentile(v, 95)) if v else math.nan


class _CollisionTimer:
    """Wraps Pinocchio's collision calls (the checker calls them through the module) to add up their time."""

    NAMES = ("computeCollisions", "computeCollisionsInParallel")

    def __init__(self) -> None:
        import pinocchio as pin

        self.spent = 0.0
        for name in self.NAMES:
            setattr(pin, name, self._timed(getattr(pin, name)))

    def _timed(self, f):
        def timed(*a):
            t = time.perf_counter()
            try:
                return f(*a)
            finally:
                self.spent += time.perf_counter() - t
        return timed


def home(args: argparse.Namespace) -> list[dict]:
    """Both planners on every query of each set; prints the summary per set and returns every run."""
    timer = _CollisionTimer() if args.split else None
    robot = WearerArm()
    runs: list[dict] = []
    for name in args.queries:
        qs = load_queries(name, robot)[: args.max_queries]
        rc, dr, rc_checks, dr_checks = [], [], [], []
        native: dict[str, list[float]] = {"D": [], "R": []}  # per run: s in collision calls, s outside
        outside: dict[str, list[float]] = {"D": [], "R": []}
        for k, q in enumerate(qs):
            ss = make_simple_setup(robot, q.start, q.goal)
            si = ss.getSpaceInformation()
            for rep in range(args.reps):  # alternating, so both planners see the same machine state
                for who, times, checks in (("R", rc, rc_checks), ("D", dr, dr_checks)):
                    planner = (og.RRTConnect(si) if who == "R"
                               else tpee_dimension_rrt(si, q.from_sector, q.to_sector, seed=k))
                    c0, n0 = robot.collision_checks, timer.spent if timer else 0.0
                    times.append(first_path_time(ss, planner, args.limit))
                    checks.append(robot.collision_checks - c0)
                    runs.append({"set": name, "query": k, "rep": rep, "planner": who, "seconds": times[-1],
                                 "checks": checks[-1]})
                    if timer and times[-1] is not None:
                        native[who].append(timer.spent - n0)
                        outside[who].append(times[-1] - native[who][-1])
        r = [x for x in rc if x is not None]
        d = [x for x in dr if x is not None]
        print(f"home {name:20s} queries {len(qs):4d}  solved D/R {len(d)}/{len(r)}  "
              f"median D {1e3 * statistics.median(d):6.1f} ms  R {1e3 * statistics.median(r):6.1f} ms  "
              f"ratio {statistics.median(d) / statistics.median(r):5.2f}  p95 D {1e3 * _p95(d):6.1f} ms  "
              f"R {1e3 * _p95(r):6.1f} ms  median checks D {statistics.median(dr_checks):.0f} "
              f"R {statistics.median(rc_checks):.0f}", flush=True)
        if timer:
            print(f"     {name:20s} median per run in collision calls "
                  f"D {1e3 * statistics.median(native['D']):5.2f} ms  "
                  f"R {1e3 * statistics.median(native['R']):5.2f} ms;  outside them D "
                  f"{1e3 * statistics.median(outside['D']):5.2f} ms  R {1e3 * statistics.median(outside['R']):5.2f} ms",
                  flush=True)
    return runs


def overhead(args: argparse.Namespace) -> None:
    n = 6
    space = ob.RealVectorStateSpace(n)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    spent = [0.0, 0]

    def valid(s: ob.State) -> bool:
        t = time.perf_counter()
        x0, x1 = s[0], s[1]
        ok = not (0.45 < x0 < 0.55) or (0.4 < x1 < 0.6)
        spent[0] += time.perf_counter() - t
        spent[1] += 1
        return ok

    ss.setStateValidityChecker(valid)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    a, b = si.allocState(), si.allocState()
    for i in range(n):
        a[i], b[i] = 0.1, 0.9
    a[1], b[1] = 0.05, 0.2
    ss.setStartAndGoalStates(a, b)
    si.setup()
    # the cost of one call of the checker from C++ (outside the timed body) measured on its own
    probe = si.allocState()
    m = 20000
    t = time.perf_counter()
    for _ in range(m):
        si.isValid(probe)
    call = (time.perf_counter() - t) / m
    rows = []
    for seed in range(3):
        ss.clear()
        p = DimensionRRT(si, groups=[[0, 1], [2, 3], [4, 5]], seed=seed, max_samples=args.samples)
        ss.setPlanner(p)
        spent[0], spent[1] = 0.0, 0
        t = time.perf_counter()
        ss.solve(60.0)
        total = time.perf_counter() - t
        st = p.last_run_stats()
        calls = spent[1]
        rows.append(((total - calls * call) / st["samples"], calls * call / st["samples"], calls / st["samples"]))
    med = [statistics.median(r[i] for r in rows) for i in range(3)]
    print(f"overhead 6-D box, no batched call, {args.samples} samples: {1e3 * med[0]:.3f} ms/sample outside the "
          f"checker, {1e3 * med[1]:.3f} ms/sample in checker calls ({med[2]:.1f} calls/sample, "
          f"{1e6 * call:.2f} us/call)", flush=True)


def main(argv: list[str] | None = None) -> None:
    ap = get_argument_parser()
    args = ap.parse_args(argv)
    if args.save and args.skip_home:
        ap.error("--save records the home runs; it cannot go with --skip-home")
    if args.save:
        try:
            check_output_path(args.save, force=args.force, what="--save file")
        except (FileExistsError, OSError, ValueError) as e:
            ap.error(str(e))
    ou.setLogLevel(ou.LOG_NONE)
    if args.ompl_seed:
        ou.RNG.setSeed(args.ompl_seed)
    if not args.skip_home:
        runs = home(args)
        if args.save:
            meta = {"ompl_seed": args.ompl_seed, "reps": args.reps, "limit": args.limit}
            atomic_write_text(args.save, json.dumps({"meta": meta, "runs": runs}), force=args.force)
            print(f"runs written to {args.save}", flush=True)
    if not args.skip_overhead:
        overhead(args)


if __name__ == "__main__":
    main()
    gc.collect()
