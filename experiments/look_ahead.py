"""What running the cost test ahead buys: the same capped runs with it on and off, same samples, same paths.

    PYTHONPATH=. .venv/bin/python experiments/look_ahead.py                        # ~1 min
    PYTHONPATH=. .venv/bin/python experiments/look_ahead.py --samples 20000 --planner paper

On a valid path most samples are shorter at no step; the search passes over them with one vectorised
cost test (``SampleDraws._pass_rejected``).  With the look-ahead (the default) that test runs over up to
``AHEAD`` samples at once and is kept while the path stays the same; switched off here (a scratch switch:
the kept test is dropped before every call, so each call tests its own window of at most 63 samples, as
before 2026-11-26).  Each run is capped at ``--samples``, so both settings draw the same samples and
must return the same path (checked); the two settings alternate per query.  Prints the total time of
each and their ratio.  ``--planner library``: ``LibraryDimensionRRT`` (Table 3's rows released after
``RELEASE_AFTER``); ``paper``: ``tpee_dimension_rrt`` (rows kept, Table 4's planner).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _common import wearer_library_queries
from ompl import util as ou

from tpee_ompl import make_simple_setup
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.planning import search_draws
from tpee_ompl.planning.tpee import tpee_dimension_rrt


def _switch(on: bool) -> None:
    """The look-ahead on (the package as it is) or off (the kept test dropped before every call)."""
    cls = search_draws.SampleDraws
    if not hasattr(cls, "_kept_pass_rejected"):
        cls._kept_pass_rejected = cls._pass_rejected

        def per_call(self, limit: int) -> None:
            self._ahead = None
            saved, search_draws.AHEAD = search_draws.AHEAD, max(1, limit)
            try:
                cls._kept_pass_rejected(self, limit)
            finally:
                search_draws.AHEAD = saved

        cls._per_call_pass_rejected = per_call
    cls._pass_rejected = cls._kept_pass_rejected if on else cls._per_call_pass_rejected


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", default="planning_necessary")
    ap.add_argument("--max-queries", type=int, default=24)
    ap.add_argument("--samples", type=int, default=5000, help="sample cap per run")
    ap.add_argument("--planner", choices=("library", "paper"), default="library")
    ap.add_argument("--reps", type=int, default=2)
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    robot, lib, rows = wearer_library_queries(args.queries, args.max_queries)
    setups = [make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"])) for q in rows]
    total = {True: 0.0, False: 0.0}
    lengths: dict[bool, list[float]] = {True: [], False: []}
    for rep in range(args.reps):
        for k, (q, ss) in enumerate(zip(rows, setups)):
            for on in ((True, False) if (k + rep) % 2 else (False, True)):
                _switch(on)
                si = ss.getSpaceInformation()
                if args.planner == "library":
                    planner = LibraryDimensionRRT(si, lib, q["from_sector"], q["to_sector"], seed=k,
                                                  max_samples=args.samples)
                else:
                    planner = tpee_dimension_rrt(si, q["from_sector"], q["to_sector"], seed=k, max_samples=args.samples)
                ss.clear()
                ss.setPlanner(planner)
                t0 = time.perf_counter()
                ss.solve(60.0)
                total[on] += time.perf_counter() - t0
                lengths[on].append(planner.last_run_stats()["best_cost"])
    _switch(True)
    same = lengths[True] == lengths[False]
    print(f"{args.planner}, {len(rows)} queries x {args.reps}, {args.samples} samples per run: look-ahead "
          f"{total[True]:.2f} s, per call {total[False]:.2f} s, ratio {total[True] / total[False]:.3f}; "
          f"{'the same path in every run' if same else 'PATHS DIFFER'}")


if __name__ == "__main__":
    main()
