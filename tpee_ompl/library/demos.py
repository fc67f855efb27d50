"""Demonstrations of the path library: the query sampler, the demo planners, collecting demos per pair.

The library's planner and query sampler are injected callables, so the library does not depend
on any particular planner::

    sample_query(rng, from_sector, to_sector) -> (start (4,), goal (4,))
    plan(start, goal, from_sector, to_sector) -> waypoints (7, 4) at the fake-time steps, or None

Default builders: :func:`query_sampler` (the planning-necessary query generator's sampling,
:mod:`tpee_ompl.planning.query_generation`) and :class:`DemoPlanner` (dimension-RRT, 2500 samples,
with a wider margin around the pointing system first, so demonstrations keep room that their DMP
generalisations can use).  :func:`collect_pair` draws, filters and plans the demonstrations of one
ordered sector pair (section 4.2.2); :class:`PairDemos` holds them with their DMPs.
"""

from __future__ import annotations

import logging
import zlib
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..model.sectors import PRESET_TOLERANCE, posture_preset
from ..model.wearer_arm import WearerArm
from ..validation import as_float_array
from .dmp import DMP

__all__ = [
    "DEMO_MARGINS",
    "MAX_PER_STEP",
    "N_FAKE_TIME_STEPS",
    "POINTING_LINKS",
    "max_query_stride",
    "DemoPlanner",
    "PairDemos",
    "Plan",
    "SampleQuery",
    "check_demo_margins",
    "collect_pair",
    "demo_problem",
    "dimension_rrt_planner",
    "query_sampler",
]

log = logging.getLogger(__name__)

N_FAKE_TIME_STEPS = 7
"""Fake-time steps of every planned path (section 4.1.2)."""
MAX_PER_STEP = 1000
"""Most samples per fake-time step a library takes: its DMPs' grid (6 x per_step + 1 samples, half as many basis
functions by default) must stay within ``dmp.MAX_GRID_ENTRIES`` (1000: 6001 x 3000).  The packaged library: 100."""


def max_query_stride(per_step: int) -> int:
    """The largest useful ``query_stride`` of a library with ``per_step`` samples per fake-time step: the length
    of its rollouts between their first and last sample (a longer stride keeps only those two)."""
    return (N_FAKE_TIME_STEPS - 1) * int(per_step)


POINTING_LINKS: tuple[str, ...] = ("link3", "link4")
"""Links moved by DOF3/DOF4, the DOFs the DMPs generate (DOF1/DOF2 follow Table 3 for every query)."""
DEMO_MARGINS: tuple[float, ...] = (0.05, 0.04, 0.03, 0.025)
"""Metres. Margins around :data:`POINTING_LINKS` tried in turn when planning a demonstration, before
the robot's own margin.  A demonstration planned at 2 cm hugs the wearer; its DMP generalisations
then cross into the margin (docs/dmp.md has the measurements)."""

SampleQuery = Callable[[np.random.Generator, int, int], tuple[np.ndarray, np.ndarray]]
"""sample_query(rng, from_sector, to_sector) -> (start (4,), goal (4,)), radians."""
Plan = Callable[[np.ndarray, np.ndarray, int, int], "np.ndarray | None"]
"""plan(start, goal, from_sector, to_sector) -> waypoints (7, 4) at the fake-time steps, or None."""


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
    from ..model.pointing import PointingGeometry
    from ..planning.query_generation import NECESSITY_REGIONS, aimable_samples, draw_cross_sector, straight_motion_valid

    geometry = PointingGeometry.from_robot(robot)
    origin = geometry.pivot
    regions = NECESSITY_REGIONS if regions is None else regions

    def sample(rng: np.random.Generator, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
        from_stream = aimable_samples(robot, geometry, i, tuple(regions[i]), rng, origin)
        to_stream = aimable_samples(robot, geometry, j, tuple(regions[j]), rng, origin)
        last = None
        for _ in range(max_draws):
            draw = draw_cross_sector(robot, geometry, from_stream, to_stream, j)
            if draw is None:
                continue
            last = (np.asarray(draw[2], dtype=float), np.asarray(draw[3], dtype=float))
            if not require_planning or not straight_motion_valid(robot, *last, i, j):
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
    from ..planning.paths import path_to_array
    from ..planning.setup import make_simple_setup, quieter_ompl
    from ..planning.tpee import tpee_dimension_rrt

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
        with quieter_ompl():
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
        margins = check_demo_margins(margins)
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

    @property
    def rungs(self) -> tuple[tuple[float, WearerArm], ...]:
        """(margin in metres, robot checked at that margin) per rung, in the order they are tried."""
        return tuple((m, r) for m, r, _ in self._rungs)

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



def check_demo_margins(margins: Sequence[float]) -> tuple[float, ...]:
    """``margins`` as a tuple of floats, each a number in [0, 1] metres (else ValueError)."""
    try:
        out = tuple(float(m) for m in margins)
    except (TypeError, ValueError):
        raise ValueError(f"demo margins must be numbers in [0, 1] metres, got {margins!r}") from None
    if not all(np.isfinite(m) and 0.0 <= m <= 1.0 for m in out):
        raise ValueError(f"demo margins must be numbers in [0, 1] metres, got {list(margins)!r}")
    return out

@dataclass
class PairDemos:
    """The demonstrations of one ordered sector pair and their DMPs (the values of ``PathLibrary.pairs``).

    Attributes
    ----------
    starts, goals : ndarray (M, 4), radians
    waypoints : ndarray (M, 7, 4), radians: each demo's planned path at the fake-time steps
    margins : ndarray (M,), metres, or None: the margin each demo was planned with (NaN: unknown)
    forward, reverse : list of DMP: per demo, DOF3/DOF4 learned from the demo and from it flipped in time
    """

    starts: np.ndarray
    goals: np.ndarray
    waypoints: np.ndarray
    margins: np.ndarray | None = None
    forward: list[DMP] = field(default_factory=list)
    reverse: list[DMP] = field(default_factory=list)

    @property
    def keys(self) -> np.ndarray:
        """(M, 4): DOF3/DOF4 of start and goal, the space in which demos are compared."""
        return np.hstack([self.starts[:, 2:], self.goals[:, 2:]])

    def closest_first(self, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """Indices of the demos, closest first in the DOF3/DOF4 (start, goal) 4-vector (stable order on ties)."""
        return np.argsort(np.linalg.norm(self.keys - _key(start, goal), axis=1), kind="stable")


def _key(start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    return np.concatenate([start[2:], goal[2:]])


def demo_problem(
    robot: WearerArm | None, i: int, j: int, starts: np.ndarray, goals: np.ndarray, waypoints: np.ndarray
) -> tuple[str, str] | None:
    """What a library file may not hold in pair (i, j)'s demonstrations: ``(array, why)`` for the first problem,
    ``array`` one of "starts", "goals", "waypoints", or None when there is none.

    ``starts``, ``goals`` (M, 4) and ``waypoints`` (M, 7, 4) are finite radians.  Checked, within
    :data:`~tpee_ompl.model.sectors.PRESET_TOLERANCE`: every value inside ``robot``'s joint limits (not checked
    when ``robot`` is None), DOF1/DOF2 of each start and first waypoint at sector i's Table-1 preset and of each
    goal and last waypoint at sector j's, each path running from its start to its goal.  Loading and saving a
    library (:mod:`tpee_ompl.library.storage`) and :func:`collect_pair` use this one check.
    """
    tol = PRESET_TOLERANCE
    if robot is not None:  # demonstrations are planned inside the limits; a DMP learned off them cannot be used
        for name, x in (("starts", starts), ("goals", goals), ("waypoints", waypoints)):
            if x.size and not (np.all(x >= robot.lower - tol) and np.all(x <= robot.upper + tol)):
                return name, "leaves the robot's joint limits"
    for name, k, rows in (("starts", i, starts), ("goals", j, goals),
                          ("waypoints", i, waypoints[:, 0]), ("waypoints", j, waypoints[:, -1])):
        if rows.size and not np.allclose(rows[:, :2], posture_preset(k), rtol=0.0, atol=tol):
            return name, f"does not {'start' if k == i else 'end'} at sector {k}'s Table-1 preset in DOF1/DOF2"
    if not (np.allclose(waypoints[:, 0], starts, rtol=0.0, atol=tol)
            and np.allclose(waypoints[:, -1], goals, rtol=0.0, atol=tol)):
        return "waypoints", "does not run from the query's start to its goal"
    return None


def _sampled(query: object, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
    """``sample_query``'s answer as (start, goal), each four finite numbers, else ValueError naming sample_query."""
    try:
        start, goal = query  # type: ignore[misc]
        start, goal = as_float_array(start, "start"), as_float_array(goal, "goal")
    except (TypeError, ValueError) as exc:
        raise ValueError(f"sample_query must return (start, goal) for pair {i}->{j}, got {query!r} ({exc})"[:400]) from None
    if start.shape != (4,) or goal.shape != (4,) or not (np.all(np.isfinite(start)) and np.all(np.isfinite(goal))):
        raise ValueError(f"sample_query must return a start and a goal of 4 finite numbers for pair {i}->{j}, "
                         f"got {start.tolist()!r} and {goal.tolist()!r}"[:400])
    return start, goal


def _planned(W: object, i: int, j: int) -> np.ndarray:
    """``plan``'s answer as a (7, 4) array of finite numbers, else ValueError naming plan."""
    try:
        W = as_float_array(W, "waypoints")
    except ValueError as exc:
        raise ValueError(f"plan returned no path for pair {i}->{j}: {exc}") from None
    if W.shape != (N_FAKE_TIME_STEPS, 4):
        raise ValueError(f"plan returned shape {W.shape}; expected ({N_FAKE_TIME_STEPS}, 4)")
    if not np.all(np.isfinite(W)):
        raise ValueError(f"plan returned a path for pair {i}->{j} that holds NaN or inf")
    return W


def collect_pair(
    sample_query: SampleQuery,
    plan: Plan,
    i: int,
    j: int,
    child: np.random.SeedSequence,
    per_pair: int,
    min_difference: float,
    max_attempts: int,
    *,
    robot: WearerArm | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Counter[str]]:
    """Draw, filter and plan the demonstrations of one pair (section 4.2.2).

    Draws with ``sample_query`` and generator ``child`` (seed sequence); a draw is kept only if its
    DOF3/DOF4 (start, goal) 4-vector is at least ``min_difference`` (radians) from every stored
    one and ``plan`` returns a path; stops at ``per_pair`` demos or ``max_attempts`` draws.
    Returns starts (M, 4), goals (M, 4), waypoints (M, 7, 4), margins (M,) (``plan.last_margin``
    when the planner has one, else NaN) and counters ("sampled", "rejected_similar",
    "plan_failed", "stored", "stored_at_<margin>mm").

    Every query and path is checked as a library file's are (:func:`demo_problem`; the joint limits of
    ``robot`` only when it is given): ValueError naming ``sample_query`` or ``plan``, whichever answered
    what a library could not save.
    """
    rng = np.random.default_rng(child)
    stats: Counter[str] = Counter()
    starts, goals, paths, keys, margins = [], [], [], [], []
    for _ in range(max_attempts):
        if len(starts) >= per_pair:
            break
        stats["sampled"] += 1
        start, goal = _sampled(sample_query(rng, i, j), i, j)
        ends = np.stack([start, goal])[None]  # the straight "path" (start, goal): checks the query alone
        problem = demo_problem(robot, i, j, start[None], goal[None], ends)
        if problem is not None:
            raise ValueError(f"sample_query returned a query for pair {i}->{j} that {problem[1]}: start "
                             f"{np.round(start, 4).tolist()}, goal {np.round(goal, 4).tolist()}")
        key = _key(start, goal)
        if keys and np.min(np.linalg.norm(np.array(keys) - key, axis=1)) < min_difference:
            stats["rejected_similar"] += 1
            continue
        W = plan(start, goal, i, j)
        if W is None:
            stats["plan_failed"] += 1
            continue
        W = _planned(W, i, j)
        problem = demo_problem(robot, i, j, start[None], goal[None], W[None])
        if problem is not None:
            raise ValueError(f"plan returned a path for pair {i}->{j} that {problem[1]}")
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
