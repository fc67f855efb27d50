"""The cross-sector path library (paper sections 4.2.2, 4.2.3 and 5.2).

One library holds, for each ordered pair of posture sectors (12 in all), demonstrations planned by
dimension-RRT and, for each, a forward and a reverse DMP of DOF3/DOF4 (:mod:`tpee_ompl.dmp`).
DOF1/DOF2 always follow Table 3.  A query picks the closest demonstration, blends the forward and
reverse rollouts, and returns the path only if every segment passes the motion check; otherwise it
tries the next closest demonstrations, then the planner (fallback).

The planner and the query sampler are injected callables, so the library does not depend on
any particular planner::

    sample_query(rng, from_sector, to_sector) -> (start (4,), goal (4,))
    plan(start, goal, from_sector, to_sector) -> waypoints (7, 4) at the fake-time steps, or None

Resampling: each straight segment between consecutive fake-time steps gets ``per_step`` samples
with a quintic time scaling (zero velocity and acceleration at every step), applied to all four
DOFs alike, so the resampled demo is *geometrically identical* to the planned (checked) path and
smooth in fake time, which the DMP needs to reproduce it within 1e-3 rad (docs/dmp.md).
"""

from __future__ import annotations

import json
import logging
import time
import zipfile
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from itertools import pairwise
from pathlib import Path

import numpy as np

from .dmp import DMP, DMPOptions, generate_blended, learn_dmp
from .ompl_problem import motion_states
from .robot import WearerArm
from .sectors import check_sector, cross_sector_trajectory

__all__ = [
    "ALL_PAIRS",
    "FORMAT_VERSION",
    "N_FAKE_TIME_STEPS",
    "LibraryFileError",
    "PathLibrary",
    "QueryResult",
    "motion_is_valid",
    "resample_waypoints",
]

log = logging.getLogger(__name__)

FORMAT_VERSION = 1
"""Version of the ``.npz`` layout written by :meth:`PathLibrary.save`."""
N_FAKE_TIME_STEPS = 7
"""Fake-time steps of every planned path (section 4.1.2)."""
ALL_PAIRS: tuple[tuple[int, int], ...] = tuple((i, j) for i in range(1, 5) for j in range(1, 5) if i != j)
"""The 12 ordered (from, to) posture-sector pairs."""

SampleQuery = Callable[[np.random.Generator, int, int], tuple[np.ndarray, np.ndarray]]
Plan = Callable[[np.ndarray, np.ndarray, int, int], "np.ndarray | None"]


class LibraryFileError(ValueError):
    """A library file that cannot be used: truncated, wrong format version, or another model."""


def resample_waypoints(waypoints: np.ndarray, per_step: int = 100) -> np.ndarray:
    """Put ``per_step`` samples on each straight segment, quintic in fake time; shape ((S-1) per_step + 1, n).

    Every sample lies on the segment between its two waypoints (same geometry as the input path).
    """
    W = np.asarray(waypoints, dtype=float)
    if W.ndim != 2 or W.shape[0] < 2:
        raise ValueError(f"waypoints must have shape (S >= 2, n); got {W.shape}")
    if per_step < 1:
        raise ValueError(f"per_step must be >= 1, got {per_step}")
    u = np.arange(per_step) / per_step
    s = u**3 * (10.0 - 15.0 * u + 6.0 * u**2)
    seg = W[:-1, None, :] + s[None, :, None] * (W[1:] - W[:-1])[:, None, :]
    return np.vstack([seg.reshape(-1, W.shape[1]), W[-1:]])


def motion_is_valid(robot: WearerArm, path: np.ndarray, step: float | None = None) -> bool:
    """True if the first state and every straight segment of ``path`` (K, 4) pass the motion check.

    Checks the states of :func:`tpee_ompl.ompl_problem.motion_states` for each segment, the same
    states as ``si.checkMotion`` in our setups, in one batched ``robot.are_valid`` call.
    """
    path = np.asarray(path, dtype=float)
    step = robot.max_joint_step() if step is None else float(step)
    chunks = [path[:1]] + [motion_states(a, b, step) for a, b in pairwise(path)]
    return bool(robot.are_valid(np.concatenate(chunks)).all())


@dataclass(frozen=True)
class QueryResult:
    """Answer to :meth:`PathLibrary.query`.

    Attributes
    ----------
    path : ndarray, shape (K, 4), radians, or None
        Motion-checked path from the query's start to its goal; None only if outcome is "failed".
    outcome : {"dmp", "repaired", "fallback", "failed"}
        "dmp": the closest demonstration's blended DMP path was valid; "repaired": a later
        candidate's was; "fallback": the planner's path; "failed": nothing valid was found.
    demo_index : int or None
        Index (within the pair) of the demonstration used, if any.
    candidates_tried : int
        Number of DMP paths generated and checked.
    seconds : float
        Wall time of the query.
    """

    path: np.ndarray | None
    outcome: str
    demo_index: int | None
    candidates_tried: int
    seconds: float


@dataclass
class _PairData:
    starts: np.ndarray  # (M, 4)
    goals: np.ndarray  # (M, 4)
    waypoints: np.ndarray  # (M, 7, 4)
    forward: list[DMP] = field(default_factory=list)
    reverse: list[DMP] = field(default_factory=list)

    @property
    def keys(self) -> np.ndarray:
        """(M, 4): DOF3/DOF4 of start and goal, the space in which demos are compared."""
        return np.hstack([self.starts[:, 2:], self.goals[:, 2:]])


def _key(start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    return np.concatenate([start[2:], goal[2:]])


class PathLibrary:
    """Demonstrations and forward/reverse DMPs for the cross-sector motions (sections 4.2.2-4.2.3).

    Build with :meth:`build`, or :meth:`load` a saved one; then :meth:`query`.
    ``plan`` (same signature as for :meth:`build`) is used for repair/fallback; without it a query
    whose DMP candidates all collide is "failed".
    """

    def __init__(
        self,
        robot: WearerArm,
        pairs: dict[tuple[int, int], _PairData],
        per_step: int = 100,
        options: DMPOptions | None = None,
        plan: Plan | None = None,
        n_candidates: int = 3,
        build_stats: dict[str, int] | None = None,
    ) -> None:
        self.robot = robot
        self.pairs = pairs
        self.per_step = int(per_step)
        self.options = options or DMPOptions()
        self.plan = plan
        self.n_candidates = int(n_candidates)
        self.build_stats = dict(build_stats or {})
        self._counts: Counter[str] = Counter()

    # ------------------------------------------------------------------ building
    @classmethod
    def build(
        cls,
        robot: WearerArm,
        sample_query: SampleQuery,
        plan: Plan,
        pairs: Sequence[tuple[int, int]] = ALL_PAIRS,
        per_pair: int = 20,
        min_difference: float = 0.3,
        seed: int = 0,
        max_attempts: int | None = None,
        per_step: int = 100,
        options: DMPOptions | None = None,
    ) -> PathLibrary:
        """Build the library as in section 4.2.2.

        For each pair, draw random cross-sector motions with ``sample_query``; keep one only if its
        DOF3/DOF4 (start, goal) 4-vector is at least ``min_difference`` (radians, Euclidean) from
        every stored one; plan it with ``plan``; resample the 7 waypoints (``per_step`` samples per
        step); learn a forward DMP of DOF3/DOF4 and a reverse DMP of the time-flipped demo.
        Stops at ``per_pair`` demos or ``max_attempts`` draws (default 20 per_pair) per pair.
        Deterministic for a given ``seed`` (one child generator per pair) if ``plan`` is.
        """
        options = options or DMPOptions()
        if per_pair < 1:
            raise ValueError(f"per_pair must be >= 1, got {per_pair}")
        if not (np.isfinite(min_difference) and min_difference >= 0):
            raise ValueError(f"min_difference must be a finite number >= 0, got {min_difference!r}")
        max_attempts = 20 * per_pair if max_attempts is None else int(max_attempts)
        stats: Counter[str] = Counter()
        data: dict[tuple[int, int], _PairData] = {}
        pair_list = [(check_sector(i), check_sector(j)) for i, j in pairs]
        for (i, j), child in zip(pair_list, np.random.SeedSequence(seed).spawn(len(pair_list))):
            if i == j:
                raise ValueError(f"pair ({i}, {j}) is not a cross-sector motion")
            rng = np.random.default_rng(child)
            starts, goals, paths, keys = [], [], [], []
            for _ in range(max_attempts):
                if len(starts) >= per_pair:
                    break
                stats["sampled"] += 1
                start, goal = (np.asarray(q, dtype=float) for q in sample_query(rng, i, j))
                key = _key(start, goal)
                if keys and np.min(np.linalg.norm(np.array(keys) - key, axis=1)) < min_difference:
                    stats["rejected_similar"] += 1
                    continue
                W = plan(start, goal, i, j)
                if W is None:
                    stats["plan_failed"] += 1
                    continue
                W = np.asarray(W, dtype=float)
                if W.shape != (N_FAKE_TIME_STEPS, 4):
                    raise ValueError(f"plan returned shape {W.shape}; expected ({N_FAKE_TIME_STEPS}, 4)")
                starts.append(start)
                goals.append(goal)
                paths.append(W)
                keys.append(key)
                stats["stored"] += 1
            pd = _PairData(np.array(starts).reshape(-1, 4), np.array(goals).reshape(-1, 4),
                           np.array(paths).reshape(-1, N_FAKE_TIME_STEPS, 4))
            for W in pd.waypoints:
                demo = resample_waypoints(W[:, 2:], per_step)
                pd.forward.append(learn_dmp(demo, options))
                pd.reverse.append(learn_dmp(demo[::-1], options))
            data[(i, j)] = pd
            log.info("pair %d->%d: %d demonstrations", i, j, len(pd.starts))
        return cls(robot, data, per_step, options, plan=plan, build_stats=dict(stats))

    # ------------------------------------------------------------------ querying
    def _dof12(self, start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray:
        """Table 3 DOF1/DOF2 on the fake-time grid, shifted (linearly in fake time) to the exact endpoints."""
        T = cross_sector_trajectory(i, j)
        base = resample_waypoints(T, self.per_step)
        u = np.linspace(0.0, 1.0, base.shape[0])[:, None]
        return base + (1.0 - u) * (start[:2] - T[0]) + u * (goal[:2] - T[-1])

    def generate(self, start: np.ndarray, goal: np.ndarray, from_sector: int, to_sector: int, demo_index: int) -> np.ndarray:
        """The blended DMP path (section 4.2.3) for one demonstration, unchecked; shape (P, 4)."""
        pd = self.pairs[(from_sector, to_sector)]
        dof34 = generate_blended(pd.forward[demo_index], pd.reverse[demo_index], start[2:], goal[2:])
        path = np.hstack([self._dof12(start, goal, from_sector, to_sector), dof34])
        path[0], path[-1] = start, goal
        return path

    def query(self, start: np.ndarray, goal: np.ndarray, from_sector: int, to_sector: int) -> QueryResult:
        """A motion-checked path from ``start`` to ``goal`` (section 4.2.3, validated).

        Tries the blended DMP paths of the ``n_candidates`` closest demonstrations (closest in the
        DOF3/DOF4 start/goal 4-vector), then the planner; counts each outcome (:meth:`stats`).
        """
        t0 = time.perf_counter()
        start, goal = self.robot.check_config(start), self.robot.check_config(goal)
        i, j = check_sector(from_sector), check_sector(to_sector)
        if i == j:
            raise ValueError(f"({i}, {j}) is not a cross-sector motion")
        self._counts["queries"] += 1
        pd = self.pairs.get((i, j))
        tried = 0
        if pd is not None and len(pd.starts):
            order = np.argsort(np.linalg.norm(pd.keys - _key(start, goal), axis=1), kind="stable")
            for rank, k in enumerate(order[: self.n_candidates]):
                tried += 1
                path = self.generate(start, goal, i, j, int(k))
                if motion_is_valid(self.robot, path):
                    outcome = "dmp" if rank == 0 else "repaired"
                    return self._result(path, outcome, int(k), tried, t0)
        if self.plan is not None:
            W = self.plan(start, goal, i, j)
            if W is not None:
                path = resample_waypoints(np.asarray(W, dtype=float), self.per_step)
                if np.allclose(path[0], start, atol=1e-9) and np.allclose(path[-1], goal, atol=1e-9):
                    path[0], path[-1] = start, goal
                    if motion_is_valid(self.robot, path):
                        return self._result(path, "fallback", None, tried, t0)
        return self._result(None, "failed", None, tried, t0)

    def _result(self, path: np.ndarray | None, outcome: str, k: int | None, tried: int, t0: float) -> QueryResult:
        self._counts[outcome] += 1
        self._counts["candidates_tried"] += tried
        return QueryResult(path, outcome, k, tried, time.perf_counter() - t0)

    def stats(self) -> dict[str, int]:
        """Counters: queries and outcomes ("dmp", "repaired", "fallback", "failed"), candidates
        tried, plus the build counters ("sampled", "rejected_similar", "plan_failed", "stored")."""
        keys = ("queries", "dmp", "repaired", "fallback", "failed", "candidates_tried")
        out = {k: int(self._counts[k]) for k in keys}
        for k in ("sampled", "rejected_similar", "plan_failed", "stored"):
            out[f"build_{k}"] = int(self.build_stats.get(k, 0))
        return out

    def __len__(self) -> int:
        return sum(len(pd.starts) for pd in self.pairs.values())

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | Path) -> Path:
        """Write the library to one ``.npz`` file (format :data:`FORMAT_VERSION`, model hash included)."""
        path = Path(path)
        meta = {
            "format_version": FORMAT_VERSION,
            "model_hash": self.robot.model_hash,
            "per_step": self.per_step,
            "n_candidates": self.n_candidates,
            "options": asdict(self.options),
            "pairs": [list(p) for p in sorted(self.pairs)],
            "build_stats": self.build_stats,
        }
        arrays: dict[str, np.ndarray] = {"meta": np.array(json.dumps(meta))}
        n_basis = self.options.basis_count((N_FAKE_TIME_STEPS - 1) * self.per_step + 1)
        for (i, j), pd in sorted(self.pairs.items()):
            p = f"p{i}{j}_"
            arrays[p + "starts"], arrays[p + "goals"], arrays[p + "waypoints"] = pd.starts, pd.goals, pd.waypoints
            for name, dmps in (("fwd", pd.forward), ("rev", pd.reverse)):
                arrays[p + name + "_weights"] = np.array([d.weights for d in dmps]).reshape(len(dmps), 2, n_basis)
                arrays[p + name + "_scaled"] = np.array([d.scaled for d in dmps], dtype=bool).reshape(len(dmps), 2)
        with open(path, "wb") as fh:
            np.savez_compressed(fh, **arrays)
        return path

    @classmethod
    def load(cls, path: str | Path, robot: WearerArm, plan: Plan | None = None) -> PathLibrary:
        """Read a library saved by :meth:`save`; refuse another format version, another model, or a damaged file."""
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
        except FileNotFoundError:
            raise
        except (zipfile.BadZipFile, EOFError, OSError, ValueError, KeyError) as exc:
            raise LibraryFileError(f"path library {path} is unreadable (truncated or not a library file): {exc}") from exc
        try:
            meta = json.loads(str(arrays["meta"]))
        except (KeyError, json.JSONDecodeError) as exc:
            raise LibraryFileError(f"path library {path} has no valid metadata: {exc}") from exc
        if meta.get("format_version") != FORMAT_VERSION:
            raise LibraryFileError(
                f"path library {path} has format version {meta.get('format_version')!r}; "
                f"this code reads version {FORMAT_VERSION}: rebuild the library"
            )
        if meta.get("model_hash") != robot.model_hash:
            raise LibraryFileError(
                f"path library {path} was built for model {meta.get('model_hash')!r}, but the robot is "
                f"model {robot.model_hash!r}: rebuild the library for this URDF/SRDF"
            )
        options = DMPOptions(**meta["options"])
        per_step = int(meta["per_step"])
        n_steps = (N_FAKE_TIME_STEPS - 1) * per_step + 1
        data: dict[tuple[int, int], _PairData] = {}
        try:
            for i, j in meta["pairs"]:
                p = f"p{i}{j}_"
                pd = _PairData(arrays[p + "starts"], arrays[p + "goals"], arrays[p + "waypoints"])
                for W, fw, fs, rw, rs in zip(pd.waypoints, arrays[p + "fwd_weights"], arrays[p + "fwd_scaled"],
                                             arrays[p + "rev_weights"], arrays[p + "rev_scaled"], strict=True):
                    pd.forward.append(DMP.from_weights(fw, W[0, 2:], W[-1, 2:], fs, n_steps, options))
                    pd.reverse.append(DMP.from_weights(rw, W[-1, 2:], W[0, 2:], rs, n_steps, options))
                data[(int(i), int(j))] = pd
        except (KeyError, ValueError) as exc:
            raise LibraryFileError(f"path library {path} is inconsistent: {exc}") from exc
        return cls(robot, data, per_step, options, plan=plan, n_candidates=int(meta["n_candidates"]),
                   build_stats=meta.get("build_stats"))
