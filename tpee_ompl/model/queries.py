"""Cross-sector benchmark queries (paper section 5.1): the query record, the straight motion, JSON I/O.

A query is a target A in sector i and a target B in sector j != i; start = (Table 1 preset i,
aimed at A), goal = (preset j, aimed at B), both collision-free with a clear line of sight.  Two
named sets ship inside the package (``tpee_ompl/data/queries/``, see :mod:`tpee_ompl.resources`):

* ``planning_necessary`` (default): targets drawn from per-sector regions where the straight
  motion tends to hit the wearer, kept only if it does when such queries can be found (see
  :mod:`tpee_ompl.planning.query_generation`).
* ``paper_random``: targets uniform over directions in the posture sector, 2-10 m, above the
  floor, as in the paper.

The straight motion is Table 3's seven (DOF1, DOF2) waypoints with DOF3/DOF4 linear from start to
goal over the same fake-time steps (:func:`straight_motion`).
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..files import atomic_write_text
from ..resources import query_set_path
from ..validation import as_float_array
from .sectors import POSTURE_PRESETS, check_sector, cross_sector_trajectory, infer_sector
from .wearer_arm import WearerArm

__all__ = [
    "FORMAT_VERSION",
    "Query",
    "QuerySetError",
    "check_set_model",
    "load_queries",
    "load_query_set",
    "query_entries",
    "read_query_document",
    "save_queries",
    "straight_motion",
]

log = logging.getLogger(__name__)

FORMAT_VERSION = 1


class QuerySetError(ValueError):
    """A query set file that cannot be used: not JSON, wrong format_version, bad entries, other model."""


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
                a = as_float_array(getattr(self, name), name).copy()
            except ValueError as exc:
                raise ValueError(f"query {self.id}: {name} must be {n} finite numbers, got {getattr(self, name)!r}"[:300]) from exc
            if a.shape != (n,) or not np.all(np.isfinite(a)):
                raise ValueError(f"query {self.id}: {name} must be {n} finite numbers, got {a!r}")
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        for name, k in (("start", self.from_sector), ("goal", self.to_sector)):  # Table 3's rows begin and end there
            if infer_sector(getattr(self, name)) != k:
                raise ValueError(f"query {self.id}: {name} DOF1/DOF2 {getattr(self, name)[:2].tolist()} is not sector "
                                 f"{k}'s Table-1 preset {POSTURE_PRESETS[k].tolist()}")

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
        """Inverse of :meth:`to_dict`, with strict JSON types: integers for ``id`` and the sectors, lists
        of numbers for the vectors (a string, a boolean or a missing or unknown field raises
        :class:`QuerySetError` naming the field; nothing is coerced)."""
        if not isinstance(d, dict):
            raise QuerySetError(f"a query must be a JSON object, got {type(d).__name__}")
        missing = [k for k in _QUERY_FIELDS if k not in d]
        if missing:
            raise QuerySetError(f"field {missing[0]!r} is missing")
        unknown = sorted(k for k in d if k not in _QUERY_FIELDS)
        if unknown:
            raise QuerySetError(f"field {unknown[0]!r} is unknown (the fields are {', '.join(_QUERY_FIELDS)})")
        for name in ("id", "from_sector", "to_sector"):
            if type(d[name]) is not int:
                raise QuerySetError(f"field {name!r} must be an integer, got {d[name]!r}")
        for name, n in _QUERY_VECTORS.items():
            v = d[name]
            if not isinstance(v, list) or len(v) != n or not all(type(x) in (int, float) for x in v):
                raise QuerySetError(f"field {name!r} must be a list of {n} numbers, got {v!r}"[:300])
        try:
            return cls(d["id"], d["from_sector"], d["to_sector"], d["target_a"], d["target_b"], d["start"], d["goal"])
        except ValueError as exc:
            raise QuerySetError(str(exc)) from None


_QUERY_VECTORS = {"target_a": 3, "target_b": 3, "start": 4, "goal": 4}
_QUERY_FIELDS = ("id", "from_sector", "to_sector", *_QUERY_VECTORS)


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


def save_queries(
    path: str | os.PathLike,
    queries: Sequence[Query],
    *,
    name: str,
    seed: int,
    model_hash: str,
    extra: dict | None = None,
    force: bool = True,
) -> Path:
    """Write a versioned JSON query set: format_version, name, seed, model_hash, queries (+ extra keys).

    Written atomically (:func:`tpee_ompl.files.atomic_write_text`); an existing file is replaced, or with
    ``force=False`` refused (:class:`~tpee_ompl.files.OutputExistsError`)."""
    doc = {"format_version": FORMAT_VERSION, "name": name, "seed": seed, "model_hash": model_hash}
    doc.update(extra or {})
    doc["queries"] = [q.to_dict() for q in queries]
    return atomic_write_text(path, json.dumps(doc, indent=1) + "\n", force=force)


def read_query_document(name_or_path: str | os.PathLike) -> tuple[Path, object]:
    """The file of a named query set (packaged) or a JSON path, and its parsed JSON (any type).

    Raises ValueError (not a name or path), FileNotFoundError (no such set or file), another OSError (a folder,
    a pipe, a file it may not read) or :class:`QuerySetError` (not JSON).  Shared by the sector sets and the joint sets
    (:mod:`tpee_ompl.model.joint_queries`)."""
    if isinstance(name_or_path, bool) or not isinstance(name_or_path, (str, os.PathLike)):
        raise ValueError(f"query set must be a name or a path, got {name_or_path!r}")
    p = Path(name_or_path)
    if not p.suffix and not p.exists():
        p = query_set_path(str(name_or_path))
    if p.is_dir():
        raise IsADirectoryError(f"query set {str(name_or_path)!r}: {p} is a folder, not a query file")
    if not p.exists():
        raise FileNotFoundError(f"query set {str(name_or_path)!r} not found (looked at {p})")
    if not p.is_file():
        raise OSError(f"query set {str(name_or_path)!r}: {p} is not a regular file (a pipe or a device)")
    try:
        return p, json.loads(p.read_text(encoding="utf-8"))
    except PermissionError as exc:
        raise PermissionError(f"query set {str(name_or_path)!r}: {p} cannot be read ({exc.strerror})") from None
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise QuerySetError(f"{p}: not a JSON query set (truncated or corrupt?): {exc}") from exc


def check_set_model(p: Path, header: dict, model_hash: str, who: str) -> None:
    """A query set's header names the model it was made for: QuerySetError unless it is ``model_hash``
    (the ``who``'s: robot or checker)."""
    if header.get("model_hash") != model_hash:
        raise QuerySetError(f"{p}: made for model_hash {header.get('model_hash')!r}, but the {who}'s is "
                            f"{model_hash!r} (regenerate the set for this model)")


def query_entries(p: Path, doc: dict, from_dict: Callable[[object], Any]) -> list:
    """The document's ``queries`` list parsed by ``from_dict``, or QuerySetError naming the file and the
    entry (not a list, a malformed entry, an id that appears twice)."""
    entries = doc.get("queries")
    if not isinstance(entries, list):
        raise QuerySetError(f"{p}: 'queries' must be a list, got {type(entries).__name__}")
    queries = []
    for k, d in enumerate(entries):
        try:
            queries.append(from_dict(d))
        except ValueError as exc:
            raise QuerySetError(f"{p}: query {k} is malformed: {exc}") from exc
    ids = [q.id for q in queries]
    if len(set(ids)) != len(ids):
        raise QuerySetError(f"{p}: query id {next(i for i in ids if ids.count(i) > 1)} appears twice")
    return queries


def load_query_set(name_or_path: str | os.PathLike, robot: WearerArm | None = None) -> tuple[list[Query], dict]:
    """Queries and the file's header (everything but ``queries``); see :func:`load_queries`."""
    if robot is not None and not isinstance(robot, WearerArm):  # (checked before the file is read)
        raise ValueError(f"robot must be None or a WearerArm, got {type(robot).__name__}")
    p, doc = read_query_document(name_or_path)
    if not isinstance(doc, dict):
        raise QuerySetError(f"{p}: expected a JSON object at the top level, got {type(doc).__name__}")
    version = doc.get("format_version")
    if str(doc.get("format", "")).startswith("joint_queries/"):  # another robot's set (tpee_ompl.model.joint_queries)
        robot = doc.get("robot")
        raise QuerySetError(f"{p}: a joint-space query set for {'robot ' + repr(robot) if robot else 'another robot'}, "
                            "not the wearer's sector queries (its campaigns: tpee-ompl bench --problem NAME, "
                            "--list-problems)")
    if isinstance(version, bool) or version != FORMAT_VERSION:
        raise QuerySetError(f"{p}: unsupported format_version {version!r} (expected {FORMAT_VERSION})")
    queries = query_entries(p, doc, Query.from_dict)
    header = {k: v for k, v in doc.items() if k != "queries"}
    if robot is not None:
        check_set_model(p, header, robot.model_hash, "robot")
    if robot is not None:
        for q in queries:
            for name in ("start", "goal"):
                v = getattr(q, name)
                if np.any(v < robot.lower) or np.any(v > robot.upper):
                    raise QuerySetError(f"{p}: query {q.id}: {name} {v.tolist()} is outside the joint limits "
                                        f"[{robot.lower.tolist()}, {robot.upper.tolist()}]")
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
    ValueError
        ``robot`` is neither None nor a WearerArm.
    """
    return load_query_set(name_or_path, robot)[0]
