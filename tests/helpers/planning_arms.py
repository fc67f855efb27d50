"""Foreign set-ups for the planning tests, in plain OMPL + numpy: planar n-joint arms among circles.

The validity checker is a plain Python function (no batched ``are_valid``), the motion validator is
OMPL's default, as a user who never heard of this project would set it up.
"""

from __future__ import annotations

import math

import numpy as np
from ompl import base as ob
from ompl import geometric as og

SIX_JOINT_OBSTACLES = ((0.0, 1.0, 0.25), (-0.9, 0.8, 0.2), (0.9, 0.75, 0.2))
"""Circles (x, y, r) around a 6-joint arm of reach 1.5 sweeping from 0.3 rad to 2.8 rad."""


def arm_points(q: np.ndarray, link: float, per_link: int = 4) -> np.ndarray:
    """Points along the links of a planar arm with joint angles q (n,), base at the origin -> (n * per_link, 2)."""
    ang = np.cumsum(q)
    d = link * np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    joints = np.vstack([np.zeros((1, 2)), np.cumsum(d, axis=0)])
    s = np.linspace(0.0, 1.0, per_link)
    return (joints[:-1, None, :] + s[None, :, None] * d[:, None, :]).reshape(-1, 2)


def planar_arm_setup(
    n: int = 6,
    start: tuple[float, ...] | None = None,
    goal: tuple[float, ...] | None = None,
    obstacles: tuple[tuple[float, float, float], ...] = SIX_JOINT_OBSTACLES,
    reach: float = 1.5,
    continuous: bool = False,
    resolution: float = 0.01,
) -> og.SimpleSetup:
    """A planar arm with n revolute joints in [-pi, pi] (SO2 joints if ``continuous``), path-length objective."""
    if continuous:
        space = ob.CompoundStateSpace()
        for _ in range(n):
            space.addSubspace(ob.SO2StateSpace(), 1.0)
    else:
        space = ob.RealVectorStateSpace(n)
        space.setBounds(-math.pi, math.pi)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    obs = np.asarray(obstacles, dtype=float).reshape(-1, 3)
    link = reach / n

    def read(s: ob.State) -> np.ndarray:
        return np.array([s[i].value for i in range(n)] if continuous else [s[i] for i in range(n)])

    def valid(s: ob.State) -> bool:
        p = arm_points(read(s), link)
        diff = p[:, None, :] - obs[None, :, :2]
        return bool(np.all(np.einsum("poc,poc->po", diff, diff) > obs[:, 2] ** 2))

    ss.setStateValidityChecker(valid)
    si.setStateValidityCheckingResolution(resolution)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    start = (0.3,) + (0.0,) * (n - 1) if start is None else start
    goal = (2.8,) + (0.0,) * (n - 1) if goal is None else goal
    s0, s1 = si.allocState(), si.allocState()
    for state, q in ((s0, start), (s1, goal)):
        for i in range(n):
            if continuous:
                state[i].value = float(q[i])
            else:
                state[i] = float(q[i])
    ss.setStartAndGoalStates(s0, s1, 1e-9)
    ss._valid_fn = valid  # type: ignore[attr-defined]  # keep the Python checker alive
    ss.endpoint_states = (s0, s1)  # type: ignore[attr-defined]  # copies (never pdef.getStartState from Python)
    si.setup()
    return ss
