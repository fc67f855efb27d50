"""Posture sectors (paper Table 1) and the DOF1/DOF2 cross-sector trajectories (Table 3).

Degrees appear only in the two tables below, exactly as printed in the paper (with the one
correction noted); everything exported is in radians.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "SECTORS",
    "POSTURE_PRESETS",
    "CROSS_SECTOR_TRAJECTORIES",
    "posture_preset",
    "cross_sector_trajectory",
    "check_sector",
]

SECTORS = (1, 2, 3, 4)

_TABLE1_DEG = {1: (-50, 160), 2: (50, 160), 3: (-50, 20), 4: (50, 20)}

# Table 3, (DOF1, DOF2) in degrees at the 7 fake-time steps.  Correction: the printed row 1->4
# ends at [20, 50], which is not sector 4's preset (50, 20) from Table 1; it is a transposition
# typo (the mirrored row 2->3 ends at sector 3's preset [-50, 20]), so we end it at [50, 20].
_TABLE3_DEG = {
    (1, 2): [(-50, 160), (-30, 150), (-15, 140), (0, 140), (15, 140), (30, 150), (50, 160)],
    (1, 3): [(-50, 160), (-50, 136), (-50, 113), (-50, 90), (-50, 67), (-50, 44), (-50, 20)],
    (1, 4): [(-50, 160), (-40, 136), (-20, 113), (0, 90), (20, 67), (40, 44), (50, 20)],
    (2, 1): [(50, 160), (30, 150), (15, 140), (0, 140), (-15, 140), (-30, 150), (-50, 160)],
    (2, 3): [(50, 160), (40, 136), (20, 113), (0, 90), (-20, 67), (-40, 44), (-50, 20)],
    (2, 4): [(50, 160), (50, 136), (50, 113), (50, 90), (50, 67), (50, 44), (50, 20)],
    (3, 1): [(-50, 20), (-50, 44), (-50, 67), (-50, 90), (-50, 113), (-50, 136), (-50, 160)],
    (3, 2): [(-50, 20), (-40, 44), (-20, 67), (0, 90), (20, 113), (40, 136), (50, 160)],
    (3, 4): [(-50, 20), (-40, 30), (-20, 40), (0, 40), (20, 40), (40, 30), (50, 20)],
    (4, 1): [(50, 20), (40, 44), (20, 67), (0, 90), (-20, 113), (-40, 136), (-50, 160)],
    (4, 2): [(50, 20), (50, 44), (50, 67), (50, 90), (50, 113), (50, 136), (50, 160)],
    (4, 3): [(50, 20), (40, 30), (20, 40), (0, 40), (-20, 40), (-40, 30), (-50, 20)],
}

POSTURE_PRESETS: dict[int, np.ndarray] = {k: np.deg2rad(np.array(v, dtype=float)) for k, v in _TABLE1_DEG.items()}
"""Sector -> (DOF1, DOF2) in radians (Table 1)."""

CROSS_SECTOR_TRAJECTORIES: dict[tuple[int, int], np.ndarray] = {
    k: np.deg2rad(np.array(v, dtype=float)) for k, v in _TABLE3_DEG.items()
}
"""(from, to) -> array (7, 2) of (DOF1, DOF2) in radians at the fake-time steps (Table 3)."""

for _arr in (*POSTURE_PRESETS.values(), *CROSS_SECTOR_TRAJECTORIES.values()):
    _arr.setflags(write=False)


def check_sector(k: object) -> int:
    """Return k as a sector number 1-4, or raise ValueError."""
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or int(k) not in SECTORS:
        raise ValueError(f"unknown sector {k!r}: sectors are 1, 2, 3, 4")
    return int(k)


def posture_preset(k: int) -> np.ndarray:
    """(DOF1, DOF2) of posture sector k, radians, shape (2,)."""
    return POSTURE_PRESETS[check_sector(k)].copy()


def cross_sector_trajectory(i: int, j: int) -> np.ndarray:
    """Table 3 trajectory of (DOF1, DOF2) from sector i to sector j != i, radians, shape (7, 2)."""
    i, j = check_sector(i), check_sector(j)
    if i == j:
        raise ValueError(f"no cross-sector trajectory from sector {i} to itself")
    return CROSS_SECTOR_TRAJECTORIES[(i, j)].copy()
