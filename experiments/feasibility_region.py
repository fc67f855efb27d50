"""Where the layered trees draw their samples before a first path: around the path they start from, or uniformly.

    PYTHONPATH=. .venv/bin/python experiments/feasibility_region.py                 # both named sets, ~1.5 min
    PYTHONPATH=. .venv/bin/python experiments/feasibility_region.py --queries /tmp/heldout/planning_necessary.json \
        --settings uniform 0.35:32 0.25:32 0.35:inf 0.5:32 0.25:16     # how the package's values were chosen,
    PYTHONPATH=. .venv/bin/python experiments/feasibility_region.py --queries /tmp/heldout/planning_necessary.json \
        /tmp/heldout/paper_random.json --ompl-seed 2 --settings uniform 0.35:32 0.25:32 0.25:16 0.15:16  # twice
    PYTHONPATH=. .venv/bin/python experiments/feasibility_region.py --planner library

Every setting (``uniform``: the paper's samples, uniform over the planned DOFs' bounds; ``PAD:DOUBLING``: all
but 10 % of them from the box the trees' first path sweeps, padded by PAD of each DOF's range, the padding
growing as 2^(n / DOUBLING) with the samples n, ``inf`` never; ``search_draws.FEASIBILITY_PAD`` and ``FEASIBILITY_DOUBLING``,
the package's being 0.25:16) and RRTConnect run to their first exact path on every query of each set, on the
wearer's ``make_simple_setup``, alternating per query, ``--reps`` runs each (dimension-RRT seeded with the
query index and the repetition, OMPL seeded with ``--ompl-seed``). Prints per setting the median, mean and p95
time to the first path, its ratio to RRTConnect's median in the same run, the collision checks, and the first
path's median length.  ``--planner library``: ``LibraryDimensionRRT`` with the default library, whose search
starts from the DMP path (its trees only when that path is invalid).
"""

from __future__ import annotations

import argparse
import math
import statistics

import numpy as np
from _common import first_path_time, missing_query_files, summary
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.library.path_library import PathLibrary
from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning import search_draws
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.resources import default_library_path


def get_argument_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--queries", nargs="+", default=["planning_necessary", "paper_random"],
                   help="named query sets or JSON files")
    p.add_argument("--settings", nargs="+", default=["uniform", "0.25:16"],
                   help="'uniform' or PAD:DOUBLING (fraction of each DOF's range; samples, or inf)")
    p.add_argument("--reps", type=int, default=3, help="runs per query and setting")
    p.add_argument("--limit", type=float, default=1.0, help="time limit per run, s")
    p.add_argument("--ompl-seed", type=int, default=1, help="OMPL's global seed (RRTConnect's runs repeat)")
    p.add_argument("--planner", choices=["paper", "library"], default="paper",
                   help="paper: tpee_dimension_rrt (Table 3's rows kept); library: LibraryDimensionRRT")
    return p


def _setting(text: str) -> tuple[float, float] | None:
    if text == "uniform":
        return None
    pad, _, doubling = text.partition(":")
    try:
        value = float(pad), float(doubling or "inf")
    except ValueError:
        raise argparse.ArgumentTypeError(f"--settings: {text!r} is neither 'uniform' nor PAD:DOUBLING") from None
    if not (value[0] > 0 and value[1] > 0 and math.isfinite(value[0])):
        raise argparse.ArgumentTypeError(f"--settings: {text!r} needs PAD > 0 and DOUBLING > 0")
    return value


def main(argv: list[str] | None = None) -> None:
    ap = get_argument_parser()
    args = ap.parse_args(argv)
    if (bad := missing_query_files(args.queries)) is not None:
        ap.error(bad)
    if args.reps < 1 or not args.limit > 0:
        ap.error(f"--reps must be at least 1 and --limit positive, got {args.reps} and {args.limit}")
    try:
        settings = {text: _setting(text) for text in args.settings}
    except argparse.ArgumentTypeError as e:
        ap.error(str(e))
    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(args.ompl_seed)
    robot = WearerArm()
    library = PathLibrary.load(default_library_path(), robot) if args.planner == "library" else None
    saved = search_draws.FEASIBILITY_PAD, search_draws.FEASIBILITY_DOUBLING
    try:
        for name in args.queries:
            qs = load_queries(name, robot)
            runs: dict[str, tuple[list[float], list[int], list[float]]] = {s: ([], [], []) for s in [*settings, "RRTConnect"]}
            for k, q in enumerate(qs):
                ss = make_simple_setup(robot, q.start, q.goal)
                si = ss.getSpaceInformation()
                for rep in range(args.reps):
                    order = list(settings) if (k + rep) % 2 == 0 else list(settings)[::-1]
                    for who in [*order, "RRTConnect"]:
                        if who == "RRTConnect":
                            planner = og.RRTConnect(si)
                        else:
                            value = settings[who]
                            search_draws.FEASIBILITY_PAD = None if value is None else value[0]
                            search_draws.FEASIBILITY_DOUBLING = saved[1] if value is None else value[1]
                            seed = 1000 * rep + k
                            planner = (LibraryDimensionRRT(si, library, seed=seed) if library is not None
                                       else tpee_dimension_rrt(si, q.from_sector, q.to_sector, seed=seed))
                        c0 = robot.collision_checks
                        t = first_path_time(ss, planner, args.limit)
                        times, checks, lengths = runs[who]
                        times.append(math.inf if t is None else t)
                        checks.append(robot.collision_checks - c0)
                        lengths.append(ss.getSolutionPath().length() if t is not None else math.nan)
            ref = statistics.median(runs["RRTConnect"][0])
            print(f"{name}: {len(qs)} queries x {args.reps} runs, planner {args.planner}", flush=True)
            for who, (times, checks, lengths) in runs.items():
                solved = sum(math.isfinite(t) for t in times)
                med = statistics.median(times)
                print(f"  {who:11s} solved {solved}/{len(times)}  first path median {1e3 * med:6.2f} ms "
                      f"(/ RRTConnect {med / ref:5.3f})  mean {1e3 * statistics.mean(times):6.2f} ms  "
                      f"p95 {1e3 * float(np.percentile(times, 95)):6.2f} ms  checks median "
                      f"{statistics.median(checks):5.0f} mean {statistics.mean(checks):6.1f}  "
                      f"first path length median {float(np.nanmedian(lengths)):.3f}", flush=True)
    finally:
        search_draws.FEASIBILITY_PAD, search_draws.FEASIBILITY_DOUBLING = saved


if __name__ == "__main__":
    main()
