"""Microseconds per configuration for single, batched and raw Pinocchio/Coal collision checks,
and for the line-of-sight check, on this machine; then Pinocchio's tree broadphase against every pair in turn.

    python experiments/collision_throughput.py [--n 20000] [--repeats 5] [--seed 0]
    python experiments/collision_throughput.py --robots wearer panda kinova    # the broadphase table, ~1 min

The broadphase table (``collision_pools.BROADPHASE``, both kinds built for each robot in one process and
timed alternately, the median of --repeats): per configuration, a batched check in calls of 16 states on the
checker's threads and a single check (``is_valid_values``, the OMPL checker's path), on collision-free random
configurations (what a motion check mostly sees) and on all of them; the verdicts are compared too.  The Panda
and the Kinova arm need the optional ``robots`` extra.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np
import pinocchio as pin

from tpee_ompl.model import collision_pools
from tpee_ompl.model.wearer_arm import WearerArm

_ROBOTS = ("wearer", "panda", "kinova")


def _median_us(fn, n: int, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)) / n * 1e6


def main(argv: list[str] | None = None) -> dict[str, float]:
    """Measure and print the throughput table; returns the figures (µs per configuration)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=20000, help="configurations per batch")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--robots", nargs="+", choices=_ROBOTS, help="print the broadphase table for these robots only")
    args = ap.parse_args(argv)
    if args.robots:
        return broadphase_table(args.robots, min(args.n, 3000), args.repeats, args.seed)
    robot = WearerArm()
    rng = np.random.default_rng(args.seed)
    Q = rng.uniform(robot.lower, robot.upper, size=(args.n, robot.nq))
    QT = np.ascontiguousarray(Q.T)
    n_single = min(args.n, 5000)

    def raw_batch() -> None:
        pin.computeCollisionsInParallel(robot.n_threads, robot.pool, QT, True, False)

    collides = robot._collides

    def raw_single() -> None:
        for q in Q[:n_single]:
            collides(q, True)

    aimed = []
    for q in Q[:2000]:
        p, u = robot.muzzle(q)
        aimed.append((q, p + rng.uniform(2.0, 10.0) * u))

    figures = {
        "raw Pinocchio batch (computeCollisionsInParallel)": _median_us(raw_batch, args.n, args.repeats),
        "WearerArm.are_valid (batched)": _median_us(lambda: robot.are_valid(Q), args.n, args.repeats),
        "raw Pinocchio single (computeCollisions with the checker's manager, loop)": _median_us(raw_single, n_single, args.repeats),
        "WearerArm.is_valid (single)": _median_us(lambda: [robot.is_valid(q) for q in Q[:n_single]], n_single, args.repeats),
        "WearerArm.is_valid_values (single, OMPL checker path)": _median_us(
            lambda: [robot.is_valid_values(q) for q in Q[:n_single].tolist()], n_single, args.repeats
        ),
        "WearerArm.line_of_sight_clear (single)": _median_us(
            lambda: [robot.line_of_sight_clear(q, t) for q, t in aimed], len(aimed), args.repeats
        ),
    }
    print(f"# collision throughput: {platform.processor() or platform.machine()}, {robot.n_threads} threads, "
          f"{len(robot.gmodel.collisionPairs)} pairs, N={args.n}, median of {args.repeats}")
    print("| check | µs per configuration |\n|---|---|")
    for k, v in figures.items():
        print(f"| {k} | {v:.2f} |")
    ratio = figures["WearerArm.are_valid (batched)"] / figures["raw Pinocchio batch (computeCollisionsInParallel)"]
    print(f"\nbatched / raw batch = {ratio:.2f} (target <= 1.5)")
    figures["batched_over_raw"] = ratio
    return figures


def _robot(name: str, broadphase: bool):
    with collision_pools.broadphase(broadphase):
        if name == "wearer":
            return WearerArm()
        from tpee_ompl.model import robots

        return robots.panda_shelf() if name == "panda" else robots.kinova_posts()


def broadphase_table(names: list[str], n: int, repeats: int, seed: int) -> dict[str, float]:
    """Print µs per configuration with the tree broadphase and with every pair in turn, per robot; return the
    ratios (pair loop / broadphase)."""
    print("| robot | active pairs | states | batched, pair loop / broadphase (µs) | ratio | single, pair loop / "
          "broadphase (µs) | ratio | same verdicts |\n|---|---|---|---|---|---|---|---|")
    out = {}
    for name in names:
        on, off = _robot(name, True), _robot(name, False)
        Q = np.random.default_rng(seed).uniform(on.lower, on.upper, size=(n, on.nq))
        ok = off.are_valid(Q)
        same = bool((on.are_valid(Q) == ok).all()
                    and [on.is_valid_values(q) for q in Q[:500].tolist()] == ok[:500].tolist())
        pairs = len(on.gmodel.collisionPairs) - len(on.separated_pairs)
        for label, S in (("free", Q[ok]), ("all", Q)):
            S = S[:1000]
            times: dict[tuple[str, bool], list[float]] = {}
            for _ in range(repeats):
                for kind, robot in (("on", on), ("off", off)):
                    t0 = time.perf_counter()
                    for a in range(0, len(S), 16):
                        robot.are_valid(S[a : a + 16])
                    t1 = time.perf_counter()
                    for q in S.tolist():
                        robot.is_valid_values(q)
                    t2 = time.perf_counter()
                    times.setdefault((kind, True), []).append((t1 - t0) / len(S) * 1e6)
                    times.setdefault((kind, False), []).append((t2 - t1) / len(S) * 1e6)
            med = {k: float(np.median(v)) for k, v in times.items()}
            rb, rs = med["off", True] / med["on", True], med["off", False] / med["on", False]
            out[f"{name}_{label}_batched"], out[f"{name}_{label}_single"] = rb, rs
            print(f"| {name} | {pairs} | {label} ({len(S)}) | {med['off', True]:.1f} / {med['on', True]:.1f} | {rb:.2f} | "
                  f"{med['off', False]:.1f} / {med['on', False]:.1f} | {rs:.2f} | {'yes' if same else 'NO'} |")
    return out


if __name__ == "__main__":
    main()
