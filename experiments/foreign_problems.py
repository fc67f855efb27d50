"""Foreign suite: dimension-RRT vs RRTConnect (+ OMPL's PathSimplifier) on generic problems set up
with plain OMPL + numpy (no project code in their set-up), every listed grouping, same seeds.

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

import numpy as np
from _common import first_path_time
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.planning.dimension_rrt import DimensionRRT  # the planner under test only


# ----------------------------------------------------------------- problems (plain OMPL + numpy)
def _arm_points(q: np.ndarray, link: float) -> np.ndarray:
    ang = np.cumsum(q)
    d = link * np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    joints = np.vstack([np.zeros((1, 2)), np.cumsum(d, axis=0)])
    s = np.linspace(0.0, 1.0, 4)
    return (joints[:-1, None, :] + s[None, :, None] * d[:, None, :]).reshape(-1, 2)


def _setup(space, valid, start, goal, read, write, resolution=0.01):
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    ss.setStateValidityChecker(valid)
    si.setStateValidityCheckingResolution(resolution)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    s0, s1 = si.allocState(), si.allocState()
    write(s0, start)
    write(s1, goal)
    ss.setStartAndGoalStates(s0, s1, 1e-9)
    ss._keep = (valid, s0, s1)
    si.setup()
    return ss


def planar_arm(n: int, obstacles, start, goal, continuous: bool = False):
    if continuous:
        space = ob.CompoundStateSpace()
        for _ in range(n):
            space.addSubspace(ob.SO2StateSpace(), 1.0)
    else:
        space = ob.RealVectorStateSpace(n)
        space.setBounds(-math.pi, math.pi)
    obs = np.asarray(obstacles, dtype=float)
    link = 1.5 / n

    def read(s):
        return np.array([s[i].value for i in range(n)] if continuous else [s[i] for i in range(n)])

    def write(s, q):
        for i in range(n):
            if continuous:
                s[i].value = float(q[i])
            else:
                s[i] = float(q[i])

    def valid(s):
        p = _arm_points(read(s), link)
        diff = p[:, None, :] - obs[None, :, :2]
        return bool(np.all(np.einsum("poc,poc->po", diff, diff) > obs[:, 2] ** 2))

    return _setup(space, valid, start, goal, read, write)


def box_point(n: int, blocked, start, goal):
    space = ob.RealVectorStateSpace(n)
    space.setBounds(0.0, 1.0)

    def write(s, q):
        for i in range(n):
            s[i] = float(q[i])

    def valid(s):
        return not blocked([s[i] for i in range(n)])

    return _setup(space, valid, start, goal, None, write, resolution=0.005)


def wall_with_hole(x):  # 4-D: wall 0.45 < x0 < 0.55 with a hole |x_i - 0.5| < 0.12 for i = 1..3
    return 0.45 < x[0] < 0.55 and not all(abs(v - 0.5) < 0.12 for v in x[1:])


def narrow_passage(x):  # 3-D: wall 0.4 < x0 < 0.6 with a slot 0.48 < x1 < 0.52 (any x2)
    return 0.4 < x[0] < 0.6 and not 0.48 < x[1] < 0.52


ARM_OBS = ((0.0, 1.0, 0.25), (-0.9, 0.8, 0.2), (0.9, 0.75, 0.2))
ARM_OBS2 = ((0.0, 1.0, 0.25), (-0.9, 0.8, 0.2), (0.9, 0.75, 0.2), (-0.3, -0.9, 0.25), (0.6, -0.6, 0.15))


def problems():
    """(name, builder, list of groupings)."""
    def arm(n, obs, start0=0.3, goal0=2.8, continuous=False):
        return lambda: planar_arm(n, obs, (start0,) + (0.0,) * (n - 1), (goal0,) + (0.0,) * (n - 1), continuous)

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
        ("point4_hole", lambda: box_point(4, wall_with_hole, (0.1, 0.2, 0.8, 0.2), (0.9, 0.8, 0.2, 0.8)),
         groupings(4)),
        ("narrow3", lambda: box_point(3, narrow_passage, (0.1, 0.1, 0.5), (0.9, 0.9, 0.5)), groupings(3)),
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
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
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
          f" {'n D':>7s} {'us/n':>6s} {'len D':>7s} {'len R':>7s} {'len R+S':>7s}" + ("  layered: ratio, len" if args.layered else ""))
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
                    l_first.append(first_path_time(ss, DimensionRRT(si, groups=groups, seed=seed, connect=False), args.limit))
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
