"""A non-TPEE problem in plain OMPL + numpy: a planar 4-link arm among circular obstacles.

It shows DimensionRRT in an ordinary ``og.SimpleSetup`` (C++ default motion validator, a Python
validity checker with an optional batched ``are_valid``), grouped ``[[0, 1], [2, 3]]``, no
prescribed group.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from ompl import base as ob
from ompl import geometric as og

__all__ = ["PlanarArm", "main", "make_planar_arm_setup"]


class PlanarArm(ob.StateValidityChecker):
    """Validity of a planar arm of equal links (base at the origin) against circles.

    Parameters
    ----------
    si : ob.SpaceInformation
    link_length : float
        Length of each of the 4 links (m).
    obstacles : array (m, 3)
        Circles as (x, y, radius), metres.
    samples_per_link : int
        Points checked along each link.
    """

    batched_protocol = True
    """``are_valid`` is the batched form of ``isValid`` (dimension-RRT takes it without asking it about the start)."""

    def __init__(self, si: ob.SpaceInformation, link_length: float, obstacles: np.ndarray, samples_per_link: int = 6) -> None:
        super().__init__(si)
        self.link_length = float(link_length)
        self.obstacles = np.asarray(obstacles, dtype=float).reshape(-1, 3)
        self._s = np.linspace(0.0, 1.0, samples_per_link)
        self.collision_checks = 0

    def points(self, Q: np.ndarray) -> np.ndarray:
        """Points along the links for configurations Q (N, 4), radians -> (N, 4 * samples, 2)."""
        Q = np.atleast_2d(Q)
        ang = np.cumsum(Q, axis=1)
        d = self.link_length * np.stack([np.cos(ang), np.sin(ang)], axis=-1)  # (N, 4, 2)
        joints = np.concatenate([np.zeros((len(Q), 1, 2)), np.cumsum(d, axis=1)], axis=1)  # (N, 5, 2)
        pts = joints[:, :-1, None, :] + self._s[None, None, :, None] * d[:, :, None, :]
        return pts.reshape(len(Q), -1, 2)

    def are_valid(self, Q: np.ndarray) -> np.ndarray:
        """Batched validity, bool (N,)."""
        P = self.points(Q)
        self.collision_checks += len(P)
        diff = P[:, :, None, :] - self.obstacles[None, None, :, :2]
        return np.all(np.einsum("npoc,npoc->npo", diff, diff) > self.obstacles[:, 2] ** 2, axis=(1, 2))

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL override)
        """True if no link point is inside an obstacle."""
        return bool(self.are_valid(np.array([[state[i] for i in range(4)]]))[0])


def make_planar_arm_setup(
    start: ArrayLike = (0.3, 0.0, 0.0, 0.0),
    goal: ArrayLike = (2.6, 0.0, 0.0, 0.0),
    obstacles: ArrayLike = ((0.0, 1.55, 0.35), (1.2, 1.2, 0.25), (-1.0, 1.0, 0.3)),
    link_length: float = 0.5,
    resolution: float = 0.005,
) -> og.SimpleSetup:
    """SimpleSetup over ``RealVectorStateSpace(4)`` in [-pi, pi]^4 with path-length objective.

    The default query sweeps the stretched arm from 0.3 rad to 2.6 rad past an obstacle above the
    base, so the arm must fold to pass.  ``ss.getStateValidityChecker()`` returns the
    :class:`PlanarArm` checker itself (its ``are_valid``, ``points`` and ``collision_checks``).  ValueError naming
    the argument for a start or goal that is not 4 angles in [-pi, pi], obstacles that are not rows of finite
    (x, y, radius > 0), a link length that is not a finite number > 0, or a resolution outside (0, 1).
    """
    ends = {}
    for name, q in (("start", start), ("goal", goal)):
        ends[name] = np.asarray(q, dtype=float)
        if ends[name].shape != (4,) or not np.all(np.abs(ends[name]) <= np.pi):  # NaN fails too
            raise ValueError(f"{name} must be 4 joint angles in [-pi, pi], got {q!r}")
    obs = np.asarray(obstacles, dtype=float)
    if obs.ndim != 2 or obs.shape[1] != 3 or not np.all(np.isfinite(obs)) or np.any(obs[:, 2] <= 0):
        raise ValueError(f"obstacles must be rows of finite (x, y, radius > 0), got {obstacles!r}")
    if not (np.isfinite(link_length) and link_length > 0):
        raise ValueError(f"link_length must be a finite number > 0, got {link_length!r}")
    if not 0.0 < resolution < 1.0:  # NaN fails too
        raise ValueError(f"resolution must be in (0, 1) (a fraction of the space's extent), got {resolution!r}")
    space = ob.RealVectorStateSpace(4)
    space.setBounds(-np.pi, np.pi)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    checker = PlanarArm(si, float(link_length), obs)
    ss.setStateValidityChecker(checker)
    si.setStateValidityCheckingResolution(resolution)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    s0, s1 = si.allocState(), si.allocState()
    s0[0:4] = ends["start"].tolist()
    s1[0:4] = ends["goal"].tolist()
    ss.setStartAndGoalStates(s0, s1, 1e-9)
    ss._planar_arm = checker  # type: ignore[attr-defined]  # keep the Python checker alive
    si.setup()
    return ss


def main() -> None:
    """``python -m tpee_ompl.examples.planar_arm``: dimension-RRT (improving for 1 s) and RRTConnect (stopping at its
    first path) on the default query, each in a fresh setup."""
    from ompl import util as ou

    from ..planning.dimension_rrt import DimensionRRT

    ou.setLogLevel(ou.LOG_WARN)
    for name, make in (("DimensionRRT [[0, 1], [2, 3]]", lambda si: DimensionRRT(si, groups=[[0, 1], [2, 3]], seed=1)),
                       ("RRTConnect", og.RRTConnect)):
        ss = make_planar_arm_setup()
        ss.setPlanner(make(ss.getSpaceInformation()))
        status = ss.solve(1.0)
        path = ss.getSolutionPath()
        print(f"{name:30s} {status}: length {path.length():.3f} rad, {path.getStateCount()} states, "
              f"valid {path.check()}, {ss.getStateValidityChecker().collision_checks} configurations checked")


if __name__ == "__main__":
    main()
