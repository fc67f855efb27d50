"""The checker's threads when several planning processes share the cores: one process alone, then two at once.

    PYTHONPATH=. .venv/bin/python experiments/thread_contention.py            # ~15 s on 2 cores
    PYTHONPATH=. .venv/bin/python experiments/thread_contention.py --samples 500

The paper's dimension-RRT (``tpee_dimension_rrt``, Table 3's rows) on the 24 stratified
``planning_necessary`` queries, capped at ``--samples`` samples each (so every setting does the same
work and finds the same paths), with the wearer checker's ``n_threads`` 1 and 2: first one process
alone, then two identical processes started together.  Prints the wall time of each process.  The
batched checks are OpenMP regions of Pinocchio; with more threads than free cores, a region waits for a
thread that is not running, which is why campaigns with several workers give each one thread.
"""

from __future__ import annotations

import argparse
import gc
import subprocess
import sys
import time


def _run(n_threads: int, samples: int) -> float:
    """Wall time of one process's plans (this script with ``--child``)."""
    import numpy as np
    from ompl import util as ou

    from tpee_ompl import make_simple_setup
    from tpee_ompl.bench.campaign import query_rows, stratified_subset
    from tpee_ompl.model.wearer_arm import WearerArm
    from tpee_ompl.planning.tpee import tpee_dimension_rrt

    ou.setLogLevel(ou.LOG_NONE)
    robot = WearerArm(n_threads=n_threads)
    _, rows = query_rows("planning_necessary", robot)
    rows = stratified_subset(rows, 24)
    t0 = time.perf_counter()
    for k, q in enumerate(rows):
        ss = make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"]))
        ss.setPlanner(tpee_dimension_rrt(ss.getSpaceInformation(), q["from_sector"], q["to_sector"], seed=k,
                                         max_samples=samples))
        ss.solve(60.0)
    return time.perf_counter() - t0


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=2500, help="sample cap per query")
    ap.add_argument("--child", type=int, default=None, help=argparse.SUPPRESS)  # n_threads of a child process
    args = ap.parse_args(argv)
    if args.samples < 1:
        ap.error(f"--samples must be at least 1, got {args.samples}")
    if args.child is not None:
        print(f"{_run(args.child, args.samples):.2f}", flush=True)
        gc.collect()  # the bindings' objects freed before the interpreter's exit (no leak report)
        return
    cmd = [sys.executable, __file__, "--samples", str(args.samples), "--child"]
    for n_threads in (1, 2):
        alone = subprocess.run([*cmd, str(n_threads)], capture_output=True, text=True, check=True).stdout.strip()
        twins = [subprocess.Popen([*cmd, str(n_threads)], stdout=subprocess.PIPE, text=True) for _ in range(2)]
        both = [p.communicate()[0].strip() for p in twins]
        print(f"n_threads {n_threads}: one process alone {alone} s; two at once {both[0]} s and {both[1]} s", flush=True)


if __name__ == "__main__":
    main()
