"""Foreign set-ups for the planning tests, in plain OMPL + numpy: planar n-joint arms among circles.

The validity checker is a plain Python callable (no batched ``are_valid``), the motion validator is
OMPL's default, as a user who never heard of this project would set it up.  The arm itself is
``tpee_ompl.bench.generic_problems``'s (which imports only OMPL and numpy); this module adds the tests' defaults.
"""

from __future__ import annotations

from ompl import geometric as og

from tpee_ompl.bench import generic_problems as generic
from tpee_ompl.bench.generic_problems import arm_points

__all__ = ["SIX_JOINT_OBSTACLES", "arm_points", "planar_arm_setup"]

SIX_JOINT_OBSTACLES = generic.ARM_OBS
"""Circles (x, y, r) around a 6-joint arm of reach 1.5 sweeping from 0.3 rad to 2.8 rad."""


def planar_arm_setup(
    n: int = 6,
    start: tuple[float, ...] | None = None,
    goal: tuple[float, ...] | None = None,
    obstacles: tuple[tuple[float, float, float], ...] = SIX_JOINT_OBSTACLES,
    reach: float = 1.5,
    continuous: bool = False,
    resolution: float = 0.01,
) -> og.SimpleSetup:
    """A planar arm with n revolute joints in [-pi, pi] (SO2 joints if ``continuous``), path-length objective.

    By default it sweeps from (0.3, 0, ...) to (2.8, 0, ...); ``ss.endpoint_states`` are its start and goal states.
    """
    start = (0.3,) + (0.0,) * (n - 1) if start is None else start
    goal = (2.8,) + (0.0,) * (n - 1) if goal is None else goal
    ss, _ = generic.planar_arm_setup(n, start, goal, obstacles, continuous=continuous, resolution=resolution,
                                     reach=reach)
    return ss
