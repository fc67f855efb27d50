"""Posture sectors (paper Table 1), pointing sectors (Table 2) and the DOF1/DOF2 cross-sector trajectories (Table 3).

Degrees appear only in the two tables below, exactly as printed in the paper (with the one
correction noted); everything exported is in radians.
"""

from __future__ import annotations

import numpy as np

from ..validation import MAX_JOINT_VALUE, as_float_array

__all__ = [
    "CROSS_SECTOR_TRAJECTORIES",
    "POINTING_AZIMUTH",
    "POLAR_CAP",
    "POSTURE_AZIMUTH",
    "POSTURE_PRESETS",
    "PRESET_TOLERANCE",
    "SECTORS",
    "SECTOR_PAIRS",
    "check_sector",
    "cross_sector_trajectory",
    "cross_sector_length_bound",
    "in_pointing_sector",
    "infer_sector",
    "pointing_sectors",
    "posture_preset",
    "posture_sector",
    "sector_origin",
    "select_sector",
    "target_direction",
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

SECTOR_PAIRS: tuple[tuple[int, int], ...] = tuple(sorted(CROSS_SECTOR_TRAJECTORIES))
"""The 12 ordered cross-sector pairs (from, to), from != to, in lexicographic order."""

for _arr in (*POSTURE_PRESETS.values(), *CROSS_SECTOR_TRAJECTORIES.values()):
    _arr.setflags(write=False)


def check_sector(k: object) -> int:
    """Return k as a sector number 1-4, or raise ValueError."""
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or int(k) not in SECTORS:
        raise ValueError(f"unknown sector {k!r}: sectors are 1, 2, 3, 4")
    return int(k)


PRESET_TOLERANCE = 1e-6
"""Radians. How close DOF1/DOF2 must be to a Table-1 preset to be at it (:func:`infer_sector`, query files)."""


_PRESETS_FLOAT = {k: (float(v[0]), float(v[1])) for k, v in POSTURE_PRESETS.items()}


def infer_sector(q: np.ndarray) -> int | None:
    """The posture sector whose Table-1 preset (DOF1, DOF2) the configuration ``q`` is at, or None."""
    a, b = (float(v) for v in q[:2])  # plain floats: np.allclose took 20 us a sector, in every query's first path
    for k in SECTORS:
        p0, p1 = _PRESETS_FLOAT[k]
        if abs(a - p0) <= PRESET_TOLERANCE and abs(b - p1) <= PRESET_TOLERANCE:  # (False for NaN)
            return k
    return None


def posture_preset(k: int) -> np.ndarray:
    """(DOF1, DOF2) of posture sector k, radians, shape (2,)."""
    return POSTURE_PRESETS[check_sector(k)].copy()


def cross_sector_trajectory(i: int, j: int) -> np.ndarray:
    """Table 3 trajectory of (DOF1, DOF2) from sector i to sector j != i, radians, shape (7, 2)."""
    i, j = check_sector(i), check_sector(j)
    if i == j:
        raise ValueError(f"no cross-sector trajectory from sector {i} to itself")
    return CROSS_SECTOR_TRAJECTORIES[(i, j)].copy()


def cross_sector_length_bound(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> float:
    """Shortest joint-space length (rad) any path from ``start`` to ``goal`` can have while DOF1/DOF2 follow
    the Table 3 row from sector i to j: ``hypot(P, S)``, P the row's polyline length, S the straight
    distance of the other joints.

    Why: it separates what the prescribed row costs from what the search misses.  For segments
    (a_k, b_k), a_k the DOF1/DOF2 part and b_k the rest, Minkowski's inequality gives
    sum |(a_k, b_k)| >= hypot(sum |a_k|, sum |b_k|) >= hypot(P, S); a path whose other joints move
    straight, in proportion to the row's arc length, has exactly this length (obstacles ignored).
    """
    row = cross_sector_trajectory(i, j)
    start, goal = as_float_array(start, "start"), as_float_array(goal, "goal")
    if start.ndim != 1 or start.shape != goal.shape or start.size < 2:
        raise ValueError(f"start and goal must be configurations of the same size >= 2, got shapes "
                         f"{start.shape} and {goal.shape}")
    if not (np.all(np.abs(start) <= MAX_JOINT_VALUE) and np.all(np.abs(goal) <= MAX_JOINT_VALUE)):  # NaN fails too
        raise ValueError(f"start and goal must be finite joint angles within +/-{MAX_JOINT_VALUE:g} rad, got "
                         f"{start.tolist()} and {goal.tolist()}")
    for name, q, end in (("start", start, row[0]), ("goal", goal, row[-1])):
        if not np.allclose(q[:2], end, rtol=0.0, atol=1e-6):
            raise ValueError(f"{name}'s DOF1/DOF2 {q[:2].tolist()} are not the Table 3 row's end {end.tolist()} "
                             f"(sectors {i} -> {j})")
    p = float(np.linalg.norm(np.diff(row, axis=0), axis=1).sum())
    return float(np.hypot(p, np.linalg.norm(goal[2:] - start[2:])))


# ---------------------------------------------------------------------------------------------
# Pointing sectors (Table 2, re-derived for this model; see docs/pointing.md)
# ---------------------------------------------------------------------------------------------
#
# Directions are taken from the DOF1/DOF2 pivot (the origin of the paper's eq. 6), as azimuth
# alpha = atan2(y, x) (0 = ahead, +90 deg = the wearer's left) and elevation epsilon above the
# horizontal.  Posture sectors are the four azimuth quadrants, disjoint and covering the sphere:
#
#   3: front-left   0 <= alpha <  90    (posture 3 sits over the left shoulder)
#   4: front-right -90 <= alpha <  0    (posture 4 sits over the right shoulder)
#   2: rear-left   90 <= alpha <= 180   (posture 2 sits low behind, left)
#   1: rear-right -180 < alpha < -90    (posture 1 sits low behind, right)
#
# Pointing sector k is the azimuth range that posture k can aim into collision-free with a clear
# line of sight (>= 99% of targets, measured in docs/pointing.md), which contains posture sector
# k with a margin of at least 5 deg on every side (the hysteresis band), plus the cap
# epsilon >= POLAR_CAP, where every posture aims freely and azimuth is ill-defined.  As in the
# paper's Table 2, each side's stowed and shoulder pointing sectors both cover the front on their
# side; the rifle held at the chest and the arms block low targets across the front, so the
# margins past straight ahead are narrow (5-10 deg), those past the rear wide (20-50 deg).

_POLAR_CAP_DEG = 60.0

_POSTURE_AZIMUTH_DEG = {1: (-180.0, -90.0), 2: (90.0, 180.0), 3: (0.0, 90.0), 4: (-90.0, 0.0)}
_POINTING_AZIMUTH_DEG = {
    1: (-200.0, -5.0),  # the right half, 20 deg past the rear, to 5 deg short of straight ahead
    2: (10.0, 200.0),  # the left half, 20 deg past the rear, to 10 deg left of straight ahead
    3: (-5.0, 230.0),  # the left half, 5 deg past straight ahead, 50 deg into the rear-right
    4: (-230.0, 5.0),  # the right half, 5 deg past straight ahead, 50 deg into the rear-left
}

POLAR_CAP = float(np.deg2rad(_POLAR_CAP_DEG))
"""Radians. Directions at least this far above the horizontal belong to every pointing sector."""

POSTURE_AZIMUTH: dict[int, tuple[float, float]] = {
    k: (float(np.deg2rad(a)), float(np.deg2rad(b))) for k, (a, b) in _POSTURE_AZIMUTH_DEG.items()
}
"""Sector -> azimuth interval [lo, hi), radians, of the posture sector (disjoint, covering)."""

POINTING_AZIMUTH: dict[int, tuple[float, float]] = {
    k: (float(np.deg2rad(a)), float(np.deg2rad(b))) for k, (a, b) in _POINTING_AZIMUTH_DEG.items()
}
"""Sector -> azimuth interval [lo, hi], radians (may extend past +-pi), of the pointing sector."""

_DEFAULT_ORIGIN: np.ndarray | None = None


def sector_origin() -> np.ndarray:
    """World position (3,), metres, that sector directions are measured from: the packaged model's j1 pivot."""
    global _DEFAULT_ORIGIN
    if _DEFAULT_ORIGIN is None:
        from .wearer_arm import default_robot

        _DEFAULT_ORIGIN = default_robot().model.jointPlacements[1].translation.copy()
        _DEFAULT_ORIGIN.setflags(write=False)
    return _DEFAULT_ORIGIN


def target_direction(targets: np.ndarray, origin: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth (N,) in (-pi, pi] and elevation (N,) in [-pi/2, pi/2], radians, of targets (N, 3) from origin.

    Raises ValueError for non-finite targets or a target at the origin (no direction).
    """
    t = as_float_array(targets, "targets")
    single = t.ndim == 1
    t = np.atleast_2d(t)
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"targets must have shape (3,) or (N, 3); got {np.shape(targets)}")
    bad = ~np.all(np.isfinite(t), axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"targets contain NaN or inf: target {k} is {t[k]}")
    if origin is None:
        o = sector_origin()
    else:
        o = as_float_array(origin, "origin")
        if o.shape != (3,) or not np.all(np.isfinite(o)):
            raise ValueError(f"origin must be 3 finite numbers, got {origin!r}")
    with np.errstate(over="ignore", invalid="ignore"):
        d = t - o
    if not np.all(np.isfinite(d)):
        raise ValueError("targets minus origin overflow: coordinates too large")
    # scale each row by its largest coordinate so the norm cannot overflow (targets at 1e300 m)
    scale = np.max(np.abs(d), axis=1)
    if np.any(scale < 1e-9):
        k = int(np.flatnonzero(scale < 1e-9)[0])
        raise ValueError(f"target {k} {t[k]} is at the sector origin (the DOF1/DOF2 pivot) and has no direction")
    u = d / scale[:, None]
    az = np.arctan2(u[:, 1], u[:, 0])
    az = np.where(az <= -np.pi, np.pi, az)
    el = np.arcsin(np.clip(u[:, 2] / np.linalg.norm(u, axis=1), -1.0, 1.0))
    return (az[0], el[0]) if single else (az, el)


def _in_azimuth(az: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """az in [lo, hi] modulo 2*pi (interval length < 2*pi)."""
    return np.mod(az - lo, 2.0 * np.pi) <= (hi - lo) + 1e-12


def posture_sector(targets: np.ndarray, origin: np.ndarray | None = None) -> np.ndarray | int:
    """The posture sector (1-4) of each target (3,) or (N, 3): the azimuth quadrant seen from the pivot."""
    az, _ = target_direction(targets, origin)
    az_arr = np.atleast_1d(az)
    out = np.where(az_arr >= np.pi / 2, 2, np.where(az_arr >= 0, 3, np.where(az_arr >= -np.pi / 2, 4, 1)))
    return int(out[0]) if np.ndim(az) == 0 else out


def in_pointing_sector(targets: np.ndarray, k: int, origin: np.ndarray | None = None) -> np.ndarray | bool:
    """True where a target (3,) or (N, 3) lies in pointing sector k (Table 2, re-derived)."""
    k = check_sector(k)
    az, el = target_direction(targets, origin)
    lo, hi = POINTING_AZIMUTH[k]
    inside = _in_azimuth(np.atleast_1d(az), lo, hi) | (np.atleast_1d(el) >= POLAR_CAP)
    return bool(inside[0]) if np.ndim(az) == 0 else inside


def pointing_sectors(target: np.ndarray, origin: np.ndarray | None = None) -> tuple[int, ...]:
    """All pointing sectors that contain one target (3,), in increasing order (never empty)."""
    return tuple(k for k in SECTORS if in_pointing_sector(target, k, origin))


def select_sector(target: np.ndarray, current: int | None = None, origin: np.ndarray | None = None) -> int:
    """Sector to aim at target from, with hysteresis (Fig. 10).

    Keep ``current`` while the target stays in its pointing sector; otherwise (or with no current
    sector) return the target's posture sector.  Because every pointing sector contains its posture
    sector with a margin, a target moving along a posture-sector boundary causes at most one switch.
    One target (3,); ValueError for another shape (a batch has no single current sector).
    """
    if np.shape(target) != (3,):
        raise ValueError(f"target must be one point of shape (3,), got shape {np.shape(target)}")
    if current is not None:
        current = check_sector(current)
        if in_pointing_sector(target, current, origin):
            return current
    return int(posture_sector(target, origin))
