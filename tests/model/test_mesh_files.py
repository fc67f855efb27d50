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


def test_the_model_hash_covers_the_mesh_files_bytes_not_where_they_are(tmp_path, write_cube_stl):
    """Two checkers of one URDF on different meshes (package_dirs naming two copies of a package) shared a model hash,
    which the benchmark and the path libraries use to tell models apart."""
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(MESH_ARM.format(mesh="package://parts/meshes/x.stl"))
    small, large, same = (write_cube_stl(tmp_path / f"{d}/parts/meshes/x.stl", side)
                          for d, side in (("small", 0.1), ("large", 0.3), ("moved", 0.1)))
    hashes = [RobotChecker(urdf, package_dirs=[p.parents[2]]).model_hash for p in (small, large, same)]
    assert hashes[0] != hashes[1] and hashes[0] == hashes[2]
    relative = tmp_path / "small/arm.urdf"  # a relative path: its file's bytes too
    relative.write_text(MESH_ARM.format(mesh="parts/meshes/x.stl"))
    before = RobotChecker(relative).model_hash
    write_cube_stl(small, 0.2)
    assert RobotChecker(relative).model_hash != before
