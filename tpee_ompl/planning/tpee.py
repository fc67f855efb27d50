"""Dimension-RRT for the wearer's arm: the TPEE-specific factory (Table 3 prescribes DOF1/DOF2).

The generic planner (:mod:`tpee_ompl.planning.dimension_rrt`) knows nothing of sectors; this module
binds it to the paper's cross-sector trajectories.
"""

from __future__ import annotations

from typing import Any

from ompl import base as ob

from ..model.sectors import cross_sector_trajectory
from .dimension_rrt import DimensionRRT

__all__ = ["tpee_dimension_rrt"]


def tpee_dimension_rrt(si: ob.SpaceInformation, from_sector: int, to_sector: int, **kw: Any) -> DimensionRRT:
    """DimensionRRT for the wearer arm: groups ``[[0, 1], [2, 3]]``, DOF1/DOF2 prescribed by Table 3.

    Keyword arguments go to :class:`DimensionRRT` (``h`` is 7, the length of the Table 3 rows).
    """
    kw.setdefault("groups", [[0, 1], [2, 3]])
    prescribed = {0: cross_sector_trajectory(from_sector, to_sector)}
    return DimensionRRT(si, prescribed=prescribed, **kw)
