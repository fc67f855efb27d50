"""A cross-sector motion for command-line tests: sector 1 preset -> sector 4 preset, pan/tilt zero."""

from __future__ import annotations

from tpee_ompl.model.sectors import posture_preset

START = [*posture_preset(1), 0.0, 0.0]
GOAL = [*posture_preset(4), 0.0, 0.0]


def start_goal_args() -> list[str]:
    """``--start ... --goal ...`` for START and GOAL."""
    return ["--start", *map(str, START), "--goal", *map(str, GOAL)]
