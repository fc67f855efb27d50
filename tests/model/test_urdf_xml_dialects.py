"""URDFs and SRDFs that urdfdom reads are read here too (:mod:`tpee_ompl.model.urdf_xml`): each case is first loaded
with Pinocchio's own path readers (urdfdom), which must load every collision element without a line on stderr."""

from __future__ import annotations

from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest

from tpee_ompl.model.obstacles import Obstacle, box
from tpee_ompl.model.robot_checker import RobotChecker

LINK_A = ('<link name="a"><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>'
          '</link>')
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
    ('<robot name="t">', '<robot name="t" xmlns="http://www.ros.org" '
                         'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" '
                         'xsi:schemaLocation="http://www.ros.org urdf.xsd">'),
    ("</robot>", '<gazebo reference="a"><sensor:camera name="c"><sensor:fov>1</sensor:fov></sensor:camera></gazebo>'
                 '</robot>'),
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


LATIN1_COMMENT = "<!-- Author: J\u00fcrgen M\u00fcller -->\n"


def test_a_latin1_urdf_loads_in_its_declared_encoding(tmp_path, capfd, caplog):
    """A Latin-1 comment (``encoding="ISO-8859-1"`` declared) was refused as "not UTF-8 text"; urdfdom reads the
    bytes as they are.  A name in Latin-1 is read as the letters it is."""
    head = '<?xml version="1.0" encoding="ISO-8859-1"?>\n'
    urdf = _write(tmp_path / "latin1.urdf", (head + LATIN1_COMMENT + ONE_JOINT).encode("latin-1"))
    with caplog.at_level("WARNING"):
        _loads_as_urdfdom_reads_it(urdf, capfd)
    assert "Latin-1" not in caplog.text  # its encoding is declared: nothing to say
    named = _write(tmp_path / "named.urdf", (head + ONE_JOINT.replace('"a"', '"\u00e4rm"')).encode("latin-1"))
    assert RobotChecker(named, n_threads=1).model.existFrame("\u00e4rm")


def test_a_urdf_neither_utf8_nor_declared_loads_as_latin1_with_one_warning(tmp_path, capfd, caplog):
    """Without an XML declaration a Latin-1 comment was refused too; it is read as Latin-1, said once per file
    (the file is read twice per load)."""
    urdf = _write(tmp_path / "undeclared.urdf", (LATIN1_COMMENT + ONE_JOINT).encode("latin-1"))
    with caplog.at_level("WARNING"):
        _loads_as_urdfdom_reads_it(urdf, capfd)
        RobotChecker(urdf, n_threads=1)
    assert caplog.text.count("is not UTF-8 and declares no encoding: read as Latin-1") == 1


def test_a_utf16_urdf_is_refused_naming_its_encoding(tmp_path):
    """urdfdom cannot read UTF-16 (it refuses the file, printing tinyxml2's error); the message says why."""
    urdf = _write(tmp_path / "utf16.urdf", ('<?xml version="1.0" encoding="UTF-16"?>\n' + ONE_JOINT).encode("utf-16"))
    with pytest.raises(ValueError, match=f"malformed URDF {urdf}: UTF-16 .*save it as UTF-8"):
        RobotChecker(urdf)


def test_the_packaged_models_keep_their_hash():
    """Reading other encodings changed nothing for UTF-8 files: the wearer's and the Panda's query sets still match."""
    from tpee_ompl.model.wearer_arm import WearerArm

    assert WearerArm().model_hash == "146e69c3f10a0aac"
    pytest.importorskip("example_robot_data")
    from tpee_ompl.model.robots import panda_shelf

    assert panda_shelf(n_threads=1).model_hash == "98dc15b6aa845caa"


def _urdfdom_accepts(urdf: Path, capfd) -> bool:
    """Whether urdfdom (Pinocchio's path reader) builds a model from the file (it may print while refusing)."""
    try:
        pin.buildModelFromUrdf(str(urdf))
        return True
    except (RuntimeError, ValueError):
        return False
    finally:
        capfd.readouterr()


@pytest.mark.parametrize("version", [" 1.0", "1.00", "01.0", "1.01", "+1.2", "1.-0", "1. 1",  # read
                                     "1.0 ", "1", "1.0.0", "1.3", "0.9", "1.", ".1", "1.1e0", "2.0", "1.-1"])  # refused
def test_a_urdf_version_is_read_as_urdfdom_reads_it(tmp_path, capfd, version):
    """" 1.0", "1.00", "01.0" and "1.01" (which urdfdom reads as 1.1) were refused: only the strings "1.0", "1.1" and
    "1.2" were taken.  urdfdom reads two whole numbers, major.minor; a spelling loads here exactly when it loads
    there."""
    urdf = _write(tmp_path / "v.urdf", ONE_JOINT.replace('<robot name="t">', f'<robot name="t" version="{version}">'))
    if _urdfdom_accepts(urdf, capfd):
        _loads_as_urdfdom_reads_it(urdf, capfd)
    else:
        with pytest.raises(ValueError, match=r"urdfdom reads versions 1\.0, 1\.1 and 1\.2"):
            RobotChecker(urdf)


def test_version_1_02_is_compared_as_1_2(tmp_path, capfd):
    """The version is compared as numbers wherever it decides something: in 1.2 a revolute joint's <limit> needs no
    effort or velocity, whether it is spelt "1.2" or "1.02" (which was refused)."""
    text = ONE_JOINT.replace('effort="1" velocity="1"', "")
    for version in ("1.2", "1.02"):
        urdf = _write(tmp_path / "v12.urdf", text.replace('<robot name="t">', f'<robot name="t" version="{version}">'))
        _loads_as_urdfdom_reads_it(urdf, capfd)
    urdf = _write(tmp_path / "v11.urdf", text.replace('<robot name="t">', '<robot name="t" version="1.01">'))
    assert not _urdfdom_accepts(urdf, capfd)  # 1.01 is 1.1, where effort and velocity are needed
    with pytest.raises(ValueError, match=r"<limit> needs the attribute\(s\) effort, velocity"):
        RobotChecker(urdf)


CAPSULE = '<capsule radius="0.05" length="0.2"/>'


@pytest.mark.parametrize("version, old, new", [
    ("1.1", '<sphere radius="0.05"/>', CAPSULE),
    ("1.2", '<sphere radius="0.05"/>', CAPSULE),
    ("1.1", '<sphere radius="0.05"/>', '<capsule radius="0.05" length="0"/>'),  # a sphere
    ("1.1", "<collision>", f"<visual><geometry>{CAPSULE}</geometry></visual><collision>"),
], ids=["1.1-collision", "1.2-collision", "1.1-length-0", "1.1-visual"])
def test_a_capsule_in_a_version_1_1_urdf_loads_as_a_coal_capsule(tmp_path, capfd, version, old, new):
    """``<capsule>`` was refused ("urdfdom drops <capsule> silently"); urdfdom 6 reads it from version 1.1 on."""
    text = ONE_JOINT.replace(old, new, 1).replace('<robot name="t">', f'<robot name="t" version="{version}">')
    robot = _loads_as_urdfdom_reads_it(_write(tmp_path / "capsule.urdf", text), capfd)
    if "visual" not in new:
        (go,) = robot.gmodel.geometryObjects
        assert type(go.geometry) is coal.Capsule and go.geometry.radius == 0.05
        assert go.geometry.halfLength == pytest.approx(0.1 if "0.2" in new else 0.0)


def test_a_version_1_1_capsule_collides_at_its_end_cap_as_coal_measures_it(tmp_path, capfd):
    """The capsule's end cap counts: a box 1 cm into the cap (4 cm beyond the end of its cylinder part) collides at
    the angle where it is, and at every other angle the verdict is Coal's distance against the margin."""
    text = (f'<robot name="t" version="1.1"><link name="base"/><link name="a"><collision><origin xyz="0.3 0 0"/>'
            f'<geometry>{CAPSULE}</geometry></collision></link><joint name="j1" type="revolute"><parent link="base"/>'
            '<child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    urdf = _write(tmp_path / "capsule.urdf", text)
    _urdfdom_loads(urdf, capfd)
    cap_top = 0.1 + 0.05  # half the length, then the radius
    for bottom, free in ((cap_top - 0.01, False), (cap_top + 0.04, True)):
        block = Obstacle("block", "box", (0.04, 0.04, 0.04), (0.3, 0.0, bottom + 0.02))
        robot = RobotChecker(urdf, obstacles=[block], n_threads=1)
        assert robot.is_valid(np.zeros(1)) == free
        for q in np.linspace(-1.0, 1.0, 41):
            rotation = pin.SE3(pin.utils.rotate("z", q), np.zeros(3))
            distance = coal.distance(coal.Capsule(0.05, 0.2), coal.Transform3s(rotation * pin.SE3(
                np.eye(3), np.array([0.3, 0.0, 0.0]))), block.geometry(), coal.Transform3s(block.placement),
                coal.DistanceRequest(), coal.DistanceResult())
            assert robot.is_valid(np.array([q])) == (distance > robot.security_margin), q


@pytest.mark.parametrize("old, new", [
    ("</robot>", '<ros2_control name="hw" type="system"><joint name="j1"><command_interface name="position">'
                 '<param name="min">-1</param></command_interface><axis xyz="0 0"/><limit effort="x"/></joint>'
                 '</ros2_control></robot>'),
    ("</robot>", '<transmission name="t1"><type>transmission_interface/SimpleTransmission</type><joint name="j1">'
                 '<hardwareInterface>PositionJointInterface</hardwareInterface><limit effort="x"/></joint>'
                 '<actuator name="m1"><mechanicalReduction>1</mechanicalReduction></actuator></transmission></robot>'),
    ("</robot>", '<gazebo><joint name="loop" type="revolute"><parent>a</parent><child>base</child><origin xyz="0 0"/>'
                 '<axis><xyz>0 0 1</xyz></axis></joint></gazebo></robot>'),
    ('<origin xyz="0 0 0.1" rpy="0 0 0"/>', '<origin xyz="0 0 0.1" rpy="0 0 0"/><origin xyz="0 0"/>'),
    ('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><axis xyz="nan 0 0"/>'),
    ('<limit lower="-1" upper="1" effort="1" velocity="1"/>',
     '<limit lower="-1" upper="1" effort="1" velocity="1"/><limit effort="-1 x"/>'),
    ('<geometry><sphere radius="0.05"/>', '<geometry><sphere radius="0.05"/><box size="0 0"/>'),
    ("</robot>", '<link name="c"/><joint name="jc" type="fixed"><parent link="a"/><child link="c"/>'
                 '<axis xyz="0 0"/></joint></robot>'),
], ids=["ros2_control-joint", "transmission-joint", "gazebo-sdf-joint", "second-origin", "second-axis", "second-limit",
        "second-shape", "fixed-joint-axis"])
def test_numbers_urdfdom_never_reads_are_not_checked(tmp_path, capfd, old, new):
    """The number checks went through every <joint> (a <transmission>'s, a <ros2_control>'s, an SDF joint in a
    <gazebo> block) and every <origin> or <axis> of an element, and refused files urdfdom loads: it reads the robot's
    own links and joints, the first <origin>, <axis>, <limit>, shape of each, and no axis of a fixed joint."""
    urdf = _write(tmp_path / "unread.urdf", ONE_JOINT.replace(old, new, 1))
    _loads_as_urdfdom_reads_it(urdf, capfd)


def test_a_wearer_urdf_with_transmissions_is_loaded_as_the_wearer(tmp_path):
    """A <transmission>'s ``<joint name="j1">`` (no type) was taken for the arm's joint: "lacks revolute joint 'j1'"."""
    from tpee_ompl.model.wearer_arm import WearerArm
    from tpee_ompl.resources import model_file

    text = model_file("wearer_arm.urdf").read_text(encoding="utf-8")
    transmissions = "".join(f'<transmission name="t_{j}"><type>transmission_interface/SimpleTransmission</type>'
                            f'<joint name="{j}"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>'
                            f'<actuator name="m_{j}"/></transmission>' for j in ("j1", "j2", "j3", "j4"))
    urdf = _write(tmp_path / "wearer.urdf", text.replace("</robot>", transmissions + "</robot>"))
    assert WearerArm(urdf).model.names[1:].tolist() == ["j1", "j2", "j3", "j4"]


@pytest.mark.parametrize("number", [" 1", "+1", "1.", ".5", "1E+0", "1e-400", "0001", " \t1"])
def test_numbers_urdfdom_reads_are_read(tmp_path, capfd, number):
    """Every spelling urdfdom reads as a number (a C++ stream: blanks before it, a sign, no digits after the point,
    an exponent) loads, in a scalar and in a vector."""
    text = ONE_JOINT.replace('effort="1"', f'effort="{number}"').replace('xyz="0 0 0.1"', f'xyz="0 {number} 0.1"')
    _loads_as_urdfdom_reads_it(_write(tmp_path / "number.urdf", text), capfd)


@pytest.mark.parametrize("edits", [
    [('xyz="0 0 0.1"', 'xyz="0 \t0 0.1"')],  # a tab after a space: blanks before a number
    [('xyz="0 0 0.1"', 'xyz="\n0 0 0.1"')],  # ("\n  0" has a piece that is only a line break: refused)
    [('effort="1"', 'effort="\n1"')],
    [('<link name="a">', '<link name="a\tb">'), ('<child link="a"/>', '<child link="a\tb"/>')],
], ids=["tab-before-number", "line-break-first", "scalar-line-break-first", "tab-in-name"])
def test_tabs_and_line_breaks_urdfdom_reads_are_read(tmp_path, capfd, edits):
    """Reading attributes as tinyxml2 gets them (tabs and line breaks kept) refuses only what urdfdom refuses, and
    names are the ones Pinocchio gets."""
    text = ONE_JOINT
    for old, new in edits:
        text = text.replace(old, new, 1)
    robot = _loads_as_urdfdom_reads_it(_write(tmp_path / "blanks.urdf", text), capfd)
    assert robot.model.existFrame("a\tb") == (len(edits) == 2)


def test_a_version_1_1_quaternion_turns_the_joint_and_is_ignored_in_1_0(tmp_path, capfd):
    """urdfdom reads quat_xyzw from version 1.1 on (x, y, z, w: here a quarter turn about z) and ignores it in 1.0,
    where a malformed one is no error."""
    origin = '<origin xyz="0 0 0.1" rpy="0 0 0"/>'
    for version, quaternion, turned in (("1.1", "0 0 0.7071068 0.7071068", True), ("1.0", "x", False)):
        text = ONE_JOINT.replace('<robot name="t">', f'<robot name="t" version="{version}">').replace(
            origin, f'<origin xyz="0 0 0.1" quat_xyzw="{quaternion}"/>')
        robot = _loads_as_urdfdom_reads_it(_write(tmp_path / f"q{version}.urdf", text), capfd)
        expected = pin.utils.rotate("z", np.pi / 2) if turned else np.eye(3)
        assert np.allclose(robot.model.jointPlacements[1].rotation, expected, atol=1e-6)


def test_a_latin1_srdf_loads_and_its_pairs_apply(tmp_path):
    """A Latin-1 SRDF (a comment with an umlaut) was refused as "not UTF-8 text": Pinocchio was given the file read
    as UTF-8.  It gets the text as the reader decoded it now, so the file loads as MoveIt's tinyxml2 reads it."""
    urdf = _write(tmp_path / "one.urdf", ONE_JOINT)
    srdf = _write(tmp_path / "latin1.srdf", ('<?xml version="1.0" encoding="ISO-8859-1"?>\n' + LATIN1_COMMENT
                                             + '<robot name="t"><disable_default_collisions link="a"/></robot>'
                                             ).encode("latin-1"))
    post = box("post", (0.1, 0.1, 0.1), (0.3, 0.2, 0.1))  # within the sphere's reach
    assert len(RobotChecker(urdf, obstacles=[post]).gmodel.collisionPairs) == 1  # a against the post
    assert len(RobotChecker(urdf, srdf, obstacles=[post]).gmodel.collisionPairs) == 0


def test_an_axis_without_xyz_is_refused_as_the_zero_axis_urdfdom_reads(tmp_path):
    """urdfdom takes (1, 0, 0) only when a joint has no ``<axis>``; an ``<axis/>`` without ``xyz`` is (0, 0, 0), and
    Pinocchio then scaled the child (0.62 x identity at 0.9 rad) instead of turning it: it loaded without a word."""
    urdf = _write(tmp_path / "axis.urdf", ONE_JOINT.replace('<axis xyz="0 0 1"/>', "<axis/>"))
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    pin.forwardKinematics(model, data, np.array([0.9]))
    assert np.allclose(data.oMi[1].rotation, np.cos(0.9) * np.eye(3))  # what urdfdom + Pinocchio make of it
    with pytest.raises(ValueError, match=r"joint 'j1' has <axis> without xyz \(a zero axis\)"):
        RobotChecker(urdf)
    without = _write(tmp_path / "none.urdf", ONE_JOINT.replace('<axis xyz="0 0 1"/>', ""))
    assert RobotChecker(without, n_threads=1).nq == 1  # no <axis> at all: urdfdom's (1, 0, 0)


@pytest.mark.parametrize("declared", ["UTF-16", "UTF-16LE", "utf_32"])
def test_a_latin1_urdf_declaring_utf16_loads_as_urdfdom_reads_its_bytes(tmp_path, capfd, declared):
    """The declaration was trusted: "UTF-16" raised a bare UnicodeError naming no file, "UTF-16LE" decoded the bytes
    into nonsense refused as not well-formed; urdfdom reads the bytes as they are and loads both."""
    head = f'<?xml version="1.0" encoding="{declared}"?>\n'
    text = head + LATIN1_COMMENT + ONE_JOINT
    urdf = _write(tmp_path / "declared.urdf", (text + " " * (len(text) % 2)).encode("latin-1"))  # even length
    _loads_as_urdfdom_reads_it(urdf, capfd)
