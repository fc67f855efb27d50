"""Figures of the pointing issue on the current model: IK accuracy, sector coverage, aim success.

    python experiments/pointing_figures.py [--targets 10000] [--directions 40000] [--seed 0]

IK accuracy: targets 1-20 m from the pivot in each posture's pointing sector, Pinocchio FK of the
returned configuration, perpendicular distance of the target from the barrel ray.  Coverage: share of
directions in at least one pointing sector.  Aim success: targets 2-10 m in pointing sector k that
posture k aims at collision-free with a clear line of sight.
"""

from __future__ import annotations

import argparse

import numpy as np

from tpee_ompl.model.pointing import BlindAreaError, aim_batch, aim_checked, aim_errors
from tpee_ompl.model.wearer_arm import default_robot
from tpee_ompl.model.sectors import SECTORS, in_pointing_sector, sector_origin


def _sphere(rng: np.random.Generator, n: int) -> np.ndarray:
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None]


def main(argv: list[str] | None = None) -> dict:
    """Measure and print the figures; returns them."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--targets", type=int, default=10000, help="targets per posture sector")
    ap.add_argument("--directions", type=int, default=40000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    robot, rng, origin = default_robot(), np.random.default_rng(args.seed), sector_origin()
    out: dict = {}
    dirs = origin + 5.0 * _sphere(rng, args.directions)
    count = sum(in_pointing_sector(dirs, k).astype(int) for k in SECTORS)
    out["coverage"] = float((count >= 1).mean())
    out["mean_sectors_per_direction"] = float(count.mean())
    print(f"coverage: {100 * out['coverage']:.2f}% of {args.directions} directions "
          f"({out['mean_sectors_per_direction']:.2f} pointing sectors per direction)")
    for k in SECTORS:
        t = origin + _sphere(rng, 4 * args.targets) * rng.uniform(1.0, 20.0, (4 * args.targets, 1))
        t = t[in_pointing_sector(t, k) & (t[:, 2] > 0.0)][: args.targets]
        Q = aim_batch(t, k, strict=False)
        solved = np.all(np.isfinite(Q), axis=1)
        worst = max(aim_errors(robot, q, p)[0] for q, p in zip(Q[solved], t[solved]))
        blind = 0
        for p in t[~solved]:
            try:
                aim_batch(p[None], k)
            except BlindAreaError:
                blind += 1
            except ValueError:
                pass
        t2 = origin + _sphere(rng, 4 * args.targets) * rng.uniform(2.0, 10.0, (4 * args.targets, 1))
        t2 = t2[in_pointing_sector(t2, k)][: args.targets]
        _, ok = aim_checked(robot, t2, k)
        out[k] = {"ik_solved": float(solved.mean()), "worst_perpendicular_m": float(worst), "blind": blind,
                  "aim_success": float(ok.mean())}
        print(f"sector {k}: IK solved {100 * solved.mean():.3f}% of {len(t)} targets 1-20 m "
              f"(blind area {blind}), worst miss {worst:.1e} m; aims collision-free with clear line of sight "
              f"at {100 * ok.mean():.2f}% of {len(t2)} targets 2-10 m")
    return out


if __name__ == "__main__":
    main()
