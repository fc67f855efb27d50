"""Dimension-RRT with and without restarts (``DimensionRRTOptions.restart_after``) on the generic problems and a torus.

    PYTHONPATH=. .venv/bin/python experiments/restarts.py                  # 1 s per run, about 3 min
    PYTHONPATH=. .venv/bin/python experiments/restarts.py --problems torus kinova-posts --budget 0.5

Each query (the first --max-queries of each problem) is solved twice, alternating, with the same planner seed
(query index + 1), the problem's grouping and validator (batched on robot problems, OMPL's discrete one on the
generic ones) and a budget of --budget seconds: ``restart_after`` None (the paper's single search) and the value
of --restart-after.  ``torus`` is two continuous joints (SO2 x SO2) with the first blocked near 0 while the second is
above 0, from (-1, 0.5) to (1, 0.5): the short way (~3.0) dips the second joint to 0, the long way round the first
joint's circle is ~4.28.  Printed per problem: mean and median length of each setting and how many queries ended
more than 0.5 % shorter / longer with restarts.  Budgets, not caps: a fresh search's samples cost more than a
converged one's, so equal samples would flatter the restarts.
"""

from __future__ import annotations

import argparse
import math

from _common import summary
import numpy as np

GENERIC = ["arm4", "arm6", "arm7", "arm8", "arm5-so2", "point4-hole", "narrow3", "kinova-posts", "torus"]


def torus_queries(n: int):
    """``n`` copies of the torus query (the seed varies between runs): (make_setup, groups) pairs."""
    from tpee_ompl.examples.so2_torus import make_so2_torus_setup

    return [(make_so2_torus_setup, None)] * n


def problem_queries(name: str, n: int, query_seed: int | None = None):
    import dataclasses

    from tpee_ompl.bench.generic_problems import GENERIC_PROBLEMS, generic_queries
    from tpee_ompl.bench.problems import get_problem

    if name == "torus":
        return torus_queries(n)
    problem = get_problem(name)
    if query_seed is not None and name in GENERIC_PROBLEMS:  # held-out queries: the problem's sampler, another seed
        rows = generic_queries(dataclasses.replace(GENERIC_PROBLEMS[name], seed=query_seed))
    else:
        _, rows = problem.queries()
    checker = problem.checkers[0]
    return [((lambda q=q: problem.make_setup(q, checker)[0]), problem.groups) for q in rows[:n]]


def main() -> None:
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--problems", nargs="+", default=GENERIC, choices=GENERIC)
    p.add_argument("--max-queries", type=int, default=10)
    p.add_argument("--budget", type=float, default=1.0, help="seconds per run")
    p.add_argument("--restart-after", type=int, default=None, help="default: RESTART_AFTER")
    p.add_argument("--query-seed", type=int, default=None,
                   help="draw the generic problems' queries with this seed instead (held-out queries; kinova-posts and "
                        "the torus keep theirs)")
    args = p.parse_args()
    from ompl import util as ou

    from tpee_ompl.planning.dimension_rrt import RESTART_AFTER, DimensionRRT

    ou.setLogLevel(ou.LOG_NONE)
    after = args.restart_after or RESTART_AFTER
    print(f"budget {args.budget:g} s per run, restart_after {after} against None"
          + ("" if args.query_seed is None else f", generic queries drawn with seed {args.query_seed}"))
    for name in args.problems:
        lengths: dict[str, list[float]] = {"restarts": [], "single": []}
        for k, (make_setup, groups) in enumerate(problem_queries(name, args.max_queries, args.query_seed)):
            for label, value in (("restarts", after), ("single", None)):
                ss = make_setup()
                ss.setPlanner(DimensionRRT(ss.getSpaceInformation(), groups=groups, seed=k + 1, restart_after=value))
                ss.solve(args.budget)
                lengths[label].append(ss.getSolutionPath().length() if ss.haveExactSolutionPath() else math.nan)
        on, off = np.array(lengths["restarts"]), np.array(lengths["single"])
        print(f"{name:13s} mean {np.nanmean(on):.4f} / {np.nanmean(off):.4f}   median {np.nanmedian(on):.4f} / "
              f"{np.nanmedian(off):.4f}   shorter / longer by > 0.5 %: {int((on < off * 0.995).sum())} / "
              f"{int((on > off * 1.005).sum())} of {len(on)}", flush=True)


if __name__ == "__main__":
    main()
