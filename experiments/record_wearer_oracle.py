"""Record what WearerArm answers today, as the regression oracle for refactoring its checking code.

Writes tests/model/data/wearer_oracle.npz: seeded random configurations within limits (and some just
outside), the batched and single verdicts at three settings, clearances, closest pairs, lever arms,
the motion step, the pruned and kept collision pairs.  tests/model/test_wearer_oracle.py compares.

    PYTHONPATH=. python experiments/record_wearer_oracle.py
"""

from __future__ import annotations

import argparse
from pathlib import Path

from _common import summary
import numpy as np

from tpee_ompl.files import atomic_write, check_output_path
from tpee_ompl.model.wearer_arm import WearerArm

SETTINGS = {  # name -> WearerArm keyword arguments
    "default": {},
    "margin0": {"security_margin": 0.0},
    "links": {"link_margins": {"link3": 0.03, "link4": 0.05}},
}


def oracle_configs(robot: WearerArm, n: int, seed: int) -> np.ndarray:
    """n configurations uniform within limits, then n // 20 slightly beyond them."""
    rng = np.random.default_rng(seed)
    Q = robot.lower + rng.random((n, robot.nq)) * (robot.upper - robot.lower)
    span = robot.upper - robot.lower
    out = robot.lower - 0.05 * span + rng.random((n // 20, robot.nq)) * 1.1 * span
    return np.concatenate([Q, out])


def record(robot: WearerArm, Q: np.ndarray, prefix: str) -> dict[str, np.ndarray]:
    """Every answer of the checking API on Q, keyed with prefix."""
    names = robot.gmodel.geometryObjects
    pairs = [f"{names[cp.first].name}|{names[cp.second].name}" for cp in robot.gmodel.collisionPairs]
    within = np.array([robot.within_limits(q) for q in Q])
    inside = Q[within][:500]
    closest = [robot.closest_pair(q) for q in inside[:200]]
    return {
        f"{prefix}_are_valid": robot.are_valid(Q),
        f"{prefix}_is_valid": np.array([robot.is_valid(q) for q in Q[:1000]]),
        f"{prefix}_is_valid_values": np.array([robot.is_valid_values(q.tolist()) for q in Q[:1000]]),
        f"{prefix}_clearance": np.array([robot.clearance(q) for q in inside]),
        f"{prefix}_closest_names": np.array([f"{a}|{b}" for a, b, _ in closest]),
        f"{prefix}_closest_dist": np.array([d for _, _, d in closest]),
        f"{prefix}_lever_arms": robot.lever_arms(),
        f"{prefix}_max_joint_step": np.array(robot.max_joint_step() if robot.security_margin > 0 else np.nan),
        f"{prefix}_pruned_pairs": np.array(robot.pruned_pairs),
        f"{prefix}_pairs": np.array(pairs),
        f"{prefix}_n_pairs": np.array(len(pairs)),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "tests/model/data/wearer_oracle.npz")
    ap.add_argument("-n", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--force", action="store_true", help="replace --out (the recorded test oracle by default)")
    args = ap.parse_args()
    try:
        check_output_path(args.out, force=args.force, what="--out file")
    except (OSError, ValueError) as exc:
        ap.error(str(exc))
    base = WearerArm(n_threads=2)
    Q = oracle_configs(base, args.n, args.seed)
    data = {"Q": Q, "within": np.all((Q >= base.lower) & (Q <= base.upper), axis=1)}
    for name, kwargs in SETTINGS.items():
        data.update(record(WearerArm(n_threads=2, **kwargs), Q, name))
    def save(tmp: Path) -> None:
        with open(tmp, "wb") as f:  # (a file name not ending in .npz would get one added)
            np.savez_compressed(f, **data)

    atomic_write(args.out, save, force=args.force)
    valid = data["default_are_valid"]
    print(f"wrote {args.out}: {len(Q)} configs, {valid.sum()} valid at the default margin, "
          f"{data['default_n_pairs']} pairs ({data['default_pruned_pairs']} pruned)")


if __name__ == "__main__":
    main()
