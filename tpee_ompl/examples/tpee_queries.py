"""Seeded TPEE cross-sector test queries for dimension-RRT (independent of the aiming IK).

A query goes from (preset of sector i, pan, tilt) to (preset of sector j, pan, tilt), pan/tilt
(DOF3, DOF4) drawn uniformly within the joint limits until the configuration is valid.  Queries
whose *straight* motion (Table 3 for DOF1/DOF2, linear for DOF3/DOF4) collides are preferred, so
planning is necessary.
"""

from __future__ import annotations

import numpy as np

from ..planning.paths import motion_is_valid
from ..model.queries import straight_motion
from ..model.wearer_arm import WearerArm
from ..model.sectors import cross_sector_trajectory, posture_preset
from ..validation import MAX_COUNT, as_float_array, check_bool, check_int

__all__ = ["cross_sector_query", "straight_motion_valid", "straight_motion_waypoints"]


def straight_motion_waypoints(i: int, j: int, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """The 7 waypoints (7, 4): Table 3 for DOF1/DOF2, DOF3/DOF4 linear from start to goal.

    ValueError when start or goal is not 4 finite numbers at the row's ends (the interior follows the row,
    so the answer would be about another motion); the waypoints are
    :func:`~tpee_ompl.model.queries.straight_motion`'s."""
    row = cross_sector_trajectory(i, j)
    start, goal = as_float_array(start, "start"), as_float_array(goal, "goal")
    for name, q, end in (("start", start, row[0]), ("goal", goal, row[-1])):
        if q.shape != (4,) or not np.all(np.isfinite(q)) or not np.allclose(q[:2], end, rtol=0.0, atol=1e-6):
            raise ValueError(f"{name} must be 4 finite numbers with DOF1/DOF2 at the Table 3 row's end {end.tolist()} "
                             f"(sectors {i} -> {j}), got {q.tolist()}")
    return straight_motion(start, goal, i, j)


def straight_motion_valid(robot: WearerArm, i: int, j: int, start: np.ndarray, goal: np.ndarray) -> bool:
    """True if the un-planned motion (Table 3 + linear DOF3/DOF4) is collision-free at the guarantee step."""
    return motion_is_valid(robot, straight_motion_waypoints(i, j, start, goal), robot.max_joint_step())


def cross_sector_query(
    robot: WearerArm,
    i: int,
    j: int,
    rng: np.random.Generator,
    need_planning: bool = True,
    tries: int = 200,
    limit_margin: float = 0.05,
) -> tuple[np.ndarray, np.ndarray]:
    """A valid (start, goal) pair, shape (4,) each, radians, from sector i to sector j.

    With ``need_planning`` the first pair (of up to ``tries``) whose straight motion collides is
    returned; if none does, the last valid pair.  Pan/tilt keep ``limit_margin`` (fraction of the
    range) away from the joint limits: at the limit corners (pan near +-3.3, tilt near -1.65) the
    barrel sits in a pocket that is a separate free-space component of every intermediate Table 3
    slice, so such queries have no solution along the prescribed DOF1/DOF2 (paper 4.1.3).
    """
    if not 0.0 <= limit_margin < 0.5:
        raise ValueError(f"limit_margin must be in [0, 0.5), got {limit_margin!r}")
    tries = check_int("tries", tries, minimum=1, maximum=MAX_COUNT)
    need_planning = check_bool("need_planning", need_planning)
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    p0, p1 = posture_preset(i), posture_preset(j)
    lo, hi = robot.lower[2:], robot.upper[2:]
    lo, hi = lo + limit_margin * (hi - lo), hi - limit_margin * (hi - lo)
    last = None
    for _ in range(tries):
        q0 = np.r_[p0, rng.uniform(lo, hi)]
        q1 = np.r_[p1, rng.uniform(lo, hi)]
        if not (robot.is_valid(q0) and robot.is_valid(q1)):
            continue
        last = (q0, q1)
        if not need_planning or not straight_motion_valid(robot, i, j, q0, q1):
            return last
    if last is None:
        raise RuntimeError(f"no valid query found for sectors {i} -> {j} in {tries} tries")
    return last
