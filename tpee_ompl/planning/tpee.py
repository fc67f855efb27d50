"""Dimension-RRT for the wearer's arm: the TPEE-specific factory (Table 3 prescribes DOF1/DOF2).

The generic planner (:mod:`tpee_ompl.planning.dimension_rrt`) knows nothing of sectors; this module
binds it to the paper's cross-sector trajectories.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from ompl import base as ob

from ..model.sectors import cross_sector_trajectory
from .dimension_rrt import DimensionRRT, DimensionRRTOptions

__all__ = ["tpee_dimension_rrt"]


def tpee_dimension_rrt(
    si: ob.SpaceInformation,
    from_sector: int,
    to_sector: int,
    options: DimensionRRTOptions | None = None,
    *,
    initial_waypoints: np.ndarray | None = None,
    **overrides: Any,
) -> DimensionRRT:
    """DimensionRRT for the wearer arm from sector ``from_sector`` to ``to_sector``.

    Groups ``[[0, 1], [2, 3]]`` unless ``options`` says otherwise; DOF1/DOF2 follow the Table 3 row
    (7 fake-time steps).  ``options``, ``initial_waypoints`` and the keyword overrides are those of
    :class:`DimensionRRT`.
    """
    if options is None or options.groups is None:
        overrides.setdefault("groups", ((0, 1), (2, 3)))
    prescribed = {0: cross_sector_trajectory(from_sector, to_sector)}
    return DimensionRRT(si, options, prescribed=prescribed, initial_waypoints=initial_waypoints, **overrides)
