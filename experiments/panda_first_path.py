"""Time to a first exact path on a robot problem (the Franka Panda shelf by default, or the Kinova arm between
posts): dimension-RRT vs RRTConnect, same setups, same process.

    PYTHONPATH=. .venv/bin/python experiments/panda_first_path.py                  # 12 queries x 3 seeds, ~3 min
    PYTHONPATH=. .venv/bin/python experiments/panda_first_path.py --queries 30 --seeds 5 --limit 5
    PYTHONPATH=. .venv/bin/python experiments/panda_first_path.py --problem kinova-posts --queries 30 --seeds 2
    PYTHONPATH=. .venv/bin/python experiments/panda_first_path.py --broadphase-ab     # broadphase vs pair loop

For each of the first --queries queries of ``--problem`` (the benchmark's problem: Pinocchio + Coal checker, the
screened batched motion validator) and each seed, RRTConnect then dimension-RRT (the problem's groups, that
seed) run one after the other, each stopped by ``exactSolnPlannerTerminationCondition`` or --limit s.  Prints,
over the runs both solved, the median time to the first exact path and the median configurations checked, and
how many runs each solved; then the median over all runs with a run without a path counted at the limit.
OMPL's global seed is set (``--ompl-seed``), so a run repeats, RRTConnect included.  ``--broadphase-ab``: each
query's setup built twice, its checks through Pinocchio's tree broadphase and through every pair in turn
(``collision_pools.BROADPHASE``), each planner run on both in alternating order with the same OMPL seed; prints per planner the median
first-path time with each and their ratio (the same verdicts, so the same runs with both).
"""

from __future__ import annotations

import argparse
import statistics

from _common import first_path_time, summary
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.bench.problems import get_problem
from tpee_ompl.model import collision_pools
from tpee_ompl.planning.dimension_rrt import DimensionRRT


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--problem", choices=("panda-shelf", "kinova-posts"), default="panda-shelf")
    ap.add_argument("--queries", type=int, default=12, help="first N queries of the problem")
    ap.add_argument("--seeds", type=int, default=3, help="runs per query and planner (dimension-RRT seeds 0..k-1)")
    ap.add_argument("--limit", type=float, default=2.0, help="time limit per run, s")
    ap.add_argument("--ompl-seed", type=int, default=3, help="OMPL's global seed (0: unseeded)")
    ap.add_argument("--broadphase-ab", action="store_true", help="broadphase against the pair loop, side by side")
    args = ap.parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    if args.ompl_seed:
        ou.RNG.setSeed(args.ompl_seed)
    problem = get_problem(args.problem)
    _, queries = problem.load_queries(None, False)
    if args.broadphase_ab:
        _broadphase_ab(args, problem, queries)
        return
    rows = []
    for query in queries[: args.queries]:
        ss, checker = problem.build(query, "batched", None)
        si = ss.getSpaceInformation()
        for seed in range(args.seeds):
            c0 = checker.collision_checks
            rc = first_path_time(ss, og.RRTConnect(si), args.limit)
            c1 = checker.collision_checks
            dr = first_path_time(ss, DimensionRRT(si, groups=problem.groups, seed=seed), args.limit)
            rows.append((rc, c1 - c0, dr, checker.collision_checks - c1))
    both = [r for r in rows if r[0] is not None and r[2] is not None]
    med = statistics.median
    print(f"{args.problem}, {args.queries} queries x {args.seeds} seeds, limit {args.limit} s: solved RRTConnect "
          f"{sum(r[0] is not None for r in rows)}/{len(rows)}, dimension-RRT {sum(r[2] is not None for r in rows)}/{len(rows)}")
    if both:
        rc_t, dr_t = med(r[0] for r in both), med(r[2] for r in both)
        print(f"runs both solved: {len(both)}; median first path RRTConnect {1e3 * rc_t:.1f} ms, dimension-RRT "
              f"{1e3 * dr_t:.1f} ms (ratio {dr_t / rc_t:.2f}); median checks RRTConnect {med(r[1] for r in both):.0f}, "
              f"dimension-RRT {med(r[3] for r in both):.0f}")
    at_limit = [(args.limit if r[0] is None else r[0], args.limit if r[2] is None else r[2]) for r in rows]
    print(f"all {len(rows)} runs, a run without a path at the limit: median first path RRTConnect "
          f"{1e3 * med(a for a, _ in at_limit):.1f} ms, dimension-RRT {1e3 * med(b for _, b in at_limit):.1f} ms")


def _broadphase_ab(args: argparse.Namespace, problem, queries: list) -> None:
    """Each planner on each query's two setups (broadphase / pair loop), alternating; median first path per kind."""
    from tpee_ompl.model import robots
    from tpee_ompl.planning.setup import make_simple_setup

    checkers = {}
    for kind in ("broadphase", "pair loop"):  # the problem keeps one checker per process: two built here
        with collision_pools.broadphase(kind == "broadphase"):
            checkers[kind] = robots.panda_shelf() if args.problem == "panda-shelf" else robots.kinova_posts()
    times: dict[tuple[str, str], list[float]] = {}
    for k, query in enumerate(queries[: args.queries]):
        setups = {kind: make_simple_setup(c, query["start"], query["goal"], motion_validator="batched")
                  for kind, c in checkers.items()}
        for seed in range(args.seeds):
            for kind in (("broadphase", "pair loop") if (k + seed) % 2 == 0 else ("pair loop", "broadphase")):
                ss = setups[kind]
                si = ss.getSpaceInformation()
                for name in ("RRTConnect", "dimension-RRT"):
                    ou.RNG.setSeed(1 + 1000 * k + seed)  # the same random numbers for both kinds: the same runs
                    planner = og.RRTConnect(si) if name == "RRTConnect" else DimensionRRT(si, groups=problem.groups, seed=seed)
                    t = first_path_time(ss, planner, args.limit)
                    times.setdefault((name, kind), []).append(args.limit if t is None else t)
    print(f"{args.problem}, {args.queries} queries x {args.seeds} seeds, limit {args.limit} s (a run without a path at "
          "the limit), median first path:")
    for name in ("RRTConnect", "dimension-RRT"):
        on, off = statistics.median(times[name, "broadphase"]), statistics.median(times[name, "pair loop"])
        print(f"  {name}: broadphase {1e3 * on:.1f} ms, pair loop {1e3 * off:.1f} ms (pair loop / broadphase {off / on:.2f})")


if __name__ == "__main__":
    main()
