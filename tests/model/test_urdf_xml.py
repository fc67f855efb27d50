"""A URDF or SRDF read as XML and checked before urdfdom reads it (:mod:`tpee_ompl.model.urdf_xml`)."""

from __future__ import annotations

import pinocchio as pin
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


_LIMIT = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'


def _urdfdom_fails_and_we_refuse_in_one_line(urdf, match: str, capfd) -> None:
    """urdfdom refuses the file or drops the link's collision geometry, printing why; RobotChecker refuses it first,
    in one line matching ``match`` after the file's name, with nothing on stderr."""
    capfd.readouterr()
    try:  # urdfdom refuses the file, or drops the link's collision geometry, printing why
        model = pin.buildModelFromUrdf(str(urdf))
        assert pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION).ngeoms == 0
    except ValueError:
        pass
    assert "Error" in capfd.readouterr().err
    with pytest.raises(ValueError, match=f"URDF {urdf}: {match}") as info:
        RobotChecker(urdf)
    assert "\n" not in str(info.value) and capfd.readouterr().err == ""


@pytest.mark.parametrize("old, new, match", [
    ('<robot name="t">', "<robot>", "<robot> has no name attribute"),
    ('<robot name="t">', '<robot name="t" version="2.0">',
     '<robot version="2.0">: urdfdom reads versions 1.0, 1.1 and 1.2'),
    (_LIMIT, "", "joint 'j1' is revolute without a <limit>"),
    ('type="revolute"', 'type="revolutee"', "joint 'j1' has type 'revolutee'"),
    ('effort="1" ', "", r"joint 'j1': <limit> needs the attribute\(s\) effort"),
    ('effort="1"', 'effort="-1"', "joint 'j1': <limit effort=\"-1\"> is negative"),
    ('<axis xyz="0 0 1"/>', '<axis xyz="0 1"/>', "joint 'j1': <axis xyz=\"0 1\"> needs 3 numbers"),
    ('<sphere radius="0.05"/>', "<sphere/>", r"link 'a': <sphere> needs the attribute\(s\) radius"),
    ('<sphere radius="0.05"/>', '<cone radius="1"/>', "link 'a': <collision> shape <cone>"),
    ('<sphere radius="0.05"/>', "", "link 'a': a <collision> has no <geometry> shape"),
    ('<sphere radius="0.05"/>', '<mesh filename="x.stl" scale="1 1"/>', "link 'a': <mesh scale=\"1 1\"> needs 3"),
    ('<link name="base"/>', '<link name="base"/><link name="a"/>', "link 'a' appears twice"),
    ('<link name="base"/>', '<link name="base"/><link name="z"/>', r"2 root links \['base', 'z'\]"),
    ("</robot>", '<joint name="j9" type="fixed"><parent link="a"/><child link="base"/></joint></robot>',
     "no root link: the joints form a loop"),
    ("</robot>", '<link name="c"/><joint name="j9" type="fixed"><parent link="c"/><child link="a"/></joint></robot>',
     "link 'a' is the child of two joints, 'j1' and 'j9'"),
    ("</joint>", '<dynamics/></joint>', "joint 'j1': <dynamics> needs damping or friction"),
    ("</joint>", '<mimic multiplier="2"/></joint>', "joint 'j1': <mimic> needs joint"),
    ('<link name="a">', '<link name="a"><inertial><mass value="1"/></inertial>',
     "link 'a': <inertial> needs <inertia>"),
])
def test_a_malformed_urdf_is_refused_in_one_line_before_urdfdom_prints_its_errors(tmp_path, capfd, old, new, match):
    """urdfdom printed its C++ errors on stderr (several lines, twice: Pinocchio parses the file for the model and again
    for the geometry), then the error said only "The XML stream does not contain a valid URDF model"."""
    assert old in ONE_JOINT
    urdf = tmp_path / "bad.urdf"
    urdf.write_text(ONE_JOINT.replace(old, new, 1))
    capfd.readouterr()
    with pytest.raises(ValueError, match=f"URDF {urdf}: {match}") as info:
        RobotChecker(urdf)
    assert "\n" not in str(info.value) and capfd.readouterr().err == ""


def test_a_collision_mesh_scaled_by_zero_is_refused_naming_the_link_and_the_file(tmp_path, write_cube_stl):
    """A mesh with scale="0 1 1" loaded flat, with no volume: nothing could collide with it, and no error said so."""
    write_cube_stl(tmp_path / "meshes/x.stl", 0.1)
    urdf = tmp_path / "flat.urdf"
    urdf.write_text(ONE_JOINT.replace('<sphere radius="0.05"/>', f'<mesh filename="{tmp_path}/meshes/x.stl" '
                                                                 'scale="0 1 1"/>'))
    with pytest.raises(ValueError, match=f"URDF {urdf}: link 'a': <mesh filename=\"{tmp_path}/meshes/x.stl\" "
                                         "scale=\"0 1 1\"> has a zero scale"):
        RobotChecker(urdf)
    whole = tmp_path / "whole.urdf"  # the same mesh at its own scale loads
    whole.write_text(ONE_JOINT.replace('<sphere radius="0.05"/>', f'<mesh filename="{tmp_path}/meshes/x.stl"/>'))
    assert RobotChecker(whole).gmodel.ngeoms == 1


@pytest.mark.parametrize("old, new", [
    ('<sphere radius="0.05"/>', '<capsule radius="0.05" length="0.2"/>'),
    ("<collision>", '<visual><geometry><capsule radius="0.05" length="0.2"/></geometry></visual><collision>'),
], ids=["collision", "visual"])
def test_a_capsule_in_a_version_1_0_urdf_is_refused_saying_what_urdfdom_does_with_it(tmp_path, capfd, old, new):
    """The message said "urdfdom drops <capsule> silently": in a version 1.0 URDF urdfdom fails to parse the element
    (printing errors) and the link loses all its collision geometry, even for a capsule in a <visual>; from
    version 1.1 on it reads the capsule."""
    urdf = tmp_path / "capsule.urdf"
    urdf.write_text(ONE_JOINT.replace(old, new, 1))
    capfd.readouterr()
    model = pin.buildModelFromUrdf(str(urdf))
    assert pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION).ngeoms == 0
    assert "Could not parse" in capfd.readouterr().err
    with pytest.raises(ValueError, match=f"URDF {urdf}: link 'a': <capsule> needs <robot version=\"1.1\"> .*in 1.0 it "
                                         "fails to parse the <(collision|visual)> and link 'a' loses all its collision "
                                         "geometry"):
        RobotChecker(urdf)


@pytest.mark.parametrize("old, new, match", [
    ('effort="1"', 'effort="1 2"', "joint 'j1': <limit effort=\"1 2\"> needs 1 number"),
    ('lower="-1"', 'lower="-1 -2"', "joint 'j1': <limit lower=\"-1 -2\"> needs 1 number"),
    ('effort="1"', 'effort="1 "', "joint 'j1': <limit effort=\"1 \"> has a blank after its number"),
    ('<sphere radius="0.05"/>', '<sphere radius="0.05 0.06"/>', "link 'a': <sphere radius=\"0.05 0.06\"> needs 1"),
    ('<sphere radius="0.05"/>', '<sphere radius="0.05 "/>', "link 'a': <sphere radius=\"0.05 \"> has a blank after"),
    ('<sphere radius="0.05"/>', '<sphere radius="0.0_5"/>', "link 'a': <sphere radius=\"0.0_5\"> is not a list of"),
    ('<sphere radius="0.05"/>', '<sphere radius="0x1"/>', "link 'a': <sphere radius=\"0x1\"> is not a list of"),
    ('<link name="a">', '<link name="a"><inertial><mass value="1 "/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
                        'izz="1"/></inertial>', "link 'a': <mass value=\"1 \"> has a blank after its number"),
    ("</joint>", '<mimic joint="j0" multiplier="1 2"/></joint>', "joint 'j1': <mimic multiplier=\"1 2\"> needs 1"),
    ("</joint>", '<calibration rising="0 1"/></joint>', "joint 'j1': <calibration rising=\"0 1\"> needs 1 number"),
    ("</joint>", '<safety_controller k_velocity="infinity"/></joint>',
     "joint 'j1': <safety_controller k_velocity=\"infinity\"> is not a list"),
    ('<axis xyz="0 0 1"/>', '<axis xyz="0&#9;0&#9;1"/>', r"joint 'j1': <axis xyz=\"0\\t0\\t1\"> has a tab or line "
                                                       "break between"),
])
def test_a_number_urdfdom_cannot_read_is_named_with_its_file_element_and_attribute(tmp_path, capfd, old, new, match):
    """``effort="1 2"`` raised a bare "could not convert string to float: '1 2'" (no file, no element), and "1 ",
    "0.0_5" or a radius of two numbers passed (Python's float reads them) until urdfdom refused the file or dropped
    the link's collision geometry, printing C++ errors: urdfdom reads one number whole (blanks before it, nothing
    after) and a vector split at spaces."""
    assert old in ONE_JOINT
    urdf = tmp_path / "bad.urdf"
    urdf.write_text(ONE_JOINT.replace(old, new, 1))
    _urdfdom_fails_and_we_refuse_in_one_line(urdf, match, capfd)


@pytest.mark.parametrize("visual, match", [
    ('<visual><origin xyz="0 0 0"/></visual>', "a <visual> has no <geometry> shape"),
    ('<visual><geometry><cone radius="1"/></geometry></visual>', "<visual> shape <cone> is none of urdfdom's"),
    ("<visual><geometry><sphere/></geometry></visual>", r"<sphere> needs the attribute\(s\) radius"),
    ('<visual><geometry><box size="0.1 0.1 0.1"/></geometry><material><color rgba="1 0 0 1"/></material></visual>',
     "a <visual>'s <material> has no name"),
])
def test_a_visual_urdfdom_cannot_read_is_refused_before_the_link_loses_its_collision_geometry(tmp_path, capfd, visual,
                                                                                              match):
    """A malformed <visual> passed: urdfdom then dropped all of its link's collision geometry, printing C++ errors,
    and the error said only that "1 <collision> elements but only 0 geometries were loaded (unsupported shape?)"."""
    urdf = tmp_path / "visual.urdf"
    urdf.write_text(ONE_JOINT.replace("<collision>", visual + "<collision>", 1))
    capfd.readouterr()
    model = pin.buildModelFromUrdf(str(urdf))
    assert pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION).ngeoms == 0
    assert "Could not parse visual element for Link [a]" in capfd.readouterr().err
    with pytest.raises(ValueError, match=f"URDF {urdf}: link 'a': {match}.*link 'a' loses all its collision geometry"):
        RobotChecker(urdf)
    assert capfd.readouterr().err == ""


@pytest.mark.parametrize("old, new, match", [
    ('<axis xyz="0 0 1"/>', '<axis xyz="0\t0\t1"/>', r"joint 'j1': <axis xyz=\"0\\t0\\t1\"> has a tab or line break"),
    ('<axis xyz="0 0 1"/>', '<axis xyz="0 0\n  1"/>', r"joint 'j1': <axis xyz=\"0 0\\n  1\"> has a tab or line break"),
    ('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1\n"/>', r"joint 'j1': <axis xyz=\"0 0 1\\n\"> has a tab or line break"),
    ('effort="1"', 'effort="1\n"', r"joint 'j1': <limit effort=\"1\\n\"> has a blank after its number"),
    ('<sphere radius="0.05"/>', '<sphere radius="0.05\t"/>', r"link 'a': <sphere radius=\"0.05\\t\"> has a blank"),
    ('<sphere radius="0.05"/>', '<sphere radius="&r;"/>', "link 'a': <sphere radius=\"&r;\"> is not a list of finite"),
])
def test_a_tab_line_break_or_entity_in_a_number_is_refused_as_urdfdom_reads_it(tmp_path, capfd, old, new, match):
    """XML parsers make a tab or line break in an attribute a space, and expand a DOCTYPE's entities; tinyxml2
    (urdfdom's parser) does neither, so these passed and urdfdom refused the file or dropped the link's collision
    geometry, printing C++ errors.  The attribute is read as urdfdom gets it, and the message stays on one line."""
    assert old in ONE_JOINT
    urdf = tmp_path / "raw.urdf"
    head = '<!DOCTYPE robot [ <!ENTITY r "0.05"> ]>\n' if "&r;" in new else ""
    urdf.write_bytes((head + ONE_JOINT.replace(old, new, 1)).replace("\n", "\r\n").encode())  # a Windows file too
    _urdfdom_fails_and_we_refuse_in_one_line(urdf, match, capfd)


@pytest.mark.parametrize("origin, match", [
    ('<origin xyz="0 0 0.1" quat_xyzw="0 0 1"/>', r"joint 'j1': <origin quat_xyzw=\"0 0 1\"> needs 4 numbers"),
    ('<origin xyz="0 0 0.1" rpy="0 0 0" quat_xyzw="0 0 0 1"/>', "joint 'j1': an <origin> has both rpy and quat_xyzw"),
    ('<origin xyz="0 0 0.1" quat_xyzw="0 0 0 0"/>', r"joint 'j1': <origin quat_xyzw=\"0 0 0 0\"> is no rotation"),
])
def test_a_version_1_1_quaternion_urdfdom_refuses_or_pinocchio_ignores_is_named(tmp_path, capfd, origin, match):
    """URDF 1.1 gives an <origin> a quaternion (quat_xyzw); one of three numbers, or beside rpy, passed until urdfdom
    refused the file printing C++ errors, and a zero one loaded as no rotation without a word."""
    text = ONE_JOINT.replace('<robot name="t">', '<robot name="t" version="1.1">').replace(
        '<axis xyz="0 0 1"/>', origin + '<axis xyz="0 0 1"/>')
    urdf = tmp_path / "quaternion.urdf"
    urdf.write_text(text)
    if "no rotation" not in match:  # urdfdom refuses these, printing why

        with pytest.raises(ValueError):
            pin.buildModelFromUrdf(str(urdf))
        assert "Error" in capfd.readouterr().err
    with pytest.raises(ValueError, match=f"URDF {urdf}: {match}"):
        RobotChecker(urdf)
    assert capfd.readouterr().err == ""
