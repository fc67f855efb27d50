"""Random configurations of the wearer's arm, valid and colliding, for checker tests."""

from __future__ import annotations

import numpy as np

from tpee_ompl.model.robot_checker import RobotChecker


def valid_and_colliding(robot: RobotChecker, rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n valid and n invalid configurations drawn uniformly within the joint limits."""
    Q = rng.uniform(robot.lower, robot.upper, (max(4000, 8 * n), robot.nq))
    ok = robot.are_valid(Q)
    assert ok.sum() >= n and (~ok).sum() >= n
    return Q[ok][:n], Q[~ok][:n]
