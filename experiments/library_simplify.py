"""Would OMPL's path simplifier close the library pipeline's cost gap to AORRTC at equal time? (issue 17)

On 24 stratified ``planning_necessary`` queries, LibraryDimensionRRT plans for 70 % of the budget, then one
of OMPL's ``PathSimplifier`` routines runs on its path: ``partial`` (reduceVertices + partialShortcutPath),
``rope`` (ropeShortcutPath) or ``simplify`` (simplify with the rest of the budget as its termination
condition).  Prints the median cost before and after, the total time and whether every path passes
``PathGeometric.check``.

    PYTHONPATH=. python experiments/library_simplify.py [--budget 0.1] [--mode partial rope simplify]
"""

from __future__ import annotations

import argparse
import statistics
import time

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.bench.campaign import stratified_subset
from tpee_ompl.bench.problems import get_problem
from tpee_ompl.library.path_library import PathLibrary
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.resources import default_library_path


def _run(mode: str, budget: float, queries: list[dict]) -> str:
    problem = get_problem("wearer")
    library, rows = None, []
    for query in queries:
        ss, robot = problem.build(query, "batched", 1)
        library = library or PathLibrary.load(default_library_path(), robot)
        si = ss.getSpaceInformation()
        ss.setPlanner(LibraryDimensionRRT(si, library, seed=1))
        ss.setup()
        t0 = time.perf_counter()
        ss.solve(0.7 * budget)
        path = og.PathGeometric(ss.getSolutionPath())
        before = path.length()
        simplifier = og.PathSimplifier(si)
        if mode == "partial":
            simplifier.reduceVertices(path)
            simplifier.partialShortcutPath(path)
        elif mode == "rope":
            simplifier.ropeShortcutPath(path)
        else:
            simplifier.simplify(path, ob.timedPlannerTerminationCondition(budget - (time.perf_counter() - t0)))
        rows.append((before, path.length(), time.perf_counter() - t0, path.check()))
    return (f"{mode}, budget {budget} s: median cost {statistics.median(r[0] for r in rows):.3f} -> "
            f"{statistics.median(r[1] for r in rows):.3f}; total time median {statistics.median(r[2] for r in rows):.3f} s, "
            f"max {max(r[2] for r in rows):.3f} s; every path valid: {all(r[3] for r in rows)}")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--budget", type=float, default=0.1)
    ap.add_argument("--mode", nargs="+", default=["partial", "rope", "simplify"], choices=["partial", "rope", "simplify"])
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_ERROR)
    ou.RNG.setSeed(5)
    _, queries = get_problem("wearer").load_queries(None, False)
    queries = stratified_subset(queries, 24)
    for mode in args.mode:
        print(_run(mode, args.budget, queries))


if __name__ == "__main__":
    main()
