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
