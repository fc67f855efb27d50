"""How the narrowing defaults of dimension-RRT were chosen: mean path length after 500 and 2500 samples
on a held-out query set, for several (narrow_after, narrowing) pairs.

    PYTHONPATH=. .venv/bin/python experiments/narrowing_defaults.py                   # ~3 min
    PYTHONPATH=. .venv/bin/python experiments/narrowing_defaults.py --queries /tmp/heldout/planning_necessary.json

Without --queries it draws the held-out set first, as ``experiments/make_queries.py --seed 777
--n-per-pair 3`` does (36 planning-necessary queries, into a temporary folder): not the named benchmark
sets, so the defaults are not fitted to the queries they are measured on.  The paper narrows the
sampling range once a stable path exists but gives no numbers.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import summary
import numpy as np
from ompl import util as ou

from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.planning.tpee import tpee_dimension_rrt

GRID = [(200, 0.5), (100, 0.5), (50, 0.5), (200, 0.3), (150, 0.3), (100, 0.3), (50, 0.3), (0, 0.3),
        (100, 0.2), (50, 0.2), (100, 0.1), (100, 0.7)]


def get_argument_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--queries", type=Path, default=None, help="query set JSON (default: draw the held-out set)")
    p.add_argument("--samples", type=int, nargs="+", default=[500, 2500])
    return p


def main() -> None:
    args = get_argument_parser().parse_args()
    ou.setLogLevel(ou.LOG_ERROR)
    with tempfile.TemporaryDirectory() as tmp:
        path = args.queries
        if path is None:
            subprocess.run([sys.executable, str(Path(__file__).with_name("make_queries.py")), "--seed", "777",
                            "--n-per-pair", "3", "--out", tmp], check=True, capture_output=True)
            path = Path(tmp) / "planning_necessary.json"
        robot = WearerArm(n_threads=1)
        queries = load_queries(path, robot)
        setups = [(make_simple_setup(robot, q.start, q.goal), q) for q in queries]
        print(f"{len(queries)} queries from {path if args.queries else 'the held-out draw (seed 777)'}")
        for after, factor in GRID:
            row = []
            for cap in args.samples:
                lengths, seconds = [], 0.0
                for k, (ss, q) in enumerate(setups):
                    ss.clear()
                    planner = tpee_dimension_rrt(ss.getSpaceInformation(), q.from_sector, q.to_sector, seed=k + 1,
                                                 max_samples=cap, narrow_after=after, narrowing=factor)
                    ss.setPlanner(planner)
                    t = time.perf_counter()
                    ss.solve(30.0)
                    seconds += time.perf_counter() - t
                    lengths.append(ss.getSolutionPath().length())
                row.append(f"{cap} samples: mean length {np.mean(lengths):.4f} ({seconds:.2f} s)")
            print(f"narrow_after {after:4d} narrowing {factor:.1f}:  " + "  ".join(row), flush=True)


if __name__ == "__main__":
    main()
