"""The SRDF's collision entries applied to the pairs (:mod:`tpee_ompl.model.srdf_pairs`)."""

from __future__ import annotations

import logging

import pytest

from tpee_ompl.model.robot_checker import RobotChecker

ARM = """<robot name="t"><link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
<link name="a"><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
<link name="b"><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0.2"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""


@pytest.fixture
def arm(tmp_path):
    """``arm(srdf_body)``: the URDF and an SRDF of those entries."""
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(ARM)

    def write(entries: str):
        srdf = tmp_path / "arm.srdf"
        srdf.write_text(f'<robot name="t">{entries}</robot>')
        return urdf, srdf

    return write


def _link_pairs(robot: RobotChecker) -> set[frozenset[str]]:
    g, frames = robot.gmodel.geometryObjects, robot.model.frames
    return {frozenset((frames[g[c.first].parentFrame].name, frames[g[c.second].parentFrame].name))
            for c in robot.gmodel.collisionPairs}


def test_an_srdf_entry_naming_a_joint_instead_of_a_link_is_refused_naming_the_entry(arm, caplog):
    """<disable_collisions link1="j1" link2="b"/> passed without a word and disabled nothing (MoveIt warns "Link 'j1'
    is not known to URDF" and ignores the entry: the pair stays checked)."""
    urdf, srdf = arm('<disable_collisions link1="j1" link2="b" reason="Adjacent"/>')
    with pytest.raises(ValueError, match=f"SRDF {srdf}: <disable_collisions link1=\"j1\" link2=\"b\"> names joint "
                                         "'j1', not a link \\(its child link is 'a'\\)"):
        RobotChecker(urdf, srdf)
    with caplog.at_level(logging.WARNING):  # an SRDF of a larger robot: passed over, but said once
        robot = RobotChecker(urdf, srdf, srdf_unknown_links="skip")
    assert "names joint 'j1', not a link" in caplog.text and frozenset(("a", "b")) in _link_pairs(robot)


def test_moveits_disable_default_collisions_disables_a_links_pairs_but_those_enabled_again(arm):
    """<disable_default_collisions link="b"/> was ignored without a word: every pair of b stayed checked.  As in
    MoveIt's allowed collision matrix, b's default covers the obstacles too, <enable_collisions> re-enables a pair,
    and <disable_collisions> wins over <enable_collisions>."""
    from tpee_ompl.model.obstacles import box

    post = box("post", (0.1, 0.1, 0.1), (0.4, 0.0, 0.75))
    urdf, srdf = arm('<disable_default_collisions link="b"/><enable_collisions link1="base" link2="b"/>')
    every = _link_pairs(RobotChecker(urdf, obstacles=[post]))
    assert {frozenset(p) for p in (("a", "b"), ("b", "universe"), ("b", "base"))} <= every
    robot = RobotChecker(urdf, srdf, obstacles=[post])
    assert _link_pairs(robot) == every - {frozenset(("a", "b")), frozenset(("b", "universe"))}
    urdf, srdf = arm('<disable_default_collisions link="b"/><enable_collisions link1="base" link2="b"/>'
                     '<disable_collisions link1="b" link2="base"/>')
    assert _link_pairs(RobotChecker(urdf, srdf, obstacles=[post])) == every - {
        frozenset(p) for p in (("a", "b"), ("b", "universe"), ("b", "base"))}


@pytest.mark.parametrize("entries, match", [
    ('<disable_default_collisions link="j2"/>', "<disable_default_collisions link=\"j2\"> names joint 'j2'"),
    ('<disable_default_collisions link="c"/>', "unknown link 'c'"),
    ('<enable_collisions link1="a" link2="c"/>', "unknown link 'c'"),
    ('<disable_default_collisions/>', "<disable_default_collisions> has no link"),
    ('<disable_collisions link1="a"/>', "<disable_collisions link1=\"a\"> has no link2"),
])
def test_every_srdf_collision_entry_names_links_of_the_urdf(arm, entries, match):
    urdf, srdf = arm(entries)
    with pytest.raises(ValueError, match=f"SRDF {srdf}.*{match}"):
        RobotChecker(urdf, srdf)


def test_the_clearance_of_a_robot_with_no_pair_left_to_check_is_infinite(arm):
    """A robot whose every pair is disabled raised IndexError from Pinocchio's empty distance results."""
    urdf, srdf = arm('<disable_default_collisions link="a"/><disable_default_collisions link="b"/>')
    robot = RobotChecker(urdf, srdf)
    assert len(robot.gmodel.collisionPairs) == 0 and robot.is_valid([0.0, 0.0])
    assert robot.clearance([0.0, 0.0]) == float("inf") == robot.clearance([0.0, 0.0], from_margins=True)


def test_closest_pair_of_a_robot_with_no_pair_left_to_check_says_so(arm):
    """It raised IndexError from Pinocchio's empty pair list."""
    urdf, srdf = arm('<disable_default_collisions link="a"/><disable_default_collisions link="b"/>')
    with pytest.raises(ValueError, match="closest_pair: no collision pair is checked"):
        RobotChecker(urdf, srdf).closest_pair([0.0, 0.0])
