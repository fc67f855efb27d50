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
from .dimension_rrt_options import resolve_options

__all__ = ["tpee_dimension_rrt", "tpee_options"]


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

    Raises
    ------
    ValueError
        Groups whose first group is not DOF1/DOF2 (``[0, 1]``, the row Table 3 prescribes), ``h``
        other than the row's 7 steps (``max_h`` may raise it during the search), or a ``restart_after``.
    """
    row = cross_sector_trajectory(from_sector, to_sector)
    return DimensionRRT(si, tpee_options(options, **overrides), prescribed={0: row},
                        initial_waypoints=initial_waypoints)


def tpee_options(options: DimensionRRTOptions | None = None, **overrides: Any) -> DimensionRRTOptions:
    """The options :func:`tpee_dimension_rrt` plans with: ``options`` with the overrides, groups ``[[0, 1], [2, 3]]``
    when none are given; ValueError (as there) for a first group other than ``[0, 1]``, ``h`` other than Table 3's
    steps or a ``restart_after`` (no restarts on a prescribed row).  The library pipeline checks its settings with it
    when it is made."""
    if options is not None and not isinstance(options, DimensionRRTOptions):
        raise ValueError(f"options must be a DimensionRRTOptions, got {type(options).__name__}")
    if overrides.get("groups", options.groups if options is not None else None) is None:
        overrides["groups"] = ((0, 1), (2, 3))
    opts = resolve_options(options, overrides)
    if list(opts.groups[0]) != [0, 1]:
        raise ValueError(f"groups: Table 3 prescribes DOF1/DOF2, so the first group must be [0, 1], got "
                         f"{[list(g) for g in opts.groups]} (DimensionRRT plans other groupings without the rows)")
    if opts.restart_after is not None:  # DimensionRRT refuses it with a prescribed row (Table 3's): said here too
        raise ValueError("restart_after: restarts are for problems without a prescribed group (Table 3's rows "
                         "are released with release_after instead)")
    steps = len(cross_sector_trajectory(1, 2))  # every row of Table 3 has as many
    if opts.h != steps:
        raise ValueError(f"h must be {steps} for the wearer arm (Table 3's rows have {steps} fake-time steps), "
                         f"got {opts.h}; max_h lets the search raise it")
    return opts
