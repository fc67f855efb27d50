"""The checker's threads when several planning processes share the cores: one process alone, then two at once.

    PYTHONPATH=. .venv/bin/python experiments/thread_contention.py            # ~15 s on 2 cores
    PYTHONPATH=. .venv/bin/python experiments/thread_contention.py --samples 500
    PYTHONPATH=. .venv/bin/python experiments/thread_contention.py --no-stall-guard   # as before 2026-11-26 (late)
    PYTHONPATH=. .venv/bin/python experiments/thread_contention.py --deadline         # 0.1-s solves beside two busy loops

The paper's dimension-RRT (``tpee_dimension_rrt``, Table 3's rows) on the 24 stratified
``planning_necessary`` queries, capped at ``--samples`` samples each (so every setting does the same
work and finds the same paths), with the wearer checker's ``n_threads`` 1 and 2: first one process
alone, then two identical processes started together.  Prints the wall time of each process.  The
batched checks are OpenMP regions of Pinocchio; with more threads than free cores, a region waits for a
thread that is not running, which is why campaigns with several workers give each one thread.  The checker
notices such a stalled call and goes on one thread for a while (``stall_guard.STALL_SECONDS``);
``--no-stall-guard`` switches that off, and each process prints how often it went on one thread.

``--deadline``: how late a solve given 0.1 s ends (``ss.solve(0.1)``, the paper's planner and the library
pipeline on the same 24 queries) while two processes busy-loop on the two cores, per ``n_threads``: the
median and largest time past the budget.
"""

from __future__ import annotations

import argparse
import gc
import subprocess
import sys
import time

from _common import summary


def _run(n_threads: int, samples: int, guard: bool) -> tuple[float, int]:
    """Wall time of one process's plans (this script with ``--child``) and its checker's stalled calls."""
    import numpy as np
    from ompl import util as ou

    from tpee_ompl import make_simple_setup
    from tpee_ompl.bench.campaign import query_rows, stratified_subset
    from tpee_ompl.model import stall_guard
    from tpee_ompl.model.wearer_arm import WearerArm
    from tpee_ompl.planning.tpee import tpee_dimension_rrt

    ou.setLogLevel(ou.LOG_NONE)
    if not guard:
        stall_guard.STALL_SECONDS = (float("inf"), 0.0)
    robot = WearerArm(n_threads=n_threads)
    _, rows = query_rows("planning_necessary", robot)
    rows = stratified_subset(rows, 24)
    t0 = time.perf_counter()
    for k, q in enumerate(rows):
        ss = make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"]))
        ss.setPlanner(tpee_dimension_rrt(ss.getSpaceInformation(), q["from_sector"], q["to_sector"], seed=k,
                                         max_samples=samples))
        ss.solve(60.0)
    return time.perf_counter() - t0, robot.stalls


def _deadline(n_threads: int, guard: bool) -> str:
    """How late 0.1-s solves end while the cores are busy (this script with ``--deadline``)."""
    import numpy as np
    from ompl import util as ou

    from tpee_ompl import LibraryDimensionRRT, PathLibrary, make_simple_setup
    from tpee_ompl.bench.campaign import query_rows, stratified_subset
    from tpee_ompl.model import stall_guard
    from tpee_ompl.model.wearer_arm import WearerArm
    from tpee_ompl.planning.tpee import tpee_dimension_rrt
    from tpee_ompl.resources import default_library_path

    ou.setLogLevel(ou.LOG_NONE)
    if not guard:
        stall_guard.STALL_SECONDS = (float("inf"), 0.0)
    robot = WearerArm(n_threads=n_threads)
    library = PathLibrary.load(default_library_path(), robot)
    _, rows = query_rows("planning_necessary", robot)
    late: dict[str, list[float]] = {"dimension-RRT": [], "pipeline": []}
    for k, q in enumerate(stratified_subset(rows, 24)):
        ss = make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"]))
        for name, planner in (("dimension-RRT", tpee_dimension_rrt(ss.getSpaceInformation(), q["from_sector"],
                                                                    q["to_sector"], seed=k)),
                              ("pipeline", LibraryDimensionRRT(ss.getSpaceInformation(), library, seed=k))):
            ss.clear()
            ss.setPlanner(planner)
            t = time.perf_counter()
            ss.solve(0.1)
            late[name].append(time.perf_counter() - t - 0.1)
    return "; ".join(f"{name} {1e3 * float(np.median(v)):.1f} ms median, {1e3 * max(v):.1f} ms at most"
                     for name, v in late.items()) + f" (on one thread after stalls: {robot.stalls}x)"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--samples", type=int, default=2500, help="sample cap per query")
    ap.add_argument("--no-stall-guard", action="store_true", help="the checker never falls back to one thread")
    ap.add_argument("--deadline", action="store_true", help="how late 0.1-s solves end beside two busy processes")
    ap.add_argument("--child", type=int, default=None, help=argparse.SUPPRESS)  # n_threads of a child process
    args = ap.parse_args(argv)
    if args.samples < 1:
        ap.error(f"--samples must be at least 1, got {args.samples}")
    if args.deadline:
        busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(2)]
        try:
            time.sleep(0.5)
            for n_threads in (1, 2):
                print(f"n_threads {n_threads}, 0.1-s solves beside two busy processes, time past the budget: "
                      f"{_deadline(n_threads, not args.no_stall_guard)}", flush=True)
        finally:
            for p in busy:
                p.kill()
                p.wait()
        gc.collect()
        return
    if args.child is not None:
        seconds, stalls = _run(args.child, args.samples, not args.no_stall_guard)
        print(f"{seconds:.2f} s (on one thread after stalls: {stalls}x)", flush=True)
        gc.collect()  # the bindings' objects freed before the interpreter's exit (no leak report)
        return
    cmd = [sys.executable, __file__, "--samples", str(args.samples), *(["--no-stall-guard"] if args.no_stall_guard else []),
           "--child"]
    for n_threads in (1, 2):
        alone = subprocess.run([*cmd, str(n_threads)], capture_output=True, text=True, check=True).stdout.strip()
        twins = [subprocess.Popen([*cmd, str(n_threads)], stdout=subprocess.PIPE, text=True) for _ in range(2)]
        both = [p.communicate()[0].strip() for p in twins]
        print(f"n_threads {n_threads}: one process alone {alone}; two at once {both[0]} and {both[1]}", flush=True)


if __name__ == "__main__":
    main()
