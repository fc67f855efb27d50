"""The first plan of a fresh process: what a user's first query costs beside the next ones.

    PYTHONPATH=. .venv/bin/python experiments/cold_start.py            # ~10 s

(The processes import ``tpee_ompl`` from the current directory first: to time another checkout, run
this from that checkout's root with ``PYTHONPATH`` pointing there.)

For each planner (dimension-RRT, RRTConnect, the library pipeline), ``--runs`` fresh Python processes
each build the wearer, a setup per query and solve the stratified ``planning_necessary`` queries
``--queries`` in turn (by default query 5 twice), each stopped at its first exact path; prints the
median over the processes of the first solve's time and of the last one's (the same query, warm).  The set-up before the first solve (imports,
the robot, ``make_simple_setup``) is not timed; ``ss.solve`` is, with the set-up it does itself.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys

from _common import summary

_CHILD = r"""
import json, sys, time
import numpy as np
from ompl import base as ob, geometric as og, util as ou
ou.setLogLevel(ou.LOG_NONE)
from tpee_ompl import PathLibrary, WearerArm, make_simple_setup
from tpee_ompl.bench.campaign import query_rows, stratified_subset
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.resources import default_library_path
who, picks = sys.argv[1], [int(x) for x in sys.argv[2].split(",")]
robot = WearerArm()
lib = PathLibrary.load(default_library_path(), robot) if who == "library" else None
_, rows = query_rows("planning_necessary", robot)
rows = stratified_subset(rows, 24)
setups = [(make_simple_setup(robot, np.array(rows[k]["start"]), np.array(rows[k]["goal"])), rows[k], k) for k in picks]
times = []
for ss, q, k in setups:
    si = ss.getSpaceInformation()
    if who == "dimension-rrt":
        p = tpee_dimension_rrt(si, q["from_sector"], q["to_sector"], seed=k)
    elif who == "rrtconnect":
        p = og.RRTConnect(si)
    else:
        p = LibraryDimensionRRT(si, lib, q["from_sector"], q["to_sector"], seed=k)
    ss.setPlanner(p)  # no ss.setup() here: solve() does it, as in a user's first call
    ptc = ob.plannerOrTerminationCondition(ob.exactSolnPlannerTerminationCondition(ss.getProblemDefinition()),
                                           ob.timedPlannerTerminationCondition(1.0))
    t = time.perf_counter()
    ss.solve(ptc)
    times.append(time.perf_counter() - t)
print(json.dumps(times))
"""


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--runs", type=int, default=5, help="fresh processes per planner")
    ap.add_argument("--queries", default="5,5", help="indices into the 24 stratified queries, solved in turn")
    args = ap.parse_args(argv)
    for who in ("dimension-rrt", "rrtconnect", "library"):
        first, later = [], []
        for _ in range(args.runs):
            out = subprocess.run([sys.executable, "-c", _CHILD, who, args.queries], capture_output=True, text=True,
                                 check=True)
            times = json.loads(out.stdout.strip().splitlines()[-1])
            first.append(times[0])
            later.append(times[-1])
        print(f"{who:14s} first solve of a process: median {1e3 * statistics.median(first):5.1f} ms; "
              f"last solve: median {1e3 * statistics.median(later):5.1f} ms ({args.runs} processes)", flush=True)


if __name__ == "__main__":
    main()
