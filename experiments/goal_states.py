"""Several goal states (OMPL's ``GoalStates``): a planar arm whose tip must reach a point, with its IK solutions.

    PYTHONPATH=. .venv/bin/python experiments/goal_states.py                 # 6 targets x 3 seeds, ~40 s
    PYTHONPATH=. .venv/bin/python experiments/goal_states.py --targets 10 --seeds 5 --time 2

Set up with plain OMPL + numpy, as a user would: a 6-joint planar arm (links 0.25, joints in [-pi, pi])
among three circles, a Python validity checker, OMPL's default motion validator.  For each target point
(drawn with --seed on the far side of the obstacles) the goal is every valid inverse-kinematics
solution found by drawing the first four joints at random and solving the last two in closed form (both
elbows), up to --goals of them, as ``ob.GoalStates``.  Planners, each on the same setup in one process:
dimension-RRT with all the goal states (one search per goal state, ``DimensionRRTOptions.max_goals``),
dimension-RRT with the goal state nearest the start as its only goal (what a planner that takes one
goal state would be given), RRTConnect with all of them, and RRTConnect + OMPL's ``PathSimplifier``.
Prints per planner: runs solved within --time s, the median time to the first exact path (stopped by
``exactSolnPlannerTerminationCondition``), and the median path length after --time s, with its ratio
to the shortest any planner found for that target and seed.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

from _common import summary
import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.planning.dimension_rrt import DimensionRRT  # the planner under test only

N, LINK = 6, 0.25
OBSTACLES = np.array([(0.0, 1.0, 0.25), (-0.9, 0.8, 0.2), (0.9, 0.75, 0.2)])
START = (0.3, 0.0, 0.0, 0.0, 0.0, 0.0)


def _points(q: np.ndarray) -> np.ndarray:
    ang = np.cumsum(q)
    d = LINK * np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    joints = np.vstack([np.zeros((1, 2)), np.cumsum(d, axis=0)])
    s = np.linspace(0.0, 1.0, 4)
    return (joints[:-1, None, :] + s[None, :, None] * d[:, None, :]).reshape(-1, 2)


def _free(q: np.ndarray) -> bool:
    diff = _points(q)[:, None, :] - OBSTACLES[None, :, :2]
    return bool(np.all(np.einsum("poc,poc->po", diff, diff) > OBSTACLES[:, 2] ** 2))


def _ik(target: np.ndarray, rng: np.random.Generator, want: int, tries: int = 4000) -> list[np.ndarray]:
    """Up to ``want`` valid joint vectors placing the tip at ``target``: four joints at random, the last two
    in closed form (both elbows)."""
    out: list[np.ndarray] = []
    for _ in range(tries):
        q = np.zeros(N)
        q[: N - 2] = rng.uniform(-math.pi, math.pi, N - 2)
        base = _points(np.r_[q[: N - 2], 0.0, 0.0])[4 * (N - 2) - 1]  # tip of link N-2
        ang = float(np.sum(q[: N - 2]))
        dx, dy = target - base
        c = (dx * dx + dy * dy - 2 * LINK**2) / (2 * LINK**2)
        if abs(c) > 1:
            continue
        for elbow in (1.0, -1.0):
            q5 = elbow * math.acos(c)
            q4 = math.atan2(dy, dx) - math.atan2(LINK * math.sin(q5), LINK + LINK * math.cos(q5)) - ang
            q[N - 2], q[N - 1] = (q4 + math.pi) % (2 * math.pi) - math.pi, q5
            if _free(q):
                out.append(q.copy())
                if len(out) == want:
                    return out
    return out


def _setup(goals: list[np.ndarray]) -> og.SimpleSetup:
    space = ob.RealVectorStateSpace(N)
    space.setBounds(-math.pi, math.pi)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()

    def valid(s: ob.State) -> bool:
        return _free(np.array([s[i] for i in range(N)]))

    ss.setStateValidityChecker(valid)
    si.setStateValidityCheckingResolution(0.01)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    start = si.allocState()
    for i, v in enumerate(START):
        start[i] = v
    ss.setStartState(start)
    goal = ob.GoalStates(si)
    for q in goals:
        s = si.allocState()
        for i, v in enumerate(q):
            s[i] = float(v)
        goal.addState(s)
    ss.setGoal(goal)
    ss._keep = (valid, start, goal)  # keep the Python objects alive
    si.setup()
    return ss


def _run(ss: og.SimpleSetup, make, seconds: float, first: bool, simplify: bool = False) -> float:
    """Time to the first exact path (``first``) or the path length after ``seconds``; inf when unsolved."""
    ss.clear()
    ss.setPlanner(make(ss.getSpaceInformation()))
    ss.setup()
    if first:
        pdef = ss.getProblemDefinition()
        ptc = ob.plannerOrTerminationCondition(ob.exactSolnPlannerTerminationCondition(pdef),
                                               ob.timedPlannerTerminationCondition(seconds))
        t = time.perf_counter()
        ss.solve(ptc)
        return time.perf_counter() - t if ss.haveExactSolutionPath() else math.inf
    t = time.perf_counter()
    ss.solve(seconds)
    if not ss.haveExactSolutionPath():
        return math.inf
    path = ss.getSolutionPath()
    if simplify:  # the rest of the same time
        og.PathSimplifier(ss.getSpaceInformation()).simplify(path, max(0.0, seconds - (time.perf_counter() - t)))
    return path.length()


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--targets", type=int, default=6)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--goals", type=int, default=8, help="IK solutions per target (goal states)")
    ap.add_argument("--time", type=float, default=1.0, help="s per run")
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    rng = np.random.default_rng(args.seed)
    start = np.array(START)
    names = ("D, all goal states", "D, nearest goal state", "RRTConnect", "RRTConnect + simplifier")
    first = {n: [] for n in names}
    length = {n: [] for n in names}
    n_goals = []
    made = 0
    while made < args.targets:
        r, a = rng.uniform(0.8, 1.35), rng.uniform(2.2, 2.9)  # left, beyond the obstacles
        goals = _ik(np.array([r * math.cos(a), r * math.sin(a)]), rng, args.goals)
        if len(goals) < 2:
            continue
        made += 1
        n_goals.append(len(goals))
        nearest = min(goals, key=lambda q: float(np.linalg.norm(q - start)))
        setups = {names[0]: _setup(goals), names[1]: _setup([nearest]), names[2]: _setup(goals), names[3]: _setup(goals)}
        for s in range(args.seeds):
            ou.RNG.setSeed(1000 * made + s + 1)
            d_seed = 1000 * made + s
            makers = {names[0]: lambda si, seed=d_seed: DimensionRRT(si, seed=seed),
                      names[1]: lambda si, seed=d_seed: DimensionRRT(si, seed=seed), names[2]: og.RRTConnect,
                      names[3]: og.RRTConnect}
            lens = {}
            for n in names:
                if n != names[3]:
                    first[n].append(_run(setups[n], makers[n], args.time, first=True))
                lens[n] = _run(setups[n], makers[n], args.time, first=False, simplify=n == names[3])
            best = min(lens.values())
            for n in names:
                length[n].append((lens[n], lens[n] / best if math.isfinite(lens[n]) else math.inf))
    print(f"{args.targets} targets x {args.seeds} seeds, {min(n_goals)}-{max(n_goals)} goal states each, {args.time} s per run")
    print(f"{'planner':26s} {'solved':>8s} {'first path, median':>19s} {'length, median':>15s} {'length / shortest':>18s}")
    for n in names:
        solved = sum(math.isfinite(v) for v, _ in length[n])
        f = f"{1e3 * statistics.median(first[n]):.1f} ms" if first[n] else "(as RRTConnect)"
        print(f"{n:26s} {solved:3d} / {len(length[n]):<3d} {f:>19s} {statistics.median(v for v, _ in length[n]):15.3f} "
              f"{statistics.median(r for _, r in length[n]):18.3f}")


if __name__ == "__main__":
    main()
