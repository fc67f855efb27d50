"""Dimension-RRT started from the library's DMP path vs from the straight line (the library's repair).

For every query of a stored set: the closest demonstration's DMP path at the 7 fake-time steps is
handed to dimension-RRT as ``initial_waypoints``; the same planner (same seed, same sample cap) is run
without it.  Reports success, time to the first valid path and final length, for all queries and for
those whose raw DMP path collides (the ones the library repairs).  Writes ``<out>.json``.

    python experiments/dmp_seeded_planning.py --query-set planning_necessary --samples 500
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from ompl import util as ou

from tpee_ompl.bench.results import new_output_stem
from tpee_ompl.library import N_FAKE_TIME_STEPS, PathLibrary
from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.wearer_arm import default_robot
from tpee_ompl.planning.paths import motion_is_valid
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.resources import default_library_path


def _run(robot, q, samples: int, seed: int, initial: np.ndarray | None) -> dict:
    ss = make_simple_setup(robot, q.start, q.goal)
    planner = tpee_dimension_rrt(ss.getSpaceInformation(), q.from_sector, q.to_sector, max_samples=samples, seed=seed,
                                 initial_waypoints=initial)
    ss.setPlanner(planner)
    t0 = time.perf_counter()
    ss.solve(30.0)
    wall = time.perf_counter() - t0
    st = planner.last_run_stats()
    ok = ss.haveExactSolutionPath()
    return {"solved": bool(ok), "first_s": st["first_solution_time"], "wall_s": wall,
            "length": ss.getSolutionPath().length() if ok else float("nan")}


def _block(rows: list[dict], key: str) -> dict:
    sel = [r[key] for r in rows]
    first = [r["first_s"] for r in sel if r["first_s"] is not None]
    return {"solved": sum(r["solved"] for r in sel), "first_solution_median_ms": float(np.median(first) * 1e3) if first else None,
            "wall_median_ms": float(np.median([r["wall_s"] for r in sel]) * 1e3),
            "length_median": float(np.nanmedian([r["length"] for r in sel]))}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--library", type=Path, default=default_library_path())
    ap.add_argument("--query-set", default="planning_necessary")
    ap.add_argument("--samples", type=int, default=500)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=Path("experiments/library/seeded_planning"))
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_WARN)
    robot = default_robot()
    lib = PathLibrary.load(args.library, robot)
    rows = []
    for k, q in enumerate(load_queries(args.query_set, robot)):
        i, j = q.from_sector, q.to_sector
        d = int(lib.demo_order(q.start, q.goal, i, j)[0])
        raw_valid = motion_is_valid(robot, lib.generate(q.start, q.goal, i, j, d, stride=lib.query_stride))
        W = np.clip(lib.generate(q.start, q.goal, i, j, d, stride=lib.per_step), robot.lower, robot.upper)
        assert W.shape == (N_FAKE_TIME_STEPS, 4)
        rows.append({"id": q.id, "raw_valid": raw_valid,
                     "seeded": _run(robot, q, args.samples, args.seed + k, W),
                     "straight": _run(robot, q, args.samples, args.seed + k, None)})
    out = {"query_set": args.query_set, "samples": args.samples, "queries": len(rows)}
    for label, sel in (("all", rows), ("raw_dmp_invalid", [r for r in rows if not r["raw_valid"]])):
        if sel:
            out[label] = {"queries": len(sel), "seeded": _block(sel, "seeded"), "straight": _block(sel, "straight")}
            print(f"{label} ({len(sel)} queries, {args.samples} samples): seeded {out[label]['seeded']}; "
                  f"straight {out[label]['straight']}")
    stem = new_output_stem(args.out, (".json",))  # never overwrite earlier results
    stem.with_name(stem.name + ".json").write_text(json.dumps({**out, "rows": rows}, indent=1))
    print(f"wrote {stem.with_name(stem.name + '.json')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
