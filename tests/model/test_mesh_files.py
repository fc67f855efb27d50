"""Mesh files of a URDF: where relative paths are found, and what of them the model hash covers
(:mod:`tpee_ompl.model.mesh_files`)."""

from __future__ import annotations

import pytest

from tpee_ompl.model.robot_checker import RobotChecker

MESH_ARM = """<robot name="m"><link name="base"/>
<link name="arm"><collision><origin xyz="0.5 0 0"/><geometry><mesh filename="{mesh}"/></geometry></collision></link>
<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""


def test_a_relative_mesh_path_is_found_in_the_urdfs_folder(tmp_path, write_cube_stl, monkeypatch):
    """<mesh filename="meshes/x.stl"/> was looked up only in package_dirs: "Mesh meshes/x.stl could not be found"."""
    write_cube_stl(tmp_path / "robot/meshes/x.stl", 0.1)
    urdf = tmp_path / "robot/arm.urdf"
    urdf.write_text(MESH_ARM.format(mesh="meshes/x.stl"))
    monkeypatch.chdir(tmp_path)  # not the URDF's folder
    robot = RobotChecker(urdf)
    assert robot.gmodel.geometryObjects[0].meshPath == str(tmp_path / "robot/meshes/x.stl")
    assert robot.gmodel.ngeoms == 1 and robot.is_valid([0.0])


def test_a_relative_mesh_found_nowhere_says_where_it_was_looked_for(tmp_path):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(MESH_ARM.format(mesh="meshes/nowhere.stl"))
    with pytest.raises(ValueError, match=f"Mesh meshes/nowhere.stl could not be found. \\(a relative mesh path is "
                                         f"looked up in the URDF's folder {tmp_path}, then in package_dirs; given: "
                                         "none\\)"):
        RobotChecker(urdf)
