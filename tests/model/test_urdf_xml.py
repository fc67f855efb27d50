"""A URDF or SRDF read as XML and checked before urdfdom reads it (:mod:`tpee_ompl.model.urdf_xml`)."""

from __future__ import annotations

import pytest

from tpee_ompl.model.robot_checker import RobotChecker

ONE_JOINT = """<robot name="t"><link name="base"/>
<link name="a"><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""


def test_a_folder_given_as_the_urdf_or_srdf_is_said_to_be_a_folder(tmp_path):
    """RobotChecker("/some/folder") said "URDF file not found", though the folder was there."""
    urdf = tmp_path / "one.urdf"
    urdf.write_text(ONE_JOINT)
    with pytest.raises(ValueError, match=f"URDF path {tmp_path} is a folder: a URDF file is expected"):
        RobotChecker(tmp_path)
    with pytest.raises(ValueError, match=f"SRDF path {tmp_path} is a folder: an SRDF file is expected"):
        RobotChecker(urdf, tmp_path)
    with pytest.raises(FileNotFoundError, match="URDF file not found"):  # a missing file still is one
        RobotChecker(tmp_path / "missing.urdf")
