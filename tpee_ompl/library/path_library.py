"""The cross-sector path library (paper sections 4.2.2, 4.2.3 and 5.2): :class:`PathLibrary` and its queries.

One library holds, for each ordered pair of posture sectors (12 in all), demonstrations planned by
dimension-RRT and, for each, a forward and a reverse DMP of DOF3/DOF4 (:mod:`tpee_ompl.library.dmp`).
DOF1/DOF2 always follow Table 3.  A query picks the closest demonstration, blends the forward and
reverse rollouts, and returns the path only if every segment passes the motion check; otherwise it
tries the next closest demonstrations, then the planner (fallback).

The planner and the query sampler are injected callables (:mod:`tpee_ompl.library.demos`), so the
library does not depend on any particular planner.  :meth:`PathLibrary.build_default` uses the
default ones (:func:`~tpee_ompl.library.demos.query_sampler`, :class:`~tpee_ompl.library.demos.DemoPlanner`),
in parallel over the pairs; the settings of a build are a :class:`~tpee_ompl.library.build.LibraryBuildOptions`.
Files: :mod:`tpee_ompl.library.storage`; evaluation on a query set: :mod:`tpee_ompl.library.evaluation`.
:meth:`PathLibrary.as_planner` plugs a library into :class:`tpee_ompl.library.tracker.Tracker`.
"""

from __future__ import annotations

import inspect
import logging
import os
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..model.sectors import check_sector, cross_sector_trajectory, infer_sector, posture_preset
from ..model.wearer_arm import WearerArm
from ..planning.paths import motion_is_valid, motion_step, planned_waypoints, resample_waypoints
from ..validation import check_bool, check_int
from .build import LIBRARY_DMP_OPTIONS, LibraryBuildOptions, collect_default_demos, default_build_params, learn_demos
from .demos import (MAX_PER_STEP, N_FAKE_TIME_STEPS, PairDemos, Plan, SampleQuery, collect_pair, dimension_rrt_planner,
                    max_query_stride)
from .dmp import DMPOptions, generate_blended
from .storage import read_library, write_library

__all__ = ["CHECK_STEP", "PathLibrary", "QueryResult"]

log = logging.getLogger(__name__)

CHECK_STEP = 0.01
"""Radians: the joint step the tracker checks its motions at by default (``TrackerOptions.check_step``), and so
the library's as a tracker planner (a robot whose ``max_joint_step()`` is smaller is checked at that)."""


@dataclass(frozen=True)
class QueryResult:
    """Answer to :meth:`PathLibrary.query`.

    Attributes
    ----------
    path : ndarray, shape (K, 4), radians, or None
        Motion-checked path from the query's start to its goal; None only if outcome is "failed".
    outcome : {"dmp", "repaired", "fallback", "failed"}
        "dmp": the closest demonstration's blended DMP path was valid; "repaired": a later
        candidate's was; "fallback": the planner's path (seeded with the closest DMP path when the
        planner takes ``initial_waypoints``); "failed": nothing valid was found.
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


def _takes_initial_waypoints(plan: Callable) -> bool:
    try:
        return "initial_waypoints" in inspect.signature(plan).parameters
    except (TypeError, ValueError):
        return False


class PathLibrary:
    """Demonstrations and forward/reverse DMPs for the cross-sector motions (sections 4.2.2-4.2.3).

    Build with :meth:`build` (or :meth:`build_default`), or :meth:`load` a saved one; then
    :meth:`query`.  ``plan`` (same signature as for :meth:`build`) is the fallback; without it a
    query whose DMP candidates all collide is "failed".  ``query_stride``: a query returns every
    ``query_stride``-th sample of the ``per_step``-dense DMP rollout (plus the last), i.e. a
    polyline of ``(N_FAKE_TIME_STEPS - 1) per_step / query_stride + 1`` points; that polyline is
    what is checked and returned, so the stride changes cost, never the guarantee (default: 10, or the rollout's
    length when shorter).
    """

    def __init__(
        self,
        robot: WearerArm,
        pairs: dict[tuple[int, int], PairDemos],
        per_step: int = 100,
        options: DMPOptions | None = None,
        plan: Plan | None = None,
        n_candidates: int = 3,
        build_stats: dict[str, int] | None = None,
        query_stride: int | None = None,
        build_params: dict | None = None,
    ) -> None:
        self.robot = robot
        self.pairs = pairs
        self.per_step = check_int("per_step", per_step, minimum=1, maximum=MAX_PER_STEP)
        n_steps = (N_FAKE_TIME_STEPS - 1) * self.per_step + 1
        for (i, j), pd in pairs.items():  # every DMP of a pair is learned on one grid: the first one tells
            dmp = next(iter(pd.forward), None)
            if dmp is not None and dmp.n_steps != n_steps:
                raise ValueError(f"per_step {self.per_step} gives DMPs of {n_steps} samples, but pair {i}->{j}'s "
                                 f"have {dmp.n_steps}")
        if options is not None and not isinstance(options, DMPOptions):
            raise ValueError(f"options must be DMPOptions, got {type(options).__name__}")
        self.options = options or LIBRARY_DMP_OPTIONS
        if plan is not None and not callable(plan):
            raise ValueError(f"plan must be a planner callable or None, got {type(plan).__name__}")
        self.plan = plan
        self.n_candidates = check_int("n_candidates", n_candidates, minimum=1)  # a library file's bound too
        self.build_stats = dict(build_stats or {})
        self.build_params = dict(build_params or {})
        longest = max_query_stride(self.per_step)
        self.query_stride = min(10, longest) if query_stride is None else check_int("query_stride", query_stride,
                                                                                    minimum=1, maximum=longest)
        self._counts: Counter[str] = Counter()
        self._dof12_cache: dict[tuple[int, int], np.ndarray] = {}

    # ------------------------------------------------------------------ building
    @classmethod
    def build(
        cls,
        robot: WearerArm,
        sample_query: SampleQuery,
        plan: Plan,
        options: LibraryBuildOptions | None = None,
        **overrides: Any,
    ) -> PathLibrary:
        """Build the library as in section 4.2.2.

        For each pair of ``options.pairs``, draw random cross-sector motions with ``sample_query``;
        keep one only if its DOF3/DOF4 (start, goal) 4-vector is at least ``min_difference``
        (radians, Euclidean) from every stored one; plan it with ``plan``; resample the 7 waypoints
        (``per_step`` samples per step); learn a forward DMP of DOF3/DOF4 and a reverse DMP of the
        time-flipped demo (``dmp_options``).  Stops at ``per_pair`` demos or ``max_attempts`` draws
        per pair.  Deterministic for a given ``seed`` (one child generator per pair) if ``plan``
        is.  A ``plan`` with a ``last_margin`` attribute (:class:`~tpee_ompl.library.demos.DemoPlanner`)
        has it stored per demonstration.  ``options`` (default :class:`LibraryBuildOptions`) with
        keyword ``overrides`` of its fields (``per_pair=4, seed=7``); the fields of the default
        sampler and planner (max_samples, timeout, require_planning, demo_margins, workers) are
        not used.  A query or path that a library file could not hold (outside ``robot``'s joint limits,
        off the pair's Table-1 presets, a path not from its start to its goal) is a ValueError naming
        ``sample_query`` or ``plan`` (:func:`~tpee_ompl.library.demos.collect_pair`).
        """
        opts = LibraryBuildOptions.resolve(options, overrides)
        stats: Counter[str] = Counter()
        collected = {}
        for (i, j), child in zip(opts.pairs, np.random.SeedSequence(opts.seed).spawn(len(opts.pairs))):
            collected[(i, j)] = collect_pair(sample_query, plan, i, j, child, opts.per_pair, opts.min_difference,
                                             opts.draws_per_pair, robot=robot)
            stats.update(collected[(i, j)][4])
        return cls._learn(robot, collected, stats, opts.per_step, opts.dmp_options, plan)

    @classmethod
    def _learn(cls, robot: WearerArm, collected: dict, stats: dict[str, int], per_step: int, options: DMPOptions,
               plan: Plan | None) -> PathLibrary:
        """A library of the collected demos, their DMPs learned with ``options`` (:func:`~tpee_ompl.library.build.learn_demos`)."""
        return cls(robot, learn_demos(collected, per_step, options), per_step, options, plan=plan,
                   build_stats=dict(stats))

    @classmethod
    def build_default(
        cls, robot: WearerArm, options: LibraryBuildOptions | None = None, **overrides: Any
    ) -> PathLibrary:
        """:meth:`build` with :func:`~tpee_ompl.library.demos.query_sampler` and
        :class:`~tpee_ompl.library.demos.DemoPlanner`; the parameters are recorded in
        ``build_params`` (saved in the file's metadata).

        ``options`` (default :class:`LibraryBuildOptions`, the packaged library's settings) with
        keyword ``overrides`` of its fields.  ``workers`` > 1 builds the pairs in that many
        processes, each with a copy of ``robot`` (same files and margins); the result is the same
        as with one (each pair has its own seed), unless a demo hits the wall-clock ``timeout``.
        The fallback of the returned library is :func:`~tpee_ompl.library.demos.dimension_rrt_planner`
        at the robot's margin.
        """
        opts = LibraryBuildOptions.resolve(options, overrides)
        t0 = time.perf_counter()
        collected, stats = collect_default_demos(robot, opts)
        fallback = dimension_rrt_planner(robot, max_samples=opts.max_samples, seed=opts.seed, timeout=opts.timeout)
        lib = cls._learn(robot, collected, stats, opts.per_step, opts.dmp_options, fallback)
        lib.build_params = default_build_params(opts, time.perf_counter() - t0)
        return lib

    def with_options(self, options: DMPOptions) -> PathLibrary:
        """The same demonstrations with DMPs learned anew with ``options`` (e.g. to compare scalings)."""
        if not isinstance(options, DMPOptions):
            raise ValueError(f"options must be a DMPOptions, got {options!r}")
        collected = {pair: (pd.starts, pd.goals, pd.waypoints, pd.margins, Counter()) for pair, pd in self.pairs.items()}
        lib = self._learn(self.robot, collected, self.build_stats, self.per_step, options, self.plan)
        lib.build_params = {**self.build_params, "dmp_options": asdict(options)}
        lib.n_candidates, lib.query_stride = self.n_candidates, self.query_stride
        return lib

    # ------------------------------------------------------------------ querying
    def _dof12(self, start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray:
        """Table 3 DOF1/DOF2 on the fake-time grid, shifted (linearly in fake time) to the exact endpoints."""
        base = self._dof12_cache.get((i, j))
        if base is None:
            base = self._dof12_cache[(i, j)] = resample_waypoints(cross_sector_trajectory(i, j), self.per_step)
        T0, T1 = base[0], base[-1]
        u = np.linspace(0.0, 1.0, base.shape[0])[:, None]
        return base + (1.0 - u) * (start[:2] - T0) + u * (goal[:2] - T1)

    def demo_order(self, start: np.ndarray, goal: np.ndarray, from_sector: int, to_sector: int) -> np.ndarray:
        """Indices of the pair's demonstrations, closest first in the DOF3/DOF4 (start, goal) 4-vector."""
        start, goal = self.robot.check_config(start), self.robot.check_config(goal)
        pair = (check_sector(from_sector), check_sector(to_sector))
        pd = self.pairs.get(pair)
        if pd is None:
            raise ValueError(f"the library has no demonstrations for {pair[0]}->{pair[1]} (pairs: {sorted(self.pairs)})")
        return pd.closest_first(start, goal)

    def candidate_paths(self, start: np.ndarray, goal: np.ndarray, from_sector: int,
                        to_sector: int) -> Iterator[tuple[int, int, np.ndarray]]:
        """The DMP paths a query tries, unchecked: ``(rank, demonstration index, path)`` for the ``n_candidates``
        demonstrations closest to (start, goal), closest first, each generated at ``query_stride``."""
        for rank, k in enumerate(self.demo_order(start, goal, from_sector, to_sector)[: self.n_candidates]):
            yield rank, int(k), self.generate(start, goal, from_sector, to_sector, int(k), stride=self.query_stride)

    def generate(
        self, start: np.ndarray, goal: np.ndarray, from_sector: int, to_sector: int, demo_index: int, stride: int = 1
    ) -> np.ndarray:
        """The blended DMP path (section 4.2.3) for one demonstration, not checked for collision.

        Shape (P, 4) with P = (N_FAKE_TIME_STEPS - 1) per_step + 1; with ``stride`` > 1 only every
        ``stride``-th sample and the last one are kept.  Raises ValueError for a start or goal that is not
        a finite configuration, a pair the library has no demonstrations for, a ``demo_index`` out of range,
        or a ``stride`` that is not an integer >= 1.
        """
        start, goal = self.robot.check_config(start), self.robot.check_config(goal)
        stride = check_int("stride", stride, minimum=1)
        pd = self.pairs.get((check_sector(from_sector), check_sector(to_sector)))
        if pd is None:
            raise ValueError(f"the library has no demonstrations for {from_sector}->{to_sector} (pairs: {sorted(self.pairs)})")
        if isinstance(demo_index, bool) or not isinstance(demo_index, (int, np.integer)) or not 0 <= demo_index < len(pd.starts):
            raise ValueError(f"demo_index must be 0..{len(pd.starts) - 1} for {from_sector}->{to_sector}, got {demo_index!r}")
        dof34 = generate_blended(pd.forward[demo_index], pd.reverse[demo_index], start[2:], goal[2:])
        path = np.hstack([self._dof12(start, goal, from_sector, to_sector), dof34])
        if stride > 1:
            keep = np.arange(0, len(path), stride)
            if keep[-1] != len(path) - 1:
                keep = np.append(keep, len(path) - 1)
            path = path[keep]
        path[0], path[-1] = start, goal
        return path

    def check_robot(self, robot: object, what: str = "library") -> None:
        """ValueError naming ``what`` unless ``robot`` checks as the library's own does (its model and margins): its
        paths are validated with the library's robot, so a library of another model gives paths that model's
        robot may reject."""
        mine = self.robot
        if getattr(robot, "model_hash", None) != mine.model_hash:
            raise ValueError(f"{what}: built for model {mine.model_hash!r}, not the robot's "
                             f"{getattr(robot, 'model_hash', None)!r} (load or build one for this model)")
        if not np.array_equal(robot.pair_margins(), mine.pair_margins()):
            theirs, ours = dict(getattr(robot, "link_margins", None) or {}), dict(mine.link_margins or {})
            which = (f"security_margin {mine.security_margin:g} against {robot.security_margin:g} m"
                     if mine.security_margin != robot.security_margin else
                     f"link_margins {ours} against {theirs}" if ours != theirs else "pair margins")
            raise ValueError(f"{what}: its robot has other collision margins than this robot ({which}): load it with "
                             "this robot")

    def query(
        self, start: np.ndarray, goal: np.ndarray, from_sector: int, to_sector: int, step: float | None = None
    ) -> QueryResult:
        """A motion-checked path from ``start`` to ``goal`` (section 4.2.3, validated).

        Tries the blended DMP paths of the ``n_candidates`` closest demonstrations (closest in the
        DOF3/DOF4 start/goal 4-vector), then the planner; counts each outcome (:meth:`stats`).
        Every segment of the returned path passes the check of ``si.checkMotion`` at resolution
        ``step`` (default ``robot.max_joint_step()``, the setups' resolution, also the largest taken;
        :func:`~tpee_ompl.planning.paths.motion_step`).  ValueError for a step below ``MIN_JOINT_STEP`` or a
        fallback planner whose answer is not a path (K >= 2, 4) of finite numbers.
        """
        t0 = time.perf_counter()
        step = motion_step(self.robot, step)
        start, goal = self.robot.check_config(start), self.robot.check_config(goal)
        i, j = check_sector(from_sector), check_sector(to_sector)
        if i == j:
            raise ValueError(f"({i}, {j}) is not a cross-sector motion")
        for name, q, k in (("start", start, i), ("goal", goal, j)):
            if infer_sector(q) != k:  # the paths follow the (i, j) row of Table 3, from posture i to posture j
                raise ValueError(f"{name}: DOF1/DOF2 {np.round(q[:2], 4).tolist()} are not sector {k}'s Table-1 "
                                 f"posture {np.round(posture_preset(k), 4).tolist()}")
        self._counts["queries"] += 1
        pd = self.pairs.get((i, j))
        tried = 0
        seed_path = None
        if pd is not None and len(pd.starts):
            closest = None
            for rank, k, path in self.candidate_paths(start, goal, i, j):
                tried += 1
                closest = k if closest is None else closest
                if motion_is_valid(self.robot, path, step):
                    return self._result(path, "dmp" if rank == 0 else "repaired", k, tried, t0)
            if self.plan is not None and closest is not None:
                seed_path = self.generate(start, goal, i, j, closest, stride=self.per_step)
        if self.plan is not None:
            kw = {}
            if seed_path is not None and seed_path.shape == (N_FAKE_TIME_STEPS, 4) and _takes_initial_waypoints(self.plan):
                kw["initial_waypoints"] = seed_path
                self._counts["fallback_seeded"] += 1
            W = self.plan(start, goal, i, j, **kw)
            if W is not None:
                path = planned_waypoints(W, self.robot.nq, "the fallback planner")
                if np.allclose(path[0], start, atol=1e-9) and np.allclose(path[-1], goal, atol=1e-9):
                    path[0], path[-1] = start, goal
                    if motion_is_valid(self.robot, path, step):
                        return self._result(path, "fallback", None, tried, t0)
        return self._result(None, "failed", None, tried, t0)

    def _result(self, path: np.ndarray | None, outcome: str, k: int | None, tried: int, t0: float) -> QueryResult:
        self._counts[outcome] += 1
        self._counts["candidates_tried"] += tried
        return QueryResult(path, outcome, k, tried, time.perf_counter() - t0)

    def stats(self) -> dict[str, int]:
        """Counters: queries and outcomes ("dmp", "repaired", "fallback", "failed"), candidates
        tried, fallbacks seeded with a DMP path, plus the build counters ("sampled",
        "rejected_similar", "plan_failed", "stored", "stored_at_<margin>mm")."""
        keys = ("queries", "dmp", "repaired", "fallback", "failed", "candidates_tried", "fallback_seeded")
        out = {k: int(self._counts[k]) for k in keys}
        for k in ("sampled", "rejected_similar", "plan_failed", "stored"):
            out[f"build_{k}"] = int(self.build_stats.get(k, 0))
        for k in sorted(self.build_stats):
            if k.startswith("stored_at_"):
                out[f"build_{k}"] = int(self.build_stats[k])
        return out

    def reset_stats(self) -> None:
        """Zero the query counters (build counters are kept)."""
        self._counts.clear()

    def as_planner(
        self, step: float | None = None, same_sector: Callable[[np.ndarray, np.ndarray, int, int], np.ndarray] | None = None
    ) -> Callable[[np.ndarray, np.ndarray, int, int], np.ndarray]:
        """The library as a :class:`tpee_ompl.library.tracker.Tracker` planner: ``(start, goal, i, j) -> (K, 4)``.

        Cross-sector calls go to :meth:`query` at resolution ``step`` (pass the tracker's
        ``options.check_step`` so its own check sees exactly the states checked here; default
        ``min(robot.max_joint_step(), CHECK_STEP)``, the tracker's default).  Raises
        RuntimeError when the outcome is "failed".  Same-sector calls (the tracker's re-aim
        around an obstacle) have no demonstrations: they go to ``same_sector``, by default
        :func:`tpee_ompl.library.tracker.make_default_planner`.
        """
        step = motion_step(self.robot, CHECK_STEP if step is None else step)
        fallback = same_sector

        def plan(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray:
            nonlocal fallback
            if i == j:
                if fallback is None:
                    from .tracker import make_default_planner

                    fallback = make_default_planner(self.robot)
                return fallback(start, goal, i, j)
            res = self.query(start, goal, i, j, step=step)
            if res.path is None:
                raise RuntimeError(f"path library: no collision-free path {i}->{j} (outcome 'failed')")
            return res.path

        return plan

    def __len__(self) -> int:
        return sum(len(pd.starts) for pd in self.pairs.values())
    # ------------------------------------------------------------------ persistence
    def save(self, path: str | Path, *, force: bool = True) -> Path:
        """Write the library to one ``.npz`` file, atomically (:func:`tpee_ompl.library.storage.write_library`);
        with ``force=False`` an existing file is refused (:class:`~tpee_ompl.files.OutputExistsError`)."""
        return write_library(self, path, force=check_bool("force", force))

    @classmethod
    def load(cls, path: str | os.PathLike, robot: WearerArm, plan: Plan | None = None) -> PathLibrary:
        """Read a library saved by :meth:`save` (:func:`tpee_ompl.library.storage.read_library`), with
        ``plan`` as its fallback; a file of another format version, another model, or a damaged one
        raises :class:`~tpee_ompl.library.storage.LibraryFileError`; a ``robot`` that is not a WearerArm, ValueError."""
        if not isinstance(getattr(robot, "model_hash", None), str):  # (what the file is checked against)
            raise ValueError(f"robot must be a WearerArm (the library's model), got {type(robot).__name__}")
        pairs, settings = read_library(path, robot)
        return cls(robot, pairs, plan=plan, **settings)
