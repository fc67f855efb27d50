"""Generate the Kinova posts problem's SRDF (tpee_ompl/data/model/kinova_posts.srdf) and query set
(tpee_ompl/data/queries/kinova_posts.json), seeded.

The SRDF disables the link pairs touching in at least 95 % of 300 random configurations of the arm alone (its
meshes as convex hulls; ``mesh_robots.user_srdf``, the MoveIt setup assistant's "always" pairs; example-robot-data's
own SRDF disables none).  Each query joins two random collision-free configurations (uniform within the limits;
the continuous joints anywhere on the circle) whose straight motion collides (``si.checkMotion`` of
``make_simple_setup``: the short way round for a continuous joint); its label says whether a continuous joint's
short way crosses pi (``across-pi``) or not (``within``).  Finally OMPL's RRTConnect tries each query for
--check-time seconds; the count is reported (unsolved queries are kept: a harder query is still a valid query).

    PYTHONPATH=. python experiments/make_kinova_queries.py
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from _common import summary
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_panda_queries import check_outputs, save_robot_queries  # noqa: E402
from mesh_robots import user_srdf  # noqa: E402

from tpee_ompl.model.joint_queries import JointQuery  # noqa: E402
from tpee_ompl.model.robots import KINOVA_SRDF, kinova_files, kinova_posts  # noqa: E402
from tpee_ompl.planning.space_layout import RealVectorLayout  # noqa: E402
from tpee_ompl.planning.setup import make_simple_setup  # noqa: E402
from tpee_ompl.resources import data_path, query_set_path  # noqa: E402


def make_queries(checker, rng: np.random.Generator, n: int) -> list[JointQuery]:
    """n queries between random free configurations whose straight motion collides."""
    si = make_simple_setup(checker).getSpaceInformation()
    layout = RealVectorLayout(si.getStateSpace())
    queries: list[JointQuery] = []
    while len(queries) < n:
        Q = rng.uniform(checker.lower, checker.upper, (64, checker.nq))
        free = Q[checker.are_valid(Q)]
        for a, b in zip(free[0::2], free[1::2]):
            if len(queries) == n:
                break
            if si.checkMotion(layout.write(si.allocState(), a), layout.write(si.allocState(), b)):
                continue  # straight motion free: no planning needed
            across = bool((np.abs(b - a)[checker.circular] > np.pi).any())
            queries.append(JointQuery(len(queries), a, b, "across-pi" if across else "within"))
    return queries


def main() -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--out", type=Path, default=query_set_path("kinova_posts"))
    ap.add_argument("--srdf", type=Path, default=data_path("model", KINOVA_SRDF))
    ap.add_argument("-n", type=int, default=30, help="number of queries")
    ap.add_argument("--seed", type=int, default=2022)
    ap.add_argument("--check-time", type=float, default=1.0, help="RRTConnect seconds per query (0: skip)")
    ap.add_argument("--force", action="store_true", help="replace --out and --srdf if they exist (the packaged files "
                    "by default)")
    args = ap.parse_args()
    check_outputs(ap, [args.out, args.srdf], args.force)
    urdf, dirs = kinova_files()
    user_srdf(urdf, None, dirs, args.srdf)
    print(f"wrote {args.srdf}")
    checker = kinova_posts(n_threads=1, srdf=args.srdf)
    queries = make_queries(checker, np.random.default_rng(args.seed), args.n)
    labels = {label: sum(q.label == label for q in queries) for label in ("across-pi", "within")}
    save_robot_queries(args.out, queries, "kinova_posts", args.seed, checker, {"labels": labels}, args.check_time,
                       force=args.force)
    print(f"wrote {len(queries)} queries to {args.out} ({labels})")


if __name__ == "__main__":
    main()
