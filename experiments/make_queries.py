"""Regenerate the named cross-sector query sets in tpee_ompl/data/queries/ (paper section 5.1).

Usage: python experiments/make_queries.py [--seed N] [--n-per-pair N] [--out DIR] [--force]
(an existing set, e.g. the packaged one, is replaced only with --force)
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from _common import summary
from tpee_ompl.files import OutputExistsError, check_output_path
from tpee_ompl.model.queries import save_queries
from tpee_ompl.model.wearer_arm import default_robot
from tpee_ompl.planning.query_generation import generate_queries, planning_necessity
from tpee_ompl.resources import data_path

SETS = ("planning_necessary", "paper_random")


def get_argument_parser() -> argparse.ArgumentParser:
    """Command-line options."""
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--seed", type=int, default=2022, help="seed of the planning_necessary set (paper_random: seed + 1)")
    p.add_argument("--n-per-pair", type=int, default=10, help="queries per ordered sector pair (12 pairs)")
    p.add_argument("--out", type=Path, default=data_path("queries"), help="output directory")
    p.add_argument("--force", action="store_true", help="replace existing sets (the packaged ones by default)")
    return p


def main(argv: list[str] | None = None) -> None:
    """Generate both sets, save them, and log their planning-necessity rates."""
    ap = get_argument_parser()
    args = ap.parse_args(argv)
    for name in SETS:  # before any work: nothing is replaced without --force
        try:
            check_output_path(args.out / f"{name}.json", force=args.force, what="query set")
        except (OutputExistsError, ValueError) as exc:
            ap.error(str(exc))
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    robot = default_robot()
    for name, seed, require in zip(SETS, (args.seed, args.seed + 1), (True, False)):
        queries, stats = generate_queries(robot, n_per_pair=args.n_per_pair, seed=seed, require_planning=require)
        rate, per_pair = planning_necessity(robot, queries)
        extra = {
            "generator": "tpee_ompl.planning.query_generation.generate_queries",
            "n_per_pair": args.n_per_pair,
            "require_planning": require,
            "straight_motion_step_rad": 0.01,
            "planning_necessity_rate": rate,
            "planning_necessary_per_pair": {f"{i}->{j}": n for (i, j), n in sorted(per_pair.items())},
            "generation_stats": stats,
        }
        path = save_queries(args.out / f"{name}.json", queries, name=name, seed=seed,
                            model_hash=robot.model_hash, extra=extra, force=args.force)
        logging.getLogger("make_queries").info("%s: %d queries, planning necessary for %.1f%% (min per pair %d of %d) -> %s",
                     name, len(queries), 100 * rate, min(per_pair.values()), args.n_per_pair, path)


if __name__ == "__main__":
    main()
