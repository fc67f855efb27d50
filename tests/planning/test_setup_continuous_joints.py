"""A URDF robot with continuous joints: each is planned as an SO2 angle that wraps around (make_space,
the validity checker, the batched motion validator, the planners)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl import DimensionRRT, RobotChecker, make_simple_setup
from tpee_ompl.model.obstacles import box
from tpee_ompl.planning.paths import path_passes_motion_checks, path_to_array
from tpee_ompl.planning.setup import make_space
from tpee_ompl.planning.space_layout import RealVectorLayout

LENGTHS = (0.5, 0.4, 0.3, 0.2)


def _chain(tmp_path: Path, types: tuple[str, ...]) -> Path:
    """A planar chain about z: link k a box along x, a gap either side of each joint."""
    links, joints, parent = ['<link name="base"/>'], [], "base"
    for k, (kind, length) in enumerate(zip(types, LENGTHS)):
        links.append(f'<link name="l{k}"><collision><origin xyz="{length / 2:.3f} 0 0"/>'
                     f'<geometry><box size="{length - 0.14:.3f} 0.05 0.05"/></geometry></collision></link>')
        origin = f'<origin xyz="{LENGTHS[k - 1]:.3f} 0 0"/>' if k else ""
        limit = '<limit lower="-2.2" upper="2.2" effort="1" velocity="1"/>' if kind == "revolute" else ""
        joints.append(f'<joint name="j{k}" type="{kind}"><parent link="{parent}"/><child link="l{k}"/>{origin}'
                      f'<axis xyz="0 0 1"/>{limit}</joint>')
        parent = f"l{k}"
    path = tmp_path / ("_".join(t[0] for t in types) + ".urdf")
    path.write_text(f'<robot name="chain">{"".join(links)}{"".join(joints)}</robot>')
    return path


MIXED = ("continuous", "revolute", "revolute", "continuous")


def _post(x: float, y: float) -> list:
    return [box("post", (0.05, 0.05, 0.3), (x, y, 0.0))]


def test_continuous_joints_are_so2_subspaces_in_joint_order_and_other_joints_stay_real_vector(tmp_path):
    robot = RobotChecker(_chain(tmp_path, MIXED))
    assert robot.circular.tolist() == [True, False, False, True]
    assert (robot.lower[[0, 3]] == -math.pi).all() and (robot.upper[[0, 3]] == math.pi).all()
    space = make_space(robot)
    kinds = [type(space.getSubspace(k)).__name__ for k in range(space.getSubspaceCount())]
    assert kinds == ["SO2StateSpace", "RealVectorStateSpace", "SO2StateSpace"]
    assert space.getSubspace(1).getDimension() == 2
    layout = RealVectorLayout(space)
    assert layout.circular.tolist() == robot.circular.tolist()  # a state's flat values are the joints in order
    plain = RobotChecker(_chain(tmp_path, ("revolute",) * 4))
    assert not plain.circular.any() and isinstance(make_space(plain), ob.RealVectorStateSpace)


@pytest.mark.parametrize("validator", ["batched", "dense"])
@pytest.mark.parametrize("factor", [1, 4])
def test_the_batched_motion_validator_checks_the_states_ompls_discrete_validator_checks(tmp_path, validator, factor):
    """At factor 1 the segment counts are the compound space's own (``validSegmentCount``) and the verdicts OMPL's;
    at factor 4 (ot.Benchmark's strict check) 4x the segments, a superset of the states: never a motion OMPL's
    validator rejects (OMPL's own does not pass the factor to a compound's subspaces)."""
    robot = RobotChecker(_chain(tmp_path, MIXED), obstacles=_post(-0.7, 0.3))
    ours = make_simple_setup(robot, motion_validator=validator).getSpaceInformation()
    ompl = make_simple_setup(robot, motion_validator="discrete").getSpaceInformation()
    for si in (ours, ompl):
        si.getStateSpace().setValidSegmentCountFactor(factor)
    space, mv = ours.getStateSpace(), ours.getMotionValidator()
    layout = RealVectorLayout(space)
    rng = np.random.default_rng(3)
    verdicts, theirs, A, B = [], [], [], []
    while len(verdicts) < 150:
        a, b = rng.uniform(robot.lower, robot.upper, (2, robot.nq))
        s1, s2 = layout.write(ours.allocState(), a), layout.write(ours.allocState(), b)
        if not robot.is_valid(a):
            continue
        assert mv.segment_counts(a[None], b[None])[0] == factor * max(1, space.validSegmentCount(s1, s2))
        verdicts.append(ours.checkMotion(s1, s2))
        theirs.append(ompl.checkMotion(s1, s2))
        A.append(a)
        B.append(b)
    if factor == 1:
        assert verdicts == theirs
    else:
        assert not any(v and not t for v, t in zip(verdicts, theirs))
    assert 20 < sum(verdicts) < 130  # both verdicts are tested
    batch = mv.check_motions(np.array(A), np.array(B))
    assert batch.tolist() == verdicts  # many motions in one call: the same verdicts


def test_half_a_turn_goes_the_way_ompls_so2_interpolation_goes(tmp_path):
    """From -pi/2 to +pi/2 both ways round are as short: OMPL's SO2StateSpace goes the + way (through 0)."""
    robot = RobotChecker(_chain(tmp_path, MIXED), obstacles=_post(0.7, 0.0))  # at angle 0
    start, goal = [-math.pi / 2, 0.0, 0.0, 0.0], [math.pi / 2, 0.0, 0.0, 0.0]
    for validator in ("batched", "dense", "discrete"):
        si = make_simple_setup(robot, start, goal, motion_validator=validator).getSpaceInformation()
        layout = RealVectorLayout(si.getStateSpace())
        s1, s2, mid = layout.write(si.allocState(), start), layout.write(si.allocState(), goal), si.allocState()
        si.getStateSpace().interpolate(s1, s2, 0.5, mid)
        np.testing.assert_allclose(layout.interpolate(np.array(start), np.array(goal), 0.5), layout.read(mid),
                                   atol=1e-12)
        assert not si.checkMotion(s1, s2), validator  # through the post


def test_a_motion_across_pi_is_checked_the_short_way_round(tmp_path):
    start, goal = [3.0, 0.0, 0.0, 0.0], [-3.0, 0.0, 0.0, 0.0]
    behind = RobotChecker(_chain(tmp_path, MIXED), obstacles=_post(-0.7, 0.0))  # on the short way, at angle pi
    ahead = RobotChecker(_chain(tmp_path, MIXED), obstacles=_post(0.7, 0.0))  # on the long way, at angle 0
    for robot, free in ((behind, False), (ahead, True)):
        si = make_simple_setup(robot, start, goal).getSpaceInformation()
        layout = RealVectorLayout(si.getStateSpace())
        assert robot.is_valid(start) and robot.is_valid(goal)
        assert si.checkMotion(layout.write(si.allocState(), start), layout.write(si.allocState(), goal)) is free


def test_start_and_goal_angles_of_continuous_joints_are_wrapped_into_so2(tmp_path):
    robot = RobotChecker(_chain(tmp_path, MIXED))
    ss = make_simple_setup(robot, [3.0 + 2 * math.pi, 0.1, 0.0, -7.0], [-3.0, 0.0, 0.0, 0.0])
    ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
    assert ss.solve(5.0) == ob.PlannerStatus.EXACT_SOLUTION
    W = RealVectorLayout(ss.getSpaceInformation().getStateSpace()).from_path(ss.getSolutionPath())
    np.testing.assert_allclose(W[0], [3.0, 0.1, 0.0, -7.0 + 2 * math.pi], atol=1e-12)  # the start as SO2 holds it
    with pytest.raises(ValueError, match="start .* is outside the joint limits"):  # a bounded joint is not wrapped
        make_simple_setup(robot, [0.0, 3.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0])


def test_unwrapped_angles_of_continuous_joints_get_the_verdict_of_their_wrapped_angle(tmp_path):
    """ROS's joint_states report continuous joints unwrapped (7.0 rad): every validity check takes such an angle
    as the same position; a bounded joint outside its limits and a non-finite angle stay invalid."""
    robot = RobotChecker(_chain(tmp_path, MIXED), obstacles=_post(-0.7, 0.3))
    rng = np.random.default_rng(11)
    Q = rng.uniform(robot.lower, robot.upper, (200, robot.nq))
    turns = rng.integers(-3, 4, (200, 2)) * 2 * math.pi
    U = Q.copy()
    U[:, [0, 3]] += turns
    wrapped = robot.are_valid(Q)
    assert 20 < wrapped.sum() < 180  # both verdicts are tested
    assert robot.are_valid(U).tolist() == wrapped.tolist()
    assert [robot.is_valid(u) for u in U] == wrapped.tolist()
    assert [robot.is_valid_values(u.tolist()) for u in U] == wrapped.tolist()
    first = int(np.argmin(wrapped))
    assert robot.first_invalid(U) == first and robot.within_limits(U[first])
    free = U[int(np.argmax(wrapped))]
    np.testing.assert_array_equal(robot.check_free(free), free)
    out = free.copy()
    out[1] = 3.0  # a revolute joint past its 2.2-rad limit
    assert not robot.is_valid(out) and not robot.is_valid_values(out.tolist()) and not robot.are_valid(out[None])[0]
    for bad in (math.inf, math.nan):
        assert not robot.is_valid_values([bad, 0.0, 0.0, 0.0])


@pytest.mark.parametrize("planner", ["RRTConnect", "DimensionRRT"])
def test_planners_find_the_short_way_round_and_their_paths_pass_the_motion_checks(tmp_path, planner):
    robot = RobotChecker(_chain(tmp_path, MIXED), obstacles=_post(0.7, 0.0) + [box("wall", (0.05, 0.05, 0.3),
                                                                                    (-0.9, 0.0, 0.0))])
    ss = make_simple_setup(robot, [3.0, 0.0, 0.0, 2.0], [-3.0, 0.0, 0.0, -2.0])
    si = ss.getSpaceInformation()
    ss.setPlanner(DimensionRRT(si, seed=1, max_samples=2000) if planner == "DimensionRRT" else og.RRTConnect(si))
    assert ss.solve(5.0) == ob.PlannerStatus.EXACT_SOLUTION
    if planner == "RRTConnect":
        ss.simplifySolution(1.0)
    path = ss.getSolutionPath()
    assert path.check() and path_passes_motion_checks(si, path)
    layout = RealVectorLayout(si.getStateSpace())
    W = layout.from_path(path)
    assert np.abs(W).max() <= math.pi
    travel = np.abs(layout.delta(W[:-1], W[1:])[:, 0]).sum()
    assert travel < math.pi  # the first joint went the short way round (the long way is over 6 rad)


def test_path_checks_of_a_compound_space_give_ompls_verdicts(tmp_path):
    robot = RobotChecker(_chain(tmp_path, MIXED), obstacles=_post(-0.7, 0.3))
    si = make_simple_setup(robot).getSpaceInformation()
    layout = RealVectorLayout(si.getStateSpace())
    rng = np.random.default_rng(5)
    seen = set()
    for _ in range(40):
        W = rng.uniform(robot.lower, robot.upper, (4, robot.nq))
        W[0] = [0.0, 0.3, 0.3, 0.0]
        path = layout.to_path(si, W)
        verdict = path_passes_motion_checks(si, path)
        assert verdict == all(si.checkMotion(path.getState(k), path.getState(k + 1)) for k in range(3))
        seen.add(verdict)
    assert seen == {True, False}


def test_reading_a_compound_path_as_real_vector_states_is_refused_with_the_way_out(tmp_path):
    robot = RobotChecker(_chain(tmp_path, MIXED))
    si = make_simple_setup(robot).getSpaceInformation()
    path = RealVectorLayout(si.getStateSpace()).to_path(si, np.zeros((2, robot.nq)))
    with pytest.raises(ValueError, match="CompoundStateSpace.s need read=RealVectorLayout"):
        path_to_array(path, robot.nq)  # was a segfault: s[3] past the compound's three subspaces


def test_the_certified_validator_refuses_continuous_joints_by_name(tmp_path):
    robot = RobotChecker(_chain(tmp_path, MIXED))
    with pytest.raises(ValueError, match=r"certified motion validator .*continuous: \['j0', 'j3'\]"):
        make_simple_setup(robot, motion_validator="certified")


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_a_motion_to_a_non_finite_state_is_invalid_in_a_compound_space(tmp_path, bad):
    robot = RobotChecker(_chain(tmp_path, MIXED))
    si = make_simple_setup(robot, motion_validator="batched").getSpaceInformation()
    layout, mv = RealVectorLayout(si.getStateSpace()), si.getMotionValidator()
    a, b = np.zeros(4), np.array([0.3, 0.2, -0.2, 0.1])
    c = b.copy()
    c[1] = bad
    assert not si.checkMotion(layout.write(si.allocState(), a), layout.write(si.allocState(), c))
    assert mv.check_motions(np.stack([a, a]), np.stack([c, b])).tolist() == [False, True]


def test_a_checker_set_on_the_setup_checks_the_short_way_round_across_plus_minus_pi(tmp_path):
    robot = RobotChecker(_chain(tmp_path, MIXED))
    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    layout = RealVectorLayout(si.getStateSpace())
    a = layout.write(si.allocState(), np.array([2.8, 0.3, 0.3, 0.0]))
    b = layout.write(si.allocState(), np.array([-2.8, 0.3, 0.3, 0.0]))  # the short way passes +/-pi
    assert si.checkMotion(a, b)
    own = si.getStateValidityChecker()

    class AwayFromPi(ob.StateValidityChecker):
        def isValid(self, s: ob.State) -> bool:  # noqa: N802
            return bool(own.isValid(s) and abs(layout.read(s)[0]) < 3.0)  # (a numpy bool: std::bad_cast)

    checker = AwayFromPi(si)
    ss.setStateValidityChecker(checker)
    assert si.isValid(a) and si.isValid(b) and not si.checkMotion(a, b)
