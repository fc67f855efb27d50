"""OMPL set-up (tpee_ompl.planning.setup): bounds, resolution, motion-check guarantee, motion_check_step, RRT* end to end."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.planning.setup import BatchedMotionValidator, make_simple_setup, motion_check_step
from tpee_ompl.planning.paths import motion_states, path_passes_motion_checks, path_to_array, set_state
from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.model.sectors import posture_preset


def preset(k: int, pan: float = 0.0, tilt: float = 0.0) -> np.ndarray:
    return np.r_[posture_preset(k), pan, tilt]


def test_setup_bounds_come_from_the_urdf_limits(robot):
    ss = make_simple_setup(robot)
    b = ss.getStateSpace().getBounds()
    np.testing.assert_allclose([b.low[i] for i in range(4)], robot.lower)
    np.testing.assert_allclose([b.high[i] for i in range(4)], robot.upper)


def test_default_resolution_is_the_safe_joint_step(robot):
    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    step = si.getStateValidityCheckingResolution() * si.getMaximumExtent()
    assert step == pytest.approx(robot.max_joint_step())
    assert isinstance(si.getMotionValidator(), BatchedMotionValidator)


def test_lever_arm_bound_holds_for_every_arm_point(robot, rng):
    """No sampled arm point moves more than ||dq|| * ||lever arms|| for a joint step dq."""
    R = float(np.linalg.norm(robot.lever_arms()))
    worst = 0.0
    for _ in range(300):
        q = rng.uniform(robot.lower, robot.upper)
        dq = rng.normal(size=4)
        dq *= 1e-3 / np.linalg.norm(dq)
        moved = max(
            np.linalg.norm(robot.frame_placement(q + dq, f).translation - robot.frame_placement(q, f).translation)
            for f in ("muzzle", "link4", "link3", "link2")
        )
        worst = max(worst, moved / (1e-3 * R))
    assert worst <= 1.0


def test_accepted_motions_keep_half_the_margin_under_a_much_denser_check(robot, rng):
    """Every motion that checkMotion accepts keeps >= margin/2 clearance when re-checked 10x denser."""
    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    half = WearerArm(security_margin=robot.security_margin / 2)
    a, b = si.allocState(), si.allocState()
    accepted = 0
    while accepted < 150:
        q0 = rng.uniform(robot.lower, robot.upper)
        q1 = q0 + rng.normal(scale=0.4, size=4)
        if not (robot.within_limits(q1) and robot.is_valid(q0)):
            continue
        if si.checkMotion(set_state(a, q0), set_state(b, q1)):
            accepted += 1
            dense = motion_states(q0, q1, robot.max_joint_step() / 10)
            assert half.are_valid(dense).all()


@pytest.mark.parametrize("batched", [True, False])
def test_batched_and_discrete_motion_validators_agree(robot, rng, batched):
    ss_b = make_simple_setup(robot, batched_motion_validator=True)
    ss_d = make_simple_setup(robot, batched_motion_validator=False)
    sb, sd = ss_b.getSpaceInformation(), ss_d.getSpaceInformation()
    a, b = sb.allocState(), sb.allocState()
    for _ in range(200):
        q0 = rng.uniform(robot.lower, robot.upper)
        q1 = np.clip(q0 + rng.normal(scale=0.5, size=4), robot.lower, robot.upper)
        set_state(a, q0), set_state(b, q1)
        assert sb.checkMotion(a, b) == sd.checkMotion(a, b)


@pytest.mark.parametrize("screened", [True, False])
def test_a_motion_that_ends_exactly_at_a_joint_limit_is_judged_by_its_end_state_as_ompl_does(robot, rng, screened):
    """The last state checked was a + 1.0 * (b - a), which can be an ulp past the limit b sits on: such valid motions
    were refused where OMPL's DiscreteMotionValidator accepts them (a helper's probe on the Panda: 173 of 300)."""
    from tpee_ompl.planning.paths import batched_motion_states

    ss_b = make_simple_setup(robot, batched_motion_validator=True)
    ss_d = make_simple_setup(robot, batched_motion_validator=False)
    sb, sd = ss_b.getSpaceInformation(), ss_d.getSpaceInformation()
    mv = sb.getMotionValidator()
    mv.screen_levels = mv.screen_levels if screened else ()
    found = 0
    for _ in range(20000):
        k = int(rng.integers(4))
        q0 = rng.uniform(robot.lower, robot.upper)
        q1 = q0 + rng.normal(scale=0.05, size=4)
        q1[k] = robot.upper[k]
        if not (robot.within_limits(q1) and (q0 + 1.0 * (q1 - q0))[k] > robot.upper[k]):
            continue  # only the ends the old arithmetic pushed past the limit
        if not (robot.is_valid(q0) and robot.is_valid(q1)):
            continue
        a, b = set_state(sb.allocState(), q0), set_state(sb.allocState(), q1)
        assert motion_states(q0, q1, 0.01)[-1].tolist() == q1.tolist()
        assert batched_motion_states(q0[None], q1[None], 0.01)[0][-1].tolist() == q1.tolist()
        assert sb.checkMotion(a, b) == sd.checkMotion(a, b)
        found += 1
        if found == 20:
            break
    assert found == 20


def test_rrtstar_between_two_presets_returns_an_exact_path_whose_every_segment_passes_check_motion(robot):
    ou.RNG.setSeed(7) if ou.RNG.getSeed() == 0 else None
    ss = make_simple_setup(robot, preset(1), preset(4))
    si = ss.getSpaceInformation()
    planner = og.RRTstar(si)
    ss.setPlanner(planner)
    status = ss.solve(ob.PlannerTerminationCondition(lambda: planner.numIterations() >= 300))
    assert status == ob.PlannerStatus.EXACT_SOLUTION
    assert ss.haveExactSolutionPath()
    path = ss.getSolutionPath()
    assert path_passes_motion_checks(si, path)
    W = path_to_array(path, 4)
    np.testing.assert_allclose(W[0], preset(1))
    np.testing.assert_allclose(W[-1], preset(4))


def test_start_in_collision_is_refused_with_the_colliding_parts(robot):
    with pytest.raises(ValueError, match=r"start .* in collision \(.*helmet"):
        make_simple_setup(robot, [-0.085, 0.299, -0.799, -1.202], preset(4))


def test_goal_outside_limits_is_refused(robot):
    with pytest.raises(ValueError, match="goal .* outside the joint limits"):
        make_simple_setup(robot, preset(1), [0.0, 4.0, 0.0, 0.0])


@pytest.mark.parametrize("step", [0.0, -1.0, float("nan")])
def test_bad_joint_step_raises(robot, step):
    with pytest.raises(ValueError, match="joint_step"):
        make_simple_setup(robot, joint_step=step)


def test_ompl_state_checker_agrees_with_the_model_inside_and_outside_the_limits(robot, rng):
    si = make_simple_setup(robot).getSpaceInformation()
    s = si.allocState()
    for q in rng.uniform(robot.lower - 0.2, robot.upper + 0.2, size=(2000, 4)):
        assert si.isValid(set_state(s, q)) == robot.is_valid(q)
    assert not robot.is_valid_values([float("nan"), 0.0, 0.0, 0.0])


@pytest.mark.parametrize("joint_step", [None, 0.01, 0.05])
def test_motion_check_step_is_the_setups_joint_step(robot, joint_step):
    ss = make_simple_setup(robot, joint_step=joint_step)
    want = robot.max_joint_step() if joint_step is None else joint_step
    assert motion_check_step(ss) == want  # exactly: read from the batched motion validator
    assert motion_check_step(ss.getSpaceInformation()) == want
    si = ss.getSpaceInformation()
    assert want == pytest.approx(si.getStateValidityCheckingResolution() * si.getStateSpace().getMaximumExtent())
    discrete = make_simple_setup(robot, joint_step=joint_step, batched_motion_validator=False)
    assert motion_check_step(discrete) == pytest.approx(want)


def test_motion_check_step_refuses_other_objects():
    with pytest.raises(ValueError, match="SimpleSetup or ob.SpaceInformation"):
        motion_check_step(0.01)


def test_the_validity_checker_is_generic_and_keeps_its_wearer_name():
    from tpee_ompl.planning.setup import RobotValidityChecker, WearerValidityChecker

    assert WearerValidityChecker is RobotValidityChecker


def test_make_simple_setup_plans_for_the_panda_shelf():
    pytest.importorskip("example_robot_data", reason="install the optional 'robots' extra")
    from ompl import geometric as og

    from tpee_ompl.model.joint_queries import load_joint_query_set
    from tpee_ompl.model.robots import panda_shelf

    checker = panda_shelf(n_threads=2)
    q = load_joint_query_set("panda_shelf", checker)[0][0]
    ss = make_simple_setup(checker, q.start, q.goal, batched_motion_validator=True)
    assert ss.getSpaceInformation().getStateDimension() == 7
    assert not ss.getSpaceInformation().checkMotion(_state(ss, q.start), _state(ss, q.goal))  # straight line collides
    ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
    ss.solve(0.05)  # runs through the batched validator without error, solved or not


def _state(ss, values):
    s = ss.getSpaceInformation().allocState()
    for i, v in enumerate(values):
        s[i] = float(v)
    return s


@pytest.mark.parametrize("screened", [True, False])
def test_batched_check_motions_gives_each_motion_check_motions_verdict(robot, rng, screened):
    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    mv = BatchedMotionValidator(si, robot, motion_check_step(si), screen_levels=(2.0, 1.0) if screened else ())
    a, b = si.allocState(), si.allocState()
    for _ in range(40):
        K = int(rng.integers(2, 7))
        A = rng.uniform(robot.lower - 0.05, robot.upper + 0.05, (K, robot.nq))  # some ends outside the limits
        B = A + rng.normal(scale=0.4, size=A.shape) * (rng.random((K, 1)) < 0.8)  # some zero-length motions
        got = mv.check_motions(A, B)
        for k in range(K):
            set_state(a, A[k]), set_state(b, B[k])
            assert got[k] == mv.checkMotion(a, b)
    assert mv.check_motions(np.zeros((0, robot.nq)), np.zeros((0, robot.nq))).shape == (0,)  # no motion, no verdict


def test_a_motion_given_as_joint_values_gets_check_motions_verdict_and_stops_at_a_colliding_probe(robot, rng):
    """``check_motion_values(a, b, probes)`` checks that many of the motion's states first (its end, then the middles
    breadth first): a planner's first question, the query's direct motion, mostly collides and is answered there."""
    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    mv = si.getMotionValidator()
    a, b = si.allocState(), si.allocState()
    at_a_probe = 0
    for _ in range(60):
        A = rng.uniform(robot.lower, robot.upper)
        B = np.clip(A + rng.normal(scale=0.8, size=A.shape), robot.lower, robot.upper)
        set_state(a, A), set_state(b, B)
        before = robot.collision_checks
        ok = mv.check_motion_values(A, B, 15)
        checked = robot.collision_checks - before
        assert ok == mv.checkMotion(a, b) == bool(robot.are_valid(motion_states(A, B, mv.step)).all())
        at_a_probe += not ok and checked <= 15
    assert at_a_probe >= 10


def test_an_unscreened_motion_check_stops_at_its_first_invalid_state_in_bisection_order(robot, rng):
    """Without clearance balls (robots where they do not pay) one motion's states were all checked in one batch, a
    colliding one too: 1 s for a 400-state motion of an xArm7 against 26 ms for OMPL's discrete validator."""
    from tpee_ompl.planning.paths import motion_states

    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    mv = BatchedMotionValidator(si, robot, motion_check_step(si), screen_levels=())
    a, b = si.allocState(), si.allocState()
    fewer = 0
    for _ in range(60):
        A = rng.uniform(robot.lower, robot.upper)
        B = np.clip(A + rng.normal(scale=0.8, size=A.shape), robot.lower, robot.upper)
        S = motion_states(A, B, mv.step)  # the end included, the start not
        set_state(a, A), set_state(b, B)
        before = robot.collision_checks
        ok = mv.checkMotion(a, b)
        checked = robot.collision_checks - before
        assert ok == bool(robot.are_valid(S).all())
        assert checked <= len(S) and (checked == len(S) or not ok)
        fewer += checked < len(S) - 1
    assert fewer >= 10  # colliding motions stop early


def test_motion_counts_are_the_validators_own_and_a_fraction_needs_a_counted_motion(robot: WearerArm) -> None:
    from tpee_ompl.planning.setup import motion_counts, valid_motion_fraction

    start, goal = np.r_[posture_preset(1), 0.0, 0.0], np.r_[posture_preset(4), 0.0, 0.0]
    for validator in ("batched", "discrete"):
        ss = make_simple_setup(robot, start, goal, motion_validator=validator)
        si = ss.getSpaceInformation()
        mv = si.getMotionValidator()
        before = motion_counts(mv)
        a, b = si.allocState(), si.allocState()
        for k in range(4):
            a[k], b[k] = float(start[k]), float(goal[k])
        ok = [si.checkMotion(a, b), si.checkMotion(a, a)]
        valid, checked = (x - y for x, y in zip(motion_counts(mv), before))
        assert (valid, checked) == (sum(ok), 2), validator  # OMPL's own counters stay at 0 for the batched one
        assert valid_motion_fraction(before, motion_counts(mv)) == sum(ok) / 2
    assert valid_motion_fraction((3, 5), (3, 5)) is None and valid_motion_fraction(None, (1, 1)) is None


@pytest.mark.parametrize("factor, steps", [(1, 1.2), (4, 1.2), (4, 2.7), (3, 0.4)])
def test_the_batched_validator_checks_as_many_states_as_ompls_at_any_segment_count_factor(robot, factor, steps):
    """OMPL's DiscreteMotionValidator checks ``f * ceil(d / step)`` states (``ot.Benchmark``'s strict check
    sets f = 4); the batched one used ``ceil(f * d / step)`` (5 instead of 8 states for 1.2 steps)."""
    start = robot.lower + 0.5 * (robot.upper - robot.lower)
    counts = {}
    for kind in ("dense", "discrete"):
        si = make_simple_setup(robot, motion_validator=kind).getSpaceInformation()
        si.getStateSpace().setValidSegmentCountFactor(factor)
        step = robot.max_joint_step()
        a, b = si.allocState(), si.allocState()
        set_state(a, start)
        set_state(b, start + np.r_[steps * step, 0.0, 0.0, 0.0])
        before = robot.collision_checks
        si.checkMotion(a, b)
        counts[kind] = robot.collision_checks - before
    assert counts["dense"] == counts["discrete"] == factor * int(np.ceil(steps))


def test_segment_counts_of_a_real_vector_setup_are_ompls_valid_segment_counts(robot, rng):
    """``segment_counts`` was for compound spaces only (an AttributeError on the wearer's RealVector setup)."""
    si = make_simple_setup(robot).getSpaceInformation()
    space, mv = si.getStateSpace(), si.getMotionValidator()
    A, B = rng.uniform(robot.lower, robot.upper, (2, 30, robot.nq))
    B[0] = A[0]
    for factor in (1, 4):
        space.setValidSegmentCountFactor(factor)
        theirs = []
        for a, b in zip(A, B):
            s1, s2 = si.allocState(), si.allocState()
            set_state(s1, a)
            set_state(s2, b)
            theirs.append(max(factor, space.validSegmentCount(s1, s2)))  # OMPL's validator checks >= 1 segment
        assert mv.segment_counts(A, B).tolist() == theirs
    with pytest.raises(ValueError, match="finite"):
        mv.segment_counts(A[:1], np.full((1, robot.nq), np.nan))


def test_a_margin_so_small_that_its_motion_step_is_below_the_floor_is_refused_not_densified():
    """A 1e-9-m margin made one 1-rad motion check allocate 12 GiB; a zero margin names the margin."""
    tiny = WearerArm(security_margin=1e-9)
    with pytest.raises(ValueError, match="below MIN_JOINT_STEP"):
        make_simple_setup(tiny)
    make_simple_setup(tiny, joint_step=0.01)  # a step given explicitly is the caller's choice
    zero = WearerArm(security_margin=0.0)
    with pytest.raises(ValueError, match="security_margin is 0"):
        zero.max_joint_step()
    from tpee_ompl.planning.paths import motion_is_valid, motion_step

    assert motion_step(zero, 0.01) == 0.01  # a step given: no cap at a zero margin
    with pytest.raises(ValueError, match="security_margin is 0"):
        motion_step(zero)
    q = zero.lower + 0.5 * (zero.upper - zero.lower)
    motion_is_valid(zero, np.stack([q, q + 0.01]), 0.01)


def test_setup_arguments_are_named_in_their_errors(robot):
    good = robot.lower + 0.5 * (robot.upper - robot.lower)
    with pytest.raises(ValueError, match="^start: "):
        make_simple_setup(robot, [0.0, 0.0], good)
    with pytest.raises(ValueError, match="^goal: "):
        make_simple_setup(robot, good, [float("nan")] * 4)
    with pytest.raises(ValueError, match="check_endpoints"):
        make_simple_setup(robot, check_endpoints=None)
    with pytest.raises(ValueError, match="contradicts"):
        make_simple_setup(robot, batched_motion_validator=True, motion_validator="discrete")
    for bad in (None, "wearer", robot.nq):
        with pytest.raises(ValueError, match="^robot must be a RobotChecker"):
            make_simple_setup(bad)


def test_a_robot_whose_screen_costs_more_than_it_saves_is_checked_densely_with_the_same_verdicts(rng, monkeypatch):
    from tpee_ompl.model.clearance_balls import SCREEN_COST_LIMIT, SCREEN_LEVELS, BallScreen

    ratios = {"costly": 10 * SCREEN_COST_LIMIT, "cheap": SCREEN_COST_LIMIT / 10}
    validators = {}
    for kind, ratio in ratios.items():
        monkeypatch.setattr(BallScreen, "cost_ratio", lambda self, radius, r=ratio: r)
        robot = WearerArm()  # its own screen: the measured ratio is kept per robot
        validators[kind] = make_simple_setup(robot).getSpaceInformation().getMotionValidator()
    assert validators["costly"].screen_levels == () and validators["cheap"].screen_levels == SCREEN_LEVELS
    costly = validators["costly"]
    si = make_simple_setup(costly.robot).getSpaceInformation()
    assert BatchedMotionValidator(si, costly.robot, costly.step, screen_levels=(2.0, 1.0)).screen_levels == (2.0, 1.0)
    robot = validators["cheap"].robot
    A = rng.uniform(robot.lower, robot.upper, (60, robot.nq))
    B = np.clip(A + rng.normal(scale=0.3, size=A.shape), robot.lower, robot.upper)
    np.testing.assert_array_equal(validators["costly"].check_motions(A, B), validators["cheap"].check_motions(A, B))


@pytest.mark.parametrize("validator", ["batched", "dense", "certified"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_motion_to_a_non_finite_state_is_invalid_as_ompls_validator_says(robot, validator, bad):
    """OMPL's DiscreteMotionValidator answers False; ours raised on the segment count of a NaN or inf motion."""
    si = make_simple_setup(robot, motion_validator=validator).getSpaceInformation()
    mv = si.getMotionValidator()
    a = load_queries("planning_necessary")[0].start
    b = a + np.r_[0.0, 0.0, 0.01, 0.0]
    c = b.copy()
    c[2] = bad
    assert not si.checkMotion(set_state(si.allocState(), a), set_state(si.allocState(), c))
    before = mv.motions_checked
    assert mv.check_motions(np.stack([a, a, a]), np.stack([b, c, b])).tolist() == [True, False, True]
    assert mv.motions_checked - before == 3


def test_quieter_ompl_raises_the_level_for_its_block_only_and_never_lowers_it():
    from tpee_ompl.planning.setup import quieter_ompl

    before = ou.getLogLevel()
    try:
        for level, inside in ((ou.LOG_INFO, ou.LOG_WARN), (ou.LOG_NONE, ou.LOG_NONE)):
            ou.setLogLevel(level)
            with quieter_ompl():
                assert ou.getLogLevel() == inside
            assert ou.getLogLevel() == level
    finally:
        ou.setLogLevel(before)


def test_seed_ompl_makes_the_next_planners_draw_the_same_numbers_after_numbers_were_drawn(capfd):
    from ompl import util as ou

    from tpee_ompl.planning.setup import seed_ompl

    def draws() -> list[float]:  # a new RNG takes its seed from the generator, as a planner's or sampler's does
        rngs = [ou.RNG() for _ in range(2)]
        return [r.uniform01() for r in rngs for _ in range(3)]

    ou.RNG()  # numbers drawn before: OMPL logs an error at a later setSeed
    seed_ompl(17)
    first = draws()
    seed_ompl(17)
    assert draws() == first
    seed_ompl(18)
    assert draws() != first
    assert "already started" not in capfd.readouterr().err


def test_the_validity_checkers_clearance_is_the_workspace_distance_to_the_nearest_invalid_configuration(robot, rng):
    """OMPL's default clearance() is 0, so Planner Arena showed every path touching an obstacle."""
    si = make_simple_setup(robot).getSpaceInformation()
    checker, s = si.getStateValidityChecker(), si.allocState()
    Q = rng.uniform(robot.lower, robot.upper, (60, robot.nq))
    seen = set()
    for q in Q:
        set_state(s, q)
        c = checker.clearance(s)
        assert c == pytest.approx(robot.clearance(q, from_margins=True))
        assert (c >= 0) == robot.is_valid(q)  # inside a margin (invalid) is negative
        seen.add(robot.is_valid(q))
        margins = robot.pair_margins()
        assert robot.clearance(q) - margins.max() - 1e-12 <= c <= robot.clearance(q) - margins.min() + 1e-12
    assert seen == {True, False}
