"""The cross-sector path library (paper sections 4.2.2, 4.2.3 and 5.2).

One library holds, for each ordered pair of posture sectors (12 in all), demonstrations planned by
dimension-RRT and, for each, a forward and a reverse DMP of DOF3/DOF4 (:mod:`tpee_ompl.library.dmp`).
DOF1/DOF2 always follow Table 3.  A query picks the closest demonstration, blends the forward and
reverse rollouts, and returns the path only if every segment passes the motion check; otherwise it
tries the next closest demonstrations, then the planner (fallback).

The planner and the query sampler are injected callables, so the library does not depend on
any particular planner::

    sample_query(rng, from_sector, to_sector) -> (start (4,), goal (4,))
    plan(start, goal, from_sector, to_sector) -> waypoints (7, 4) at the fake-time steps, or None

Default builders: :func:`query_sampler` (the planning-necessary query generator's sampling,
:mod:`tpee_ompl.model.queries`) and :class:`DemoPlanner` (dimension-RRT, 2500 samples, with a wider margin
around the pointing system first, so demonstrations keep room that their DMP generalisations can
use); :meth:`PathLibrary.build_default` uses both, in parallel over the pairs with ``workers``.  :meth:`PathLibrary.as_planner` plugs a library
into :class:`tpee_ompl.library.tracker.Tracker`.

Resampling: each straight segment between consecutive fake-time steps gets ``per_step`` samples
with a quintic time scaling (zero velocity and acceleration at every step), applied to all four
DOFs alike, so the resampled demo is *geometrically identical* to the planned (checked) path and
smooth in fake time, which the DMP needs to reproduce it within 1e-3 rad (docs/dmp.md).
"""

from __future__ import annotations

import inspect
import json
import logging
import time
import zipfile
import zlib
from collections import Counter
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from multiprocessing import get_context
from pathlib import Path

import numpy as np

from .dmp import DMP, DMPOptions, generate_blended, learn_dmp
from ..planning.paths import motion_is_valid, path_length, resample_waypoints
from ..model.wearer_arm import WearerArm
from ..model.sectors import check_sector, cross_sector_trajectory

__all__ = [
    "ALL_PAIRS",
    "DEMO_MARGINS",
    "FORMAT_VERSION",
    "LIBRARY_DMP_OPTIONS",
    "N_FAKE_TIME_STEPS",
    "POINTING_LINKS",
    "DemoPlanner",
    "LibraryFileError",
    "PathLibrary",
    "QueryResult",
    "benchmark_queries",
    "dimension_rrt_planner",
    "motion_is_valid",
    "path_length",
    "query_sampler",
    "resample_waypoints",
]

log = logging.getLogger(__name__)

FORMAT_VERSION = 2
"""Version of the ``.npz`` layout written by :meth:`PathLibrary.save` (2: per-demo planning margins)."""
N_FAKE_TIME_STEPS = 7
"""Fake-time steps of every planned path (section 4.1.2)."""
ALL_PAIRS: tuple[tuple[int, int], ...] = tuple((i, j) for i in range(1, 5) for j in range(1, 5) if i != j)
"""The 12 ordered (from, to) posture-sector pairs."""
POINTING_LINKS: tuple[str, ...] = ("link3", "link4")
"""Links moved by DOF3/DOF4, the DOFs the DMPs generate (DOF1/DOF2 follow Table 3 for every query)."""
DEMO_MARGINS: tuple[float, ...] = (0.05, 0.04, 0.03, 0.025)
"""Metres. Margins around :data:`POINTING_LINKS` tried in turn when planning a demonstration, before
the robot's own margin.  A demonstration planned at 2 cm hugs the wearer; its DMP generalisations
then cross into the margin (docs/dmp.md has the measurements)."""
LIBRARY_DMP_OPTIONS = DMPOptions(scaling="none")
"""DMP options of the library's DOF3/DOF4 primitives: absolute forcing instead of eq. 13's (g - y0)
scaling, which flips or shrinks a demo's detour whenever the query moves pan or tilt the other way
or less far than the demo (docs/dmp.md has the measurements)."""

SampleQuery = Callable[[np.random.Generator, int, int], tuple[np.ndarray, np.ndarray]]
Plan = Callable[[np.ndarray, np.ndarray, int, int], "np.ndarray | None"]


class LibraryFileError(ValueError):
    """A library file that cannot be used: truncated, wrong format version, or another model."""


def query_sampler(
    robot: WearerArm,
    regions: dict | None = None,
    require_planning: bool = True,
    max_draws: int = 2000,
) -> SampleQuery:
    """The default ``sample_query``: random cross-sector motions as the query generator draws them.

    Start and goal aim at random targets of :data:`tpee_ompl.planning.query_generation.NECESSITY_REGIONS` (or
    ``regions``) from postures i and j (goal pan nearest the start pan), as in
    :func:`tpee_ompl.planning.query_generation.generate_queries`.  With ``require_planning`` a draw is kept only if
    its straight motion collides (about 2 % of draws: slow, ~1 s per pair); after ``max_draws``
    the last valid draw is returned.  Deterministic given the generator passed in.
    """
    from ..model.pointing import PointingGeometry, aim_checked
    from ..planning.query_generation import NECESSITY_REGIONS, _sample_aimable, straight_motion_valid

    geometry = PointingGeometry.from_robot(robot)
    origin = geometry.pivot
    regions = NECESSITY_REGIONS if regions is None else regions

    def sample(rng: np.random.Generator, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
        from_stream = _sample_aimable(robot, geometry, i, tuple(regions[i]), rng, origin)
        to_stream = _sample_aimable(robot, geometry, j, tuple(regions[j]), rng, origin)
        last = None
        for _ in range(max_draws):
            _, qa = next(from_stream)
            tb, _ = next(to_stream)
            qb, ok = aim_checked(robot, tb[None], j, pan_reference=qa[2], geometry=geometry)
            if not ok[0]:
                continue
            last = (np.asarray(qa, dtype=float), np.asarray(qb[0], dtype=float))
            if not require_planning or not straight_motion_valid(robot, qa, qb[0], i, j):
                return last
        if last is None:
            raise RuntimeError(f"no valid cross-sector motion {i}->{j} in {max_draws} draws")
        return last

    return sample


def dimension_rrt_planner(
    robot: WearerArm, max_samples: int = 2500, seed: int = 0, timeout: float = 10.0
) -> Plan:
    """The default ``plan``: dimension-RRT (sec. 4.1.2) with Table 3's DOF1/DOF2, 7 waypoints or None.

    Each call builds :func:`~tpee_ompl.planning.setup.make_simple_setup` and runs
    :func:`~tpee_ompl.planning.tpee.tpee_dimension_rrt` for ``max_samples`` samples (or
    ``timeout`` s); the planner's seed is ``seed`` mixed with a CRC of (start, goal), so a query
    gets the same path whatever was planned before.  ``initial_waypoints`` (7, 4), e.g. a DMP path
    at the fake-time steps, is the planner's first guess (clipped to the joint limits; checked like
    any other path).  Returns the exact solution's (7, 4) waypoints (every segment passed
    ``si.checkMotion``), else None.
    """
    from ompl import util as ou

    from ..planning.tpee import tpee_dimension_rrt
    from ..planning.setup import make_simple_setup
    from ..planning.paths import path_to_array

    ou.setLogLevel(ou.LOG_WARN)

    def plan(
        start: np.ndarray, goal: np.ndarray, i: int, j: int, initial_waypoints: np.ndarray | None = None
    ) -> np.ndarray | None:
        start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
        call_seed = (int(seed) * 1_000_003 + zlib.crc32(np.r_[start, goal].tobytes())) % (2**31)
        try:
            ss = make_simple_setup(robot, start, goal)
        except ValueError as exc:  # start or goal in collision / out of limits
            log.warning("dimension-RRT %d->%d not run: %s", i, j, exc)
            return None
        planner = tpee_dimension_rrt(ss.getSpaceInformation(), i, j, max_samples=max_samples, seed=call_seed)
        if initial_waypoints is not None:
            planner.set_initial_waypoints(np.clip(np.asarray(initial_waypoints, dtype=float), robot.lower, robot.upper))
        ss.setPlanner(planner)
        ss.solve(timeout)
        if not ss.haveExactSolutionPath():
            return None
        W = path_to_array(ss.getSolutionPath(), robot.nq)
        return W if W.shape == (N_FAKE_TIME_STEPS, robot.nq) else None

    return plan


class DemoPlanner:
    """The default ``plan`` of :meth:`PathLibrary.build_default`: dimension-RRT, wide margins first.

    For each margin of ``margins`` (largest first, those above the robot's own only) the start and
    goal are checked, and dimension-RRT is run, with that margin around ``links`` (never below the
    robot's own ``link_margins``); the first exact path is returned, else the plan with the robot
    itself.  Every rung is at least as strict as the robot, so a path valid on a rung is valid for
    the robot.  ``last_margin`` is the margin of the last returned path;
    ``counts`` counts paths per margin ("margin_30mm", ...) and "failed".
    """

    def __init__(
        self,
        robot: WearerArm,
        margins: Sequence[float] = DEMO_MARGINS,
        links: Sequence[str] = POINTING_LINKS,
        max_samples: int = 2500,
        seed: int = 0,
        timeout: float = 10.0,
    ) -> None:
        margins = _check_margins(margins)
        srdf = robot.files.srdf if robot.files.srdf is not None else False
        rungs: list[tuple[float, WearerArm]] = []
        for m in sorted(set(margins), reverse=True):
            wider = {name: max(m, robot.link_margins.get(name, 0.0)) for name in links}
            if m > robot.security_margin and any(v > robot.link_margins.get(n, robot.security_margin)
                                                 for n, v in wider.items()):
                rungs.append((m, WearerArm(robot.files.urdf, srdf, security_margin=robot.security_margin,
                                           link_margins={**robot.link_margins, **wider}, n_threads=robot.n_threads)))
        rungs.append((robot.security_margin, robot))
        self.margins = tuple(m for m, _ in rungs)
        self._rungs = [(m, r, dimension_rrt_planner(r, max_samples=max_samples, seed=seed, timeout=timeout))
                       for m, r in rungs]
        self.counts: Counter[str] = Counter()
        self.last_margin: float | None = None

    def __call__(
        self, start: np.ndarray, goal: np.ndarray, i: int, j: int, initial_waypoints: np.ndarray | None = None
    ) -> np.ndarray | None:
        """Waypoints (7, 4) of the first exact dimension-RRT path down the margin ladder, or None."""
        self.last_margin = None
        for m, r, plan in self._rungs:
            if not (r.is_valid(start) and r.is_valid(goal)):
                continue
            W = plan(start, goal, i, j, initial_waypoints=initial_waypoints)
            if W is not None:
                self.last_margin = m
                self.counts[f"margin_{round(m * 1000)}mm"] += 1
                return W
        self.counts["failed"] += 1
        return None


def _check_margins(margins: Sequence[float]) -> tuple[float, ...]:
    try:
        out = tuple(float(m) for m in margins)
    except (TypeError, ValueError):
        raise ValueError(f"demo margins must be numbers in [0, 1] metres, got {margins!r}") from None
    if not all(np.isfinite(m) and 0.0 <= m <= 1.0 for m in out):
        raise ValueError(f"demo margins must be numbers in [0, 1] metres, got {list(margins)!r}")
    return out


def _takes_initial_waypoints(plan: Callable) -> bool:
    try:
        return "initial_waypoints" in inspect.signature(plan).parameters
    except (TypeError, ValueError):
        return False


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


@dataclass
class _PairData:
    starts: np.ndarray  # (M, 4)
    goals: np.ndarray  # (M, 4)
    waypoints: np.ndarray  # (M, 7, 4)
    margins: np.ndarray | None = None  # (M,) metres each demo was planned with (NaN: unknown)
    forward: list[DMP] = field(default_factory=list)
    reverse: list[DMP] = field(default_factory=list)

    @property
    def keys(self) -> np.ndarray:
        """(M, 4): DOF3/DOF4 of start and goal, the space in which demos are compared."""
        return np.hstack([self.starts[:, 2:], self.goals[:, 2:]])


def _key(start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    return np.concatenate([start[2:], goal[2:]])


def _closest_first(pd: _PairData, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    return np.argsort(np.linalg.norm(pd.keys - _key(start, goal), axis=1), kind="stable")


def _check_build_args(
    pairs: Sequence[tuple[int, int]], per_pair: int, min_difference: float, max_attempts: int | None
) -> tuple[list[tuple[int, int]], int]:
    if isinstance(per_pair, bool) or not isinstance(per_pair, (int, np.integer)) or per_pair < 1:
        raise ValueError(f"per_pair must be an integer >= 1, got {per_pair!r}")
    if not (np.isfinite(min_difference) and min_difference >= 0):
        raise ValueError(f"min_difference must be a finite number >= 0, got {min_difference!r}")
    max_attempts = 20 * per_pair if max_attempts is None else int(max_attempts)
    if max_attempts < 1:
        raise ValueError(f"max_attempts must be >= 1, got {max_attempts}")
    pair_list = [(check_sector(i), check_sector(j)) for i, j in pairs]
    for i, j in pair_list:
        if i == j:
            raise ValueError(f"pair ({i}, {j}) is not a cross-sector motion")
    return pair_list, max_attempts


def _collect_pair(
    sample_query: SampleQuery,
    plan: Plan,
    i: int,
    j: int,
    child: np.random.SeedSequence,
    per_pair: int,
    min_difference: float,
    max_attempts: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Counter[str]]:
    """Draw, filter and plan the demonstrations of one pair: starts, goals, waypoints, margins, counters."""
    rng = np.random.default_rng(child)
    stats: Counter[str] = Counter()
    starts, goals, paths, keys, margins = [], [], [], [], []
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
        margin = getattr(plan, "last_margin", None)
        starts.append(start)
        goals.append(goal)
        paths.append(W)
        keys.append(key)
        margins.append(np.nan if margin is None else float(margin))
        stats["stored"] += 1
        if margin is not None:
            stats[f"stored_at_{round(margin * 1000)}mm"] += 1
    return (np.array(starts).reshape(-1, 4), np.array(goals).reshape(-1, 4),
            np.array(paths).reshape(-1, N_FAKE_TIME_STEPS, 4), np.array(margins, dtype=float), stats)


def _collect_default_pair(job: tuple, robot: WearerArm | None = None) -> tuple:
    """:func:`_collect_pair` with the default sampler and :class:`DemoPlanner` (runs in a worker process)."""
    model, i, j, child, per_pair, min_difference, max_attempts, max_samples, timeout, require, margins, seed = job
    if robot is None:
        urdf, srdf, margin, link_margins, n_threads = model
        robot = WearerArm(urdf, srdf if srdf is not None else False, security_margin=margin,
                          link_margins=link_margins, n_threads=n_threads)
    plan = DemoPlanner(robot, margins=margins, max_samples=max_samples, seed=seed, timeout=timeout)
    return _collect_pair(query_sampler(robot, require_planning=require), plan, i, j, child, per_pair,
                         min_difference, max_attempts)


class PathLibrary:
    """Demonstrations and forward/reverse DMPs for the cross-sector motions (sections 4.2.2-4.2.3).

    Build with :meth:`build` (or :meth:`build_default`), or :meth:`load` a saved one; then
    :meth:`query`.  ``plan`` (same signature as for :meth:`build`) is the fallback; without it a
    query whose DMP candidates all collide is "failed".  ``query_stride``: a query returns every
    ``query_stride``-th sample of the ``per_step``-dense DMP rollout (plus the last), i.e. a
    polyline of ``(N_FAKE_TIME_STEPS - 1) per_step / query_stride + 1`` points; that polyline is
    what is checked and returned, so the stride changes cost, never the guarantee.
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
        query_stride: int = 10,
        build_params: dict | None = None,
    ) -> None:
        self.robot = robot
        self.pairs = pairs
        self.per_step = int(per_step)
        self.options = options or LIBRARY_DMP_OPTIONS
        self.plan = plan
        self.n_candidates = int(n_candidates)
        self.build_stats = dict(build_stats or {})
        self.build_params = dict(build_params or {})
        if query_stride < 1:
            raise ValueError(f"query_stride must be >= 1, got {query_stride}")
        self.query_stride = int(query_stride)
        self._counts: Counter[str] = Counter()
        self._dof12_cache: dict[tuple[int, int], np.ndarray] = {}

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
        step); learn a forward DMP of DOF3/DOF4 and a reverse DMP of the time-flipped demo
        (``options``, default :data:`LIBRARY_DMP_OPTIONS`).  Stops at ``per_pair`` demos or
        ``max_attempts`` draws (default 20 per_pair) per pair.  Deterministic for a given ``seed``
        (one child generator per pair) if ``plan`` is.  A ``plan`` with a ``last_margin``
        attribute (:class:`DemoPlanner`) has it stored per demonstration.
        """
        pair_list, max_attempts = _check_build_args(pairs, per_pair, min_difference, max_attempts)
        stats: Counter[str] = Counter()
        collected = {}
        for (i, j), child in zip(pair_list, np.random.SeedSequence(seed).spawn(len(pair_list))):
            collected[(i, j)] = _collect_pair(sample_query, plan, i, j, child, per_pair, min_difference, max_attempts)
            stats.update(collected[(i, j)][4])
        return cls._learn(robot, collected, stats, per_step, options, plan)

    @classmethod
    def _learn(
        cls,
        robot: WearerArm,
        collected: dict[tuple[int, int], tuple],
        stats: Counter[str],
        per_step: int,
        options: DMPOptions | None,
        plan: Plan | None,
    ) -> PathLibrary:
        options = options or LIBRARY_DMP_OPTIONS
        data: dict[tuple[int, int], _PairData] = {}
        for (i, j), (starts, goals, waypoints, margins, _) in collected.items():
            pd = _PairData(starts, goals, waypoints, margins)
            for W in pd.waypoints:
                demo = resample_waypoints(W[:, 2:], per_step)
                pd.forward.append(learn_dmp(demo, options))
                pd.reverse.append(learn_dmp(demo[::-1], options))
            data[(i, j)] = pd
            log.info("pair %d->%d: %d demonstrations", i, j, len(pd.starts))
        return cls(robot, data, per_step, options, plan=plan, build_stats=dict(stats))

    @classmethod
    def build_default(
        cls,
        robot: WearerArm,
        per_pair: int = 10,
        seed: int = 0,
        pairs: Sequence[tuple[int, int]] = ALL_PAIRS,
        min_difference: float = 0.15,
        max_samples: int = 2500,
        timeout: float = 10.0,
        require_planning: bool = True,
        max_attempts: int | None = None,
        demo_margins: Sequence[float] = DEMO_MARGINS,
        workers: int = 1,
        options: DMPOptions | None = None,
    ) -> PathLibrary:
        """:meth:`build` with :func:`query_sampler` and :class:`DemoPlanner`; the parameters are
        recorded in ``build_params`` (saved in the file's metadata).

        ``max_attempts`` (draws per pair) defaults to 3 per_pair: planning-necessary draws of
        the shoulder pairs (3 <-> 4) cost several seconds each and cluster within ~0.3 rad.
        ``workers`` > 1 builds the pairs in that many processes, each with a copy of ``robot``
        (same files and margins); the result is the same as with one (each pair has its own seed),
        unless a demo hits the wall-clock ``timeout``.  ``options``: the DMPs' (default
        :data:`LIBRARY_DMP_OPTIONS`).  The fallback of the returned library is
        :func:`dimension_rrt_planner` at the robot's margin.
        """
        pair_list, max_attempts = _check_build_args(pairs, per_pair, min_difference,
                                                    max_attempts if max_attempts is not None else 3 * per_pair)
        if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
            raise ValueError(f"workers must be an integer >= 1, got {workers!r}")
        t0 = time.perf_counter()
        children = np.random.SeedSequence(seed).spawn(len(pair_list))
        demo_margins = _check_margins(demo_margins)
        model = (robot.files.urdf, robot.files.srdf, robot.security_margin, dict(robot.link_margins), robot.n_threads)
        jobs = [(model, i, j, child, per_pair, min_difference, max_attempts, max_samples, timeout, require_planning,
                 demo_margins, seed)
                for (i, j), child in zip(pair_list, children)]
        if workers > 1 and len(jobs) > 1:
            with ProcessPoolExecutor(min(workers, len(jobs)), mp_context=get_context("spawn")) as ex:
                results = list(ex.map(_collect_default_pair, jobs))
        else:
            results = [_collect_default_pair(job, robot) for job in jobs]
        stats: Counter[str] = Counter()
        for r in results:
            stats.update(r[4])
        collected = dict(zip(pair_list, results))
        lib = cls._learn(robot, collected, stats, 100, options,
                         dimension_rrt_planner(robot, max_samples=max_samples, seed=seed, timeout=timeout))
        lib.build_params = {
            "builder": "PathLibrary.build_default",
            "per_pair": int(per_pair),
            "seed": int(seed),
            "pairs": [list(map(int, p)) for p in pair_list],
            "min_difference": float(min_difference),
            "max_attempts": int(max_attempts),
            "sampler": f"query_sampler(NECESSITY_REGIONS, require_planning={bool(require_planning)})",
            "planner": f"DemoPlanner(margins={[float(m) for m in demo_margins]}, links={list(POINTING_LINKS)}, "
                       f"max_samples={max_samples}, timeout={timeout:g})",
            "dmp_options": asdict(lib.options),
            "workers": int(workers),
            "build_seconds": round(time.perf_counter() - t0, 1),
        }
        return lib

    def with_options(self, options: DMPOptions) -> PathLibrary:
        """The same demonstrations with DMPs learned anew with ``options`` (e.g. to compare scalings)."""
        if not isinstance(options, DMPOptions):
            raise ValueError(f"options must be a DMPOptions, got {options!r}")
        collected = {pair: (pd.starts, pd.goals, pd.waypoints, pd.margins, Counter()) for pair, pd in self.pairs.items()}
        lib = self._learn(self.robot, collected, Counter(self.build_stats), self.per_step, options, self.plan)
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
        return _closest_first(pd, start, goal)

    def generate(
        self, start: np.ndarray, goal: np.ndarray, from_sector: int, to_sector: int, demo_index: int, stride: int = 1
    ) -> np.ndarray:
        """The blended DMP path (section 4.2.3) for one demonstration, unchecked.

        Shape (P, 4) with P = (N_FAKE_TIME_STEPS - 1) per_step + 1; with ``stride`` > 1 only every
        ``stride``-th sample and the last one are kept.
        """
        pd = self.pairs[(from_sector, to_sector)]
        start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
        dof34 = generate_blended(pd.forward[demo_index], pd.reverse[demo_index], start[2:], goal[2:])
        path = np.hstack([self._dof12(start, goal, from_sector, to_sector), dof34])
        if stride > 1:
            keep = np.arange(0, len(path), int(stride))
            if keep[-1] != len(path) - 1:
                keep = np.append(keep, len(path) - 1)
            path = path[keep]
        path[0], path[-1] = start, goal
        return path

    def query(
        self, start: np.ndarray, goal: np.ndarray, from_sector: int, to_sector: int, step: float | None = None
    ) -> QueryResult:
        """A motion-checked path from ``start`` to ``goal`` (section 4.2.3, validated).

        Tries the blended DMP paths of the ``n_candidates`` closest demonstrations (closest in the
        DOF3/DOF4 start/goal 4-vector), then the planner; counts each outcome (:meth:`stats`).
        Every segment of the returned path passes the check of ``si.checkMotion`` at resolution
        ``step`` (default ``robot.max_joint_step()``, the setups' resolution).
        """
        t0 = time.perf_counter()
        step = self.robot.max_joint_step() if step is None else float(step)
        start, goal = self.robot.check_config(start), self.robot.check_config(goal)
        i, j = check_sector(from_sector), check_sector(to_sector)
        if i == j:
            raise ValueError(f"({i}, {j}) is not a cross-sector motion")
        self._counts["queries"] += 1
        pd = self.pairs.get((i, j))
        tried = 0
        seed_path = None
        if pd is not None and len(pd.starts):
            order = _closest_first(pd, start, goal)  # start, goal and pair already checked above
            for rank, k in enumerate(order[: self.n_candidates]):
                tried += 1
                path = self.generate(start, goal, i, j, int(k), stride=self.query_stride)
                if motion_is_valid(self.robot, path, step):
                    outcome = "dmp" if rank == 0 else "repaired"
                    return self._result(path, outcome, int(k), tried, t0)
            if self.plan is not None:
                seed_path = self.generate(start, goal, i, j, int(order[0]), stride=self.per_step)
        if self.plan is not None:
            kw = {}
            if seed_path is not None and seed_path.shape == (N_FAKE_TIME_STEPS, 4) and _takes_initial_waypoints(self.plan):
                kw["initial_waypoints"] = seed_path
                self._counts["fallback_seeded"] += 1
            W = self.plan(start, goal, i, j, **kw)
            if W is not None:
                path = np.array(W, dtype=float)
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
        ``min(robot.max_joint_step(), 0.01)``, 0.01 being the tracker's default).  Raises
        RuntimeError when the outcome is "failed".  Same-sector calls (the tracker's re-aim
        around an obstacle) have no demonstrations: they go to ``same_sector``, by default
        :func:`tpee_ompl.library.tracker.make_default_planner`.
        """
        step = min(self.robot.max_joint_step(), 0.01) if step is None else float(step)
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
            "build_params": self.build_params,
            "query_stride": self.query_stride,
        }
        arrays: dict[str, np.ndarray] = {"meta": np.array(json.dumps(meta))}
        n_basis = self.options.basis_count((N_FAKE_TIME_STEPS - 1) * self.per_step + 1)
        for (i, j), pd in sorted(self.pairs.items()):
            p = f"p{i}{j}_"
            arrays[p + "starts"], arrays[p + "goals"], arrays[p + "waypoints"] = pd.starts, pd.goals, pd.waypoints
            arrays[p + "margins"] = pd.margins if pd.margins is not None else np.full(len(pd.starts), np.nan)
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
                pd = _PairData(arrays[p + "starts"], arrays[p + "goals"], arrays[p + "waypoints"], arrays[p + "margins"])
                if not (len(pd.starts) == len(pd.goals) == len(pd.waypoints) == len(pd.margins)):
                    raise ValueError(f"pair {i}->{j}: starts, goals, waypoints and margins differ in length")
                for W, fw, fs, rw, rs in zip(pd.waypoints, arrays[p + "fwd_weights"], arrays[p + "fwd_scaled"],
                                             arrays[p + "rev_weights"], arrays[p + "rev_scaled"], strict=True):
                    pd.forward.append(DMP.from_weights(fw, W[0, 2:], W[-1, 2:], fs, n_steps, options))
                    pd.reverse.append(DMP.from_weights(rw, W[-1, 2:], W[0, 2:], rs, n_steps, options))
                data[(int(i), int(j))] = pd
        except (KeyError, ValueError) as exc:
            raise LibraryFileError(f"path library {path} is inconsistent: {exc}") from exc
        return cls(robot, data, per_step, options, plan=plan, n_candidates=int(meta["n_candidates"]),
                   build_stats=meta.get("build_stats"), query_stride=int(meta.get("query_stride", 10)),
                   build_params=meta.get("build_params"))


def benchmark_queries(
    library: PathLibrary,
    queries: Sequence,
    reference: Plan | None = None,
) -> list[dict]:
    """One row per query (objects with start, goal, from_sector, to_sector, id), ready for a DataFrame.

    Columns: ``pair``, ``id``, ``outcome``, ``query_s`` (whole :meth:`PathLibrary.query`, with
    validation, repair and fallback), ``generation_s`` (nearest demo + its DMP path, no check),
    ``raw_valid`` (that path passed the motion check), ``length`` (rad, joint-space), and with a
    ``reference`` planner ``ref_length`` and ``length_ratio`` (NaN when either has no path).
    """
    rows = []
    step = library.robot.max_joint_step()
    for q in queries:
        i, j = int(q.from_sector), int(q.to_sector)
        start, goal = np.asarray(q.start, dtype=float), np.asarray(q.goal, dtype=float)
        t0 = time.perf_counter()
        k = int(library.demo_order(start, goal, i, j)[0])
        raw = library.generate(start, goal, i, j, k, stride=library.query_stride)
        gen_s = time.perf_counter() - t0
        raw_valid = motion_is_valid(library.robot, raw, step)
        res = library.query(start, goal, i, j)
        length = path_length(res.path) if res.path is not None else float("nan")
        row = {"pair": f"{i}->{j}", "id": int(getattr(q, "id", len(rows))), "outcome": res.outcome,
               "query_s": res.seconds, "generation_s": gen_s, "raw_valid": bool(raw_valid),
               "candidates_tried": res.candidates_tried, "length": length}
        if reference is not None:
            W = reference(start, goal, i, j)
            ref = path_length(W) if W is not None else float("nan")
            row.update(ref_length=ref, length_ratio=length / ref if ref > 0 else float("nan"))
        rows.append(row)
    return rows
