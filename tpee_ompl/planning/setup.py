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
from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ..model.robot_checker import RobotChecker
from ..validation import MOTION_VALIDATORS, check_bool, check_number, check_seed
from .motion_validator import BatchedMotionValidator, finite_motions_checked
from .paths import MIN_JOINT_STEP
from .space_layout import RealVectorLayout

if TYPE_CHECKING:
    from .certified import CertifiedMotionOptions

__all__ = [
    "RobotSimpleSetup",
    "RobotValidityChecker",
    "WearerValidityChecker",
    "BatchedMotionValidator",
    "checks_as_robot",
    "finite_motions_checked",
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

    batched_protocol = True
    """``are_valid`` and ``first_invalid`` agree with ``isValid`` (tested): dimension-RRT takes them at their word."""

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


def checks_as_robot(checker: object, robot: RobotChecker) -> bool:
    """Whether a state validity checker answers as ``robot`` does (a :class:`RobotValidityChecker` of it, its checks
    not overridden): the validators of :func:`make_simple_setup` check states with the robot itself."""
    own = ("isValid", "are_valid", "first_invalid")
    return isinstance(checker, RobotValidityChecker) and checker.robot is robot and all(
        getattr(type(checker), m) is getattr(RobotValidityChecker, m) for m in own)


class RobotSimpleSetup(og.SimpleSetup):
    """:func:`make_simple_setup`'s setup.  Its validator checks states with the robot, so another checker (a user's
    constraint) given to ``setStateValidityChecker`` becomes the validator's :attr:`~BatchedMotionValidator.checker`
    (every state through it), the robot's own puts the batched checks back (``si.setStateValidityChecker`` cannot
    be followed: the package's planners then refuse to plan, :func:`.planner_base.validator_mismatch`)."""

    def setStateValidityChecker(self, checker: object) -> None:  # noqa: N802 (OMPL's name)
        if callable(checker) and not isinstance(checker, ob.StateValidityChecker):
            fn = checker  # a function's numpy bool would reach OMPL as std::bad_cast: its answer made a bool
            self._tpee_function = checker = lambda state: bool(fn(state))
        super().setStateValidityChecker(checker)
        robot, _, validator = getattr(self, "_tpee_refs", (None, None, None))
        if not isinstance(validator, BatchedMotionValidator):  # being built, or OMPL's own validator already
            return
        si = self.getSpaceInformation()
        if si.getMotionValidator() is validator:
            validator.checker = None if checks_as_robot(checker, robot) else si.getStateValidityChecker()
            if validator.checker is not None:
                log.info("another state validity checker: motions are checked state by state through it")


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
) -> RobotSimpleSetup:
    """Build an ``og.SimpleSetup`` (:class:`RobotSimpleSetup`) for a robot, optionally with start and goal configurations.

    Parameters
    ----------
    robot : RobotChecker
        Any checker: a :class:`~tpee_ompl.model.wearer_arm.WearerArm`, the Panda, another URDF.
    start, goal : sequence of nq floats (radians, metres for prismatic joints), optional
    joint_step : float, radians
        Longest joint-space step between checked states (default ``robot.max_joint_step()``,
        the guarantee in the module docstring).  The motion validator keeps it: a resolution set later with
        ``si.setStateValidityCheckingResolution`` changes what OMPL's own code reads, not its checks (give it here).
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
    if not isinstance(robot, RobotChecker):
        raise ValueError(f"robot must be a RobotChecker (a WearerArm, the Panda, any URDF), got {type(robot).__name__}")
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
    ss = RobotSimpleSetup(space)
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
