"""A load-time diagnostic: collision pairs within their margin in every configuration, so no state is ever valid.

A robot description can ship two links that sit closer than the security margin whatever the joints do (the
UR5 of ``example-robot-data`` with its ``ur5.srdf``: ``wrist_2_link`` and ``ee_link`` 1.98 cm apart, inside the
default 2 cm).  Every configuration is then invalid and a planner only reports an invalid start or a timeout.
:func:`warn_always_colliding` finds such pairs when a checker loads and says once which they are and how to fix it.

Cheap: the mid-range configuration is checked for every active pair (not stopping at the first collision), and
only the pairs found colliding there are checked again, one configuration at a time, in random configurations
within the joint limits, until none is left; for a sound robot that is one full collision check.  It uses its own
Pinocchio data, so it changes none of the checker's answers or counters (:attr:`RobotChecker.collision_checks`).
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    from .robot_checker import RobotChecker

__all__ = ["always_colliding_pairs", "warn_always_colliding"]

log = logging.getLogger(__name__)

N_SAMPLES = 48
"""Random configurations (within the joint limits, a fixed seed) besides the mid-range one."""
SEED = 20261201


def sample_configurations(robot: RobotChecker, n_samples: int = N_SAMPLES, seed: int = SEED) -> np.ndarray:
    """(1 + n_samples, nq): the mid-range configuration (0 for a continuous joint), then uniform ones within the
    joint limits (a fixed seed: the same robot gets the same answer)."""
    lower, upper = robot.lower, robot.upper
    rng = np.random.default_rng(seed)
    return np.vstack([(lower + upper) / 2, rng.uniform(lower, upper, (n_samples, robot.nq))])


def always_colliding_pairs(robot: RobotChecker, n_samples: int = N_SAMPLES, seed: int = SEED) -> list[int]:
    """Indices (``gmodel.collisionPairs``) of the checked pairs within their margin in every configuration of
    :func:`sample_configurations`; the pairs proven separated (:attr:`RobotChecker.separated_pairs`) are not checked."""
    model, gmodel = robot.model, robot.gmodel
    if not len(gmodel.collisionPairs):
        return []
    data, gdata = model.createData(), robot.new_check_data()  # margins as the checks use them, not the checks' own
    Q = sample_configurations(robot, n_samples, seed)
    pin.computeCollisions(model, data, gmodel, gdata, Q[0], False)
    active = gdata.activeCollisionPairs
    left = [k for k, r in enumerate(gdata.collisionResults) if active[k] and r.isCollision()]
    for q in Q[1:]:
        if not left:
            break
        pin.updateGeometryPlacements(model, data, gmodel, gdata, q)
        left = [k for k in left if pin.computeCollision(gmodel, gdata, k)]
    return left


def warn_always_colliding(robot: RobotChecker, n_samples: int = N_SAMPLES, seed: int = SEED) -> list[tuple[str, str]]:
    """Log one warning naming the link pairs of :func:`always_colliding_pairs`, and how to fix them; return those
    pairs (link names; an obstacle's as ``obstacle '<name>'``), empty when there are none."""
    pairs = always_colliding_pairs(robot, n_samples, seed)
    if not pairs:
        return []
    data, gdata = robot.model.createData(), pin.GeometryData(robot.gmodel)  # distances in the mid-range configuration
    pin.updateGeometryPlacements(robot.model, data, robot.gmodel, gdata, sample_configurations(robot, 0)[0])
    geoms, frames = robot.gmodel.geometryObjects, robot.model.frames
    margins = robot.pair_margins()
    found: dict[tuple[str, str], tuple[float, float]] = {}  # link pair -> (distance at mid-range, margin)
    for k in pairs:
        cp = robot.gmodel.collisionPairs[k]
        names = tuple(f"obstacle {g.name!r}" if g.parentFrame == 0 else frames[g.parentFrame].name
                      for g in (geoms[cp.first], geoms[cp.second]))
        d = float(pin.computeDistance(robot.gmodel, gdata, k).min_distance)  # 0 or less: overlapping
        old = found.get(names)
        found[names] = (min(d, old[0]), max(margins[k], old[1])) if old else (d, margins[k])
    shown = "; ".join(f"{a} / {b} ({'%.2f cm apart' % (100 * d) if d > 0 else 'overlapping'} in the mid-range "
                      f"configuration, margin {100 * m:.3g} cm)" for (a, b), (d, m) in found.items())
    links = [(a, b) for a, b in found if not a.startswith("obstacle ") and not b.startswith("obstacle ")]
    fixes = []
    if links:
        fixes.append("if the links are this close by design, disable the pair in the SRDF: " + " ".join(
            f'<disable_collisions link1="{a}" link2="{b}" reason="Always"/>' for a, b in links))
    if len(links) < len(found):
        fixes.append("move or shrink the obstacles named")
    if all(d > 0 for d, _ in found.values()):
        which = "security_margin" if all(m == robot.security_margin for _, m in found.values()) else "margins"
        fixes.append(f"or give a smaller {which}")
    log.warning("%s: %d collision pair%s within the security margin in every one of the %d configurations sampled "
                "within the joint limits, so every state will be invalid (a planner finds nothing): %s. To fix: %s",
                robot.files.urdf, len(found), "s are" if len(found) > 1 else " is", 1 + n_samples, shown,
                "; ".join(fixes))
    return list(found)
