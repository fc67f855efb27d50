"""Clearance balls (tpee_ompl.model.clearance_balls): pairs proven apart and screened motion checks change
no verdict, only the number of states checked."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tests.helpers.panda import needs_panda
from tpee_ompl.model.clearance_balls import screened_all_valid, screened_lines_valid
from tpee_ompl.model.queries import load_queries
from tpee_ompl.planning.paths import batched_motion_states, motion_states, state_to_array
from tpee_ompl.planning.setup import BatchedMotionValidator, make_simple_setup


@pytest.fixture(scope="module")
def panda():
    from tpee_ompl.model.robots import panda_shelf

    return panda_shelf()


def _all_pairs_collide(robot, Q: np.ndarray) -> np.ndarray:
    """Collision (margins, contacts) of every pair the model has, none skipped: the unpruned check."""
    gd = pin.GeometryData(robot.gmodel)
    gd.setSecurityMargins(robot.gmodel, robot._margin_matrix())
    for req in gd.collisionRequests:
        req.enable_contact = True
    data = robot.model.createData()
    return np.array([pin.computeCollisions(robot.model, data, robot.gmodel, gd, q, True) for q in Q])


def _uniform(robot, n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(robot.lower, robot.upper, (n, robot.nq))


def _check_separated(robot, n: int) -> None:
    Q = _uniform(robot, n, 5)
    gd = pin.GeometryData(robot.gmodel)
    data = robot.model.createData()
    margins = robot.pair_margins()
    pairs = list(robot.separated_pairs)
    assert pairs
    for q in Q:
        pin.computeDistances(robot.model, data, robot.gmodel, gd, q)
        assert all(gd.distanceResults[p].min_distance >= margins[p] for p in pairs)
    np.testing.assert_array_equal(robot.are_valid(Q), ~_all_pairs_collide(robot, Q))


def test_wearer_pairs_proven_apart_never_come_within_their_margin_and_change_no_verdict(robot):
    _check_separated(robot, 1500)
    names = robot.gmodel.geometryObjects
    separated = {frozenset((names[robot.gmodel.collisionPairs[p].first].name,
                            names[robot.gmodel.collisionPairs[p].second].name)) for p in robot.separated_pairs}
    # the boom and the barrel under the tilt joint: 3.5 cm apart at the closest, the margin is 2 cm
    assert frozenset(("link2_1", "link4_0")) in separated


@needs_panda
def test_panda_pairs_proven_apart_never_come_within_their_margin_and_change_no_verdict(panda):
    _check_separated(panda, 1500)


def test_clearance_still_measures_the_pairs_that_are_not_checked(robot):
    q = load_queries("planning_necessary", robot)[0].start
    gd = pin.GeometryData(robot.gmodel)
    k = pin.computeDistances(robot.model, robot.model.createData(), robot.gmodel, gd, q)
    assert robot.clearance(q) == pytest.approx(gd.distanceResults[k].min_distance)


def test_a_state_clear_at_a_radius_keeps_its_whole_ball_valid(robot):
    rng = np.random.default_rng(8)
    radius = 2 * robot.max_joint_step()
    C = _uniform(robot, 400, 9)
    clear = robot.ball_screen().clear(C, radius)
    assert 0 < clear.sum() < len(C)
    for c in C[clear]:
        D = rng.normal(size=(20, robot.nq))
        D *= (radius * rng.uniform(0, 1, (20, 1)) ** (1 / robot.nq)) / np.linalg.norm(D, axis=1)[:, None]
        ball = c + D
        ball = ball[np.all((ball >= robot.lower) & (ball <= robot.upper), axis=1)]
        assert robot.are_valid(ball).all()


def _random_motions(robot, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    A = _uniform(robot, 3 * n, seed)
    A = A[robot.are_valid(A)][:n]
    D = rng.normal(size=A.shape)
    D /= np.linalg.norm(D, axis=1)[:, None]
    return A, A + D * rng.uniform(0.005, 1.0, (len(A), 1))  # some leave the joint limits


def _check_screened_verdicts(robot, n: int, seed: int) -> None:
    screen, step = robot.ball_screen(), robot.max_joint_step()
    A, B = _random_motions(robot, n, seed)
    for s in (step, step / 4):  # OMPL Benchmark's strict re-check: 4x denser
        chunks = [motion_states(a, b, s) for a, b in zip(A, B)]
        c0 = robot.collision_checks
        dense = np.array([robot.are_valid(c).all() for c in chunks])
        c1 = robot.collision_checks
        one_by_one = np.array([screened_all_valid(robot, screen, [c], step)[0] for c in chunks])
        c2 = robot.collision_checks
        together = screened_all_valid(robot, screen, chunks, step)
        np.testing.assert_array_equal(one_by_one, dense)
        np.testing.assert_array_equal(together, dense)
        assert 0 < dense.sum() < len(dense)
        assert c2 - c1 < 0.8 * (c1 - c0)


@pytest.mark.parametrize("n", [300, pytest.param(3000, marks=pytest.mark.slow)])
def test_screened_wearer_motions_get_the_dense_verdict_with_fewer_checks(robot, n):
    _check_screened_verdicts(robot, n, 31)


@needs_panda
@pytest.mark.parametrize("n", [300, pytest.param(3000, marks=pytest.mark.slow)])
def test_screened_panda_motions_get_the_dense_verdict_with_fewer_checks(panda, n):
    _check_screened_verdicts(panda, n, 32)


def test_a_motion_leaving_the_joint_limits_is_invalid_without_a_check(robot):
    a = (robot.lower + robot.upper) / 2
    b = a.copy()
    b[0] = robot.upper[0] + 0.1
    c0 = robot.collision_checks
    assert not screened_all_valid(robot, robot.ball_screen(), [motion_states(a, b, robot.max_joint_step())],
                                  robot.max_joint_step())[0]
    assert robot.collision_checks == c0


def test_a_new_motion_validator_builds_its_ball_pools_before_the_first_check():
    from tpee_ompl.model.wearer_arm import WearerArm

    robot = WearerArm()  # its own screen: no pool built yet
    ss = make_simple_setup(robot)
    mv = ss.getSpaceInformation().getMotionValidator()
    pools = robot.ball_screen()._pools
    assert sorted(pools) == sorted(h * mv.step for h in mv.screen_levels)
    before = dict(pools)
    a = (robot.lower + robot.upper) / 2
    mv.check_motions(np.stack([a, a]), np.stack([a + 0.05, a - 0.05]))
    assert pools == before  # the check used them, built nothing


class _RecordingValidator(BatchedMotionValidator):
    """The default validator, keeping every motion a planner asked about and its verdict."""

    def __init__(self, si, robot, step) -> None:
        super().__init__(si, robot, step)
        self.seen: list[tuple[np.ndarray, np.ndarray, bool]] = []

    def checkMotion(self, s1, s2) -> bool:  # noqa: N802 (OMPL override)
        ok = super().checkMotion(s1, s2)
        self.seen.append((state_to_array(s1, self._n), state_to_array(s2, self._n), ok))
        return ok


@pytest.mark.slow
def test_every_motion_rrtstar_asks_about_gets_the_dense_verdict(robot):
    ou.setLogLevel(ou.LOG_ERROR)
    q = load_queries("planning_necessary", robot)[0]
    ss = make_simple_setup(robot, q.start, q.goal)
    si = ss.getSpaceInformation()
    step = si.getMotionValidator().step
    recorder = _RecordingValidator(si, robot, step)
    si.setMotionValidator(recorder)
    planner = og.RRTstar(si)
    ss.setPlanner(planner)
    ss.setup()
    ss.solve(ob.PlannerTerminationCondition(lambda: planner.numIterations() >= 300))
    verdicts = np.array([ok for _, _, ok in recorder.seen])
    dense = np.array([robot.are_valid(motion_states(a, b, step)).all() for a, b, _ in recorder.seen])
    assert len(verdicts) > 300 and 0 < verdicts.sum() < len(verdicts)
    np.testing.assert_array_equal(verdicts, dense)


def test_the_screens_cost_ratio_counts_no_checks_and_is_unknown_without_free_states(robot, monkeypatch):
    from tpee_ompl.model.clearance_balls import BallScreen

    screen = BallScreen(robot)
    before = (robot.collision_checks, robot.stall_guard.state())
    assert screen.cost_ratio(4 * robot.max_joint_step()) > 0
    assert (robot.collision_checks, robot.stall_guard.state()) == before  # its checks leave no trace
    monkeypatch.setattr(robot, "collision_free", lambda Q, pool=None: np.zeros(len(Q), dtype=bool))
    assert screen.cost_ratio(robot.max_joint_step()) is None and screen.pays(robot.max_joint_step())


def test_a_single_motion_into_a_collision_stops_at_its_end_state_as_ompls_validator_does(robot):
    """Helper probe, 2026-11-27: one si.checkMotion through the screen checked every ball and every uncovered state of
    a colliding motion (78 checks on a 1-rad wearer motion, 114 on Baxter), where OMPL's DiscreteMotionValidator
    stops at the end state when it collides; that handicapped RRTConnect, RRT* and the simplifier."""
    rng = np.random.default_rng(8)
    si = make_simple_setup(robot).getSpaceInformation()
    dense = make_simple_setup(robot, motion_validator="dense").getSpaceInformation()
    Q = rng.uniform(robot.lower, robot.upper, (3000, robot.nq))
    ok = robot.are_valid(Q)
    starts, ends = Q[ok][:40], Q[~ok][:40]
    a, b = si.allocState(), si.allocState()
    for q0, q1 in zip(starts, ends):
        for k in range(robot.nq):
            a[k], b[k] = q0[k], q1[k]
        c0 = robot.collision_checks
        assert not si.checkMotion(a, b)
        assert robot.collision_checks - c0 <= 2  # the end state (with two threads: the middle one beside it)
        assert not dense.checkMotion(a, b)


def test_only_si_check_motion_probes_a_free_motion_the_batched_call_does_not(robot):
    """The probe is OMPL's validator's start, for the native planners' single calls; dimension-RRT's batched calls
    come after its own screens, which stop at any collision, so a probe there would only add checks."""
    rng = np.random.default_rng(9)
    si = make_simple_setup(robot).getSpaceInformation()
    mv = si.getMotionValidator()
    Q = rng.uniform(robot.lower, robot.upper, (400, robot.nq))
    Q = Q[robot.are_valid(Q)]
    a, b = si.allocState(), si.allocState()
    found = 0
    for q0 in Q[1:]:
        q1 = q0 + 0.2 * (Q[0] - q0) / np.linalg.norm(Q[0] - q0)  # 17 states
        if not robot.are_valid(motion_states(q0, q1, robot.max_joint_step())).all():
            continue
        for k in range(robot.nq):
            a[k], b[k] = q0[k], q1[k]
        c0 = robot.collision_checks
        assert mv.check_motions(q0[None], q1[None])[0]
        c1 = robot.collision_checks
        assert si.checkMotion(a, b)
        assert robot.collision_checks - c1 == (c1 - c0) + 2  # the end state and the middle, then the same screen
        found += 1
    assert found >= 10


def test_a_colliding_motion_found_at_a_middle_state_checks_none_of_its_other_uncovered_states(robot, monkeypatch):
    """What no ball covers is checked plainly, each block's middle state first: a motion with a colliding middle gets
    no second call (before 2026-11-27 every uncovered state of a colliding motion was checked: RRTConnect's first
    paths at home took 639 checks against 515, mean, ``experiments/colliding_motions.py --switch middles``).  The
    verdicts stay the dense ones."""
    screen, step = robot.ball_screen(), robot.max_joint_step()
    A, B = _random_motions(robot, 300, 41)
    chunks = [motion_states(a, b, step) for a, b in zip(A, B)]
    dense = np.array([robot.are_valid(c).all() for c in chunks])
    calls: list[np.ndarray] = []
    real = robot.collision_free

    def recording(Q, pool=None):
        out = real(Q, pool)
        if pool is None:  # a plain check (the balls use their own pools)
            calls.append(out)
        return out

    monkeypatch.setattr(robot, "collision_free", recording)
    stopped = 0
    for chunk, ok in zip(chunks, dense):
        calls.clear()
        assert screened_all_valid(robot, screen, [chunk], step)[0] == ok
        if calls and not calls[0].all():  # a colliding middle state
            assert not ok and len(calls) == 1
            stopped += 1
    assert stopped >= 10
    calls.clear()
    np.testing.assert_array_equal(screened_all_valid(robot, screen, chunks, step), dense)  # all lines in one batch
    assert len(calls) == 2


def test_a_paths_motions_screened_as_one_polyline_get_the_dense_verdicts_with_fewer_checks(robot, rng):
    """A ball reaches across a waypoint: a path's motions (each starting where the last ended) are covered as one
    polyline.  The library's paths are 60 motions of 1-9 states each: line by line, most states were left over
    for plain checks beside a ball or two.  Chains broken anywhere, and lines outside the limits, keep their
    dense verdicts."""
    screen, step = robot.ball_screen(), robot.max_joint_step()
    checks = {True: 0, False: 0}
    verdicts = set()
    for _ in range(30):
        W = np.clip(rng.uniform(robot.lower, robot.upper) + np.cumsum(rng.normal(scale=0.04, size=(25, 4)), axis=0),
                    robot.lower - 0.02, robot.upper)  # a few waypoints below the lower limits
        A, B = W[:-1], W[1:]
        S, counts = batched_motion_states(A, B, step)
        spacing = np.linalg.norm(B - A, axis=1) / counts
        dense = np.array([robot.are_valid(c).all() for c in np.split(S, np.cumsum(counts)[:-1])])
        for chained in (np.ones(len(A) - 1, dtype=bool), None, rng.random(len(A) - 1) < 0.7):
            before = robot.collision_checks
            got = screened_lines_valid(robot, screen, S, counts, spacing, step, chained=chained)
            np.testing.assert_array_equal(got, dense)
            if chained is None or chained.all():
                checks[chained is not None] += robot.collision_checks - before
        verdicts.update(dense.tolist())
    assert verdicts == {True, False}
    assert checks[True] < 0.9 * checks[False]
