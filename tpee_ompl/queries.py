"""Cross-sector benchmark queries (paper section 5.1): generation, the straight-motion check, JSON I/O.

A query is a target A in sector i and a target B in sector j != i; start = (Table 1 preset i,
aimed at A), goal = (preset j, aimed at B), both collision-free with a clear line of sight.  Two
named sets live in ``experiments/queries/``:

* ``planning_necessary`` (default): targets drawn from per-sector regions where the straight
  motion tends to hit the wearer, kept only if it does when such queries can be found (see
  :data:`NECESSITY_REGIONS` and :func:`generate_queries`).
* ``paper_random``: targets uniform over directions in the posture sector, 2-10 m, above the
  floor, as in the paper.

The straight motion is Table 3's seven (DOF1, DOF2) waypoints with DOF3/DOF4 linear from start to
goal over the same fake-time steps (:func:`straight_motion`).
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .ompl_problem import polyline_motion_states
from .pointing import PointingGeometry, aim_checked
from .robot import WearerArm
from .sectors import (
    POSTURE_AZIMUTH,
    SECTORS,
    check_sector,
    cross_sector_trajectory,
    in_pointing_sector,
)

__all__ = [
    "FORMAT_VERSION",
    "NECESSITY_REGIONS",
    "QUERY_DIR",
    "Query",
    "QuerySetError",
    "BarrelRegion",
    "TargetRegion",
    "generate_queries",
    "load_queries",
    "load_query_set",
    "planning_necessity",
    "save_queries",
    "straight_motion",
    "straight_motion_valid",
]

log = logging.getLogger(__name__)

FORMAT_VERSION = 1
QUERY_DIR = Path(__file__).resolve().parent.parent / "experiments" / "queries"
"""Where the named query sets live (source tree)."""

STRAIGHT_MOTION_STEP = 0.01
"""Radians. Joint step for the straight-motion check (the issue asks for 0.01 rad or finer)."""


@dataclass(frozen=True, eq=False)
class Query:
    """One cross-sector planning query.

    Attributes
    ----------
    id : int
    from_sector, to_sector : int, 1-4
    target_a, target_b : ndarray (3,), metres, world frame
    start, goal : ndarray (4,), radians: preset DOF1/DOF2 plus the aiming DOF3/DOF4
    """

    id: int
    from_sector: int
    to_sector: int
    target_a: np.ndarray = field(repr=False)
    target_b: np.ndarray = field(repr=False)
    start: np.ndarray = field(repr=False)
    goal: np.ndarray = field(repr=False)

    def __post_init__(self) -> None:
        check_sector(self.from_sector)
        check_sector(self.to_sector)
        if self.from_sector == self.to_sector:
            raise ValueError(f"query {self.id}: from_sector == to_sector == {self.from_sector}")
        for name, n in (("target_a", 3), ("target_b", 3), ("start", 4), ("goal", 4)):
            try:
                a = np.array(getattr(self, name), dtype=float)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"query {self.id}: {name} must be {n} finite numbers, got {getattr(self, name)!r}") from exc
            if a.shape != (n,) or not np.all(np.isfinite(a)):
                raise ValueError(f"query {self.id}: {name} must be {n} finite numbers, got {a!r}")
            a.setflags(write=False)
            object.__setattr__(self, name, a)

    def to_dict(self) -> dict:
        """JSON-ready dict (lists of floats)."""
        return {
            "id": self.id,
            "from_sector": self.from_sector,
            "to_sector": self.to_sector,
            "target_a": self.target_a.tolist(),
            "target_b": self.target_b.tolist(),
            "start": self.start.tolist(),
            "goal": self.goal.tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict) -> Query:
        """Inverse of :meth:`to_dict`."""
        return cls(int(d["id"]), int(d["from_sector"]), int(d["to_sector"]),
                   d["target_a"], d["target_b"], d["start"], d["goal"])


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

        from .sectors import posture_preset

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


def straight_motion(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray:
    """Waypoints (7, 4): Table 3's (DOF1, DOF2) from sector i to j, DOF3/DOF4 linear start -> goal.

    The first and last waypoints are start and goal themselves.
    """
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    w = np.zeros((7, 4))
    w[:, :2] = cross_sector_trajectory(i, j)
    s = np.linspace(0.0, 1.0, 7)[:, None]
    w[:, 2:] = start[2:] + s * (goal[2:] - start[2:])
    w[0], w[-1] = start, goal
    return w


def straight_motion_valid(
    robot: WearerArm, start: np.ndarray, goal: np.ndarray, i: int, j: int, step: float = STRAIGHT_MOTION_STEP
) -> bool:
    """True if every state along the straight motion (checked every ``step`` rad) is collision-free."""
    w = straight_motion(start, goal, i, j)
    states = polyline_motion_states(w, step)
    return bool(robot.are_valid(states).all())


def _sample_aimable(
    robot: WearerArm,
    geometry: PointingGeometry,
    k: int,
    regions: Sequence[TargetRegion],
    rng: np.random.Generator,
    origin: np.ndarray,
    batch: int = 64,
    max_rounds: int = 200,
):
    """Yield (target (3,), configuration (4,)) in sector k's regions, above the floor, aimable from posture k."""
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
    streams = {k: _sample_aimable(robot, geometry, k, tuple(regions[k]), rng, origin) for k in SECTORS}
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
                ta, qa = next(streams[i])
                tb, _ = next(streams[j])
                # goal pan: the solution closest to the start pan (smaller rotation)
                qb, ok = aim_checked(robot, tb[None], j, pan_reference=qa[2], geometry=geometry)
                if not ok[0]:
                    continue
                needs = not straight_motion_valid(robot, qa, qb[0], i, j)
                drawn += 1
                colliding += needs
                if needs or not require_planning:
                    needed.append((ta, tb, qa, qb[0]))
                elif len(spare) < n_per_pair:
                    spare.append((ta, tb, qa, qb[0]))
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


def save_queries(
    path: str | os.PathLike,
    queries: Sequence[Query],
    *,
    name: str,
    seed: int,
    model_hash: str,
    extra: dict | None = None,
) -> Path:
    """Write a versioned JSON query set: format_version, name, seed, model_hash, queries (+ extra keys)."""
    doc = {"format_version": FORMAT_VERSION, "name": name, "seed": seed, "model_hash": model_hash}
    doc.update(extra or {})
    doc["queries"] = [q.to_dict() for q in queries]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc, indent=1) + "\n")
    return path


class QuerySetError(ValueError):
    """A query set file that cannot be used: not JSON, wrong format_version, bad entries, other model."""


def load_query_set(name_or_path: str | os.PathLike, robot: WearerArm | None = None) -> tuple[list[Query], dict]:
    """Queries and the file's header (everything but ``queries``); see :func:`load_queries`."""
    if isinstance(name_or_path, bool) or not isinstance(name_or_path, (str, os.PathLike)):
        raise ValueError(f"query set must be a name or a path, got {name_or_path!r}")
    p = Path(name_or_path)
    if not p.suffix and not p.exists():
        p = QUERY_DIR / f"{name_or_path}.json"
    if not p.is_file():
        raise FileNotFoundError(f"query set {str(name_or_path)!r} not found (looked at {p})")
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise QuerySetError(f"{p}: not a JSON query set (truncated or corrupt?): {exc}") from exc
    if not isinstance(doc, dict):
        raise QuerySetError(f"{p}: expected a JSON object at the top level, got {type(doc).__name__}")
    version = doc.get("format_version")
    if isinstance(version, bool) or version != FORMAT_VERSION:
        raise QuerySetError(f"{p}: unsupported format_version {version!r} (expected {FORMAT_VERSION})")
    entries = doc.get("queries")
    if not isinstance(entries, list):
        raise QuerySetError(f"{p}: 'queries' must be a list, got {type(entries).__name__}")
    queries = []
    for k, d in enumerate(entries):
        try:
            if not isinstance(d, dict):
                raise ValueError(f"expected an object, got {type(d).__name__}")
            queries.append(Query.from_dict(d))
        except (KeyError, TypeError, ValueError) as exc:
            raise QuerySetError(f"{p}: query {k} is malformed: {exc!r}") from exc
    header = {k: v for k, v in doc.items() if k != "queries"}
    if robot is not None and header.get("model_hash") != robot.model_hash:
        raise QuerySetError(
            f"{p}: made for model_hash {header.get('model_hash')!r}, but the robot's is {robot.model_hash!r} "
            "(regenerate the set for this model)"
        )
    return queries, header


def load_queries(name_or_path: str | os.PathLike, robot: WearerArm | None = None) -> list[Query]:
    """Load a query set by name (``"planning_necessary"``, ``"paper_random"``) or JSON path.

    With ``robot``, refuse a set made for another model (its ``model_hash`` differs).

    Raises
    ------
    FileNotFoundError
        No such set or file.
    QuerySetError (a ValueError)
        Not JSON (e.g. truncated), wrong ``format_version``, malformed queries, or another model.
    """
    return load_query_set(name_or_path, robot)[0]
