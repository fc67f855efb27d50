"""Stand-ins and small builds shared by the path-library tests (tests/library/).

A stand-in sampler (sector presets, random valid pan/tilt) and planners (Table 3 DOF1/2 with a
straight DOF3/4, else RRTConnect) keep library tests fast; :func:`build_rrt_library` uses the real
builders (the query generator's sampling and dimension-RRT) with small caps.
"""

from __future__ import annotations

import numpy as np
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.library import N_FAKE_TIME_STEPS, PathLibrary
from tpee_ompl.model.sectors import cross_sector_trajectory, posture_preset
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.paths import motion_is_valid, path_to_array
from tpee_ompl.planning.setup import make_simple_setup

PAIRS = ((1, 2), (2, 3))
"""Pairs of the stand-in library: straight stand-in paths are often valid here (never for 3 <-> 4)."""
RRT_PAIRS = ((1, 2), (3, 4))
"""Pairs of the small dimension-RRT library."""


def sampler(robot: WearerArm):
    """Stand-in for the query generator: sector presets for DOF1/2, random valid pan/tilt."""

    def sample(rng: np.random.Generator, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
        out = []
        for k in (i, j):
            while True:
                q = np.concatenate([posture_preset(k), rng.uniform(robot.lower[2:], robot.upper[2:])])
                if robot.is_valid(q):
                    out.append(q)
                    break
        return out[0], out[1]

    return sample


def straight_plan(robot: WearerArm):
    """Stand-in for dimension-RRT: Table 3 DOF1/2, linear DOF3/4, returned only if it passes the motion check."""

    def plan(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray | None:
        u = np.linspace(0.0, 1.0, N_FAKE_TIME_STEPS)[:, None]
        W = np.hstack([cross_sector_trajectory(i, j), start[2:] + u * (goal[2:] - start[2:])])
        W[0], W[-1] = start, goal
        return W if motion_is_valid(robot, W) else None

    return plan


def rrt_plan(robot: WearerArm):
    """The straight stand-in, else OMPL RRTConnect (simplified, re-spaced to 7 waypoints on the same segments)."""
    straight = straight_plan(robot)
    ou.setLogLevel(ou.LOG_WARN)

    def plan(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray | None:
        W = straight(start, goal, i, j)
        if W is not None:
            return W
        ss = make_simple_setup(robot, start, goal)
        ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
        if not ss.solve(2.0) or not ss.haveExactSolutionPath():
            return None
        ss.simplifySolution(0.5)
        path = ss.getSolutionPath()
        if path.getStateCount() > N_FAKE_TIME_STEPS:
            return None
        path.interpolate(N_FAKE_TIME_STEPS)  # adds states on the existing segments only
        W = path_to_array(path, 4)
        return W if W.shape == (N_FAKE_TIME_STEPS, 4) else None

    return plan


def build_standin_library(robot: WearerArm) -> PathLibrary:
    """The stand-in library: 4 demos per pair of :data:`PAIRS` at least 0.3 rad apart, seed 7, 80 draws per pair."""
    return PathLibrary.build(robot, sampler(robot), straight_plan(robot), pairs=PAIRS, per_pair=4,
                             min_difference=0.3, seed=7, max_attempts=80)


def build_rrt_library(robot: WearerArm, **overrides) -> PathLibrary:
    """A small library of the default builders: 2 demos per pair of :data:`RRT_PAIRS`, 300 samples, seed 3."""
    kw = {"per_pair": 2, "seed": 3, "pairs": RRT_PAIRS, "max_samples": 300, "timeout": 5.0, **overrides}
    return PathLibrary.build_default(robot, **kw)


def necessary_queries(pairs, n: int) -> list:
    """The first ``n`` queries of the planning_necessary set whose pair is in ``pairs``."""
    from tpee_ompl.model.queries import load_queries

    return [q for q in load_queries("planning_necessary") if (q.from_sector, q.to_sector) in pairs][:n]
