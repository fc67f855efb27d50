"""Microseconds per configuration for single, batched and raw Pinocchio/Coal collision checks,
and for the line-of-sight check, on this machine.

    python experiments/collision_throughput.py [--n 20000] [--repeats 5] [--seed 0]
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np
import pinocchio as pin

from tpee_ompl.model.wearer_arm import WearerArm


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
    args = ap.parse_args(argv)
    robot = WearerArm()
    rng = np.random.default_rng(args.seed)
    Q = rng.uniform(robot.lower, robot.upper, size=(args.n, robot.nq))
    QT = np.ascontiguousarray(Q.T)
    n_single = min(args.n, 5000)
    m, d, gm, gd = robot.model, robot.data, robot.gmodel, robot.gdata

    def raw_batch() -> None:
        pin.computeCollisionsInParallel(robot.n_threads, robot.pool, QT, True, False)

    def raw_single() -> None:
        for q in Q[:n_single]:
            pin.computeCollisions(m, d, gm, gd, q, True)

    aimed = []
    for q in Q[:2000]:
        p, u = robot.muzzle(q)
        aimed.append((q, p + rng.uniform(2.0, 10.0) * u))

    figures = {
        "raw Pinocchio batch (computeCollisionsInParallel)": _median_us(raw_batch, args.n, args.repeats),
        "WearerArm.are_valid (batched)": _median_us(lambda: robot.are_valid(Q), args.n, args.repeats),
        "raw Pinocchio single (computeCollisions loop)": _median_us(raw_single, n_single, args.repeats),
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


if __name__ == "__main__":
    main()
