"""OMPL problem set-up for any :class:`RobotChecker` (the wearer + arm included): state space,
validity checking, motion checking.

The state space is ``ob.RealVectorStateSpace(nq)`` bounded by the URDF joint limits; its metric
(the Euclidean norm of joint differences, radians) is the path-length metric for every planner.
A robot with continuous joints gets a compound space instead (:func:`make_space`): each continuous
joint an ``SO2StateSpace`` (its angle wraps around), the other joints in bounded RealVector runs; the
metric is then OMPL's compound one, the sum of the subspaces' distances (never below the Euclidean
norm of the short-way joint differences, so the guarantee below holds as stated).

Motion-check guarantee
----------------------
A motion is checked at states no more than ``robot.max_joint_step()`` apart (Euclidean, rad),
which moves no point of the robot more than the security margin m (lever-arm bound, see
:meth:`RobotChecker.max_joint_step`).  Every checked state keeps all pairs at least m apart, so any
state in between is within m/2 of a checked one: **every point of an accepted motion keeps at
least m/2 (1 cm by default) from the static world (wearer, obstacles) and from the robot's own
checked links.**
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ..model import clearance_balls
from ..model.clearance_balls import SCREEN_COST_LIMIT, SCREEN_LEVELS, screened_all_valid, screened_lines_valid
from ..model.robot_checker import RobotChecker
from ..validation import MOTION_VALIDATORS, check_bool, check_number, check_seed
from .paths import (MIN_JOINT_STEP, batched_motion_states, bisection_order, counted_motion_states, state_to_array,
                    straight_segment_counts, unchecked_motion_states)
from .space_layout import RealVectorLayout

if TYPE_CHECKING:
    from .certified import CertifiedMotionOptions

__all__ = [
    "RobotValidityChecker",
    "WearerValidityChecker",
    "BatchedMotionValidator",
    "make_space",
    "make_simple_setup",
    "motion_check_step",
    "motion_counts",
    "quieter_ompl",
    "seed_ompl",
    "valid_motion_fraction",
    "MOTION_VALIDATORS",
]

log = logging.getLogger(__name__)


@contextlib.contextmanager
def quieter_ompl(level: ou.LogLevel = ou.LOG_WARN) -> Iterator[None]:
    """OMPL's messages below ``level`` off inside the block (its "Info:" lines by default), then its level as it was:
    a library function must not change the process-wide level of its caller (who may have chosen LOG_NONE)."""
    before = ou.getLogLevel()
    ou.setLogLevel(max(before, level, key=lambda v: v.value))
    try:
        yield
    finally:
        ou.setLogLevel(before)


def seed_ompl(seed: int) -> None:
    """Set OMPL's seed generator to ``seed``: the planners and samplers made after it draw reproducible numbers.

    Once random numbers were drawn in a process, OMPL logs an error ("Random number generation already started")
    and reseeds all the same (``RandomNumbers.cpp``), so a later seed does take effect; the error is silenced.
    ValueError for a seed OMPL cannot take (:func:`~tpee_ompl.validation.check_seed`: 0 makes it run unseeded)."""
    seed = check_seed("seed", seed)
    with quieter_ompl(ou.LOG_NONE):
        ou.RNG.setSeed(seed)



class RobotValidityChecker(ob.StateValidityChecker):
    """State validity for OMPL: joint limits plus collision checking by a :class:`RobotChecker`.

    ``are_valid`` offers the batched check to planners that know about it (dimension-RRT).
    """

    def __init__(self, si: ob.SpaceInformation, robot: RobotChecker) -> None:
        super().__init__(si)
        self.robot = robot
        self._indices = range(robot.nq)
        space = si.getStateSpace()
        self._read = None if isinstance(space, ob.RealVectorStateSpace) else RealVectorLayout(space).read

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL override)
        """True if the state is collision-free with the security margin."""
        if self._read is not None:  # a compound space (continuous joints): its flat values in joint order
            return self.robot.is_valid_values(self._read(state).tolist())
        return self.robot.is_valid_values([state[i] for i in self._indices])

    def clearance(self, state: ob.State) -> float:
        """Workspace distance (m) to the nearest invalid configuration: the closest checked pair's distance less
        its margin (``RobotChecker.clearance(q, from_margins=True)``); OMPL's ``Benchmark`` averages it over a
        path's states as the solution clearance (0 for every path without this override)."""
        q = self._read(state) if self._read is not None else np.array([state[i] for i in self._indices])
        return self.robot.clearance(q, from_margins=True)

    def are_valid(self, Q: np.ndarray) -> np.ndarray:
        """Batched validity of configurations Q (N, nq)."""
        return self.robot.are_valid(Q)

    def first_invalid(self, Q: np.ndarray) -> int:
        """Index of the first invalid configuration of Q (N, nq) in row order, or -1; stops there."""
        return self.robot.first_invalid(Q)


WearerValidityChecker = RobotValidityChecker
"""The name :class:`RobotValidityChecker` had when only the wearer was checked (kept for existing code)."""


class BatchedMotionValidator(ob.MotionValidator):
    """Checks a whole straight motion with batched Pinocchio calls.

    The verdict is that of OMPL's ``DiscreteMotionValidator`` at the same resolution (every state a
    step apart valid); native planners call it through ``si.checkMotion``.  Like that validator it
    honours the space's ``validSegmentCountFactor``: OMPL's Benchmark sets it to 4 for its
    ``correct_solution_strict`` column, which then really checks 4x more densely.  In the compound space of a
    robot with continuous joints (:func:`make_space`) a motion follows the space's geodesic (SO2 the short way)
    with the compound's own segment count (:meth:`segment_counts`; there OMPL's validator ignores the factor,
    this one applies it).

    By default the states are screened first where that pays on the robot (``screen_levels``,
    :func:`~tpee_ompl.model.clearance_balls.screened_all_valid`): one state checked at margins
    inflated for a ball of a few steps certifies its neighbours, and only the states no ball covers
    are checked themselves; the verdict is the same.  ``screen_levels=()`` checks the states themselves: one
    motion in bisection order up to its first invalid state (as ``DiscreteMotionValidator``), several in one batch.
    """

    def __init__(self, si: ob.SpaceInformation, robot: RobotChecker, step: float,
                 screen_levels: Sequence[float] | None = None) -> None:
        super().__init__(si)
        self.robot = robot
        self.step = float(step)
        """Radians: the step at validSegmentCountFactor 1 (see :meth:`effective_step`)."""
        self._space = si.getStateSpace()
        self._n = robot.nq
        self._layout = None if isinstance(self._space, ob.RealVectorStateSpace) else RealVectorLayout(self._space)
        """The compound space's reader and geodesics (continuous joints as SO2); None for a RealVector space."""
        if self._layout is not None:  # OMPL's rule: each subspace's own segment length, a share of its extent
            self._leaf_steps = self.step * self._layout.leaf_extents() / float(self._space.getMaximumExtent())
        self.motions_checked = 0
        self.motions_valid = 0
        """Motions checked / found valid (OMPL's own counters stay at 0 under a Python ``checkMotion``:
        :func:`motion_counts` reads these)."""
        levels = SCREEN_LEVELS if screen_levels is None else screen_levels
        levels = tuple(check_number("screen_levels (motion-check steps)", h, low=0.5, high=1e3) for h in levels)
        if levels and screen_levels is None and not robot.ball_screen().pays(max(levels) * self.step):
            log.info("motion checks without clearance balls: on this robot a screened state costs more than "
                     "%g plain checks", SCREEN_COST_LIMIT)
            levels = ()
        if levels:
            robot.ball_screen().prepare(h * self.step for h in levels)  # not in the first plan's time
        self.screen_levels = levels
        """The ball radii screened with (motion-check steps): ``screen_levels`` as given, or by default (None)
        :data:`SCREEN_LEVELS` where screening pays on the robot
        (:meth:`~tpee_ompl.model.clearance_balls.BallScreen.pays`), else () (every state checked)."""

    checks_geodesics = True
    """:meth:`check_motions` follows the space's geodesics in a compound space (continuous joints the short way)."""

    def factor(self) -> int:
        """The space's ``validSegmentCountFactor`` f now: a motion of length d gets ``f * ceil(d / step)``
        segments, as OMPL's ``DiscreteMotionValidator`` counts them."""
        return max(1, int(self._space.getValidSegmentCountFactor()))

    def effective_step(self) -> float:
        """Longest step (radians) between checked states now: ``step / validSegmentCountFactor``."""
        return self.step / self.factor()

    def read_state(self, state: ob.State) -> np.ndarray:
        """A state of the validator's space as the robot's joint values (nq,)."""
        return state_to_array(state, self._n) if self._layout is None else self._layout.read(state)

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL override)
        """True if every state along s1 -> s2 (excluding s1) is valid (False for a NaN or inf end, as OMPL's
        ``DiscreteMotionValidator`` answers)."""
        a, b = self.read_state(s1), self.read_state(s2)
        if self._layout is not None:
            return bool(self._checked(a[None], b[None], clearance_balls.PROBES)[0])
        self.motions_checked += 1
        try:
            states = unchecked_motion_states(a, b, self.step, factor=self.factor())
        except (ValueError, OverflowError):  # the segment count of a NaN or inf motion (no cost when finite)
            if np.isfinite(a).all() and np.isfinite(b).all():
                raise
            return False
        return self._tally(bool(self.all_valid([states], clearance_balls.PROBES)[0]))

    def check_motions(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Validity of many motions A[k] -> B[k] (each excluding its start), batched together; a motion with a NaN
        or inf end is invalid."""
        return self._checked(np.atleast_2d(A), np.atleast_2d(B))

    def _checked(self, A: np.ndarray, B: np.ndarray, probes: int = 0) -> np.ndarray:
        """:meth:`check_motions`; ``probes``: a single motion's states checked plainly before its screen (the
        native planners' ``checkMotion``; :data:`~tpee_ompl.model.clearance_balls.PROBES`)."""
        try:
            return self._check_finite_motions(A, B, probes)
        except (ValueError, OverflowError):
            return finite_motions_checked(A, B, lambda A, B: self._check_finite_motions(A, B, probes), self)

    def _check_finite_motions(self, A: np.ndarray, B: np.ndarray, probes: int = 0) -> np.ndarray:
        if self._layout is not None:
            return self._check_geodesics(A, B, probes)
        S, counts = batched_motion_states(A, B, self.step, factor=self.factor())
        self.motions_checked += len(counts)
        if len(counts) < 2 or not self.screen_levels:
            ok = self.all_valid(np.split(S, np.cumsum(counts)[:-1]) if len(counts) else [], probes)
        else:
            spacing = np.sqrt(((B - A) ** 2).sum(-1)) / counts  # the states are evenly spaced along each motion
            ok = screened_lines_valid(self.robot, self.robot.ball_screen(), S, counts, spacing, self.step,
                                      self.screen_levels)
        return self._tally(ok)

    def segment_counts(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Segments of each motion A[k] -> B[k] (K, nq), times the space's ``validSegmentCountFactor``.

        In a RealVector space ``ceil(|B - A| / step)``, as OMPL's validator counts them.  In a compound space as
        OMPL's ``CompoundStateSpace`` counts them (the most any subspace needs, each subspace's segment its share
        ``step * extent_i / extent`` of the step; at most ``step`` apart in the Euclidean joint metric), with the
        factor that OMPL's own validator does not apply to a compound space's subspaces (stricter there)."""
        if self._layout is None:
            D = np.asarray(B, dtype=float) - np.asarray(A, dtype=float)
            if not np.isfinite(D).all():
                raise ValueError("motion ends must be finite")
            return straight_segment_counts(D, self.step, self.factor())
        need = np.ceil(self._layout.leaf_distances(A, B) / self._leaf_steps).max(axis=-1)
        if not np.isfinite(need).all():
            raise ValueError("motion ends must be finite")
        return self.factor() * np.maximum(1, need).astype(np.int64)

    def _check_geodesics(self, A: np.ndarray, B: np.ndarray, probes: int = 0) -> np.ndarray:
        """:meth:`check_motions` in a compound space: each motion along the space's geodesic (continuous joints
        the short way round, wrapped into [-pi, pi)), the states ``DiscreteMotionValidator`` checks at
        ``validSegmentCountFactor`` 1 (:meth:`segment_counts`)."""
        lay = self._layout
        D = lay.delta(A, B)
        counts = self.segment_counts(A, B)
        S = lay.wrap(counted_motion_states(A, D, counts))
        S[np.cumsum(counts) - 1] = B  # each end is the state itself, as OMPL checks s2
        self.motions_checked += len(counts)
        if self.screen_levels:  # the states are evenly spaced along each motion's joint-space line (unwrapped)
            spacing = np.linalg.norm(D, axis=1) / counts
            ok = screened_lines_valid(self.robot, self.robot.ball_screen(), S, counts, spacing, self.step,
                                      self.screen_levels, probes)
        else:
            ok = self.all_valid(np.split(S, np.cumsum(counts)[:-1]) if len(counts) else [])
        return self._tally(np.asarray(ok, dtype=bool))

    def _tally(self, ok):
        """Count the valid verdicts among ``ok`` (one bool or an array of them) into ``motions_valid``; return ``ok``."""
        self.motions_valid += int(np.count_nonzero(ok))
        return ok

    def all_valid(self, chunks: list[np.ndarray], probes: int = 0) -> np.ndarray:
        """Per chunk of evenly spaced states along a line (a motion's dense states), True iff all are valid: screened
        (``screen_levels``; one chunk's ``probes`` states plainly first), else one chunk in bisection order up to its
        first invalid state, several in one batch."""
        if not chunks:
            return np.zeros(0, dtype=bool)
        if self.screen_levels:
            return screened_all_valid(self.robot, self.robot.ball_screen(), chunks, self.step, self.screen_levels,
                                      probes)
        if len(chunks) == 1:  # one motion (si.checkMotion): as OMPL's DiscreteMotionValidator, in bisection order up to
            S = chunks[0]  # the first invalid state (all states in one batch took 1 s on a colliding xArm7 motion)
            return np.array([self.robot.first_invalid(S[bisection_order(len(S))]) < 0])
        ok = self.robot.are_valid(np.concatenate(chunks))
        bounds = np.cumsum([0] + [len(c) for c in chunks])
        return np.array([ok[bounds[k] : bounds[k + 1]].all() for k in range(len(chunks))], dtype=bool)


def finite_motions_checked(A: np.ndarray, B: np.ndarray, check: Callable[[np.ndarray, np.ndarray], np.ndarray],
                           validator: BatchedMotionValidator) -> np.ndarray:
    """After ``check(A, B)`` raised: ``check`` of the motions whose ends are finite, False for the others (counted
    as checked, as OMPL's ``DiscreteMotionValidator`` answers a NaN or inf end); the error again when every end is
    finite (it was another)."""
    finite = np.isfinite(A).all(axis=1) & np.isfinite(B).all(axis=1)
    if finite.all():
        raise
    out = np.zeros(len(A), dtype=bool)
    if finite.any():
        out[finite] = check(A[finite], B[finite])
    validator.motions_checked += int((~finite).sum())
    return out


def motion_counts(mv: ob.MotionValidator) -> tuple[int, int]:
    """(valid, checked) motions a validator has counted so far: the project's validators count their own
    (a Python ``checkMotion`` leaves OMPL's counters at 0, so ``getValidMotionFraction()`` says 0), OMPL's
    validators theirs."""
    if isinstance(mv, BatchedMotionValidator):
        return mv.motions_valid, mv.motions_checked
    return int(mv.getValidMotionCount()), int(mv.getCheckedMotionCount())


def valid_motion_fraction(before: tuple[int, int] | None, after: tuple[int, int] | None) -> float | None:
    """The share of valid motions among those checked between two :func:`motion_counts`; None when no motion
    was counted (nothing checked, or a Python validator without counters of its own) or a count is missing."""
    if before is None or after is None:
        return None
    valid, checked = after[0] - before[0], after[1] - before[1]
    return valid / checked if checked > 0 else None


def make_space(robot: RobotChecker) -> ob.StateSpace:
    """A RealVector state space bounded by the URDF joint limits (radians, metres for prismatic joints).

    With continuous joints (``robot.circular``): an ``ob.CompoundStateSpace`` whose subspaces follow the joint
    order, an ``ob.SO2StateSpace`` per continuous joint and a bounded RealVector space per run of other joints,
    each of weight 1 (the flat values of a state, :class:`~tpee_ompl.planning.space_layout.RealVectorLayout`,
    are the joint values in order)."""
    if not robot.circular.any():
        return _real_vector(robot.lower, robot.upper)
    space = ob.CompoundStateSpace()
    run: list[int] = []
    for i in range(robot.nq + 1):
        if i < robot.nq and not robot.circular[i]:
            run.append(i)
            continue
        if run:
            space.addSubspace(_real_vector(robot.lower[run], robot.upper[run]), 1.0)
            run = []
        if i < robot.nq:
            space.addSubspace(ob.SO2StateSpace(), 1.0)
    space.lock()
    return space


def _real_vector(lower: np.ndarray, upper: np.ndarray) -> ob.RealVectorStateSpace:
    """A RealVector space with these bounds."""
    space = ob.RealVectorStateSpace(len(lower))
    bounds = ob.RealVectorBounds(len(lower))
    for i, (lo, hi) in enumerate(zip(lower, upper)):
        bounds.setLow(i, float(lo))
        bounds.setHigh(i, float(hi))
    space.setBounds(bounds)
    return space


def make_simple_setup(
    robot: RobotChecker,
    start: ArrayLike | None = None,
    goal: ArrayLike | None = None,
    *,
    joint_step: float | None = None,
    batched_motion_validator: bool | None = None,
    check_endpoints: bool = True,
    motion_validator: str | None = None,
    certified_options: CertifiedMotionOptions | None = None,
) -> og.SimpleSetup:
    """Build an ``og.SimpleSetup`` for a robot, optionally with start and goal configurations.

    Parameters
    ----------
    robot : RobotChecker
        Any checker: a :class:`~tpee_ompl.model.wearer_arm.WearerArm`, the Panda, another URDF.
    start, goal : sequence of nq floats (radians, metres for prismatic joints), optional
    joint_step : float, radians
        Longest joint-space step between checked states (default ``robot.max_joint_step()``,
        the guarantee in the module docstring).
    batched_motion_validator : bool, optional
        Old switch: True is ``motion_validator="batched"``, False is ``"discrete"``.
    check_endpoints : bool
        Raise ValueError when start or goal is out of limits or in collision.
    motion_validator : {"batched", "certified", "dense", "discrete"}, optional
        ``"batched"`` (default): :class:`BatchedMotionValidator`, each motion's states screened by
        clearance balls in batched calls; ``"dense"``: the same validator checking every state (no
        screening, the same verdicts; kept to measure the screening against); ``"discrete"``:
        OMPL's per-state ``DiscreteMotionValidator`` (the same states);
        ``"certified"``: :class:`~tpee_ompl.planning.certified.CertifiedMotionValidator` (clearance
        certificates, falling back to the batched check near contact; a stronger guarantee).
    certified_options : CertifiedMotionOptions, optional
        Settings of the certified validator (only with ``motion_validator="certified"``).

    The objective is path length in the joint-space Euclidean metric.  The setup's
    ``getSpaceInformation()`` is fully set up on return; :func:`motion_check_step` gives back the
    joint step it checks motions at.
    """
    check_endpoints = check_bool("check_endpoints", check_endpoints)
    space = make_space(robot)
    extent = float(space.getMaximumExtent())
    step = check_number("joint_step (radians, below the space's extent)", joint_step, low=MIN_JOINT_STEP, high=extent,
                        high_open=True, optional=True)
    if step is None:
        step = robot.max_joint_step()
        if step < MIN_JOINT_STEP:  # a motion would take millions of states (a 1e-9 m margin: 12 GiB for one radian)
            raise ValueError(f"the robot's motion step {step:.3g} rad (security margin {robot.security_margin:g} m over "
                             f"its lever arms) is below MIN_JOINT_STEP = {MIN_JOINT_STEP:g} rad: give a larger "
                             "security_margin, or a joint_step")
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    checker = RobotValidityChecker(si, robot)
    ss.setStateValidityChecker(checker)
    si.setStateValidityCheckingResolution(step / extent)
    kind = _motion_validator_kind(motion_validator, batched_motion_validator)
    if certified_options is not None and kind != "certified":
        raise ValueError(f"certified_options needs motion_validator='certified', got {kind!r}")
    if kind in ("batched", "dense"):
        si.setMotionValidator(BatchedMotionValidator(si, robot, step, None if kind == "batched" else ()))
    elif kind == "certified":
        from .certified import CertifiedMotionValidator  # certified builds on this module

        si.setMotionValidator(CertifiedMotionValidator(si, robot, step, certified_options))
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    # Python objects referenced only from C++ would be collected: keep them on the setup.
    ss._tpee_refs = (robot, checker, si.getMotionValidator())  # type: ignore[attr-defined]
    if start is not None or goal is not None:
        if start is None or goal is None:
            raise ValueError("give both start and goal, or neither")
        layout = RealVectorLayout(space)  # continuous joints' angles into [-pi, pi), as SO2 states hold them
        q0, q1 = (layout.wrap(_named_config(robot, q, name)) for q, name in ((start, "start"), (goal, "goal")))
        if check_endpoints:
            q0, q1 = robot.check_free(q0, "start"), robot.check_free(q1, "goal")
        s0, s1 = layout.write(si.allocState(), q0), layout.write(si.allocState(), q1)
        ss.setStartAndGoalStates(s0, s1, 1e-9)
    si.setup()
    return ss


def _motion_validator_kind(name: str | None, batched: bool | None) -> str:
    """The motion validator named by ``motion_validator`` and the older ``batched_motion_validator``."""
    if batched is not None and not isinstance(batched, bool):
        raise ValueError(f"batched_motion_validator must be True or False, got {batched!r}")
    old = None if batched is None else ("batched" if batched else "discrete")
    if name is None:
        return old or "batched"
    if name not in MOTION_VALIDATORS:
        raise ValueError(f"motion_validator must be one of {MOTION_VALIDATORS}, got {name!r}")
    if (old == "discrete") != (name == "discrete") and old is not None:
        raise ValueError(f"batched_motion_validator={batched} contradicts motion_validator={name!r}")
    return name


def _named_config(robot: RobotChecker, q: np.ndarray, name: str) -> np.ndarray:
    """q as (nq,) finite numbers, else ValueError starting with ``name``."""
    try:
        return robot.check_config(q)
    except ValueError as exc:
        raise ValueError(f"{name}: {exc}") from None


def motion_check_step(setup: og.SimpleSetup | ob.SpaceInformation) -> float:
    """Joint-space step (radians) between the states a motion check visits, at ``validSegmentCountFactor`` 1.

    For a :func:`make_simple_setup` setup this is its ``joint_step`` exactly (default
    ``robot.max_joint_step()``), read from its :class:`BatchedMotionValidator`; for any other motion
    validator (OMPL's ``DiscreteMotionValidator``) it is the space's longest valid segment length,
    ``si.getStateValidityCheckingResolution() * space.getMaximumExtent()`` (equal up to rounding).
    While the space's ``validSegmentCountFactor`` is f > 1 (``ot.Benchmark``'s strict check), motions
    are checked at ``step / f``.  In the compound space of a robot with continuous joints the checked states are
    at most this far apart in the Euclidean joint metric (closer: each subspace is subdivided at its share of the
    step, :meth:`BatchedMotionValidator.segment_counts`).
    """
    si = setup.getSpaceInformation() if isinstance(setup, og.SimpleSetup) else setup
    if not isinstance(si, ob.SpaceInformation):
        raise ValueError(f"expected an og.SimpleSetup or ob.SpaceInformation, got {type(setup).__name__}")
    mv = si.getMotionValidator()
    if isinstance(mv, BatchedMotionValidator):
        return mv.step
    return float(si.getStateSpace().getLongestValidSegmentLength())
