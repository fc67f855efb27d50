"""Foreign suite: dimension-RRT vs RRTConnect (+ OMPL's PathSimplifier) on generic problems set up
with plain OMPL + numpy (built by ``tpee_ompl/bench/generic_problems.py``, which imports no other project
code), every listed grouping, same seeds.

    PYTHONPATH=. .venv/bin/python experiments/foreign_problems.py            # default run, ~3-5 min
    PYTHONPATH=. .venv/bin/python experiments/foreign_problems.py --seeds 5 --time 2
    PYTHONPATH=. .venv/bin/python experiments/foreign_problems.py --layered   # + connect=False, same run

Per (problem, grouping): solved (dimension-RRT within --limit s, RRTConnect within 1 s), median time to
the first exact path (dimension-RRT stopped by ``exactSolnPlannerTerminationCondition``) and its ratio
to RRTConnect's, dimension-RRT's median samples to it (``n D``) and time per sample (``us/n``, all its
first-path runs together), and the median path length after --time s for dimension-RRT, RRTConnect alone, and
RRTConnect whose path is simplified (``og.PathSimplifier.simplify``) for the rest of the same time.
``--layered`` adds dimension-RRT with ``connect=False`` (its feasibility phase before the connect trees).
Validity checkers are plain Python functions (no batched call), motion validation is OMPL's default.
OMPL's global seed is set (``--ompl-seed``), so RRTConnect's runs, and a whole run, repeat; its median
over a few runs still depends on that seed, so ratios are figures of one run.
"""

from __future__ import annotations

import argparse
import gc
import math
import statistics
import time
from collections.abc import Callable

from _common import first_path_time, summary
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.bench.generic_problems import ARM_OBS, ARM_OBS2, box_point_setup, planar_arm_setup
from tpee_ompl.planning.dimension_rrt import DimensionRRT  # the planner under test only


# ----------------------------------------------------------------- problems
def problems() -> list[tuple[str, Callable[[], og.SimpleSetup], list[list[list[int]]]]]:
    """(name, builder, list of groupings)."""
    def arm(n, obs, start0=0.3, goal0=2.8, continuous=False):
        start, goal = (start0,) + (0.0,) * (n - 1), (goal0,) + (0.0,) * (n - 1)
        return lambda: planar_arm_setup(n, start, goal, obs, continuous, resolution=0.01)[0]

    def box(n, blocked, start, goal):
        return lambda: box_point_setup(n, blocked, start, goal, resolution=0.005)[0]

    def contiguous(n, sizes):
        out, i = [], 0
        for k in sizes:
            out.append(list(range(i, i + k)))
            i += k
        return out

    def groupings(n):
        g = [contiguous(n, [1] * n), contiguous(n, [2] * (n // 2) + [1] * (n % 2)),
             contiguous(n, [n // 2, n - n // 2]), [list(range(n))]]
        g.append([list(range(0, n, 2)), list(range(1, n, 2))])  # interleaved, not contiguous
        return [x for k, x in enumerate(g) if x not in g[:k]]

    return [
        ("arm4", arm(4, ARM_OBS), groupings(4)),
        ("arm6", arm(6, ARM_OBS), groupings(6)),
        ("arm7", arm(7, ARM_OBS2), groupings(7)),
        ("arm8", arm(8, ARM_OBS2), groupings(8)),
        ("arm5_so2", arm(5, ARM_OBS, 2.8, -2.6, continuous=True), groupings(5)),
        ("point4_hole", box(4, "wall_with_hole", (0.1, 0.2, 0.8, 0.2), (0.9, 0.8, 0.2, 0.8)), groupings(4)),
        ("narrow3", box(3, "narrow_passage", (0.1, 0.1, 0.5), (0.9, 0.9, 0.5)), groupings(3)),
    ]


# ----------------------------------------------------------------- runs
def _length_at(ss, planner, seconds, simplify=False):
    ss.clear()
    ss.setPlanner(planner)
    t = time.perf_counter()
    ss.solve(seconds)
    if not ss.haveExactSolutionPath():
        return None
    path = og.PathGeometric(ss.getSolutionPath())
    if simplify:
        rest = max(0.0, seconds - (time.perf_counter() - t))
        og.PathSimplifier(ss.getSpaceInformation()).simplify(path, ob.timedPlannerTerminationCondition(rest))
    return path.length() if path.check() else None


def _med(v):
    v = [x for x in v if x is not None]
    return statistics.median(v) if v else math.nan


def main() -> None:
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--time", type=float, default=1.0, help="seconds for the equal-time length columns")
    p.add_argument("--limit", type=float, default=10.0, help="dimension-RRT's time limit for a first path")
    p.add_argument("--only", default=None, help="run only problems whose name contains this")
    p.add_argument("--layered", action="store_true", help="also run dimension-RRT with connect=False")
    p.add_argument("--ompl-seed", type=int, default=1,
                   help="OMPL's global seed (RRTConnect's samples), so a run repeats; 0 leaves it unseeded")
    args = p.parse_args()
    ou.setLogLevel(ou.LOG_NONE)
    if args.ompl_seed:
        ou.RNG.setSeed(args.ompl_seed)
    print(f"{'problem':12s} {'groups':34s} {'solved D/R':>10s} {'t1 D ms':>8s} {'t1 R ms':>8s} {'ratio':>6s}"
          f" {'n D':>7s} {'us/n':>6s} {'len D':>7s} {'len R':>7s} {'len R+S':>7s}"
          + ("  layered: ratio, len" if args.layered else ""))
    for name, build, groupings in problems():
        if args.only and args.only not in name:
            continue
        ss = build()
        si = ss.getSpaceInformation()
        rc_first, rc_len, rcs_len = [], [], []
        for seed in range(args.seeds):
            rc_first.append(first_path_time(ss, og.RRTConnect(si), 1.0))
            rc_len.append(_length_at(ss, og.RRTConnect(si), args.time))
            rcs_len.append(_length_at(ss, og.RRTConnect(si), args.time, simplify=True))
        for groups in groupings:
            d_first, d_len, l_first, l_len, d_samples = [], [], [], [], []
            for seed in range(args.seeds):
                planner = DimensionRRT(si, groups=groups, seed=seed)
                d_first.append(first_path_time(ss, planner, args.limit))
                d_samples.append(planner.last_run_stats()["samples"])
                d_len.append(_length_at(ss, DimensionRRT(si, groups=groups, seed=seed), args.time))
                if args.layered:
                    l_first.append(first_path_time(ss, DimensionRRT(si, groups=groups, seed=seed, connect=False),
                                                   args.limit))
                    l_len.append(_length_at(ss, DimensionRRT(si, groups=groups, seed=seed, connect=False), args.time))
            solved_d = sum(x is not None for x in d_first)
            solved_r = sum(x is not None for x in rc_first)
            td, tr = _med(d_first), _med(rc_first)
            extra = f"  {_med(l_first) / tr:6.2f} {_med(l_len):7.3f}" if args.layered else ""
            us = 1e6 * sum(x for x in d_first if x is not None) / max(1, sum(
                n for x, n in zip(d_first, d_samples) if x is not None))
            print(f"{name:12s} {groups!s:34s} {solved_d:>4d}/{solved_r:<4d}  {1e3 * td:8.1f} {1e3 * tr:8.1f}"
                  f" {td / tr:6.2f} {_med(d_samples):7.0f} {us:6.1f} {_med(d_len):7.3f} {_med(rc_len):7.3f}"
                  f" {_med(rcs_len):7.3f}{extra}", flush=True)
        del ss
        gc.collect()


if __name__ == "__main__":
    main()
    gc.collect()
