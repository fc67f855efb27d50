"""What the load-time check for always-colliding pairs costs, and what it finds on example-robot-data's UR5.

    PYTHONPATH=. .venv/bin/python experiments/pair_diagnostics_cost.py          # about 30 s; needs '.[robots]'

For each robot (the wearer, the Panda shelf, the Kinova posts, the UR5 with its shipped ``ur5.srdf`` and the same
SRDF with ``wrist_2_link`` / ``ee_link`` disabled): the median over --reps timings of
:func:`tpee_ompl.model.pair_diagnostics.always_colliding_pairs` on the loaded robot, the pairs it names, and how many
of --configs uniform random configurations within the joint limits are valid (seed 0).
"""

from __future__ import annotations

import argparse
import logging
import statistics
import tempfile
import time
from pathlib import Path

from _common import summary
import numpy as np


def ur5_files() -> tuple[Path, Path]:
    import example_robot_data

    root = Path(example_robot_data.__file__).resolve()
    share = next(p for p in root.parents if (p / "cmeel.prefix").is_dir()) / "cmeel.prefix" / "share"
    robots = share / "example-robot-data" / "robots" / "ur_description"
    return robots / "urdf" / "ur5_robot.urdf", robots / "srdf" / "ur5.srdf"


def main() -> None:
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--reps", type=int, default=20)
    p.add_argument("--configs", type=int, default=400)
    args = p.parse_args()
    logging.disable(logging.WARNING)  # the UR5's warning is the point, not the output
    from tpee_ompl.model.pair_diagnostics import always_colliding_pairs
    from tpee_ompl.model.robot_checker import RobotChecker
    from tpee_ompl.model.robots import kinova_posts, panda_shelf
    from tpee_ompl.model.wearer_arm import WearerArm

    urdf, srdf = ur5_files()
    fixed = Path(tempfile.mkdtemp()) / "ur5_fixed.srdf"
    fixed.write_text(srdf.read_text().replace(
        "</robot>", '<disable_collisions link1="wrist_2_link" link2="ee_link" reason="Always"/></robot>'))
    share = urdf.parents[4]  # (cmeel.prefix/share: the folder holding example-robot-data)
    robots = {"wearer": WearerArm, "panda-shelf": panda_shelf, "kinova-posts": kinova_posts,
              "ur5 + ur5.srdf": lambda: RobotChecker(urdf, srdf, package_dirs=[share]),
              "ur5, pair disabled": lambda: RobotChecker(urdf, fixed, package_dirs=[share])}
    print(f"{'robot':20s} {'check (ms, median)':>18s}  valid of {args.configs}  always colliding")
    for name, make in robots.items():
        robot = make()
        times = []
        for _ in range(args.reps):
            t = time.perf_counter()
            found = always_colliding_pairs(robot)
            times.append(1e3 * (time.perf_counter() - t))
        frames, g = robot.model.frames, robot.gmodel.geometryObjects
        pairs = [(frames[g[robot.gmodel.collisionPairs[k].first].parentFrame].name,
                  frames[g[robot.gmodel.collisionPairs[k].second].parentFrame].name) for k in found]
        Q = np.random.default_rng(0).uniform(robot.lower, robot.upper, (args.configs, robot.nq))
        print(f"{name:20s} {statistics.median(times):18.2f}  {int(robot.are_valid(Q).sum()):>8d}       {pairs}")


if __name__ == "__main__":
    main()
