"""Two continuous joints (``SO2StateSpace`` x 2) in plain OMPL: a problem with two ways round.

The first joint is blocked near 0 while the second is above 0.  From (-1, 0.5) to (1, 0.5) the short way (~3.0
rad) dips the second joint to 0 and crosses; the long way (~4.28 rad) goes round the first joint's circle.  The
paper's rule only shortens a path where it lies, so dimension-RRT keeps the way its first path took unless
``restart_after`` is set (README, "Restarts"; ``experiments/restarts.py``).
"""

from __future__ import annotations

from ompl import base as ob
from ompl import geometric as og

__all__ = ["make_so2_torus_setup"]


def make_so2_torus_setup() -> og.SimpleSetup:
    """The problem as an ``og.SimpleSetup`` with a path-length objective and its start and goal set."""
    space = ob.CompoundStateSpace()
    space.addSubspace(ob.SO2StateSpace(), 1.0)
    space.addSubspace(ob.SO2StateSpace(), 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: not (-0.2 < s[0].value < 0.2 and s[1].value > 0.0))
    si = ss.getSpaceInformation()
    a, b = si.allocState(), si.allocState()
    a[0].value, a[1].value, b[0].value, b[1].value = -1.0, 0.5, 1.0, 0.5
    ss.setStartAndGoalStates(a, b)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    return ss
