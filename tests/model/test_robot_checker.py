"""RobotChecker: agreement with Coal, the lever-arm bound, obstacles, locked joints, bad input."""

from __future__ import annotations

import time

import coal
import numpy as np
import pinocchio as pin
import pytest

from tests.helpers.panda import needs_panda
from tests.helpers.wearer_configs import valid_and_colliding
from tpee_ompl.model import robot_checker, stall_guard
from tpee_ompl.model.obstacles import Obstacle, box
from tpee_ompl.model.robot_checker import RobotChecker
from tpee_ompl.model.wearer_arm import WearerArm


@pytest.fixture(scope="module")
def panda0():
    from tpee_ompl.model.robots import panda_shelf

    return panda_shelf(n_threads=2, security_margin=0.0)


def _coal_verdicts(checker: RobotChecker, Q: np.ndarray) -> np.ndarray:
    """Collides per configuration from Coal's own per-pair distances after FK (no Pinocchio collision call)."""
    out = []
    g = checker.gmodel.geometryObjects
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    for q in Q:
        pin.framesForwardKinematics(checker.model, checker.data, q)
        pin.updateGeometryPlacements(checker.model, checker.data, checker.gmodel, checker.gdata)
        hit = False
        for cp in checker.gmodel.collisionPairs:
            res.clear()
            d = coal.distance(g[cp.first].geometry, coal.Transform3s(checker.gdata.oMg[cp.first]),
                              g[cp.second].geometry, coal.Transform3s(checker.gdata.oMg[cp.second]), req, res)
            if d <= 0:
                hit = True
                break
        out.append(hit)
    return np.array(out)


@needs_panda
def test_batched_verdicts_agree_with_coal_distances_at_margin_zero(panda0):
    rng = np.random.default_rng(3)
    Q = panda0.lower + rng.random((300, panda0.nq)) * (panda0.upper - panda0.lower)
    batched = panda0.are_valid(Q)
    assert 0 < batched.sum() < len(Q)  # both verdicts occur
    assert (batched == ~_coal_verdicts(panda0, Q)).all()


@needs_panda
def test_small_steps_never_move_a_geometry_point_more_than_the_lever_arm_bound(panda0):
    rng = np.random.default_rng(4)
    arms = panda0.lever_arms()
    pts = []  # points on each geometry: its origin and its bounding-box corners, in the geometry frame
    for go in panda0.gmodel.geometryObjects:
        go.geometry.computeLocalAABB()
        lo, hi = go.geometry.aabb_local.min_, go.geometry.aabb_local.max_
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        pts.append(np.vstack([np.zeros(3), corners]))

    def world_points(q):
        pin.framesForwardKinematics(panda0.model, panda0.data, q)
        pin.updateGeometryPlacements(panda0.model, panda0.data, panda0.gmodel, panda0.gdata)
        return [(panda0.gdata.oMg[i].rotation @ p.T).T + panda0.gdata.oMg[i].translation for i, p in enumerate(pts)]

    for _ in range(100):
        q = panda0.lower + rng.random(panda0.nq) * (panda0.upper - panda0.lower)
        dq = rng.normal(size=panda0.nq) * 0.01
        a, b = world_points(q), world_points(q + dq)
        moved = max(np.linalg.norm(pb - pa, axis=1).max() for pa, pb in zip(a, b))
        assert moved <= float(np.abs(dq) @ arms) + 1e-12
    step = panda0.max_joint_step(0.01)
    assert step == pytest.approx(0.01 / np.linalg.norm(arms))


@needs_panda
def test_obstacles_pair_with_moving_geometry_only_and_block_configurations(panda0):
    g = panda0.gmodel.geometryObjects
    static = {i for i, go in enumerate(g) if go.parentJoint == 0}
    assert "table" in panda0.geometry_names(0)
    for cp in panda0.gmodel.collisionPairs:
        assert not (cp.first in static and cp.second in static)
    from tpee_ompl.model.robots import PANDA_LOCKED, panda_files

    urdf, srdf = panda_files()
    bare = RobotChecker(urdf, srdf, security_margin=0.0, locked=PANDA_LOCKED)
    rng = np.random.default_rng(5)
    Q = bare.lower + rng.random((400, bare.nq)) * (bare.upper - bare.lower)
    with_shelf, without = panda0.are_valid(Q), bare.are_valid(Q)
    assert not (with_shelf & ~without).any()  # obstacles only remove configurations
    assert (without & ~with_shelf).any()
    assert bare.model_hash != panda0.model_hash


@needs_panda
def test_locked_joints_leave_the_planned_joints_and_keep_their_geometry(panda0):
    assert panda0.nq == 7
    assert all(not n.startswith("panda_finger") for n in panda0.joint_names)
    assert "panda_leftfinger_0" in [go.name for go in panda0.gmodel.geometryObjects]


def test_a_prismatic_chain_gets_unit_lever_arm_and_its_travel_below(tmp_path):
    urdf = tmp_path / "slider.urdf"
    urdf.write_text("""<robot name="s"><link name="base"/><link name="carriage"/><link name="arm">
      <collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="rot" type="revolute"><parent link="base"/><child link="carriage"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="slide" type="prismatic"><parent link="carriage"/><child link="arm"/><origin xyz="0.1 0 0"/>
        <axis xyz="1 0 0"/><limit lower="-0.2" upper="0.4" effort="1" velocity="1"/></joint></robot>""")
    c = RobotChecker(urdf, obstacles=[box("wall", (0.1, 1, 1), (2.0, 0, 0))])
    np.testing.assert_allclose(c.lever_arms(), [0.1 + 0.4 + 0.3 + 0.05, 1.0])
    assert c.pruned_pairs == 1  # the wall is beyond the reach of the rotating subtree
    assert c.are_valid(np.array([[0.0, 0.4]])).all()


def test_pruning_two_out_of_reach_obstacles_keeps_the_one_in_reach(tmp_path):
    """The pairs to remove were read as views into Pinocchio's pair vector: each removal shifted them, so the
    second removal took the in-reach pair and the arm passed 12.5 cm into its obstacle as valid (a helper's probe)."""
    urdf = tmp_path / "arm1.urdf"
    urdf.write_text("""<robot name="arm1"><link name="world"/><link name="arm">
      <collision><origin xyz="0.4 0 0"/><geometry><box size="0.4 0.05 0.05"/></geometry></collision></link>
      <joint name="j" type="revolute"><parent link="world"/><child link="arm"/><axis xyz="0 0 1"/>
        <limit lower="-2" upper="2" effort="1" velocity="1"/></joint></robot>""")
    c = RobotChecker(urdf, obstacles=[box("far1", (0.2, 0.2, 0.2), (5.0, 0, 0)),
                                      box("far2", (0.2, 0.2, 0.2), (0, 5.0, 0)),
                                      box("near", (0.2, 0.2, 0.2), (0, 0.4, 0))])
    G = c.gmodel.geometryObjects
    assert c.pruned_pairs == 2
    assert [(G[p.first].name, G[p.second].name) for p in c.gmodel.collisionPairs] == [("arm_0", "near")]
    q = np.array([np.pi / 2])  # the arm along +y, through the near box
    assert not c.is_valid(q) and not c.are_valid(q[None]).any() and c.clearance(q) < 0


def test_bad_input_gives_one_line_errors(tmp_path):
    urdf = WearerArm().files.urdf
    with pytest.raises(FileNotFoundError, match="URDF file not found"):
        RobotChecker(tmp_path / "missing.urdf")
    with pytest.raises(ValueError, match="locked names unknown joint 'nope'"):
        RobotChecker(urdf, locked={"nope": 0.0})
    with pytest.raises(ValueError, match="shape must be one of"):
        Obstacle("o", "cone", (1.0,))
    with pytest.raises(ValueError, match="needs 3 finite sizes"):
        Obstacle("o", "box", (1.0, -1.0, 1.0))
    with pytest.raises(ValueError, match="proper rotation"):
        Obstacle("o", "sphere", (0.1,), np.diag([1.0, 1.0, -1.0, 1.0]))
    with pytest.raises(ValueError, match="obstacles must be Obstacle"):
        RobotChecker(urdf, obstacles=["box"])
    with pytest.raises(ValueError, match="already a geometry name"):
        RobotChecker(urdf, obstacles=[box("head_0", (0.1, 0.1, 0.1), (3, 0, 0))])
    with pytest.raises(ValueError, match="outside the joint limits"):
        RobotChecker(urdf, locked={"j1": 99.0})


@pytest.mark.parametrize("attribute", ['<sphere radius="nan"/>', '<sphere radius="1e999"/>', '<box size="0.1 x 0.1"/>'])
def test_a_urdf_number_that_is_not_finite_is_named_before_urdfdom_prints_its_own_errors(tmp_path, capfd, attribute):
    urdf = tmp_path / "bad.urdf"
    urdf.write_text(f"""<robot name="s"><link name="base"/><link name="arm">
      <collision><geometry>{attribute}</geometry></collision></link>
      <joint name="rot" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>""")
    with pytest.raises(ValueError, match=r"link 'arm': <(sphere|box) .*is not a list of finite numbers"):
        RobotChecker(urdf)
    assert capfd.readouterr().err == ""  # urdfdom's C++ errors (28 lines for one NaN) never come


def test_an_obstacle_beside_the_wearer_blocks_the_arm_there():
    plain = WearerArm()
    rng = np.random.default_rng(6)
    Q = plain.lower + rng.random((50, 4)) * (plain.upper - plain.lower)
    q = Q[plain.are_valid(Q)][0]
    p = plain.frame_placement(q, "muzzle").translation
    c = RobotChecker(plain.files.urdf, plain.files.srdf, obstacles=[Obstacle("ball", "sphere", (0.05,), p)])
    assert not c.is_valid(q)
    assert "ball" in c.closest_pair(q)[:2]


def _pair_distances(checker: RobotChecker, q: np.ndarray) -> np.ndarray:
    pin.computeDistances(checker.model, checker.data, checker.gmodel, checker.gdata, q)
    return np.array([r.min_distance for r in checker.gdata.distanceResults])


def _assert_pair_levers_bound_distance_changes(checker: RobotChecker, rng: np.random.Generator, n: int) -> None:
    R = checker.pair_lever_arms()
    assert R.shape == (len(checker.gmodel.collisionPairs), checker.nq) and (R >= 0).all()
    for _ in range(n):
        q = rng.uniform(checker.lower, checker.upper)
        q2 = np.clip(q + rng.normal(size=checker.nq) * rng.choice([0.01, 0.1, 0.5]), checker.lower, checker.upper)
        change = np.abs(_pair_distances(checker, q2) - _pair_distances(checker, q))
        assert (change <= R @ np.abs(q2 - q) + 1e-7).all()


def test_pair_lever_arms_bound_every_pair_distance_change_on_the_wearer(robot):
    _assert_pair_levers_bound_distance_changes(robot, np.random.default_rng(11), 400)


@needs_panda
def test_pair_lever_arms_bound_every_pair_distance_change_on_the_panda(panda0):
    _assert_pair_levers_bound_distance_changes(panda0, np.random.default_rng(12), 400)


def test_pair_lever_arms_count_only_joints_between_the_two_bodies(robot):
    R, gm = robot.pair_lever_arms(), robot.gmodel
    names = [(gm.geometryObjects[cp.first].name, gm.geometryObjects[cp.second].name) for cp in gm.collisionPairs]
    # the barrel (link4) against the boom (link2): only pan and tilt lie between them, and the boom's
    # vertical capsule is symmetric about the pan axis, so only tilt can change that distance
    p = names.index(("link2_1", "link4_0"))
    assert R[p, :3].tolist() == [0.0, 0.0, 0.0] and R[p, 3] > 0
    # a wearer part against the barrel: every arm joint counts, never more than the arm's lever arms
    p = names.index(("backpack_0", "link4_0"))
    assert (R[p] > 0).all() and (R[p] <= robot.lever_arms() + 1e-12).all()


def test_pair_margins_follow_link_margins_for_static_pairs_only(tmp_path):
    urdf = tmp_path / "two.urdf"
    urdf.write_text("""<robot name="t"><link name="base"/><link name="a">
      <collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
      <link name="b"><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.6 0 0"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>""")
    c = RobotChecker(urdf, obstacles=[box("wall", (0.1, 1, 1), (1.1, 0, 0))], link_margins={"b": 0.05})
    gm = c.gmodel
    margins = {tuple(sorted((gm.geometryObjects[cp.first].name, gm.geometryObjects[cp.second].name))): m
               for cp, m in zip(gm.collisionPairs, c.pair_margins())}
    assert margins[("b_0", "wall")] == pytest.approx(0.05)
    assert margins[("a_0", "b_0")] == pytest.approx(c.security_margin)


@pytest.mark.parametrize("pairs", [True, False], ids=["two-rows-at-a-time", "one-row-at-a-time"])
def test_first_invalid_stops_at_the_first_invalid_row_and_counts_only_the_rows_checked(robot, rng, pairs,
                                                                                       monkeypatch) -> None:
    monkeypatch.setattr(robot_checker, "FIRST_INVALID_PAIRS", pairs)
    good, bad = valid_and_colliding(robot, rng, 4)
    Q = np.vstack([good[:2], bad[:1], good[2:], bad[1:]])  # first invalid row: 2
    c0 = robot.collision_checks
    assert robot.first_invalid(Q) == 2
    # rows 0, 1, 2 (and row 3, checked with row 2 by the other thread); the rest never checked
    assert robot.collision_checks - c0 == (4 if pairs and robot.n_threads > 1 else 3)
    c0 = robot.collision_checks
    assert robot.first_invalid(good) == -1 and robot.collision_checks - c0 == len(good)
    outside = good.copy()
    outside[1, 0] = robot.upper[0] + 0.1  # out of limits: invalid without a collision check
    outside[3] = bad[0]
    c0 = robot.collision_checks
    assert robot.first_invalid(outside) == 1 and robot.collision_checks - c0 == 1
    for _ in range(20):  # the verdict of are_valid, row by row
        M = np.vstack([good, bad])[rng.permutation(2 * len(good))[:5]]
        ok = robot.are_valid(M)
        assert robot.first_invalid(M) == (-1 if ok.all() else int(ok.argmin()))


def test_first_invalid_two_rows_at_a_time_gives_the_row_of_one_row_at_a_time_and_at_most_one_check_more(
        rng, monkeypatch) -> None:
    two = WearerArm(n_threads=2)  # pairs need two threads, whatever the machine
    good, bad = valid_and_colliding(two, rng, 12)
    pool = np.vstack([good, bad])
    for n in [1, 2, 3, 4, 5, 8, 13, 24]:
        for _ in range(6):
            Q = pool[rng.choice(len(pool), n)]
            found, checks = [], []
            for pairs in (True, False):
                monkeypatch.setattr(robot_checker, "FIRST_INVALID_PAIRS", pairs)
                c0 = two.collision_checks
                found.append(two.first_invalid(Q))
                checks.append(two.collision_checks - c0)
            assert found[0] == found[1]
            assert checks[1] <= checks[0] <= checks[1] + 1


def test_first_invalid_of_an_empty_batch_finds_none_and_checks_nothing(robot) -> None:
    c0 = robot.collision_checks
    assert robot.first_invalid(np.zeros((0, robot.nq))) == -1
    assert robot.collision_checks == c0


def _slow_parallel_calls(monkeypatch, delay: float) -> list[int]:
    """Make Pinocchio's calls on several threads take ``delay`` s longer (a core held by another process); the
    threads of every call are recorded."""
    real = pin.computeCollisionsInParallel
    threads: list[int] = []

    def slow(n, *args):
        threads.append(n)
        if n > 1:
            time.sleep(delay)
        return real(n, *args)

    monkeypatch.setattr(pin, "computeCollisionsInParallel", slow)
    return threads


def _stall_at(monkeypatch, seconds: float) -> None:
    """A call counts as stalled above ``seconds`` (far above this machine's own hiccups, even under a loaded CI)."""
    monkeypatch.setattr(stall_guard, "STALL_SECONDS", (seconds, 0.0))


def test_a_checker_whose_threaded_calls_stall_goes_on_one_thread_for_a_while_with_the_same_answers(robot, rng,
                                                                                                     monkeypatch):
    _stall_at(monkeypatch, 0.05)
    monkeypatch.setattr(stall_guard, "SERIAL_SECONDS", 0.5)
    monkeypatch.setattr(stall_guard, "STALL_WINDOW", 0.5)
    good, bad = valid_and_colliding(robot, rng, 10)  # the answers from another checker of the model: `two`'s
    Q = np.vstack([good, bad])                        # only calls are the slowed ones below
    want, first = robot.are_valid(Q), robot.first_invalid(np.vstack([good, bad[:1]]))
    two = WearerArm(n_threads=2)
    threads = _slow_parallel_calls(monkeypatch, 0.1)
    assert (two.are_valid(Q) == want).all() and two.stalls == 0  # one slow call: the machine's noise
    assert (two.are_valid(Q) == want).all() and two.stalls == 1  # a second one soon after: one thread now
    c0, before = two.collision_checks, len(threads)
    assert two.first_invalid(np.vstack([good, bad[:1]])) == first
    assert two.collision_checks - c0 == len(good) + 1 and set(threads[before:]) == {1}  # one call, stopped there
    time.sleep(0.5)
    assert (two.are_valid(Q) == want).all() and threads[-1] == 2  # the spell is over: its threads again


def test_first_invalid_finishes_on_one_thread_once_its_pairs_stall(robot, rng, monkeypatch):
    _stall_at(monkeypatch, 0.05)
    monkeypatch.setattr(stall_guard, "STALL_WINDOW", 0.5)
    good, bad = valid_and_colliding(robot, rng, 12)
    Q = np.vstack([good, bad[:1], good])  # first invalid row: 12
    two = WearerArm(n_threads=2)
    threads = _slow_parallel_calls(monkeypatch, 0.1)
    c0 = two.collision_checks
    assert two.first_invalid(Q) == len(good)
    # two pairs on two threads (the second stalls within the window of the first), the rest on one thread up to row 12
    assert threads == [2, 2, 1] and two.stalls == 1
    assert two.collision_checks - c0 == len(good) + 1


def _two_joint_urdf(path, j2: str, b_collision: bool = True, a_collision: bool = True):
    """A base with two arms: j1 revolute, j2 as given (its <joint> attributes and children after the parent/child)."""
    sphere = '<collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>'
    path.write_text(f"""<robot name="t"><link name="base"/><link name="a">{sphere if a_collision else ""}</link>
      <link name="b">{sphere if b_collision else ""}</link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="j2" {j2}</joint></robot>""")
    return path


_J2 = '<parent link="base"/><child link="b"/><origin xyz="0 0 -0.5"/><axis xyz="0 0 1"/>'


def test_joints_it_cannot_plan_are_refused_with_what_to_do_and_locking_them_works(tmp_path):
    limits = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    mimic = _two_joint_urdf(tmp_path / "mimic.urdf", f'type="revolute">{_J2}{limits}<mimic joint="j1" multiplier="-1"/>')
    with pytest.raises(ValueError, match="joint 'j2' mimics 'j1'.*lock 'j1' and the joints that mimic it"):
        RobotChecker(mimic)  # it used to be planned on its own
    # the mimic locked alone (the advice this error used to give) leaves its master planned: the two would part
    with pytest.raises(ValueError, match="joint 'j1' is planned while 'j2', which mimics it, is locked"):
        RobotChecker(mimic, locked={"j2": 0.0})
    with pytest.raises(ValueError, match="no joint left to plan"):  # both locked: the mimics pass (nothing else here)
        RobotChecker(mimic, locked={"j1": 0.5, "j2": -0.5})
    continuous = _two_joint_urdf(tmp_path / "continuous.urdf", f'type="continuous">{_J2}')
    assert RobotChecker(continuous, locked={"j2": 7.0}).nq == 1  # a locked continuous joint takes any angle
    floating = _two_joint_urdf(tmp_path / "floating.urdf", 'type="floating"><parent link="base"/><child link="b"/>')
    with pytest.raises(ValueError, match="'j2' .*7 position values.*fixed joint"):
        RobotChecker(floating)
    with pytest.raises(ValueError, match="7 position values; only 1-DOF and continuous joints can be locked"):
        RobotChecker(floating, locked={"j2": 0.0})


def test_a_robot_with_nothing_to_check_or_plan_is_refused_naming_the_file(tmp_path):
    limits = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    bare = _two_joint_urdf(tmp_path / "bare.urdf", f'type="revolute">{_J2}{limits}', b_collision=False, a_collision=False)
    with pytest.raises(ValueError, match="bare.urdf: no <collision> geometry moves"):  # was a ZeroDivisionError later
        RobotChecker(bare)
    fixed = _two_joint_urdf(tmp_path / "fixed.urdf", f'type="revolute">{_J2}{limits}')
    with pytest.raises(ValueError, match="fixed.urdf: no joint left to plan"):
        RobotChecker(fixed, locked={"j1": 0.0, "j2": 0.0})


def _one_joint_urdf(tmp_path, joint: str = 'type="revolute"', axis: str = "0 0 1", limits: str = 'lower="-1" upper="1"'):
    urdf = tmp_path / "one.urdf"
    urdf.write_text(f"""<robot name="s"><link name="base"/><link name="arm">
      <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="j" {joint}><parent link="base"/><child link="arm"/><axis xyz="{axis}"/>
        <limit {limits} effort="1" velocity="1"/></joint></robot>""")
    return urdf


@pytest.mark.parametrize("kw, match", [
    ({"axis": "0 0 0"}, "zero axis"),  # Pinocchio would scale the child instead of turning it
    ({"joint": 'type="prismatic"', "axis": "0 0 0"}, "zero axis"),
    ({"limits": 'lower="-1e10" upper="1e10"'}, "beyond"),  # a sampled motion was densified into 311 GiB
])
def test_a_urdf_joint_that_cannot_be_checked_state_by_state_is_refused_naming_it(tmp_path, kw, match):
    with pytest.raises(ValueError, match=f"joint 'j'.*{match}"):
        RobotChecker(_one_joint_urdf(tmp_path, **kw))


@pytest.mark.parametrize("size, shape, match", [((1e6, 1e6, 1e6), "box", "sizes must lie in"),
                                                ((1e-9,), "sphere", "sizes must lie in"),
                                                (["box"], ["box"], "shape must be one of")])
def test_obstacles_beyond_what_coal_answers_accurately_are_refused(size, shape, match):
    with pytest.raises(ValueError, match=match):
        Obstacle("o", shape, size)


def test_lookups_by_an_unknown_name_are_value_errors_naming_it(robot):
    q = 0.5 * (robot.lower + robot.upper)
    with pytest.raises(ValueError, match="unknown joint 'nope'"):
        robot.joint_placement(q, "nope")
    with pytest.raises(ValueError, match="unknown joint 'nope'"):
        robot.geometry_names("nope")
    with pytest.raises(ValueError, match="unknown frame 3"):
        robot.frame_placement(q, 3)
    with pytest.raises(ValueError, match="package_dirs"):
        RobotChecker(robot.files.urdf, package_dirs=3)
    with pytest.raises(ValueError, match="displacement"):
        robot.max_joint_step("x")


def test_check_free_returns_a_free_configuration_and_names_one_out_of_limits_or_colliding(robot, rng) -> None:
    free, colliding = valid_and_colliding(robot, rng, 1)
    np.testing.assert_array_equal(robot.check_free(list(free[0]), "start"), free[0])
    with pytest.raises(ValueError, match=r"^goal \[.*\] is in collision \(.+ vs .+, distance -?\d"):
        robot.check_free(colliding[0], "goal")
    with pytest.raises(ValueError, match=r"^start \[.*\] is outside the joint limits: \w+ = [-\d.]+ is outside \["):
        robot.check_free(robot.upper + 0.1, "start")
    with pytest.raises(ValueError, match=r"^initial configuration: configuration contains NaN"):
        robot.check_free(np.full(robot.nq, np.nan), "initial configuration")


def test_a_package_mesh_not_found_names_package_dirs(tmp_path):
    urdf = tmp_path / "m.urdf"
    urdf.write_text("""<robot name="m"><link name="base"/><link name="a"><collision><geometry>
      <mesh filename="package://nowhere/meshes/a.stl"/></geometry></collision></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>""")
    with pytest.raises(ValueError, match=r"could not be found.*package_dirs.*given: none"):
        RobotChecker(urdf)


def test_a_collision_between_neighbouring_links_points_to_the_srdf(tmp_path):
    ball = '<collision><geometry><sphere radius="0.1"/></geometry></collision>'
    urdf = tmp_path / "touching.urdf"
    urdf.write_text(f"""<robot name="t"><link name="base"/><link name="a">{ball}</link><link name="b">{ball}</link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0 0.05"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>""")
    with pytest.raises(ValueError, match=r"^start .* is in collision \(.* neighbouring links: .* SRDF\)"):
        RobotChecker(urdf).check_free(np.zeros(2), "start")
    srdf = tmp_path / "touching.srdf"  # the neighbours' pair disabled: what is left is the table
    srdf.write_text('<robot name="t"><disable_collisions link1="a" link2="b" reason="Adjacent"/></robot>')
    table = Obstacle("table", "box", (1.0, 1.0, 0.1), (0.0, 0.0, 0.0))  # an obstacle is nobody's neighbour
    with pytest.raises(ValueError, match=r"is in collision \(\S+ vs \S+, distance -?[\d.]+ m\)$"):
        RobotChecker(urdf, srdf, obstacles=[table]).check_free(np.zeros(2), "start")


def test_an_srdf_of_a_larger_robot_is_refused_unless_its_other_links_are_skipped(tmp_path):
    limits = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    urdf = _two_joint_urdf(tmp_path / "arm.urdf", f'type="revolute">{_J2}{limits}')
    srdf = tmp_path / "humanoid.srdf"  # one pair of this arm's links, two naming links of the rest of the robot
    srdf.write_text('<robot name="h"><disable_collisions link1="a" link2="b" reason="Never"/>'
                    '<disable_collisions link1="a" link2="head"/><disable_collisions link1="leg" link2="b"/></robot>')
    with pytest.raises(ValueError, match=r"unknown link 'head' \(2 of its 3 .*srdf_unknown_links='skip'"):
        RobotChecker(urdf, srdf)
    every = len(RobotChecker(urdf).gmodel.collisionPairs)
    robot = RobotChecker(urdf, srdf, srdf_unknown_links="skip")
    assert len(robot.gmodel.collisionPairs) == every - 1  # the arm's own pair is disabled
    with pytest.raises(ValueError, match="srdf_unknown_links must be 'error' or 'skip', got 'ignore'"):
        RobotChecker(urdf, srdf_unknown_links="ignore")


def _l_shaped_stl(path) -> None:
    """An ASCII STL of an L-shaped prism (0.4 x 0.4 x 0.1 m, the square [0.1, 0.4]^2 cut out of its corner)."""
    outline = [(0, 0), (0.4, 0), (0.4, 0.1), (0.1, 0.1), (0.1, 0.4), (0, 0.4)]
    tris = [((0, 0), (0.4, 0), (0.4, 0.1)), ((0, 0), (0.4, 0.1), (0.1, 0.1)), ((0, 0), (0.1, 0.1), (0.1, 0.4)),
            ((0, 0), (0.1, 0.4), (0, 0.4))]
    facets = [[(x, y, z) for x, y in t] for t in tris for z in (0.0, 0.1)]
    for k in range(len(outline)):  # the side walls
        (x0, y0), (x1, y1) = outline[k], outline[(k + 1) % len(outline)]
        facets += [[(x0, y0, 0), (x1, y1, 0), (x1, y1, 0.1)], [(x0, y0, 0), (x1, y1, 0.1), (x0, y0, 0.1)]]
    body = "".join("facet normal 0 0 0\n outer loop\n" + "".join(f"  vertex {x} {y} {z}\n" for x, y, z in f)
                   + " endloop\nendfacet\n" for f in facets)
    path.write_text(f"solid l\n{body}endsolid l\n")


def test_convex_meshes_check_a_mesh_as_its_hull_which_covers_its_notch(tmp_path):
    _l_shaped_stl(tmp_path / "l.stl")
    urdf = tmp_path / "l.urdf"
    urdf.write_text(f"""<robot name="l"><link name="base"/><link name="a"><collision><geometry>
      <mesh filename="{tmp_path / 'l.stl'}"/></geometry></collision></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
        <limit lower="-0.1" upper="0.1" effort="1" velocity="1"/></joint></robot>""")
    notch = [Obstacle("ball", "sphere", (0.02,), (0.2, 0.2, 0.05))]  # in the L's cut-out corner, inside its hull
    detailed = RobotChecker(urdf, obstacles=notch, security_margin=0.0)
    hull = RobotChecker(urdf, obstacles=notch, security_margin=0.0, convex_meshes=True)
    assert isinstance(hull.gmodel.geometryObjects[0].geometry, coal.ConvexBase)
    assert detailed.is_valid(np.zeros(1)) and not hull.is_valid(np.zeros(1))
    assert hull.model_hash != detailed.model_hash  # libraries and query sets made with one are not the other's


def test_convex_meshes_keep_a_flat_mesh_and_leave_a_robot_without_meshes_as_it_was(tmp_path, robot):
    (tmp_path / "flat.stl").write_text("solid f\n" + "".join(
        "facet normal 0 0 1\n outer loop\n" + "".join(f"  vertex {x} {y} 0\n" for x, y in t) + " endloop\nendfacet\n"
        for t in (((0, 0), (0.2, 0), (0.2, 0.2)), ((0, 0), (0.2, 0.2), (0, 0.2)))) + "endsolid f\n")
    urdf = tmp_path / "flat.urdf"
    urdf.write_text(f"""<robot name="f"><link name="base"/><link name="a"><collision><geometry>
      <mesh filename="{tmp_path / 'flat.stl'}"/></geometry></collision></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
        <limit lower="-0.1" upper="0.1" effort="1" velocity="1"/></joint></robot>""")
    flat = RobotChecker(urdf, convex_meshes=True)  # Coal's hull crashed the process on four coplanar points
    assert isinstance(flat.gmodel.geometryObjects[0].geometry, coal.BVHModelBase)
    assert flat.model_hash == RobotChecker(urdf).model_hash  # nothing was converted
    wearer = WearerArm()
    assert RobotChecker(wearer.files.urdf, wearer.files.srdf, convex_meshes=True).model_hash == \
        RobotChecker(wearer.files.urdf, wearer.files.srdf).model_hash


def test_more_threads_than_cores_are_warned_about(monkeypatch, caplog):
    """n_threads up to 1024 was taken without a word: on a mesh robot 1000 threads held 3.2 GB (a helper's probe)."""
    import tpee_ompl.model.robot_checker as robot_checker

    monkeypatch.setattr(robot_checker.os, "cpu_count", lambda: 1)
    with caplog.at_level("WARNING"):
        WearerArm(n_threads=2)
    assert "n_threads=2 on a machine with 1 core(s)" in caplog.text
