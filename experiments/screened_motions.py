"""Screened motion checks (clearance balls) against checking every state, side by side in one run.

For each of the first queries of a problem, RRT* runs to an iteration cap twice, once with the default
validator (screened) and once checking every state (``screen_levels=()``), in alternating order.
Then every motion the screened run asked about is checked again both ways: the verdicts must agree.

    PYTHONPATH=. python experiments/screened_motions.py [--problem wearer] [--queries 4] [--iterations 2500]
        [--threads 2] [--levels 2,1 4,1]

With --levels, the recorded motions are also checked one by one (as ``si.checkMotion`` checks them) with
each set of ball radii given (in motion-check steps), in turn, three times, and the fastest time and the
states checked are printed per set: how ``SCREEN_LEVELS`` is chosen.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.bench.problems import get_problem
from tpee_ompl.model.clearance_balls import screened_all_valid
from tpee_ompl.planning.paths import motion_states, state_to_array
from tpee_ompl.planning.setup import BatchedMotionValidator


class _Recorder(BatchedMotionValidator):
    def __init__(self, si, robot, step, screen_levels) -> None:
        super().__init__(si, robot, step, screen_levels)
        self.seen: list[tuple[np.ndarray, np.ndarray]] = []

    def checkMotion(self, s1, s2) -> bool:  # noqa: N802 (OMPL override)
        self.seen.append((state_to_array(s1, self._n), state_to_array(s2, self._n)))
        return super().checkMotion(s1, s2)


def _run(problem, query: dict, screened: bool, iterations: int, threads: int) -> dict:
    ss, robot = problem.build(query, "batched", threads)
    si = ss.getSpaceInformation()
    mv = si.getMotionValidator()
    rec = _Recorder(si, robot, mv.step, mv.screen_levels if screened else ())
    si.setMotionValidator(rec)
    planner = og.RRTstar(si)
    ss.setPlanner(planner)
    ss.setup()
    c0 = robot.collision_checks
    t0 = time.perf_counter()
    status = ss.solve(ob.PlannerTerminationCondition(lambda: planner.numIterations() >= iterations))
    return {"time": time.perf_counter() - t0, "checks": robot.collision_checks - c0, "motions": len(rec.seen),
            "exact": bool(status) and ss.haveExactSolutionPath(), "seen": rec.seen, "robot": robot, "step": mv.step}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--problem", default="wearer")
    ap.add_argument("--queries", type=int, default=4)
    ap.add_argument("--iterations", type=int, default=2500)
    ap.add_argument("--threads", type=int, default=2, help="threads of the batched checks (the default setup: 2)")
    ap.add_argument("--levels", nargs="*", default=[], metavar="R1,R2,...",
                    help="ball radii sets (motion-check steps) to time on the recorded motions, e.g. 2,1 4,1")
    args = ap.parse_args(argv)
    try:
        level_sets = [tuple(float(x) for x in spec.split(",")) for spec in args.levels]
    except ValueError:
        ap.error(f"--levels: each set is comma-separated numbers, got {args.levels}")
    ou.setLogLevel(ou.LOG_ERROR)
    problem = get_problem(args.problem)
    _, queries = problem.load_queries(None, False)
    rows = []
    level_cost = {lv: [0.0, 0] for lv in level_sets}  # summed over queries: fastest time (s), states checked
    for k, query in enumerate(queries[: args.queries]):
        order = (True, False) if k % 2 == 0 else (False, True)
        runs = {screened: _run(problem, query, screened, args.iterations, args.threads) for screened in order}
        s, d = runs[True], runs[False]
        robot, step = s["robot"], s["step"]
        chunks = [motion_states(a, b, step) for a, b in s["seen"]]
        c0 = robot.collision_checks
        dense = np.array([robot.are_valid(c).all() for c in chunks])
        c1 = robot.collision_checks
        screened = np.array([screened_all_valid(robot, robot.ball_screen(), [c], step)[0] for c in chunks])
        c2 = robot.collision_checks
        for lv in level_sets:
            best = np.inf
            for _ in range(3):
                c3, t3 = robot.collision_checks, time.perf_counter()
                for c in chunks:
                    screened_all_valid(robot, robot.ball_screen(), [c], step, lv)
                best = min(best, time.perf_counter() - t3)
            level_cost[lv][0] += best
            level_cost[lv][1] += robot.collision_checks - c3
        rows.append((s["time"], d["time"], s["checks"], d["checks"], int((dense != screened).sum()), len(chunks),
                     (c2 - c1) / max(1, c1 - c0), int((~dense).sum())))
        print(f"query {k}: RRT* {args.iterations} it: screened {s['time']:.2f} s ({s['checks']} checks), every state "
              f"{d['time']:.2f} s ({d['checks']} checks); motions re-checked {len(chunks)} ({int((~dense).sum())} "
              f"invalid), verdicts differing {rows[-1][4]}, states checked screened / every {rows[-1][6]:.2f}")
    t = np.array(rows, dtype=float)
    print(f"\n{args.problem}, {len(rows)} queries, {args.threads} thread(s): median RRT* time screened "
          f"{np.median(t[:, 0]):.2f} s, every state {np.median(t[:, 1]):.2f} s (ratio {np.median(t[:, 0] / t[:, 1]):.2f}); "
          f"collision checks ratio {np.median(t[:, 2] / t[:, 3]):.2f}; verdicts differing {int(t[:, 4].sum())} of "
          f"{int(t[:, 5].sum())} motions")
    for lv, (secs, states) in level_cost.items():
        print(f"ball radii {','.join(f'{x:g}' for x in lv):10s}: recorded motions checked one by one in {secs:.3f} s, "
              f"{states} states checked")


if __name__ == "__main__":
    main()
