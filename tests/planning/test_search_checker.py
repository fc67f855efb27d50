"""tpee_ompl.planning.search_checker: the search's batched checks that stop at the first failure."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest
from helpers.wearer_configs import valid_and_colliding
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.model import robot_checker, stall_guard
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.grouped_space import GroupedSpace
from tpee_ompl.planning.search_checker import _COARSE_STRIDE, Checker
from tpee_ompl.planning.setup import make_simple_setup


@pytest.fixture(scope="module")
def checker(robot: WearerArm) -> Checker:
    si = make_simple_setup(robot).getSpaceInformation()
    c = Checker(si, GroupedSpace(si, [[0, 1], [2, 3]], 7).layout, batch=True)
    assert c.batched
    return c


def _screened(checker: Checker, robot: WearerArm, A: np.ndarray, B: np.ndarray, starts: bool) -> np.ndarray:
    """Per motion: whether its screened states (every 8th interior one, and its start when asked) are valid."""
    S, idx, _ = checker.interior(A, B, _COARSE_STRIDE)
    bad = np.bincount(idx[~robot.are_valid(S)], minlength=len(A)) > 0
    if starts:
        bad |= ~robot.are_valid(A)
    return ~bad


def test_first_failing_motion_names_a_motion_with_an_invalid_screened_state_in_either_order(checker, robot, rng) -> None:
    good, _ = valid_and_colliding(robot, rng, 800)
    A, B = good[:400], good[400:]
    ok = _screened(checker, robot, A, B, False)
    assert 5 <= (~ok).sum() and 5 <= ok.sum()  # blocked and free motions to mix
    blocked, free = np.flatnonzero(~ok), np.flatnonzero(ok)
    for trial in range(40):
        pick = rng.permutation(np.concatenate([rng.choice(blocked, trial % 3), rng.choice(free, 4 - trial % 3)]))
        for starts in (False, True):
            want = _screened(checker, robot, A[pick], B[pick], starts)
            in_order = checker.first_failing_motion(A[pick], B[pick], bisect=False, starts=starts)
            assert in_order == (-1 if want.all() else int(want.argmin()))  # path order: the first failing motion
            k = checker.first_failing_motion(A[pick], B[pick], bisect=True, starts=starts)
            assert (k == -1) == want.all() and (k == -1 or not want[k])


def test_batched_tree_steps_pass_up_to_the_first_that_check_motion_rejects(checker, robot, rng) -> None:
    good, bad = valid_and_colliding(robot, rng, 40)
    pool = np.vstack([good, bad[:5]])
    for trial in range(25):
        chain = pool[rng.permutation(len(pool))[:5]]
        chain[0] = good[trial]  # a tree node: valid
        A, B = chain[:-1], chain[1:]
        for starts in (False, True):
            n = checker.tree_motions(A, B, starts)
            want = 0
            while want < len(A) and (not starts or robot.are_valid(A[want : want + 1])[0]) and \
                    checker.check_motion(A[want], B[want]):
                want += 1
            assert n == want


def test_candidate_motions_that_pass_are_remembered_as_passing_check_motion(checker, robot, rng) -> None:
    good, _ = valid_and_colliding(robot, rng, 90)
    A, C, B = good[:30], good[30:60], good[60:]
    yes = np.ones(30, dtype=bool)
    checker.passed.clear()
    vc, left, right = checker.candidates(C, A, B, yes, yes, np.zeros(30, dtype=bool))
    remembered = set(checker.passed)
    assert vc.all() and left.any() and right.any() and not (left & right).all()  # some pass, some fail
    checker.passed.clear()
    for k in range(30):
        for a, b, ok in ((A[k], C[k], left[k]), (C[k], B[k], right[k])):
            assert ok == checker.check_motion(a, b)  # si.checkMotion's verdict (remembered when it passes)
    assert remembered == checker.passed  # exactly the passing motions


def test_one_strict_candidate_is_valid_exactly_when_it_and_both_its_motions_pass(checker, robot, rng) -> None:
    """The improvement phase's case: the candidate, its motions' screen (every 4th state, up to the first
    failure), then the validator in full; the verdict is ``si.isValid`` and ``si.checkMotion``'s, and a
    candidate whose motion collides stops before checking all of its motions' states."""
    good, bad = valid_and_colliding(robot, rng, 600)
    # near obstacles: around the midpoints of motions that collide
    blocked = [k for k in range(300) if not checker.check_motion(good[k], good[300 + k])][:30]
    m = len(blocked)
    A, B = good[blocked + list(range(5))], good[[300 + k for k in blocked] + list(range(300, 305))]
    C = np.vstack([0.5 * (A[:m] + B[:m]) + 0.1 * rng.standard_normal((m, robot.nq)), bad[:5]])
    one = np.ones(1, dtype=bool)
    outcomes = set()
    for k in range(m + 5):
        before = checker.counter()
        vc, left, right = checker.candidates(C[k : k + 1], A[k : k + 1], B[k : k + 1], one, one, one)
        checks = checker.counter() - before
        c_ok = bool(robot.are_valid(C[k : k + 1])[0])
        motions_ok = c_ok and checker.check_motion(A[k], C[k]) and checker.check_motion(C[k], B[k])
        assert bool(vc[0] and left[0] and right[0]) == motions_ok
        dense = sum(len(checker.interior(p[None], q[None])[0]) + 1 for p, q in ((A[k], C[k]), (C[k], B[k])))
        if c_ok and not motions_ok:
            assert checks < dense  # stopped at a failure of the screen
        outcomes.add((c_ok, motions_ok))
    assert outcomes == {(False, False), (True, False), (True, True)}


@pytest.mark.parametrize("m", [1, 3])
def test_candidates_given_their_validity_are_not_checked_again_and_get_the_same_verdicts(checker, robot, rng, m) -> None:
    """``valid`` (the look-ahead checked the states already): an invalid lone candidate costs no check, and
    every verdict is the one the candidates checked here get."""
    good, bad = valid_and_colliding(robot, rng, 400)
    yes = np.ones(m, dtype=bool)
    for k in range(0, 60, m):
        A, B = good[k : k + m], good[200 + k : 200 + k + m]
        C = 0.5 * (A + B) + 0.05 * rng.standard_normal((m, robot.nq))
        if k % 4 == 0:
            C[0] = bad[k]
        own = checker.candidates(C, A, B, yes, yes, yes)
        valid = robot.are_valid(C)
        before = checker.counter()
        given = checker.candidates(C, A, B, yes, yes, yes, valid)
        checks = checker.counter() - before
        for a, b in zip(own, given):
            np.testing.assert_array_equal(a, b)
        if m == 1 and not given[0][0]:
            assert checks == 0


@pytest.mark.parametrize("pairs", [True, False], ids=["two-rows-at-a-time", "one-row-at-a-time"])
def test_a_candidate_screen_checks_first_where_the_last_screen_found_a_collision(robot, rng, pairs, monkeypatch) -> None:
    """The screen of a lone candidate's motions starts with the state nearest the last colliding state a
    screen found: the same candidate again costs its own check and one state (two when the checker checks
    rows in pairs: that state and the next), with the same verdict."""
    monkeypatch.setattr(robot_checker, "FIRST_INVALID_PAIRS", pairs)
    # the stall guard (a busy machine) would put the checker on one thread, one row at a time: not what is tested
    monkeypatch.setattr(stall_guard, "STALL_SECONDS", (math.inf, 0.0))
    monkeypatch.setattr(robot.stall_guard, "serial_until", 0.0)
    expected = 3 if pairs and robot.n_threads > 1 else 2
    si = make_simple_setup(robot).getSpaceInformation()
    checker = Checker(si, GroupedSpace(si, [[0, 1], [2, 3]], 7).layout, batch=True)
    good, _ = valid_and_colliding(robot, rng, 600)
    one = np.ones(1, dtype=bool)
    found = 0
    for k in range(300):
        A, B = good[k : k + 1], good[300 + k : 301 + k]
        C = 0.5 * (A + B) + 0.1 * rng.standard_normal((1, robot.nq))
        if not robot.are_valid(C)[0] or checker.check_motion(A[0], C[0]) and checker.check_motion(C[0], B[0]):
            continue
        first = checker.candidates(C, A, B, one, one, one)
        before = checker.counter()
        again = checker.candidates(C, A, B, one, one, one)
        if checker.counter() - before > expected:  # a thin obstacle between screened states: the full check found it
            continue
        assert checker.counter() - before == expected
        for a, b in zip(first, again):
            np.testing.assert_array_equal(a, b)
        assert not (again[1][0] and again[2][0])
        found += 1
    assert found >= 5


class _DiscsChecker(ob.StateValidityChecker):
    """A user's checker with the batched call (``are_valid``) beside OMPL's default motion validator."""

    def __init__(self, si: ob.SpaceInformation, centres: np.ndarray, radius: float) -> None:
        super().__init__(si)
        self.centres, self.radius = centres, radius

    def are_valid(self, Q: np.ndarray) -> np.ndarray:
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        return (((Q[:, None, :2] - self.centres[None]) ** 2).sum(-1) > self.radius**2).all(axis=1)

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL override)
        return bool(self.are_valid([[state[0], state[1]]])[0])


def _discs_setup(factor: int, space: ob.StateSpace | None = None) -> og.SimpleSetup:
    if space is None:
        space = ob.RealVectorStateSpace(2)
        space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    centres = np.random.default_rng(3).uniform(0.15, 0.85, (40, 2))
    ss._checker = _DiscsChecker(si, centres, 0.012)  # referenced from Python, or it is collected
    ss.setStateValidityChecker(ss._checker)
    si.setStateValidityCheckingResolution(0.02)
    space.setValidSegmentCountFactor(factor)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    return ss


@pytest.mark.parametrize("factor", [1, 2, 3])
def test_interior_states_with_ompls_motion_validator_are_the_ones_it_checks(factor, rng) -> None:
    """With a user's ``are_valid`` and OMPL's ``DiscreteMotionValidator``, the states the search judges a motion
    by are OMPL's: ``validSegmentCount`` segments, ``f * ceil(d / L)`` (the search counted ``ceil(d f / L)``)."""
    ss = _discs_setup(factor)
    si = ss.getSpaceInformation()
    si.setup()
    checker = Checker(si, GroupedSpace(si, [[0], [1]], 7).layout, batch=True)
    assert checker.batched
    A, B = rng.uniform(0, 1, (40, 2)), rng.uniform(0, 1, (40, 2))
    _, idx, _ = checker.interior(A, B)
    a, b = si.allocState(), si.allocState()
    for k in range(len(A)):
        a[0], a[1], b[0], b[1] = *A[k], *B[k]
        assert np.count_nonzero(idx == k) == si.getStateSpace().validSegmentCount(a, b) - 1


def test_no_improvement_is_refused_at_posting_when_the_segment_count_factor_is_not_one(caplog) -> None:
    """Helper probe, 2026-11-27: with factor 2, 17 of one seed's improvements passed the search's own check and
    failed ``si.checkMotion`` at posting, and the path ended 23 % longer than without the batched call."""
    lengths = {}
    for batch in (True, False):
        ss = _discs_setup(2)
        si = ss.getSpaceInformation()
        a, b = si.allocState(), si.allocState()
        a[0], a[1], b[0], b[1] = 0.05, 0.05, 0.95, 0.95
        ss.setStartAndGoalStates(a, b)
        ss.setPlanner(DimensionRRT(si, groups=[[0], [1]], max_samples=1500, seed=4, batch=batch))
        with caplog.at_level(logging.WARNING, logger="tpee_ompl"):
            assert ss.solve(30.0) == ob.PlannerStatus.EXACT_SOLUTION
        lengths[batch] = ss.getSolutionPath().length()
    assert "rejected a path the search accepted" not in caplog.text
    assert lengths[True] == pytest.approx(lengths[False], rel=1e-12)
