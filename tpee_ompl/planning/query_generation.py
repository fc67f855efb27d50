"""Generating cross-sector benchmark queries (paper section 5.1) and testing whether planning is necessary.

A query is a target A in sector i and a target B in sector j != i; start = (Table 1 preset i,
aimed at A), goal = (preset j, aimed at B), both collision-free with a clear line of sight.
``planning_necessary`` targets come from per-sector regions where the straight motion
(:func:`~tpee_ompl.model.queries.straight_motion`) tends to hit the wearer (:data:`NECESSITY_REGIONS`);
``paper_random`` targets are uniform over directions in the posture sector, 2-10 m, as in the paper.
Loading and saving query files is :mod:`tpee_ompl.model.queries`.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from ..model.pointing import PointingGeometry, aim_checked
from ..model.queries import Query, straight_motion
from ..model.sectors import POSTURE_AZIMUTH, SECTORS, in_pointing_sector
from ..model.wearer_arm import WearerArm
from .paths import motion_is_valid

__all__ = [
    "NECESSITY_REGIONS",
    "STRAIGHT_MOTION_STEP",
    "BarrelRegion",
    "TargetRegion",
    "aimable_samples",
    "draw_cross_sector",
    "generate_queries",
    "planning_necessity",
    "straight_motion_valid",
]

log = logging.getLogger(__name__)

STRAIGHT_MOTION_STEP = 0.01
"""Radians. Joint step for the straight-motion check (the issue asks for 0.01 rad or finer)."""


@dataclass(frozen=True)
class TargetRegion:
    """A box in (azimuth, elevation, distance) seen from the DOF1/DOF2 pivot.

    Attributes
    ----------
    azimuth_deg, elevation_deg : (lo, hi), degrees (azimuth 0 ahead, +90 left)
    distance : (lo, hi), metres
    """

    azimuth_deg: tuple[float, float]
    elevation_deg: tuple[float, float]
    distance: tuple[float, float] = (2.0, 10.0)

    def sample(self, rng: np.random.Generator, n: int, origin: np.ndarray) -> np.ndarray:
        """n points (n, 3), uniform over directions in the box (area-uniform) and over distance."""
        az = np.deg2rad(rng.uniform(*self.azimuth_deg, n))
        s0, s1 = np.sin(np.deg2rad(self.elevation_deg))
        el = np.arcsin(rng.uniform(s0, s1, n))
        d = np.c_[np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)]
        return origin + d * rng.uniform(*self.distance, n)[:, None]


@dataclass(frozen=True)
class BarrelRegion:
    """Targets on the barrel's ray from posture k at a uniformly random pan/tilt within the joint limits.

    Uniform over the arm's own pointing directions rather than over the sphere: it reaches the
    directions that point past the wearer's gear (across the body, down past the hip), which
    uniform target directions almost never produce.

    Attributes
    ----------
    distance : (lo, hi), metres beyond the muzzle
    """

    distance: tuple[float, float] = (2.0, 10.0)

    def sample_for(self, robot: WearerArm, k: int, rng: np.random.Generator, n: int) -> np.ndarray:
        """n target points (n, 3) in the world frame."""
        import pinocchio as pin

        from ..model.sectors import posture_preset

        q = np.c_[np.tile(posture_preset(k), (n, 1)), rng.uniform(robot.lower[2:], robot.upper[2:], (n, 2))]
        fid = robot.muzzle_frame_id
        out = np.empty((n, 3))
        for m in range(n):
            pin.forwardKinematics(robot.model, robot.data, q[m])
            M = pin.updateFramePlacement(robot.model, robot.data, fid)
            out[m] = M.translation + rng.uniform(*self.distance) * M.rotation[:, 0]
        return out


_WIDE = (-60.0, 60.0)
_ACROSS_LOW = {3: TargetRegion((-5.0, 20.0), (-45.0, -5.0)), 4: TargetRegion((-20.0, 5.0), (-45.0, -5.0))}
NECESSITY_REGIONS: dict[int, tuple[TargetRegion, ...]] = {
    # stowed postures: ground targets ahead on their own side (the barrel swings across the
    # front, past the rifle and the arms), plus their whole pointing sector
    1: (TargetRegion((-25.0, -5.0), (-45.0, -5.0)), TargetRegion((-30.0, 0.0), (-15.0, 20.0)),
        TargetRegion((-200.0, -5.0), _WIDE), BarrelRegion()),
    2: (TargetRegion((10.0, 35.0), (-45.0, -5.0)), TargetRegion((10.0, 40.0), (-15.0, 20.0)),
        TargetRegion((10.0, 200.0), _WIDE), BarrelRegion()),
    # shoulder postures: no direction region stands out (docs/pointing.md); targets along the
    # barrel at random pan/tilt reach the across-the-body directions
    # and low targets just ahead, slightly across the body: the only region where the 3<->4 swing
    # (behind the helmet) meets the wearer with the barrel tilted down (measured: 2.3% / 0.7%)
    3: (_ACROSS_LOW[3], _ACROSS_LOW[3], _ACROSS_LOW[3], TargetRegion((-5.0, 230.0), _WIDE), BarrelRegion()),
    4: (_ACROSS_LOW[4], _ACROSS_LOW[4], _ACROSS_LOW[4], TargetRegion((-230.0, 5.0), _WIDE), BarrelRegion()),
}
"""Per-sector target regions of the ``planning_necessary`` set (measured in docs/pointing.md)."""


def _random_region(k: int) -> tuple[TargetRegion, ...]:
    lo, hi = np.rad2deg(POSTURE_AZIMUTH[k])
    return (TargetRegion((lo, hi), (-90.0, 90.0)),)


def straight_motion_valid(
    robot: WearerArm, start: np.ndarray, goal: np.ndarray, i: int, j: int, step: float = STRAIGHT_MOTION_STEP
) -> bool:
    """True if every state along the straight motion is collision-free, checked every ``step`` rad (at most the
    robot's own motion step, :func:`~tpee_ompl.planning.paths.motion_step`: 0.0122 rad for the wearer)."""
    return motion_is_valid(robot, straight_motion(start, goal, i, j), step)


def aimable_samples(
    robot: WearerArm,
    geometry: PointingGeometry,
    k: int,
    regions: Sequence[TargetRegion],
    rng: np.random.Generator,
    origin: np.ndarray,
    batch: int = 64,
    max_rounds: int = 200,
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Yield (target (3,), configuration (4,)) in sector k's regions, above the floor, aimable from posture k
    (RuntimeError after ``max_rounds`` batches in a row with none)."""
    empty_rounds = 0
    while empty_rounds < max_rounds:  # an endless stream; give up only when nothing is aimable
        empty_rounds += 1
        which = rng.integers(len(regions), size=batch)
        pts = np.concatenate([
            regions[r].sample_for(robot, k, rng, int((which == r).sum())) if isinstance(regions[r], BarrelRegion)
            else regions[r].sample(rng, int((which == r).sum()), origin)
            for r in range(len(regions))
        ])
        pts = pts[rng.permutation(len(pts))]
        pts = pts[(pts[:, 2] >= 0.0) & in_pointing_sector(pts, k, origin)]
        if len(pts) == 0:
            continue
        q, ok = aim_checked(robot, pts, k, geometry=geometry)
        if ok.any():
            empty_rounds = 0
        yield from zip(pts[ok], q[ok])
    raise RuntimeError(f"could not find aimable targets for sector {k} in {regions}")


def draw_cross_sector(
    robot: WearerArm, geometry: PointingGeometry, from_stream: Iterator[tuple[np.ndarray, np.ndarray]],
    to_stream: Iterator[tuple[np.ndarray, np.ndarray]], j: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """One cross-sector draw: the start aims from its posture at the next target of ``from_stream``, the goal from
    posture j at the next of ``to_stream``, its pan the solution closest to the start's (the smaller rotation).
    (start target, goal target, start, goal), or None when posture j cannot aim there from that pan."""
    ta, qa = next(from_stream)
    tb, _ = next(to_stream)
    qb, ok = aim_checked(robot, tb[None], j, pan_reference=qa[2], geometry=geometry)
    return (ta, tb, qa, qb[0]) if ok[0] else None


def generate_queries(
    robot: WearerArm,
    *,
    n_per_pair: int = 10,
    seed: int = 0,
    regions: dict[int, Sequence[TargetRegion]] | None = None,
    require_planning: bool = True,
    max_draws_per_pair: int = 6000,
) -> tuple[list[Query], dict]:
    """Seeded cross-sector queries, n_per_pair for each of the 12 ordered sector pairs.

    Parameters
    ----------
    robot : WearerArm
    n_per_pair : int
    seed : int
        Seeds ``np.random.default_rng``; the same seed and model give the same queries.
    regions : dict sector -> regions, optional
        Where targets are drawn; default :data:`NECESSITY_REGIONS` if ``require_planning``, else
        uniform directions over the posture sector (paper-style).
    require_planning : bool
        Keep only queries whose straight motion collides (the planning-necessary set); a pair with
        fewer than n_per_pair such queries in ``max_draws_per_pair`` draws is filled with other
        valid queries from the same regions (logged, and counted in ``stats["per_pair"]``).

    Returns
    -------
    queries : list of Query
    stats : dict
        ``drawn`` (candidate queries drawn), ``colliding`` (how many of those needed planning),
        ``raw_rate`` = colliding / drawn: the necessity rate of the regions before selection.
    """
    if n_per_pair < 1:
        raise ValueError("n_per_pair must be >= 1")
    rng = np.random.default_rng(seed)
    geometry = PointingGeometry.from_robot(robot)
    origin = geometry.pivot
    if regions is None:
        regions = NECESSITY_REGIONS if require_planning else {k: _random_region(k) for k in SECTORS}
    streams = {k: aimable_samples(robot, geometry, k, tuple(regions[k]), rng, origin) for k in SECTORS}
    queries: list[Query] = []
    drawn = colliding = 0
    per_pair: dict[str, dict[str, int]] = {}
    for i in SECTORS:
        for j in SECTORS:
            if i == j:
                continue
            needed: list[Query] = []
            spare: list[tuple] = []
            tries = 0
            while len(needed) < n_per_pair and tries < max_draws_per_pair:
                tries += 1
                draw = draw_cross_sector(robot, geometry, streams[i], streams[j], j)
                if draw is None:
                    continue
                needs = not straight_motion_valid(robot, draw[2], draw[3], i, j)
                drawn += 1
                colliding += needs
                if needs or not require_planning:
                    needed.append(draw)
                elif len(spare) < n_per_pair:
                    spare.append(draw)
            n_needed = len(needed) if require_planning else -1
            if len(needed) < n_per_pair:
                log.warning("pair %d->%d: %d planning-necessary queries in %d draws; filling with others",
                            i, j, len(needed), tries)
                needed += spare[: n_per_pair - len(needed)]
            if len(needed) < n_per_pair:
                raise RuntimeError(f"pair {i}->{j}: only {len(needed)} valid queries in {tries} draws")
            for ta, tb, qa, qb in needed:
                queries.append(Query(len(queries), i, j, ta, tb, qa, qb))
            per_pair[f"{i}->{j}"] = {"draws": tries, "planning_necessary_found": n_needed}
    stats = {"drawn": drawn, "colliding": colliding, "raw_rate": colliding / max(drawn, 1), "per_pair": per_pair}
    log.info("generated %d queries (seed %d): raw rate %.3f", len(queries), seed, stats["raw_rate"])
    return queries, stats


def planning_necessity(robot: WearerArm, queries: Sequence[Query]) -> tuple[float, dict[tuple[int, int], int]]:
    """Fraction of queries whose straight motion collides, and the count per ordered pair."""
    per_pair: dict[tuple[int, int], int] = {}
    total = 0
    for q in queries:
        needs = not straight_motion_valid(robot, q.start, q.goal, q.from_sector, q.to_sector)
        key = (q.from_sector, q.to_sector)
        per_pair[key] = per_pair.get(key, 0) + int(needs)
        total += needs
    return total / max(len(queries), 1), per_pair


