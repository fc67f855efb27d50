"""Mesh robots of example-robot-data: what a check costs, whether the clearance-ball screen pays, and what
``convex_meshes=True`` changes.

    PYTHONPATH=. .venv/bin/python experiments/mesh_robots.py          # about 20 s

For each robot (UR5 with gripper, a Kinova arm, the SO101 arm, the Talos left arm), as a user would set it up:
the shipped URDF (continuous joints are SO2 angles in [-pi, pi]), and an SRDF that
disables the pairs of links touching in at least 95 % of 300 random configurations (the MoveIt setup
assistant's "always" pairs; found with the convex hulls, which touch at least as often as the meshes, and used
for both), plus the shipped SRDF's pairs of links the URDF has.  Prints, with the meshes as
they are and as convex hulls: the checker's build time, the cost of a batched check per configuration, the
share of 300 random configurations that are free, and the screen's cost ratio (:meth:`BallScreen.cost_ratio`;
the validator screens where it is at most ``SCREEN_COST_LIMIT``); the check's cost is the median of three
batches alternated with a twin checker that narrow-phases every pair (``collision_pools.BROADPHASE`` off),
whose cost follows in brackets.
"""

from __future__ import annotations

import argparse
import re
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

from _common import summary
import numpy as np
import pinocchio as pin

from tpee_ompl import RobotChecker
from tpee_ompl.model import collision_pools
from tpee_ompl.model.clearance_balls import SCREEN_COST_LIMIT

ROBOTS = ("ur5_gripper", "kinova", "so101", "talos_arm")


def robot_files(name: str, folder: Path, limited: bool = False) -> tuple[Path, Path | None, list[str]]:
    """The robot's URDF, its SRDF if shipped, its package dir.  ``limited``: a copy of the URDF (in ``folder``) with
    its continuous joints made revolute joints limited to +-pi (the workaround before continuous joints were
    planned as SO2 angles)."""
    import example_robot_data as erd
    from example_robot_data.robots_loader import ROBOTS as LOADERS

    loader = LOADERS[name]
    sub = loader.path + "/" + (loader.urdf_subpath + "/" if loader.urdf_subpath else "") + loader.urdf_filename
    base = Path(erd.getModelPath(sub))
    srdf = base / loader.path / loader.srdf_subpath / loader.srdf_filename if loader.srdf_filename else None
    package_dirs = [str((base / "../..").resolve())]
    shipped = srdf if srdf is not None and srdf.is_file() else None
    if not limited:
        return base / sub, shipped, package_dirs
    text = (base / sub).read_text()

    def as_revolute(m: re.Match) -> str:
        j = re.sub(r"<limit[^>]*/>", "", m.group(0).replace('type="continuous"', 'type="revolute"'))
        return j.replace("</joint>", f'<limit effort="10" velocity="1" lower="{-np.pi}" upper="{np.pi}"/></joint>')

    urdf = folder / f"{name}_limited.urdf"
    urdf.write_text(re.sub(r'<joint[^>]*type="continuous".*?</joint>', as_revolute, text, flags=re.S))
    return urdf, shipped, package_dirs


def user_srdf(urdf: Path, shipped: Path | None, package_dirs: list[str], out: Path) -> Path:
    """An SRDF disabling the pairs touching in >= 95 % of 300 random configurations, and the shipped SRDF's pairs
    whose links the URDF has."""
    rc = RobotChecker(urdf, None, package_dirs=package_dirs, convex_meshes=True)
    links = {f.name for f in rc.model.frames}
    pairs = set()
    if shipped is not None:
        for dc in ET.parse(shipped).getroot().iter("disable_collisions"):
            if dc.get("link1") in links and dc.get("link2") in links:
                pairs.add((dc.get("link1"), dc.get("link2")))
    gd = rc.new_check_data()
    hits: dict[tuple[str, str], int] = {}
    Q = np.random.default_rng(7).uniform(rc.lower, rc.upper, (300, rc.nq))
    for q in Q:
        pin.computeCollisions(rc.model, rc.data, rc.gmodel, gd, q, False)
        for k, r in enumerate(gd.collisionResults):
            if r.isCollision():
                cp = rc.gmodel.collisionPairs[k]
                geoms = rc.gmodel.geometryObjects
                key = tuple(rc.model.frames[geoms[i].parentFrame].name for i in (cp.first, cp.second))
                hits[key] = hits.get(key, 0) + 1
    pairs |= {p for p, n in hits.items() if n >= 0.95 * len(Q)}
    body = "\n".join(f'  <disable_collisions link1="{a}" link2="{b}" reason="Always"/>' for a, b in sorted(pairs))
    out.write_text(f'<?xml version="1.0"?>\n<robot name="user">\n{body}\n</robot>\n')
    return out


def main(argv: list[str] | None = None) -> None:
    argparse.ArgumentParser(description=summary(__doc__)).parse_args(argv)  # --help; no options
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name in ROBOTS:
            urdf, shipped, dirs = robot_files(name, folder)
            srdf = user_srdf(urdf, shipped, dirs, folder / f"{name}.srdf")
            for convex in (False, True):
                t = time.perf_counter()
                rc = RobotChecker(urdf, srdf, package_dirs=dirs, convex_meshes=convex)
                build = time.perf_counter() - t
                with collision_pools.broadphase(False):
                    loop = RobotChecker(urdf, srdf, package_dirs=dirs, convex_meshes=convex)
                Q = np.random.default_rng(0).uniform(rc.lower, rc.upper, (300, rc.nq))
                times: dict[int, list[float]] = {0: [], 1: []}
                for _ in range(3):
                    for k, checker in enumerate((rc, loop)):
                        t = time.perf_counter()
                        free = checker.are_valid(Q)
                        times[k].append((time.perf_counter() - t) / len(Q))
                check, check_loop = float(np.median(times[0])), float(np.median(times[1]))
                ratio = rc.ball_screen().cost_ratio(4 * rc.max_joint_step())
                screened = ratio is None or ratio <= SCREEN_COST_LIMIT
                print(f"{name:12s} {'convex hulls' if convex else 'meshes':12s} build {build:5.2f} s, "
                      f"{check * 1e6:7.0f} us per check ({check_loop * 1e6:.0f}), {free.mean():4.0%} free, screen cost ratio "
                      f"{'-' if ratio is None else f'{ratio:.1f}'} ({'screened' if screened else 'dense'})", flush=True)


if __name__ == "__main__":
    main()
