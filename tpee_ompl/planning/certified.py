"""Motion checking with clearance certificates: a few Coal distance queries instead of one check per joint step.

A distance d_p(q) of collision pair p at state q bounds the pair's distance at every q' with
``d_p(q') >= d_p(q) - sum_i |q'_i - q_i| R[p, i]`` (R: :meth:`RobotChecker.pair_lever_arms`, only the
joints between the pair's two bodies count).  So a straight motion a -> b is covered by balls: walk
in from both ends, at each state take the longest step along the segment that keeps every pair at
least its security margin m_p, and repeat until the two fronts meet.  Pairs are grouped by the
joints between their bodies (and their margin), each group with its own lever bound and one
Pinocchio ``computeDistances`` call over its pairs only; a pair whose distance cannot change
(no joint between its bodies) is checked once at construction and then skipped, and the pairs the
robot proved never within their margin (``robot.separated_pairs``) are left out.

Guarantee (stronger than the dense check's): **every** state of a certified motion, not only the
states a joint step apart, keeps every checked pair at least its margin apart, so a dense re-check at
any resolution accepts it.  Where the steps get short (near contact) the rest of the motion goes to
the dense batched check of :class:`~tpee_ompl.planning.setup.BatchedMotionValidator` at the setup's
step, whose guarantee (m/2 between checked states) then holds there.  A motion is rejected only on
a state found invalid by ``robot.is_valid`` / ``robot.are_valid``.
"""

from __future__ import annotations

import logging
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from ompl import base as ob

from ..model.robot_checker import RobotChecker
from ..validation import check_int, check_number
from .paths import state_to_array, unchecked_motion_states
from .motion_validator import BatchedMotionValidator, finite_motions_checked

__all__ = ["CertifiedMotionOptions", "ClearanceGroups", "CertifiedMotionValidator"]

log = logging.getLogger(__name__)

DISTANCE_TOLERANCE = 1e-5
"""Metres subtracted from every Coal distance before it certifies anything (GJK's accuracy is far better)."""


@dataclass(frozen=True)
class CertifiedMotionOptions:
    """Settings of :class:`CertifiedMotionValidator`.

    min_gain : float
        Give the rest of a motion to the dense check once a certificate step is shorter than
        ``min_gain`` dense steps (one distance evaluation costs several batched boolean checks).
    cache_size : int
        Motion end states whose group distances are kept (least recently used dropped first).
    max_evaluations : int
        Distance evaluations per motion before the rest goes to the dense check.
    """

    min_gain: float = 3.0
    cache_size: int = 4096
    max_evaluations: int = 64

    def __post_init__(self) -> None:
        check_number("min_gain (dense steps)", self.min_gain, low=0.0, high=1e6)
        check_int("cache_size", self.cache_size, minimum=0, maximum=10**7)
        check_int("max_evaluations", self.max_evaluations, minimum=1, maximum=10**6)


class ClearanceGroups:
    """The robot's checked pairs grouped by the joints between their bodies (and their margin).

    Attributes: ``levers`` (G, nq) per-group lever bound (the largest of its pairs' rows of
    :meth:`RobotChecker.pair_lever_arms`), ``margins`` (G,) metres, ``constant_ok`` (the pairs whose
    distance cannot change all keep their margin).
    """

    def __init__(self, robot: RobotChecker) -> None:
        self.robot = robot
        R, margins = robot.pair_lever_arms(), robot.pair_margins()
        self._data = robot.model.createData()
        keys: dict[tuple, list[int]] = {}
        constant = []
        separated = set(robot.separated_pairs)  # proven never within their margin: nothing to certify
        for p in range(len(R)):
            if p in separated:
                continue
            if not R[p].any():
                constant.append(p)
                continue
            keys.setdefault((tuple(np.flatnonzero(R[p])), float(margins[p])), []).append(p)
        self.pair_groups = list(keys.values())
        """Pair indices of each group."""
        self.levers = np.array([R[ps].max(axis=0) for ps in self.pair_groups]).reshape(-1, robot.nq)
        self.margins = np.array([margins[ps[0]] for ps in self.pair_groups])
        self._gdatas = []
        for ps in self.pair_groups:
            gd = pin.GeometryData(robot.gmodel)
            gd.deactivateAllCollisionPairs()
            for p in ps:
                gd.activateCollisionPair(p)
            self._gdatas.append(gd)
        self.constant_ok = self._constant_pairs_ok(constant, margins)
        self.evaluations = 0
        """States whose group distances were computed."""

    def _constant_pairs_ok(self, pairs: list[int], margins: np.ndarray) -> bool:
        if not pairs:
            return True
        gd = pin.GeometryData(self.robot.gmodel)
        pin.computeDistances(self.robot.model, self._data, self.robot.gmodel, gd, pin.neutral(self.robot.model))
        return all(gd.distanceResults[p].min_distance >= margins[p] for p in pairs)

    def slack(self, q: np.ndarray) -> np.ndarray:
        """Per group, its smallest pair distance minus its margin and the tolerance (metres, shape (G,))."""
        model, gmodel, data = self.robot.model, self.robot.gmodel, self._data
        pin.forwardKinematics(model, data, q)
        out = np.empty(len(self._gdatas))
        for g, gd in enumerate(self._gdatas):
            pin.updateGeometryPlacements(model, data, gmodel, gd)
            k = pin.computeDistances(gmodel, gd)
            out[g] = gd.distanceResults[k].min_distance
        self.evaluations += 1
        return out - self.margins - DISTANCE_TOLERANCE


class CertifiedMotionValidator(BatchedMotionValidator):
    """An ``ob.MotionValidator`` that certifies straight motions with clearance balls (module docstring).

    Same constructor as :class:`BatchedMotionValidator` plus ``options``.  Counters:
    ``distance_evaluations`` (states whose group distances were computed; each costs one Coal
    distance per pair), ``cache_hits``, ``fallbacks`` (motions finished by the dense check),
    ``motions_checked``; the dense states go to ``robot.collision_checks`` as before.
    """

    def __init__(self, si: ob.SpaceInformation, robot: RobotChecker, step: float,
                 options: CertifiedMotionOptions | None = None) -> None:
        if robot.circular.any():
            names = [n for n, c in zip(robot.joint_names, robot.circular) if c]
            raise ValueError(f"the certified motion validator needs a robot without continuous joints (its "
                             f"certificates bound straight joint motions); continuous: {names}; use 'batched'")
        super().__init__(si, robot, step, screen_levels=())  # its own certificates, not the balls' screen
        self.options = options if options is not None else CertifiedMotionOptions()
        if not isinstance(self.options, CertifiedMotionOptions):
            raise ValueError(f"options must be CertifiedMotionOptions, got {type(self.options).__name__}")
        self.groups = ClearanceGroups(robot)
        self._cache: OrderedDict[bytes, np.ndarray] = OrderedDict()
        self.cache_hits = 0
        self.fallbacks = 0
        self.last_rejection: np.ndarray | None = None
        """The invalid state that decided the last rejection, or None if the dense check decided it."""

    @property
    def distance_evaluations(self) -> int:
        """States whose group distances were computed so far."""
        return self.groups.evaluations

    def _end_slack(self, q: np.ndarray) -> np.ndarray:
        key = q.tobytes()
        hit = self._cache.get(key)
        if hit is not None:
            self._cache.move_to_end(key)
            self.cache_hits += 1
            return hit
        s = self.groups.slack(q)
        if self.options.cache_size > 0:
            self._cache[key] = s
            if len(self._cache) > self.options.cache_size:
                self._cache.popitem(last=False)
        return s

    def certify(self, a: np.ndarray, b: np.ndarray) -> bool | np.ndarray:
        """True (every state of a -> b keeps all margins), False (an invalid state was found, kept in
        ``last_rejection``) or the dense states still to check (shape (k, nq), possibly empty -> True)."""
        self.last_rejection = None
        step = self.effective_step()
        lower, upper = self.robot.lower, self.robot.upper
        if not (self.groups.constant_ok and np.all((a >= lower) & (a <= upper) & (b >= lower) & (b <= upper))):
            return unchecked_motion_states(a, b, self.step, factor=self.factor())  # OMPL's states
        u = b - a
        length = float(np.linalg.norm(u))
        speed = self.groups.levers @ np.abs(u)  # metres per unit of the segment parameter t
        moving = speed > 0
        min_dt = self.options.min_gain * step / length if length > 0 else np.inf

        def reach(slack: np.ndarray) -> float:
            """Segment-parameter radius certified by a state's slack (-1 if it certifies nothing)."""
            if np.any(slack < 0):
                return -1.0
            return float(np.min(slack[moving] / speed[moving])) if moving.any() else np.inf

        r_lo = reach(self._end_slack(a))
        r_hi = reach(self._end_slack(b))
        if r_hi < 0 and not self.robot.is_valid(b):
            self.last_rejection = b
            return False
        # [0, lo] and [hi, 1] are certified; a front stops once its steps are shorter than min_dt.
        lo, hi = max(r_lo, 0.0), 1.0 - max(r_hi, 0.0)
        live_lo, live_hi = r_lo >= min_dt, r_hi >= min_dt
        evaluations = 0
        while lo < hi:
            if not (live_lo or live_hi) or evaluations >= self.options.max_evaluations:
                return self._dense_between(a, u, lo, hi)
            forward = live_lo and (not live_hi or evaluations % 2 == 0)
            t = lo if forward else hi
            q = a + t * u
            r = reach(self.groups.slack(q))
            evaluations += 1
            if r < 0:
                if not self.robot.is_valid(q):
                    self.last_rejection = q
                    return False
                r = 0.0  # valid but within the tolerance of a margin: this front stops here
            if forward:
                lo, live_lo = t + r, r >= min_dt
            else:
                hi, live_hi = t - r, r >= min_dt
        return True

    def _dense_between(self, a: np.ndarray, u: np.ndarray, lo: float, hi: float) -> np.ndarray:
        """The dense states of a -> a + u (OMPL's: ``f * ceil(d / step)`` of them at ``validSegmentCountFactor`` f)
        whose parameter lies in [lo, hi] (the rest is certified); when no
        grid state falls in that gap (it is shorter than a step), its midpoint: never an empty check, so a
        motion with an uncertified stretch is always counted as a fallback."""
        n = self.factor() * max(1, int(np.ceil(float(np.linalg.norm(u)) / self.step)))  # OMPL's count
        t = np.arange(1, n + 1) / n
        t = t[(t >= lo - 1e-12) & (t <= hi + 1e-12)]
        if not len(t):
            t = np.array([0.5 * (lo + hi)])
        return a + t[:, None] * u

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL override)
        """True if the motion s1 -> s2 is certified, or its uncertified part passes the dense check (False for a
        NaN or inf end)."""
        a, b = state_to_array(s1, self._n), state_to_array(s2, self._n)
        return bool(self.check_motions(a[None], b[None])[0])

    def check_motions(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Validity of many motions A[k] -> B[k]; their uncertified parts go to one batched call (a motion with a
        NaN or inf end is invalid)."""
        A, B = np.atleast_2d(np.asarray(A, dtype=float)), np.atleast_2d(np.asarray(B, dtype=float))
        check = self._check_finite_motions if self.checker is None else self._through_checker
        try:
            return check(A, B)
        except (ValueError, OverflowError):
            return finite_motions_checked(A, B, check, self)

    def _check_finite_motions(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        verdicts = [self.certify(a, b) for a, b in zip(A, B)]
        self.motions_checked += len(A)
        return self._tally(np.array(self._decide(verdicts), dtype=bool))

    def _decide(self, verdicts: list[bool | np.ndarray]) -> list[bool]:
        dense = [v for v in verdicts if isinstance(v, np.ndarray) and len(v)]
        if not dense:
            return [v if isinstance(v, bool) else True for v in verdicts]
        self.fallbacks += len(dense)
        ok = self.robot.are_valid(np.concatenate(dense))
        out, start = [], 0
        for v in verdicts:
            if isinstance(v, np.ndarray) and len(v):
                out.append(bool(ok[start : start + len(v)].all()))
                start += len(v)
            else:
                out.append(v if isinstance(v, bool) else True)
        return out
