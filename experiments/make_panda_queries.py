"""Generate the Panda shelf query set (tpee_ompl/data/queries/panda_shelf.json), seeded.

Each query goes from the tool point in one labelled region (a shelf compartment, or the table
beside the shelf) to another; start and goal are collision-free and the straight joint-space
motion between them collides (checked at the checker's max_joint_step).  Configurations come from
position-only damped least-squares IK towards random points of each region, seeded near the SRDF's
``default`` posture (elbow up, hand down; +-0.4 rad), so that start and goal belong to one arm
family as in a pick-and-place task (seeds uniform over the limits gave wrist flips and 15-18 rad
joint-space paths that RRTConnect solved 7 times in 30 within 1 s).
Finally OMPL's RRTConnect tries each query for --check-time seconds; the count is reported
(unsolved queries are kept: a harder query is still a valid query).

    PYTHONPATH=. python experiments/make_panda_queries.py
"""

from __future__ import annotations

import argparse
import itertools
from pathlib import Path

from _common import summary
import numpy as np
import pinocchio as pin

from tpee_ompl.files import OutputExistsError, check_output_path
from tpee_ompl.model.joint_queries import JointQuery, save_joint_queries
from tpee_ompl.model.robots import PANDA_SHELF_REGIONS, PANDA_TOOL_FRAME, panda_region, panda_shelf
from tpee_ompl.planning.paths import motion_states
from tpee_ompl.resources import query_set_path


READY = np.array([0.0, -0.785398, 0.0, -2.35619, 0.0, 1.5707, 0.785398])
"""The Panda SRDF's ``default`` group state (radians): the IK seeds are drawn around it."""


def ik_position(checker, target: np.ndarray, q0: np.ndarray, iters: int = 80) -> np.ndarray:
    """Damped least-squares IK of the tool point to ``target`` (position only), clipped to the limits."""
    model, data = checker.model, checker.data
    fid = model.getFrameId(PANDA_TOOL_FRAME)
    q = q0.copy()
    for _ in range(iters):
        pin.framesForwardKinematics(model, data, q)
        err = target - data.oMf[fid].translation
        if np.linalg.norm(err) < 1e-3:
            break
        J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)[:3]
        q = np.clip(q + J.T @ np.linalg.solve(J @ J.T + 1e-3 * np.eye(3), err), checker.lower, checker.upper)
    return q


def region_configs(checker, rng: np.random.Generator, per_region: int, attempts: int) -> dict[str, list[np.ndarray]]:
    """Up to ``per_region`` valid configurations with the tool point in each region."""
    out: dict[str, list[np.ndarray]] = {label: [] for label in PANDA_SHELF_REGIONS}
    for label, (lo, hi) in PANDA_SHELF_REGIONS.items():
        for _ in range(attempts):
            if len(out[label]) >= per_region:
                break
            q0 = np.clip(READY + rng.uniform(-0.4, 0.4, checker.nq), checker.lower, checker.upper)
            q = ik_position(checker, lo + rng.random(3) * (np.asarray(hi) - lo), q0)
            if checker.is_valid(q) and panda_region(checker, q) == label:
                out[label].append(q)
    return out


def make_queries(checker, rng: np.random.Generator, n: int, pools: dict[str, list[np.ndarray]]) -> list[JointQuery]:
    """n queries across region pairs (round robin over shuffled pairs), straight motion colliding."""
    labels = [k for k, v in pools.items() if v]
    pairs = list(itertools.permutations(labels, 2))
    rng.shuffle(pairs)
    step = checker.max_joint_step()
    queries: list[JointQuery] = []
    for a, b in itertools.islice(itertools.cycle(pairs), 50 * n):
        if len(queries) == n:
            break
        qa = pools[a][rng.integers(len(pools[a]))]
        qb = pools[b][rng.integers(len(pools[b]))]
        if checker.are_valid(motion_states(qa, qb, step)).all():
            continue  # straight motion free: no planning needed
        queries.append(JointQuery(len(queries), qa, qb, f"{a}->{b}"))
    return queries


def rrtconnect_solved(checker, queries: list[JointQuery], seconds: float) -> list[bool]:
    """Whether OMPL's RRTConnect solves each query within ``seconds`` with make_simple_setup."""
    from ompl import geometric as og
    from ompl import util as ou

    from tpee_ompl.planning.setup import make_simple_setup

    ou.setLogLevel(ou.LOG_WARN)
    solved = []
    for q in queries:
        ss = make_simple_setup(checker, q.start, q.goal)
        ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
        solved.append(bool(ss.solve(seconds)) and ss.haveExactSolutionPath())
    return solved


def report_rrtconnect(checker, queries: list[JointQuery], seconds: float) -> dict:
    """:func:`rrtconnect_solved`, printed, and as the query set's ``rrtconnect_solved`` entry."""
    solved = rrtconnect_solved(checker, queries, seconds)
    print(f"RRTConnect solved {sum(solved)} of {len(solved)} within {seconds} s; unsolved ids "
          f"{[q.id for q, s in zip(queries, solved) if not s]}")
    return {"seconds": seconds, "solved": sum(solved), "of": len(solved)}


def check_outputs(ap: argparse.ArgumentParser, paths: list[Path], force: bool) -> None:
    """Refuse (a usage error, before any work) an output that exists unless ``force``: the defaults are the packaged
    files."""
    for path in paths:
        try:
            check_output_path(path, force=force)
        except (OutputExistsError, ValueError) as exc:
            ap.error(str(exc))


def save_robot_queries(out: Path, queries: list[JointQuery], robot: str, seed: int, checker, details: dict,
                       check_time: float, force: bool = True) -> None:
    """Write a robot's query set named ``robot``: its header names the robot, the margin, ``details`` and, when
    ``check_time`` > 0, how many queries RRTConnect solves in that time (:func:`report_rrtconnect`)."""
    extra = {"robot": robot, "security_margin": checker.security_margin, **details}
    if check_time > 0:
        extra["rrtconnect_solved"] = report_rrtconnect(checker, queries, check_time)
    save_joint_queries(out, queries, name=robot, seed=seed, checker=checker, extra=extra, force=force)


def main() -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--out", type=Path, default=query_set_path("panda_shelf"))
    ap.add_argument("-n", type=int, default=30, help="number of queries")
    ap.add_argument("--seed", type=int, default=2022)
    ap.add_argument("--per-region", type=int, default=12)
    ap.add_argument("--attempts", type=int, default=400, help="IK attempts per region at most")
    ap.add_argument("--check-time", type=float, default=1.0, help="RRTConnect seconds per query (0: skip)")
    ap.add_argument("--force", action="store_true", help="replace --out if it exists (the packaged set by default)")
    args = ap.parse_args()
    check_outputs(ap, [args.out], args.force)
    rng = np.random.default_rng(args.seed)
    checker = panda_shelf(n_threads=1)
    pools = region_configs(checker, rng, args.per_region, args.attempts)
    print("configurations per region:", {k: len(v) for k, v in pools.items()})
    queries = make_queries(checker, rng, args.n, pools)
    regions = {k: [list(lo), list(hi)] for k, (lo, hi) in PANDA_SHELF_REGIONS.items()}
    save_robot_queries(args.out, queries, "panda_shelf", args.seed, checker, {"regions": regions}, args.check_time,
                       force=args.force)
    print(f"wrote {len(queries)} queries to {args.out}")


if __name__ == "__main__":
    main()
