"""Small OMPL problems for the planning tests: a unit box with a counted, batched box-obstacle checker."""

from __future__ import annotations

import numpy as np
from ompl import base as ob


class BoxObstacle(ob.StateValidityChecker):
    """Valid unless inside the axis-aligned box [lo, hi]; counts per-state and batched checks."""

    def __init__(self, si: ob.SpaceInformation, lo, hi) -> None:
        super().__init__(si)
        self.lo, self.hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        self.n = len(self.lo)
        self.calls = 0

    def are_valid(self, Q: np.ndarray) -> np.ndarray:
        Q = np.atleast_2d(Q)
        self.calls += len(Q)
        return ~np.all((Q >= self.lo) & (Q <= self.hi), axis=1)

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL override)
        return bool(self.are_valid(np.array([[state[i] for i in range(self.n)]]))[0])


def box_problem(lo=(0.4, -0.2), hi=(0.6, 0.2), resolution: float = 0.01) -> tuple[ob.SpaceInformation, BoxObstacle]:
    """A set-up SpaceInformation over [-1, 1]^n (n = len(lo)) with one box obstacle; keep both alive."""
    space = ob.RealVectorStateSpace(len(lo))
    space.setBounds(-1.0, 1.0)
    si = ob.SpaceInformation(space)
    checker = BoxObstacle(si, lo, hi)
    si.setStateValidityChecker(checker)
    si.setStateValidityCheckingResolution(resolution)
    si.setup()
    return si, checker


def free_so2_space(n: int = 2) -> ob.SpaceInformation:
    """A set-up SpaceInformation over ``n`` continuous joints (a compound of SO2 spaces), every state valid."""
    space = ob.CompoundStateSpace()
    for _ in range(n):
        space.addSubspace(ob.SO2StateSpace(), 1.0)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda s: True)
    si.setup()
    return si


class LengthTimes100(ob.OptimizationObjective):
    """An objective other than path length: a motion costs 100 x its length (a direct ``OptimizationObjective``
    subclass, so OMPL calls its Python ``motionCost``; a ``StateCostIntegralObjective`` subclass's is not called)."""

    def __init__(self, si: ob.SpaceInformation) -> None:
        super().__init__(si)
        self._si = si

    def stateCost(self, s: ob.State) -> ob.Cost:
        return ob.Cost(0.0)

    def motionCost(self, a: ob.State, b: ob.State) -> ob.Cost:
        return ob.Cost(100.0 * self._si.distance(a, b))


def locked_dimension_space(n: int, locked: int, value: float = 0.5, bound: float = 1.0) -> ob.RealVectorStateSpace:
    """A RealVector(n) space over [-bound, bound] whose dimension ``locked`` has bounds of width 0 (at ``value``),
    as OMPL users lock a joint."""
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    bounds.setLow(-bound)
    bounds.setHigh(bound)
    bounds.setLow(locked, value)
    bounds.setHigh(locked, value)
    space.setBounds(bounds)
    return space


class PathLengthTimes100(ob.PathLengthOptimizationObjective):
    """:class:`LengthTimes100` as a subclass of OMPL's path-length objective overriding its ``motionCost``: an
    ``isinstance`` test would take it for path length."""

    def __init__(self, si: ob.SpaceInformation) -> None:
        super().__init__(si)
        self._si = si

    def motionCost(self, a: ob.State, b: ob.State) -> ob.Cost:
        return ob.Cost(100.0 * self._si.distance(a, b))
