"""A path's motions through the default validator screened as one polyline against line by line (``CHAINS``).

    PYTHONPATH=. .venv/bin/python experiments/chained_paths.py            # ~15 s
    PYTHONPATH=. .venv/bin/python experiments/chained_paths.py --reps 1

The validator's batched ``check_motions`` gets a path's motions together (``path_passes_motion_checks``); each motion
starts where the last ended.  With ``clearance_balls.CHAINS`` (the default since 2026-11-27) such chained motions are
cut into clearance balls by their position along the polyline, so a ball reaches across a waypoint; before, each
motion was a line of its own.  The library's DMP paths are 60 motions of 1-9 states at the query stride, so line by
line most of their states were left for plain checks beside a ball or two.  For every query of both named sets, the
library's three candidate paths (1 thread, as a campaign worker), each checked with the switch off and on,
alternating: the verdicts (which must agree), the states checked and the time per path.
"""

from __future__ import annotations

import argparse
import time

from _common import summary
from ompl import util as ou

from tpee_ompl import PathLibrary, WearerArm, load_queries, make_simple_setup
from tpee_ompl.model import clearance_balls
from tpee_ompl.planning.paths import path_passes_motion_checks
from tpee_ompl.resources import default_library_path


def main(argv: list[str] | None = None) -> None:
    """Print per query set the paths, their verdicts and the checks and time per path with the switch off and on."""
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--reps", type=int, default=2, help="times each path is checked in each setting")
    ap.add_argument("--sets", nargs="+", default=["planning_necessary", "paper_random"])
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_WARN)
    robot = WearerArm(n_threads=1)
    lib = PathLibrary.load(default_library_path(), robot)
    saved = clearance_balls.CHAINS
    try:
        for name in args.sets:
            paths = []
            for q in load_queries(name, robot):
                si = make_simple_setup(robot, q.start, q.goal).getSpaceInformation()
                si.setup()
                paths += [(si, W) for _, _, W in lib.candidate_paths(q.start, q.goal, q.from_sector, q.to_sector)]
            checks, seconds, verdicts = {False: 0, True: 0}, {False: 0.0, True: 0.0}, {False: [], True: []}
            for rep in range(args.reps):
                for i, (si, W) in enumerate(paths):
                    for on in ((False, True) if (i + rep) % 2 else (True, False)):
                        clearance_balls.CHAINS = on
                        before, t0 = robot.collision_checks, time.perf_counter()
                        ok = path_passes_motion_checks(si, W, in_bounds=True)
                        seconds[on] += time.perf_counter() - t0
                        checks[on] += robot.collision_checks - before
                        verdicts[on].append(ok)
            if verdicts[True] != verdicts[False]:
                raise SystemExit(f"{name}: the verdicts differ")
            n = len(paths) * args.reps
            print(f"{name}: {len(paths)} paths, {sum(verdicts[True]) // args.reps} valid, the same verdicts; per path "
                  f"line by line {checks[False] / n:.1f} checks, {1e3 * seconds[False] / n:.3f} ms; as polylines "
                  f"{checks[True] / n:.1f} checks, {1e3 * seconds[True] / n:.3f} ms "
                  f"(checks x{checks[True] / checks[False]:.2f}, time x{seconds[True] / seconds[False]:.2f})")
    finally:
        clearance_balls.CHAINS = saved


if __name__ == "__main__":
    main()
