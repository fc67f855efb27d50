"""Validity of states and motions for dimension-RRT's search: :class:`Checker`, batched when the setup allows it.

One ``SpaceInformation``; one batched ``are_valid`` call per pass when its validity checker offers it
(else ``si.isValid`` / ``si.checkMotion``), its ``first_invalid`` (in order, stopping at the first
failure) for screens that only need the first failure, and the project's motion validator's own
``check_motions`` for whole motions when it is the validator
(:mod:`tpee_ompl.planning.dimension_search` runs the search on top of it).
"""

from __future__ import annotations

import logging
import math
import weakref
from collections.abc import Callable

import numpy as np
from ompl import base as ob

from .paths import bisection_levels, motion_interior_states
from .space_layout import RealVectorLayout

__all__ = ["Checker", "segment_key"]

log = logging.getLogger(__name__)

_COARSE_STRIDE = 16
"""First pass over a motion checks every 16th interior state (collisions span many states): 8 until
2026-11-25; 16 took 5 % less time to a first path at home (320-340 checks either way) and 26 % less on
the Panda shelf (7,719 -> 5,741 checks), with Table 4 unchanged; 32 was no better, 64 had a longer tail."""
_SCREEN_ONLY_STRIDE = 8
"""Screen of candidates taken on their screens (``Checker.candidates(screen_only=True)``): the settling
shortcut sweeps check the motions they changed in full once, at the end, and start again with full
checks when one fails.  Paper's dimension-RRT at 500 samples, 24 queries x 4 seeds: every 16th state
61 fallbacks, every 8th 39, every 4th 27; 8 took the least time (scratch A/B, 2026-11-26)."""
_NEAREST_FIRST = True
"""Screens in bisection order check the states nearest the last collision a screen found first
(:meth:`Checker._screen`); False: bisection order only (before 2026-11-26; a switch for experiments)."""
_CANDIDATE_STRIDE = 4
"""The improvement phase's screen of one candidate's two motions checks every 4th interior state (nearest
the last collision first, :meth:`Checker._screen`, up to the first failure) before the validator
checks them in full: a shortening candidate pokes into an obstacle by little, and with every 16th state
two thirds of the full checks failed.  Same
verdicts; 16 -> 4 took 0.90 of the time for the library pipeline (5,000 samples per run, 25 % fewer
checks) and 0.95 for the paper's dimension-RRT (2,500): ``experiments/speed_switches.py candidate-stride``."""


def _screen_levels(idx: np.ndarray, K: int) -> np.ndarray:
    """Bisection level of each screened state, given its motion idx (in motion order, K motions)."""
    counts = np.bincount(idx, minlength=K).tolist()
    return np.concatenate([bisection_levels(m) for m in counts if m])


def _longest_stretch_key(level: np.ndarray, length: np.ndarray) -> np.ndarray:
    """Sort key of screened states, longest stretch first: minus the stretch each state halves (a motion of
    that length at that bisection level leaves stretches of length / 2^(level+1))."""
    return -length / np.exp2(level + 1)


_PROBED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""Validity checker -> whether its ``are_valid`` passed :func:`_answers_per_row` (asked once per checker)."""


def _answers_per_row(svc: ob.StateValidityChecker, are_valid: Callable[[np.ndarray], object], q: np.ndarray) -> bool:
    """Whether a checker's ``are_valid`` is the batched call the search takes it for: one true answer for the row q,
    a state ``isValid`` passed (the start), read as :meth:`Checker.states` reads it (booleans, 0/1).  A method of that
    name meaning something else ("are all of these valid?") made every solve CRASH; it is passed over with a warning
    and the states are checked one by one.  A checker whose class sets ``batched_protocol = True`` (the project's)
    is not asked."""
    try:
        ok = np.asarray(are_valid(q[None, :]), dtype=bool)
        if ok.shape == (1,) and bool(ok[0]):
            return True
        got = f"returned {ok!r} for the start state, which isValid passed (one true answer wanted)"
    except Exception as exc:  # noqa: BLE001 (a method of that name with other arguments)
        got = f"raised {type(exc).__name__}: {exc}"
    log.warning("the validity checker's are_valid (%s) %s: not taken as the batched check; checking state by state "
                "(set batched_protocol = True on the checker's class to skip this test)", type(svc).__name__, got)
    return False


def _weakrefable(obj: object) -> bool:
    try:
        weakref.ref(obj)
    except TypeError:
        return False
    return True


def segment_key(a: np.ndarray, b: np.ndarray) -> bytes:
    """Key of the motion a -> b (n,): the bytes of its two float64 ends, as ``W[k : k + 2].tobytes()``."""
    return np.ascontiguousarray(a, dtype=float).tobytes() + np.ascontiguousarray(b, dtype=float).tobytes()


class Checker:
    """Validity of states and motions for one SpaceInformation, batched when the setup allows it."""

    def __init__(self, si: ob.SpaceInformation, layout: RealVectorLayout, batch: bool,
                 probe: np.ndarray | None = None) -> None:
        self.si = si
        self.layout = layout
        svc = si.getStateValidityChecker()
        mv = si.getMotionValidator()
        are_valid = getattr(svc, "are_valid", None)
        self.probe_checks = 0
        """States checked to test the checker's ``are_valid`` (the start, once per checker), before any count."""
        if batch and callable(are_valid) and probe is not None and not getattr(svc, "batched_protocol", False):
            answers = _PROBED.get(svc) if _weakrefable(svc) else None
            if answers is None:
                answers, self.probe_checks = _answers_per_row(svc, are_valid, probe), 1
                if _weakrefable(svc):
                    _PROBED[svc] = answers
            are_valid = are_valid if answers else None
        self.step: float | None = None
        self.euclid = True
        self._ompl_counts = False
        if batch and callable(are_valid):
            factor = max(1, int(si.getStateSpace().getValidSegmentCountFactor()))
            if isinstance(getattr(mv, "step", None), float) and callable(getattr(mv, "check_motions", None)):
                # BatchedMotionValidator: Euclidean, ceil(|b-a| / step) segments (step / factor)
                self.step = float(mv.effective_step()) if callable(getattr(mv, "effective_step", None)) else mv.step
            elif type(mv) is ob.MotionValidator:  # the C++ default, DiscreteMotionValidator
                self.step = float(si.getStateSpace().getLongestValidSegmentLength()) / factor
                self.euclid = layout.is_plain
                # its verdicts are the interior states (:meth:`interior`): the motion validator's own count
                self._ompl_counts = True
        self.batched = self.step is not None
        self._are_valid = are_valid if self.batched else None
        first_invalid = getattr(svc, "first_invalid", None)
        self._first_invalid = first_invalid if self.batched and callable(first_invalid) else None
        all_valid = getattr(mv, "all_valid", None)
        # the project's validator screens a motion's evenly spaced states (straight lines, or in a compound
        # space of a robot with continuous joints the space's geodesics)
        geodesic = layout.is_plain or getattr(mv, "checks_geodesics", False) is True
        self._all_valid = all_valid if self.batched and callable(all_valid) and geodesic else None
        # the project's validators check many motions at once, each as its checkMotion would
        self._check_motions = mv.check_motions if self._all_valid is not None else None
        if self.step is None:  # only for the coarse screening of motions (si.checkMotion decides)
            factor = max(1, int(si.getStateSpace().getValidSegmentCountFactor()))
            self._coarse_step = float(si.getStateSpace().getLongestValidSegmentLength()) / factor
            self.euclid = layout.is_plain
        else:
            self._coarse_step = self.step
        counter_owner = getattr(svc, "robot", svc)
        self._counter_owner = counter_owner if isinstance(getattr(counter_owner, "collision_checks", None), int) else None
        self.own_checks = 0
        """Configurations checked, counted here (an upper bound) for a validity checker without an exact counter
        of its own; with one (:meth:`counter` reads it) this count is not kept up to date."""
        self._longest = float(si.getStateSpace().getLongestValidSegmentLength())
        self._s1, self._s2 = si.allocState(), si.allocState()
        self.passed: set[bytes] = set()
        """Keys (:func:`segment_key`) of the motions that passed ``si.checkMotion`` here."""
        self._collision: np.ndarray | None = None
        """The last colliding state a screen found (:meth:`_screen` checks its nearest states first)."""

    def counter(self) -> int:
        """Configurations checked so far (the robot's counter when available, else our own count)."""
        return self._counter_owner.collision_checks if self._counter_owner is not None else self.own_checks

    def states(self, Q: np.ndarray) -> np.ndarray:
        """Validity of configurations Q (m, n)."""
        if len(Q) == 0:
            return np.zeros(0, dtype=bool)
        self.own_checks += len(Q)
        if self._are_valid is not None:
            ok = np.asarray(self._are_valid(Q), dtype=bool)
            if ok.shape != (len(Q),):
                raise ValueError(f"the validity checker's are_valid returned shape {ok.shape} for {len(Q)} states "
                                 "(one bool per row wanted)")
            return ok
        s = self._s1
        out = np.empty(len(Q), dtype=bool)
        for k, q in enumerate(Q):
            self.layout.write(s, q)
            out[k] = self.si.isValid(s)
        return out

    def first_invalid(self, Q: np.ndarray) -> int:
        """Index of the first invalid configuration of Q (m, n) in row order, or -1.  The validity checker's
        own ``first_invalid`` (checks in order and stops at the first failure) when it has one, else
        :meth:`states` of all of them."""
        if len(Q) == 0:
            return -1
        if self._first_invalid is None:
            ok = self.states(Q)
            return -1 if ok.all() else int(ok.argmin())
        self.own_checks += len(Q)  # at most (the robot's own counter, when there is one, is exact)
        return int(self._first_invalid(Q))

    def first_failing_motion(self, A: np.ndarray, B: np.ndarray, bisect: bool, starts: bool = False) -> int:
        """The motion k (A[k] -> B[k]) of the first invalid state found among every 16th interior state
        of each motion (and A[k] itself when ``starts``), or -1 when all of those are valid.

        ``bisect``: for a candidate path whose failure can be anywhere and tends to span many states,
        each motion in bisection order (its middle state, then the quarter points, ...), and across
        motions the state that halves the longest unchecked stretch first (a motion of length L at
        bisection level l leaves stretches of L / 2^(l+1)), so long motions are probed more finely
        before short ones (on the wearer's candidate paths: 9.2 states checked to a failure, mean,
        against 13.6 with every motion's level l before any level l + 1;
        ``experiments/screen_order.py``).  Else motion by motion from A[0], for a chain of steps whose
        valid prefix is wanted (every motion before the one returned passed).  With a checker that
        stops at the first failure, the states after it are not checked."""
        if len(A) == 0:
            return -1
        S, idx = self._screen(A, B, bisect, starts)
        i = self.first_invalid(S)
        if i < 0:
            return -1
        self._collision = S[i].copy()
        return int(idx[i])

    def _screen(self, A: np.ndarray, B: np.ndarray, bisect: bool, starts: bool = False,
                stride: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The states of a screen (every ``stride``-th interior state, default :data:`_COARSE_STRIDE`) in
        :meth:`first_failing_motion`'s order, and the motion of each.

        ``bisect`` (without ``starts``) once a screen has found a colliding state: nearest that state first
        instead.  Only the order of the checks depends on it, and the screen stops at the first failure:
        candidates tend to poke into the obstacle where the last one did.  A lone candidate of the
        improvement phase fails its screen with the same verdict (the screen fails when any of its states
        collides); a candidate path may report another of its failing motions.  Measured: on 959 screens of
        the library pipeline's improvement phase, replayed, 4.0 states checked per screen against 8.4 in
        bisection order (37 against 71 us); on the 734 screens of 120 first paths at home, 6.0 against 9.2;
        in runs ``experiments/speed_switches.py screen-order``."""
        K = len(A)
        S, idx, j = self.interior(A, B, stride or _COARSE_STRIDE)  # in motion order, then step order
        if bisect and not starts and self._collision is not None and _NEAREST_FIRST:
            D = S - self._collision
            order = np.argsort(np.einsum("ij,ij->i", D, D), kind="stable")
            return S[order], idx[order]
        if bisect and len(idx):
            j = _longest_stretch_key(_screen_levels(idx, K), self.layout.distance(A, B)[idx])
        if starts:  # each motion's start before its interior states
            S, idx = np.concatenate((A, S)), np.concatenate((np.arange(K), idx))
            j = np.concatenate((np.full(K, -np.inf), j))
        order = np.lexsort((idx, j)) if bisect else np.lexsort((j, idx))
        return S[order], idx[order]

    def interior(self, A: np.ndarray, B: np.ndarray, stride: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Interior states of motions A[k] -> B[k]: (states (M, n), motion index (M,), step index j >= 1;
        only the multiples of ``stride``).

        SO2 entries move the short way round and are wrapped into [-pi, pi), as ``SO2StateSpace``
        interpolates."""
        lay = self.layout
        counts = self._segment_counts(A, B) if self._ompl_counts else None
        if not lay.has_circular:
            return motion_interior_states(A, B, self._coarse_step, None if self.euclid else lay.distance(A, B), stride,
                                          counts)
        S, idx, j = motion_interior_states(A, A + lay.delta(A, B), self._coarse_step, lay.distance(A, B), stride,
                                           counts)
        return lay.wrap(S), idx, j

    def _segment_counts(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """OMPL's ``validSegmentCount`` of each motion A[k] -> B[k]: the segments ``DiscreteMotionValidator`` checks
        (``f * ceil(d / L)``, the most any subspace needs in a compound space); asked of the space itself."""
        space, lay, s1, s2 = self.si.getStateSpace(), self.layout, self._s1, self._s2
        out = np.empty(len(A), dtype=np.int64)
        for k in range(len(A)):
            lay.write(s1, A[k])
            lay.write(s2, B[k])
            out[k] = space.validSegmentCount(s1, s2)
        return out

    def coarse(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Whether every 16th interior state of the motions A[k] -> B[k] is valid (one batched call, or
        per-state checks): most invalid motions already fail here (not all: a thin wall can fit
        between two of those states)."""
        K = len(A)
        if K == 0:
            return np.ones(0, dtype=bool)
        S, idx, _ = self.interior(A, B, _COARSE_STRIDE)
        return np.bincount(idx[~self.states(S)], minlength=K) == 0

    def motions(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Validity of the motions A[k] -> B[k] (valid ends assumed): :meth:`coarse`, then
        :meth:`check_motions` for the motions still in question."""
        out = np.zeros(len(A), dtype=bool)
        go = np.flatnonzero(self.coarse(A, B))
        out[go] = self.check_motions(A[go], B[go])
        return out

    def check_motions(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """:meth:`check_motion` of each motion A[k] -> B[k]; with the project's validator, through its own
        ``check_motions`` (all motions batched together, each with ``checkMotion``'s verdict)."""
        if self._check_motions is None:
            return np.array([self.check_motion(a, b) for a, b in zip(A, B)], dtype=bool)
        if len(A) == 0:
            return np.zeros(0, dtype=bool)
        if self._counter_owner is None:  # else counter() reads the robot's exact count
            self.own_checks += int(np.maximum(1, np.ceil(self.layout.distance(A, B) / self.step)).sum())  # at most
        ok = np.asarray(self._check_motions(A, B), dtype=bool)
        self.passed.update(segment_key(A[k], B[k]) for k in np.flatnonzero(ok))
        return ok

    def tree_motions(self, A: np.ndarray, B: np.ndarray, starts: bool) -> int:
        """The connect trees' checks of the motions A[k] -> B[k] (and of A[k] when ``starts``), in full:
        how many pass before the first that does not (batched: every 16th state of each in path order,
        up to the first failure (:meth:`first_failing_motion`), then the motions before it in full;
        else in order, stopping at the first failure, as RRTConnect)."""
        if self.batched:
            k = self.first_failing_motion(A, B, bisect=False, starts=starts)
            m = len(A) if k < 0 else k
            ok = self.check_motions(A[:m], B[:m])
            return m if ok.all() else int(ok.argmin())
        n = 0
        while n < len(A) and self.check_step(A[n].tolist(), B[n].tolist(), starts):
            n += 1
        return n

    def check_step(self, a: list[float], b: list[float], start: bool) -> bool:
        """A tree step a -> b given as plain lists (the flat vector): ``si.isValid(a)`` when ``start``,
        then ``si.checkMotion(a, b)``, as RRTConnect checks a goal-tree step; the lean per-state path
        of the connect trees (nothing is remembered: the trees know their checked edges)."""
        lay, s1, s2 = self.layout, self._s1, self._s2
        plain = lay.is_plain
        if plain:
            s1[0 : lay.n] = a
        else:
            lay.write(s1, a)
        if start:
            self.own_checks += 1
            if not self.si.isValid(s1):
                return False
        if plain:
            s2[0 : lay.n] = b
        else:
            lay.write(s2, b)
        d = math.dist(a, b) if plain else float(lay.distance(np.array(a), np.array(b)))
        self.own_checks += max(1, math.ceil(d / self._longest))
        return bool(self.si.checkMotion(s1, s2))

    def check_motion(self, a: np.ndarray, b: np.ndarray) -> bool:
        """``si.checkMotion`` of a -> b (n,); a motion that passes is remembered in :attr:`passed`."""
        lay = self.layout
        lay.write(self._s1, a)
        lay.write(self._s2, b)
        d = math.dist(a.tolist(), b.tolist()) if lay.is_plain else float(lay.distance(a, b))
        self.own_checks += max(1, math.ceil(d / self._longest))
        ok = bool(self.si.checkMotion(self._s1, self._s2))
        if ok:
            self.passed.add(segment_key(a, b))
        return ok

    def candidates(
        self, C: np.ndarray, A: np.ndarray, B: np.ndarray, left_known: np.ndarray, right_known: np.ndarray,
        strict: np.ndarray, valid: np.ndarray | None = None, screen_only: bool = False,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Evaluate candidate waypoints C (m, n) between neighbours A and B (m, n).

        ``left_known[k]`` / ``right_known[k]`` false means that neighbour is invalid, so that motion is
        invalid without a check.  For ``strict[k]`` candidates only all-valid matters, so the motions are
        not finished once one fails.  ``valid``: the validity of C when it was checked already (not
        checked again).  Returns validity of C, of A->C and of C->B (ends incl.).  ``screen_only``: a
        motion passes on its screen (a lone candidate's every 4th state, several candidates' every
        :data:`_SCREEN_ONLY_STRIDE`-th), not checked in full: the caller checks it later (the settling
        shortcut sweeps).
        """
        m = len(C)
        if m == 1 and self._first_invalid is not None and self._check_motions is not None \
                and bool(strict[0] and left_known[0] and right_known[0]):
            # one strict candidate (the improvement phase's usual case): the candidate (the screen is not
            # even built when it collides), then its motions' screen (:meth:`_screen`), stopping at the first
            # failure; the motions in full if none
            no = np.zeros(1, dtype=bool)
            if (self.first_invalid(C) >= 0) if valid is None else not valid[0]:
                return no, no, no
            A2, B2 = np.concatenate((A, C)), np.concatenate((C, B))
            S = self._screen(A2, B2, bisect=True, stride=_CANDIDATE_STRIDE)[0]
            i = self.first_invalid(S)
            if i >= 0:
                self._collision = S[i].copy()
                return ~no, no, no
            if screen_only:
                return ~no, ~no, ~no
            ok = self.check_motions(A2, B2)
            return np.ones(1, dtype=bool), ok[:1], ok[1:]
        vc = self.states(C) if not self.batched and valid is None else valid
        if self.batched:
            # pass 1: candidate states (unless ``valid`` gives them) + every 16th (``screen_only``: 8th) interior
            # state of motions whose other end is valid (only those built when the validator checks the motions
            # itself in pass 2, or when there is no pass 2)
            coarse = _SCREEN_ONLY_STRIDE if screen_only else _COARSE_STRIDE
            stride = coarse if self._check_motions is not None or screen_only else 1
            SL, iL, jL = self.interior(A, C, stride)
            SR, iR, jR = self.interior(C, B, stride)
            cL, cR = (jL % coarse == 0) & left_known[iL], (jR % coarse == 0) & right_known[iR]
            if valid is None:
                ok = self.states(np.concatenate([C, SL[cL], SR[cR]]))
                vc = ok[:m]
            else:
                ok = np.concatenate((valid, self.states(np.concatenate([SL[cL], SR[cR]]))))
            nl = int(cL.sum())
            badL = np.bincount(iL[cL][~ok[m : m + nl]], minlength=m) > 0
            badR = np.bincount(iR[cR][~ok[m + nl :]], minlength=m) > 0
            goL = vc & left_known & ~badL
            goR = vc & right_known & ~badR
            both = goL & goR
            goL &= both | ~strict
            goR &= both | ~strict
            if screen_only:
                return vc, goL, goR
            # pass 2: the remaining interior states of motions still in question
            if self._check_motions is not None:  # the motion validator's own verdicts, remembered as such
                kL, kR = np.flatnonzero(goL), np.flatnonzero(goR)
                ok2 = self.check_motions(np.concatenate([A[kL], C[kR]]), np.concatenate([C[kL], B[kR]]))
                left, right = goL.copy(), goR.copy()
                left[kL], right[kR] = ok2[: len(kL)], ok2[len(kL) :]
                return vc, left, right
            fL, fR = ~cL & goL[iL], ~cR & goR[iR]
            ok2 = self.states(np.concatenate([SL[fL], SR[fR]]))
            nl2 = int(fL.sum())
            left = goL & (np.bincount(iL[fL][~ok2[:nl2]], minlength=m) == 0)
            right = goR & (np.bincount(iR[fR][~ok2[nl2:]], minlength=m) == 0)
            return vc, left, right
        left = np.zeros(m, dtype=bool)
        right = np.zeros(m, dtype=bool)
        for k in range(m):
            if not vc[k]:
                continue
            if left_known[k]:
                left[k] = self.check_motion(A[k], C[k])
            if right_known[k] and (left[k] or not strict[k]):
                right[k] = self.check_motion(C[k], B[k])
        return vc, left, right
