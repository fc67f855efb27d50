"""URDF ``<mimic>`` joints: planned with the joint they follow or locked with it, consistently
(:mod:`tpee_ompl.model.mimic_joints`)."""

from __future__ import annotations

import pytest

from tests.helpers.panda import needs_panda
from tpee_ompl.model.robot_checker import RobotChecker

FINGERS = """<robot name="g"><link name="base"/>
<link name="palm"><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
<link name="f1"><collision><origin xyz="0.1 0 0"/><geometry><sphere radius="0.02"/></geometry></collision></link>
<link name="f2"><collision><origin xyz="0.1 0 0"/><geometry><sphere radius="0.02"/></geometry></collision></link>
<joint name="arm" type="revolute"><parent link="base"/><child link="palm"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="finger1" type="prismatic"><parent link="palm"/><child link="f1"/><origin xyz="0.4 0.05 0"/>
  <axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="1" velocity="1"/></joint>
<joint name="finger2" type="{kind}"><parent link="palm"/><child link="f2"/><origin xyz="0.4 -0.05 0"/>
  <axis xyz="0 1 0"/><limit lower="-0.04" upper="0.04" effort="1" velocity="1"/>
  <mimic joint="finger1" multiplier="-1" offset="0.01"/></joint></robot>"""


@pytest.fixture
def fingers(tmp_path):
    def write(kind: str = "prismatic"):
        path = tmp_path / f"fingers_{kind}.urdf"
        path.write_text(FINGERS.format(kind=kind))
        return path

    return write


def test_locked_values_that_break_a_mimic_relation_are_refused_naming_both_joints(fingers):
    """finger2 = -1 x finger1 + 0.01: locking finger1 at 0.02 and finger2 at 0.02 loaded a gripper it cannot take."""
    urdf = fingers()
    with pytest.raises(ValueError, match=r"locked\['finger2'\] = 0.02, but 'finger2' mimics 'finger1': "
                                         r"'finger2' = -1 x 'finger1' \+ 0.01 = -0.01 at locked\['finger1'\] = 0.02"):
        RobotChecker(urdf, locked={"finger1": 0.02, "finger2": 0.02})
    assert RobotChecker(urdf, locked={"finger1": 0.02, "finger2": -0.01}).joint_names == ("arm",)


def test_a_mimic_whose_master_is_locked_is_told_the_value_to_lock_it_at(fingers):
    with pytest.raises(ValueError, match=r"joint 'finger2' mimics 'finger1'.*locked=\{'finger1': v, "
                                         r"'finger2': -1 \* v \+ 0.01\}"):
        RobotChecker(fingers(), locked={"finger1": 0.02})


def test_a_mimic_on_a_fixed_joint_is_ignored_and_the_joint_stays_fixed(fingers):
    """As Pinocchio's own mimic support does; it was refused with advice to lock the fixed joint, which no one can
    (example-robot-data's Talos arm: its gripper's fingers are fixed joints that mimic the gripper joint)."""
    robot = RobotChecker(fingers("fixed"))
    assert robot.joint_names == ("arm", "finger1")


def test_a_mimic_of_a_joint_the_file_lacks_is_refused_with_advice_that_can_be_followed(tmp_path):
    path = tmp_path / "unknown.urdf"
    path.write_text(FINGERS.format(kind="prismatic").replace('mimic joint="finger1"', 'mimic joint="finger9"'))
    with pytest.raises(ValueError, match="joint 'finger2' mimics 'finger9', which is not a moving joint of the URDF: "
                                         r"lock 'finger2' \(locked=\{'finger2': value\}\) or remove its <mimic>"):
        RobotChecker(path)
    assert RobotChecker(path, locked={"finger2": 0.0}).nq == 2


@needs_panda
def test_the_talos_arm_loads_with_its_fixed_mimic_fingers():
    from pathlib import Path

    import example_robot_data

    robots = Path(example_robot_data.getModelPath("talos_data/robots/talos_left_arm.urdf"))
    robot = RobotChecker(robots / "talos_data/robots/talos_left_arm.urdf", package_dirs=[robots / "../.."])
    assert "gripper_left_joint" in robot.joint_names and "gripper_left_fingertip_1_joint" not in robot.joint_names
