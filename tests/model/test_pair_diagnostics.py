"""The load-time warning about collision pairs within their margin in every configuration
(:mod:`tpee_ompl.model.pair_diagnostics`)."""

from __future__ import annotations

import logging

import pytest

from tpee_ompl.model.obstacles import box
from tpee_ompl.model.pair_diagnostics import always_colliding_pairs
from tpee_ompl.model.robot_checker import RobotChecker

LOGGER = "tpee_ompl.model.pair_diagnostics"

STUCK = """<robot name="t"><link name="base"/>
<link name="a"><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
<link name="b"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0.11"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""
"""b's sphere spins on j2's axis 0.11 m above a's: the two are 1 cm apart whatever the joints do (within 2 cm)."""

SOMETIMES = (STUCK.replace('<link name="b"><collision><geometry>',
                           '<link name="b"><collision><origin xyz="-0.25 0 -0.11"/><geometry>')
             .replace('<origin xyz="0.3 0 0.11"/>', '<origin xyz="0.55 0 0.11"/>'))
"""b's sphere swings 0.25 m from j2's axis, through a's sphere at j2 = 0 only (0.24 m from it at j2 = +/-1)."""


@pytest.fixture
def files(tmp_path):
    """``files(urdf_text, srdf_entries=None)``: the URDF (and an SRDF of those entries) written in tmp_path."""

    def write(text: str, entries: str | None = None):
        urdf = tmp_path / "t.urdf"
        urdf.write_text(text)
        if entries is None:
            return urdf, None
        srdf = tmp_path / "t.srdf"
        srdf.write_text(f'<robot name="t">{entries}</robot>')
        return urdf, srdf

    return write


def _warnings(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.name == LOGGER and r.levelno == logging.WARNING]


def test_a_pair_within_its_margin_in_every_configuration_is_named_once_with_its_fix(files, caplog):
    """A robot whose two links sit 1 cm apart, inside the 2 cm margin, in every configuration loaded without a word
    (example-robot-data's UR5 with its own SRDF: wrist_2_link / ee_link 1.98 cm apart); every state was invalid and a
    planner found nothing."""
    urdf, _ = files(STUCK)
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        robot = RobotChecker(urdf, n_threads=1)
    [message] = _warnings(caplog)
    assert "a / b (1.00 cm apart in the mid-range configuration, margin 2 cm)" in message
    assert "in every one of the 49 configurations sampled" in message and "every state will be invalid" in message
    assert '<disable_collisions link1="a" link2="b" reason="Always"/>' in message
    assert "or give a smaller security_margin" in message
    assert not robot.are_valid(robot.lower[None])[0]  # the warning is right


def test_the_check_changes_no_answer_pair_or_counter(files):
    """The diagnostic uses its own Pinocchio data: the pairs stay, and no collision check is counted."""
    urdf, _ = files(STUCK)
    robot = RobotChecker(urdf, n_threads=1)
    assert robot.collision_checks == 0 and len(robot.gmodel.collisionPairs) == 1
    assert always_colliding_pairs(robot) == [0] and robot.collision_checks == 0


@pytest.mark.parametrize("entries, margin", [
    ('<disable_collisions link1="a" link2="b" reason="Always"/>', 0.02),  # the fix the warning gives
    (None, 0.005),  # a margin below their distance
])
def test_no_warning_once_the_pair_is_disabled_or_the_margin_smaller(files, caplog, entries, margin):
    urdf, srdf = files(STUCK, entries)
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        robot = RobotChecker(urdf, srdf, security_margin=margin, n_threads=1)
    assert _warnings(caplog) == [] and robot.are_valid(robot.lower[None])[0]


def test_a_pair_colliding_in_some_configurations_only_is_not_named(files, caplog):
    """In collision at the mid-range configuration (j2 = 0), free elsewhere: no warning."""
    urdf, _ = files(SOMETIMES)
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        robot = RobotChecker(urdf, n_threads=1)
    assert not robot.is_valid([0.0, 0.0]) and robot.is_valid([0.0, 1.0])
    assert _warnings(caplog) == [] and always_colliding_pairs(robot) == []


def test_an_obstacle_over_a_link_in_every_configuration_is_named(files, caplog):
    """b's sphere spins in place above the base when j1 is fixed: an obstacle around it collides always."""
    urdf, _ = files(STUCK, '<disable_collisions link1="a" link2="b" reason="Always"/>')
    srdf = urdf.with_suffix(".srdf")
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        RobotChecker(urdf, srdf, locked={"j1": 0.0}, n_threads=1,
                     obstacles=[box("lid", (0.2, 0.2, 0.02), (0.3, 0, 0.61))])
    [message] = _warnings(caplog)
    assert "1 collision pair is within" in message and "b / obstacle 'lid' (overlapping" in message
    assert "move or shrink the obstacles named" in message and "disable_collisions" not in message


def test_the_projects_robots_load_without_the_warning(caplog):
    from tpee_ompl.model.wearer_arm import WearerArm

    with caplog.at_level(logging.WARNING, logger=LOGGER):
        WearerArm()
    pytest.importorskip("example_robot_data")
    from tpee_ompl.model import robots

    with caplog.at_level(logging.WARNING, logger=LOGGER):
        robots.panda_shelf(n_threads=1)
        robots.kinova_posts(n_threads=1)
    assert _warnings(caplog) == []
