"""Target tracking strategy of Fig. 10: re-aim inside a pointing sector, plan only across sectors.

The :class:`Tracker` consumes a stream of target positions (and "lock a new target" events).
While the target stays in the current pointing sector it only re-aims with the closed-form IK
(:func:`tpee_ompl.model.pointing.aim`), no planning.  When the target leaves the pointing sector, a new
target lies outside it, or the target falls in the blind area or out of the line of sight, it
switches to the target's posture sector (or another sector that can aim at it) through a
cross-sector motion produced by a pluggable planner::

    planner(start_q, goal_q, from_sector, to_sector) -> waypoints, ndarray (K, 4)

Output: a time-stamped joint trajectory plus events (aim, cross-sector, blind-area, unreachable).
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import numpy as np

from ..model.pointing import AimingError, BlindAreaError, PointingGeometry, aim_batch, check_target
from ..model.sectors import SECTORS, check_sector, in_pointing_sector, infer_sector, posture_preset, posture_sector
from ..model.wearer_arm import WearerArm
from ..planning.paths import MIN_JOINT_STEP, motion_is_valid, motion_states, motion_step, planned_waypoints
from ..validation import MAX_SECONDS, as_float_array, check_bool, check_number, check_type
from .path_library import CHECK_STEP, PathLibrary

__all__ = [
    "Planner",
    "TrackEvent",
    "TrackResult",
    "Tracker",
    "TrackerOptions",
    "make_default_planner",
]

log = logging.getLogger(__name__)

MIN_JOINT_SPEED = 1e-6
"""rad/s. Slowest ``joint_speed`` accepted (a slower one made a motion's duration overflow to inf)."""
MAX_TIME = 1e10
"""Seconds. Largest |t| of a target sample: Unix times fit, and time steps of a few microseconds are still resolved."""

Planner = Callable[[np.ndarray, np.ndarray, int, int], np.ndarray]
"""planner(start_q (4,), goal_q (4,), from_sector, to_sector) -> waypoints (K, 4), radians."""


@dataclass(frozen=True)
class TrackerOptions:
    """Tracker settings.

    Attributes
    ----------
    joint_speed : float, rad/s
        Largest joint speed used to time-stamp the motions (max-norm over joints): a cross-sector motion's
        waypoints, and a re-aim that a target sample asks sooner than that speed allows.
    check_step : float, radians
        Joint step at which every motion the tracker commands is checked for collision (a larger one than
        the robot's ``max_joint_step()``, the step its collision guarantee holds for, is taken as that).
    """

    joint_speed: float = 1.0
    check_step: float = CHECK_STEP

    def __post_init__(self) -> None:
        set_ = lambda field_, value: object.__setattr__(self, field_, value)  # noqa: E731 (frozen dataclass)
        set_("joint_speed", check_number("joint_speed", self.joint_speed, low=MIN_JOINT_SPEED))
        set_("check_step", check_number("check_step", self.check_step, low=MIN_JOINT_STEP))


@dataclass(frozen=True)
class TrackEvent:
    """Something the tracker did or could not do.

    kind is one of ``"aim"`` (re-aimed inside the sector; ``detail`` starts with "planned" when the direct
    re-aim motion collided and the planner found one), ``"cross-sector"`` (switched posture),
    ``"blind-area"`` (the target was in the current posture's blind cylinder), ``"unreachable"``
    (no sector can aim at it, or the planner found no path to those that can: the arm holds still).
    """

    time: float
    kind: str
    sector: int | None
    detail: str = ""


@dataclass
class TrackResult:
    """Time-stamped joint trajectory and events.

    Attributes
    ----------
    times : ndarray (M,), seconds
    configurations : ndarray (M, 4), radians
    targets : ndarray (M, 3), metres: the target the row aims at, NaN inside planned motions
        and while holding still on an unreachable target
    sectors : ndarray (M,), int: the posture sector in use (0 inside planned motions: cross-sector, or a re-aim)
    events : list of TrackEvent
    """

    times: np.ndarray
    configurations: np.ndarray
    targets: np.ndarray
    sectors: np.ndarray
    events: list[TrackEvent] = field(default_factory=list)

    def count(self, kind: str) -> int:
        """Number of events of one kind."""
        return sum(e.kind == kind for e in self.events)


class Tracker:
    """Fig. 10 tracking with a pluggable cross-sector planner.

    Parameters
    ----------
    robot : WearerArm
    planner : Planner
    initial : ndarray (4,), optional
        Starting configuration (default: posture ``initial_sector``'s preset with pan = tilt = 0).
    initial_sector : int
    options : TrackerOptions, optional
    """

    def __init__(
        self,
        robot: WearerArm,
        planner: Planner,
        *,
        initial: np.ndarray | None = None,
        initial_sector: int = 3,
        options: TrackerOptions | None = None,
    ) -> None:
        if not isinstance(robot, WearerArm):
            raise ValueError(f"robot must be a WearerArm, got {type(robot).__name__}")
        if not callable(planner):
            raise ValueError(f"planner must be a callable (start, goal, from_sector, to_sector) -> waypoints, got "
                             f"{type(planner).__name__}")
        self.robot = robot
        self.planner = planner
        self.options = options or TrackerOptions()
        self.geometry = PointingGeometry.from_robot(robot)
        self.sector = check_sector(initial_sector)
        q0 = np.r_[posture_preset(self.sector), 0.0, 0.0] if initial is None else robot.check_config(initial)
        if infer_sector(q0) != self.sector:
            raise ValueError(f"initial configuration's DOF1/DOF2 {np.round(q0[:2], 4).tolist()} is not sector "
                             f"{self.sector}'s Table-1 preset {np.round(posture_preset(self.sector), 4).tolist()} "
                             "(initial_sector)")
        self.check_step = motion_step(robot, self.options.check_step)
        """The step the tracker checks its motions at: ``check_step``, at most the robot's ``max_joint_step()``."""
        self.q = robot.check_free(q0, "initial configuration").copy()
        self.time = -math.inf
        self._times: list[float] = []
        self._qs: list[np.ndarray] = []
        self._targets: list[np.ndarray] = []
        self._sectors: list[int] = []
        self.events: list[TrackEvent] = []
        self._no_path: list[str] = []

    # ------------------------------------------------------------------ helpers
    def _record(self, t: float, q: np.ndarray, target: np.ndarray | None, sector: int) -> None:
        self._times.append(t)
        self._qs.append(q.copy())
        self._targets.append(np.full(3, np.nan) if target is None else target.copy())
        self._sectors.append(sector)

    def _aim_from(self, target: np.ndarray, k: int) -> np.ndarray | None:
        """Configuration aiming at target from posture k (pan nearest the current pan), or None if not valid."""
        q = aim_batch(target[None], k, geometry=self.geometry, pan_reference=self.q[2], strict=False)[0]
        if not np.all(np.isfinite(q)):
            return None
        if not (self.robot.is_valid(q) and self.robot.line_of_sight_clear(q, target)):
            return None
        return q

    def _motion_free(self, a: np.ndarray, b: np.ndarray) -> bool:
        return bool(self.robot.are_valid(motion_states(a, b, self.check_step)).all())

    def _candidate_sectors(self, target: np.ndarray, current_tried: bool) -> list[int]:
        """Sectors to try: the posture sector, the other pointing sectors, then the current one (unless it was
        tried already: the target is in its pointing sector), the rest.  A target outside every pointing sector
        whose posture can aim at it is then aimed at from where the arm is, without crossing."""
        pivot = self.geometry.pivot
        home = int(posture_sector(target, pivot))
        order = [home] + [k for k in SECTORS if k != home and in_pointing_sector(target, k, pivot)]
        order = [k for k in order if k != self.sector] + ([] if current_tried else [self.sector])
        return order + [k for k in SECTORS if k not in order and k != self.sector]

    def _reaim(self, t: float, q: np.ndarray, target: np.ndarray) -> bool:
        """Aim at target with q from the current posture: a direct re-aim when that motion is free, else one
        planned inside the sector; False when the planner found no path."""
        if self._motion_free(self.q, q):
            self.events.append(TrackEvent(t, "aim", self.sector))
            # a re-aim takes the time joint_speed allows (the rows' times increase while the arm moves)
            t = max(t, self.time + float(np.max(np.abs(q - self.q))) / self.options.joint_speed)
            self.q = q
            self._record(t, q, target, self.sector)
            self.time = t
            return True
        arrival = self._cross(t, q, self.sector, target, "re-aim motion collides")
        if arrival is not None:
            self.time = arrival
        return arrival is not None

    def _cross(self, t: float, goal: np.ndarray, k: int, target: np.ndarray, why: str) -> float | None:
        """Run the planner from the current configuration to goal in sector k; return the arrival time, or None
        when the planner found no path (it returned None or raised RuntimeError: the reason goes to
        ``self._no_path``).  A path that does not start and end there, or collides, raises ValueError."""
        try:
            found = self.planner(self.q.copy(), goal.copy(), self.sector, k)
        except RuntimeError as exc:
            self._no_path.append(f"{self.sector}->{k}: {exc}")
            return None
        if found is None:
            self._no_path.append(f"{self.sector}->{k}: the planner found no path")
            return None
        waypoints = planned_waypoints(found, self.robot.nq)
        if not (np.allclose(waypoints[0], self.q, atol=1e-6) and np.allclose(waypoints[-1], goal, atol=1e-6)):
            raise ValueError("planner path does not start at the current configuration and end at the goal")
        waypoints[0], waypoints[-1] = self.q, goal
        if not motion_is_valid(self.robot, waypoints, self.check_step):
            raise ValueError(f"planner path {self.sector}->{k} collides or leaves the joint limits (checked every "
                             f"{self.check_step:g} rad; a planner must check its paths at least this finely: "
                             "make_default_planner(step=...))")
        if k == self.sector:  # a re-aim, planned: the posture stays
            self.events.append(TrackEvent(t, "aim", k, f"planned: {why}, {len(waypoints)} waypoints"))
        else:
            self.events.append(TrackEvent(t, "cross-sector", k, f"{self.sector}->{k}: {why}, {len(waypoints)} waypoints"))
        clock = t
        for i in range(1, len(waypoints)):
            a, b = waypoints[i - 1], waypoints[i]
            clock += float(np.max(np.abs(b - a))) / self.options.joint_speed
            last = i == len(waypoints) - 1  # the arrival: aimed at the target, in sector k
            self._record(clock, b, target if last else None, k if last else 0)
        self.sector, self.q = k, goal.copy()
        return clock

    # ------------------------------------------------------------------ API
    def step(self, t: float, target: np.ndarray, new_target: bool = False) -> None:
        """Process one target sample at time t (seconds); ``new_target`` marks a 'lock a new target' event.

        A time before the last one is clamped to it, and a re-aim takes at least the time ``joint_speed``
        allows.  A target that is not finite, too far
        (``MAX_TARGET_DISTANCE``) or inside the wearer is recorded as an ``"unreachable"`` event.

        Raises
        ------
        ValueError
            If t is not a finite number within +/-``MAX_TIME``, target is not 3 numbers or ``new_target``
            is not a bool.
        """
        t = check_number("time t (seconds)", t, low=-MAX_TIME, high=MAX_TIME)
        new_target = check_bool("new_target", new_target)
        raw = as_float_array(target, "target")
        if raw.shape != (3,):
            raise ValueError(f"target must have shape (3,); got {raw.shape}")
        if self.time == -math.inf:  # the arm rests at its initial configuration until the first sample
            self.time = float(t)
        t = max(float(t), self.time)
        try:
            target = check_target(target, self.robot)
        except AimingError as exc:
            self.events.append(TrackEvent(t, "unreachable", self.sector, str(exc)))
            self._record(t, self.q, None, self.sector)
            self.time = t
            return
        why = "new target outside the pointing sector" if new_target else "target left the pointing sector"
        self._no_path = []
        here = in_pointing_sector(target, self.sector, self.geometry.pivot)
        if here:
            try:
                aim_batch(target[None], self.sector, geometry=self.geometry, pan_reference=self.q[2])
            except BlindAreaError as exc:
                self.events.append(TrackEvent(t, "blind-area", self.sector, str(exc)))
                why = "blind-area"
            except AimingError as exc:  # an "unreachable" event only if no other posture can aim at it either (below)
                why = f"not reachable from posture {self.sector} ({exc})"
            else:
                q = self._aim_from(target, self.sector)
                if q is not None and self._reaim(t, q, target):
                    return
                why = "no collision-free aim with a clear line of sight from this posture"
        for k in self._candidate_sectors(target, current_tried=here):
            q = self._aim_from(target, k)
            if q is None:
                continue
            if k == self.sector:  # outside its pointing sector, but this posture can aim at it
                if self._reaim(t, q, target):
                    return
                continue
            arrival = self._cross(t, q, k, target, why)
            if arrival is not None:
                self.time = arrival
                return
        detail = "no posture can aim at the target" if not self._no_path else "no path: " + "; ".join(self._no_path)
        self.events.append(TrackEvent(t, "unreachable", self.sector, detail))
        self._record(t, self.q, None, self.sector)
        self.time = t

    def run(self, stream: Iterable[tuple[float, np.ndarray] | tuple[float, np.ndarray, bool]]) -> TrackResult:
        """Process (time, target[, new_target]) samples and return the whole trajectory so far."""
        for item in stream:
            self.step(*item)
        return self.result()

    def result(self) -> TrackResult:
        """The trajectory and events recorded so far."""
        return TrackResult(
            times=np.array(self._times, dtype=float),
            configurations=np.array(self._qs, dtype=float).reshape(-1, 4),
            targets=np.array(self._targets, dtype=float).reshape(-1, 3),
            sectors=np.array(self._sectors, dtype=int),
            events=list(self.events),
        )


def make_default_planner(
    robot: WearerArm,
    *,
    timeout: float = 2.0,
    seed: int | None = 1,
    library: PathLibrary | str | os.PathLike | None = "default",
    library_time: float = 0.05,
    step: float | None = None,
) -> Planner:
    """The tracker's cross-sector planner: the paper's pipeline, with plain fallbacks.

    A cross-sector motion goes to :class:`~tpee_ompl.library.planner.LibraryDimensionRRT` (the DMP
    library's validated path, refined by dimension-RRT) for ``library_time`` seconds; ``library`` is
    the packaged default library (``"default"``; skipped for a robot of another model, which it was not built
    for), a file, a loaded :class:`PathLibrary`, or None to skip this step (anything else: ValueError).  Otherwise, and for same-sector re-aims: Table 3's straight motion
    (:func:`tpee_ompl.model.queries.straight_motion`; within a sector a straight joint motion) when
    collision-free, else OMPL RRTConnect on :func:`tpee_ompl.planning.setup.make_simple_setup` for
    at most ``timeout`` seconds, simplified.  Every path is checked at ``step`` (default the tracker's default step,
    :data:`~tpee_ompl.library.path_library.CHECK_STEP`; the robot's motion step if smaller: give a tracker's finer
    ``check_step`` here); a loaded ``library`` of another model or other margins than ``robot`` is refused; raises
    RuntimeError if none is found.  OMPL's log level is left as the caller set it (its "Info:" lines are off
    while a motion is planned), and OMPL's seed generator is set to ``seed`` here (:func:`seed_ompl`).  ``seed`` fixes the samples,
    not the time: the library step stops after ``library_time`` seconds of wall-clock time, so how far it
    refined a path, and so the tracker's trajectory, can differ between runs (``library=None``, or a planner
    capped by samples, repeats exactly).
    """
    from ompl import geometric as og

    from ..model.queries import straight_motion
    from ..planning.paths import path_to_array
    from ..planning.setup import make_simple_setup, quieter_ompl, seed_ompl
    from .planner import LibraryDimensionRRT

    check_type("robot", robot, WearerArm)
    if not (library is None or isinstance(library, PathLibrary)
            or isinstance(library, (str, os.PathLike)) and os.fspath(library)):
        raise ValueError("library must be 'default', a library file's path, a PathLibrary or None, "
                         f"got {library!r:.80}")
    timeout = check_number("timeout (seconds)", timeout, low=0.0, low_open=True, high=MAX_SECONDS)
    library_time = check_number("library_time (seconds)", library_time, low=0.0, low_open=True, high=MAX_SECONDS)
    if seed is not None:
        seed_ompl(seed)
    step = motion_step(robot, CHECK_STEP if step is None else step)
    lib: PathLibrary | None = None
    if isinstance(library, PathLibrary):
        library.check_robot(robot)
        lib = library
    elif library == "default":  # the packaged library, when it was built for this model (else none, as track does)
        from .storage import packaged_library_for

        packaged = packaged_library_for(robot)
        if packaged is not None:
            lib = PathLibrary.load(packaged, robot)
        else:
            log.info("the packaged path library was built for another model: cross-sector motions are planned "
                     "without it")
    elif library is not None:
        lib = PathLibrary.load(library, robot)

    def plan(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray:
        with quieter_ompl():  # no "Info:" line per tracker motion
            return _plan(start, goal, i, j)

    def _plan(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray:
        if i != j and lib is not None:
            ss = make_simple_setup(robot, start, goal, joint_step=step)
            ss.setPlanner(LibraryDimensionRRT(ss.getSpaceInformation(), lib, i, j, seed=seed))
            if ss.solve(library_time) and ss.haveExactSolutionPath():
                return path_to_array(ss.getSolutionPath(), robot.nq)
        w = straight_motion(start, goal, i, j) if i != j else np.array([start, goal], dtype=float)
        if motion_is_valid(robot, w, step):
            return w
        ss = make_simple_setup(robot, start, goal, joint_step=step)
        ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
        if not ss.solve(timeout) or not ss.haveExactSolutionPath():
            raise RuntimeError(f"RRTConnect found no path {i}->{j} in {timeout} s")
        ss.simplifySolution()
        path = ss.getSolutionPath()
        path.interpolate()
        return path_to_array(path, robot.nq)

    return plan
