"""The project's motion validator: a whole straight motion checked with batched Pinocchio calls (screened by clearance
balls where that pays), with the verdict of OMPL's ``DiscreteMotionValidator`` at the same resolution.  The set-up that
installs it, and the guarantee its step gives: :mod:`tpee_ompl.planning.setup`."""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence

import numpy as np
from ompl import base as ob

from ..model import clearance_balls
from ..model.clearance_balls import SCREEN_COST_LIMIT, SCREEN_LEVELS, screened_all_valid, screened_lines_valid
from ..model.robot_checker import RobotChecker
from ..validation import check_number
from .paths import (batched_motion_states, bisection_order, counted_motion_states, state_to_array,
                    straight_segment_counts, unchecked_motion_states)
from .space_layout import RealVectorLayout

__all__ = ["BatchedMotionValidator", "finite_motions_checked"]

log = logging.getLogger(__name__)


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
        self.checker: ob.StateValidityChecker | None = None
        """None: states are checked with the robot (the setup's own checker answers as it does).  Else the state
        validity checker that replaced it (:class:`~tpee_ompl.planning.setup.RobotSimpleSetup` sets it): every
        state goes through its ``isValid``, the end state first, then in bisection order, as OMPL's validator."""
        self._scratch: ob.State | None = None  # the state the checker is given (the space's: si's would keep si alive)
        self._writer: RealVectorLayout | None = None  # writes the states into it (both made on the first use)

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
        if self._layout is not None or self.checker is not None:
            return bool(self._checked(a[None], b[None], clearance_balls.PROBES)[0])
        self.motions_checked += 1
        try:
            states = unchecked_motion_states(a, b, self.step, factor=self.factor())
        except (ValueError, OverflowError):  # the segment count of a NaN or inf motion (no cost when finite)
            if np.isfinite(a).all() and np.isfinite(b).all():
                raise
            return False
        return self._tally(bool(self.all_valid([states], clearance_balls.PROBES)[0]))

    def check_motion_values(self, a: np.ndarray, b: np.ndarray, probes: int = clearance_balls.PROBES) -> bool:
        """:meth:`checkMotion` of a -> b given as joint values (n,), with ``probes`` of its states checked plainly
        first (its end, then the middles breadth first, up to the first invalid one): for a motion likely to collide,
        which is mostly found there (a query's direct motion, asked about before anything else)."""
        return bool(self._checked(np.atleast_2d(np.asarray(a, dtype=float)), np.atleast_2d(np.asarray(b, dtype=float)),
                                  probes)[0])

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
        if self.checker is not None:
            return self._through_checker(A, B)
        if self._layout is not None:
            return self._check_geodesics(A, B, probes)
        S, counts = batched_motion_states(A, B, self.step, factor=self.factor())
        self.motions_checked += len(counts)
        if len(counts) < 2 or not self.screen_levels:
            ok = self.all_valid(np.split(S, np.cumsum(counts)[:-1]) if len(counts) else [], probes)
        else:
            spacing = np.sqrt(((B - A) ** 2).sum(-1)) / counts  # the states are evenly spaced along each motion
            chained = (A[1:] == B[:-1]).all(axis=1)  # a path's motions: screened as one polyline
            ok = screened_lines_valid(self.robot, self.robot.ball_screen(), S, counts, spacing, self.step,
                                      self.screen_levels, chained=chained)
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
        S, counts, D = self._geodesic_states(A, B)
        self.motions_checked += len(counts)
        if self.screen_levels:  # the states are evenly spaced along each motion's joint-space line (unwrapped)
            spacing = np.linalg.norm(D, axis=1) / counts
            ok = screened_lines_valid(self.robot, self.robot.ball_screen(), S, counts, spacing, self.step,
                                      self.screen_levels, probes)
        else:
            ok = self.all_valid(np.split(S, np.cumsum(counts)[:-1]) if len(counts) else [])
        return self._tally(np.asarray(ok, dtype=bool))

    def _through_checker(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """The motions' states (as the robot's checks would visit them) through :attr:`checker`, each motion up to its
        first invalid state."""
        if self._layout is None:
            S, counts = batched_motion_states(A, B, self.step, factor=self.factor())
        else:
            S, counts, _ = self._geodesic_states(A, B)
        self.motions_checked += len(counts)
        if self._scratch is None:
            self._scratch, self._writer = self._space.allocState(), RealVectorLayout(self._space)
        is_valid, state, write = self.checker.isValid, self._scratch, self._writer.write
        ok = np.ones(len(counts), dtype=bool)
        for k, M in enumerate(np.split(S, np.cumsum(counts)[:-1]) if len(counts) else []):
            order = [len(M) - 1] + [i for i in bisection_order(len(M)).tolist() if i != len(M) - 1]
            ok[k] = all(is_valid(write(state, M[i])) for i in order)
        return self._tally(ok)

    def _geodesic_states(self, A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """In a compound space: the motions' states along the space's geodesics (wrapped into [-pi, pi)), each
        motion's count of them, and the motions' joint-space displacements."""
        D = self._layout.delta(A, B)
        counts = self.segment_counts(A, B)
        S = self._layout.wrap(counted_motion_states(A, D, counts))
        S[np.cumsum(counts) - 1] = B  # each end is the state itself, as OMPL checks s2
        return S, counts, D

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
