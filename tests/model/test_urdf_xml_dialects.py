"""URDFs and SRDFs that urdfdom reads are read here too (:mod:`tpee_ompl.model.urdf_xml`): each case is first loaded
with Pinocchio's own path readers (urdfdom), which must load every collision element without a line on stderr."""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin
import pytest

from tpee_ompl.model.robot_checker import RobotChecker

LINK_A = '<link name="a"><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>'
JOINT = ('<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0 0 0.1" rpy="0 0 0"/>'
         '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
ONE_JOINT = f'<robot name="t">\n<link name="base"/>\n{LINK_A}\n{JOINT}\n</robot>\n'
"""One revolute joint turning a sphere 0.3 m from its axis."""


def _write(path: Path, text: str | bytes) -> Path:
    path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
    return path


def _urdfdom_loads(urdf: Path, capfd) -> int:
    """The number of collision geometries urdfdom (Pinocchio's path readers) loads from the file, after asserting
    that it printed nothing on stderr (no C++ error, no dropped element)."""
    capfd.readouterr()
    model = pin.buildModelFromUrdf(str(urdf))
    n = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION).ngeoms
    assert capfd.readouterr().err == ""
    return n


def _loads_as_urdfdom_reads_it(urdf: Path, capfd, srdf: Path | None = None) -> RobotChecker:
    """RobotChecker loads the URDF with the geometries urdfdom loads, printing nothing."""
    n = _urdfdom_loads(urdf, capfd)
    robot = RobotChecker(urdf, srdf, n_threads=1)
    assert robot.gmodel.ngeoms == n and capfd.readouterr().err == ""
    return robot


@pytest.mark.parametrize("old, new", [
    ('<robot name="t">', '<robot name="t" xmlns="http://drake.mit.edu">'),
    ('<robot name="t">', '<robot name="t" xmlns="http://www.ros.org" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'
                         ' xsi:schemaLocation="http://www.ros.org urdf.xsd">'),
    ("</robot>", '<gazebo reference="a"><sensor:camera name="c"><sensor:fov>1</sensor:fov></sensor:camera></gazebo></robot>'),
    ('<robot name="t">', '<robot name="t" xacro:foo="1">'),
], ids=["drake-default-namespace", "urdf-xsd-namespace", "undeclared-element-prefix", "undeclared-attribute-prefix"])
def test_a_urdf_with_a_default_namespace_or_an_undeclared_prefix_loads(tmp_path, capfd, old, new):
    """Drake's ``<robot xmlns="http://drake.mit.edu">`` was refused ("root element is <{http://drake.mit.edu}robot>"),
    and so was a prefix no ``xmlns:`` declares ("unbound prefix"): urdfdom's XML parser knows no namespaces and
    reads both."""
    urdf = _write(tmp_path / "ns.urdf", ONE_JOINT.replace(old, new, 1))
    assert _loads_as_urdfdom_reads_it(urdf, capfd).joint_names == ("j1",)


def test_an_srdf_with_a_default_namespace_or_an_undeclared_prefix_disables_its_pairs(tmp_path, capfd):
    """The SRDF goes through the same reader: a namespaced one was refused as malformed."""
    urdf = _write(tmp_path / "two.urdf", ONE_JOINT.replace(
        "</robot>", '<link name="b"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>'
                    '<joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0.2"/>'
                    '<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'))
    assert len(_loads_as_urdfdom_reads_it(urdf, capfd).gmodel.collisionPairs) == 1  # a-b
    for head in ('<robot name="t" xmlns="http://drake.mit.edu">', '<robot name="t"><srdf:note text="x"/>'):
        srdf = _write(tmp_path / "pairs.srdf", f'{head}<disable_collisions link1="a" link2="b" reason="x"/></robot>')
        assert len(RobotChecker(urdf, srdf, n_threads=1).gmodel.collisionPairs) == 0
