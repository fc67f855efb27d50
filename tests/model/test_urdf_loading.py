"""Loading a URDF and its SRDF (:mod:`tpee_ompl.model.urdf_loading`)."""

from __future__ import annotations


def test_an_srdf_not_named_srdf_is_read_like_one(tmp_path):
    """Pinocchio's path reader refused a valid SRDF saved as .xml, after this package had read it without trouble."""
    from tpee_ompl.model.wearer_arm import WearerArm
    from tpee_ompl.resources import model_file

    urdf, srdf = model_file("wearer_arm.urdf"), model_file("wearer_arm.srdf")
    xml = tmp_path / "pairs.xml"
    xml.write_bytes(srdf.read_bytes())
    packaged, renamed = WearerArm(urdf, srdf), WearerArm(urdf, xml)
    assert len(renamed.gmodel.collisionPairs) == len(packaged.gmodel.collisionPairs)


def test_a_joint_to_a_missing_link_is_named_before_urdfdom_fails_vaguely(tmp_path):
    """urdfdom printed "child link [l2x] of joint [j2] not found" on stderr and the error said only "not a valid URDF"."""
    import pytest

    from tpee_ompl.model.robot_checker import RobotChecker
    from tpee_ompl.resources import model_file

    text = model_file("wearer_arm.urdf").read_text(encoding="utf-8")
    first_child = text.index('<child link="')
    broken = text[:first_child] + '<child link="nowhere"/>' + text[text.index("/>", first_child) + 2:]
    (tmp_path / "broken.urdf").write_text(broken, encoding="utf-8")
    with pytest.raises(ValueError, match="child link 'nowhere', which is not a <link>"):
        RobotChecker(tmp_path / "broken.urdf")


def test_a_urdf_of_another_robot_given_as_the_wearer_says_where_such_robots_are_planned(tmp_path):
    """`tpee-ompl plan --urdf ur5.urdf` said only that joint 'j1' was missing."""
    import pytest

    from tpee_ompl.model.urdf_loading import load_wearer_model

    urdf = tmp_path / "other.urdf"
    urdf.write_text('<robot name="o"><link name="base"/><link name="a"/><joint name="shoulder" type="revolute">'
                    '<parent link="base"/><child link="a"/><axis xyz="0 0 1"/>'
                    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    with pytest.raises(ValueError, match=r"lacks revolute joint 'j1'.*another robot is planned with RobotChecker"):
        load_wearer_model(urdf, None)


def test_an_srdf_floating_base_is_said_to_be_fixed_here(tmp_path, caplog):
    """go1's and the Bravo7's SRDFs declare a floating root joint; the model loaded with its base welded to the
    world without a word (a helper's probe)."""
    from tpee_ompl.model.wearer_arm import WearerArm
    from tpee_ompl.resources import model_file

    urdf, srdf = model_file("wearer_arm.urdf"), model_file("wearer_arm.srdf")
    text = srdf.read_text().replace("</robot>", '<virtual_joint name="root_joint" type="floating" '
                                                'parent_frame="world" child_link="base_link"/></robot>')
    floating = tmp_path / "floating.srdf"
    floating.write_text(text)
    with caplog.at_level("WARNING"):
        WearerArm(urdf, floating)
    assert "declares the floating virtual joint 'root_joint': its base is fixed to the world here" in caplog.text


GAZEBO_URDF = """<?xml version="1.0"?>
<robot name="r"><link name="world"/>
<link name="arm"><collision><origin xyz="0.5 0 0"/><geometry><box size="0.2 0.1 0.1"/></geometry></collision></link>
<joint name="j" type="revolute"><parent link="world"/><child link="arm"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<gazebo reference="arm">{extra}</gazebo></robot>"""


def test_collision_and_capsule_tags_outside_links_are_not_taken_for_the_links_shapes(tmp_path):
    """A Gazebo <collision> (contact settings) was counted as a shape Pinocchio had dropped, and a <capsule> outside
    any link refused the file: valid URDFs (example-robot-data's HyQ, simple_humanoid) would not load."""
    import pytest

    from tpee_ompl.model.robot_checker import RobotChecker

    for name, extra in (("friction", "<collision><surface><friction/></surface></collision>"),
                        ("capsule", "<collision><geometry><capsule><radius>0.1</radius><length>0.2</length></capsule>"
                                    "</geometry></collision>")):
        (tmp_path / f"{name}.urdf").write_text(GAZEBO_URDF.format(extra=extra), encoding="utf-8")
        assert RobotChecker(tmp_path / f"{name}.urdf").gmodel.ngeoms == 1
    link_capsule = GAZEBO_URDF.format(extra="").replace("<box size=\"0.2 0.1 0.1\"/>",
                                                        "<capsule radius=\"0.05\" length=\"0.2\"/>")
    (tmp_path / "link_capsule.urdf").write_text(link_capsule, encoding="utf-8")
    with pytest.raises(ValueError, match="<capsule>"):  # a link's capsule is still dropped by urdfdom: refused
        RobotChecker(tmp_path / "link_capsule.urdf")


def test_a_nearly_flat_mesh_is_not_given_a_convex_hull():
    """A float32 plate 1e-8 of its size thick passed the flatness test (1e-9) and Coal's hull crashed the process."""
    import numpy as np

    from tpee_ompl.model.urdf_loading import _solid

    class Mesh:
        def __init__(self, V):
            self.V = V

        def vertices(self):
            return self.V

    rng = np.random.default_rng(0)
    plate = np.c_[rng.uniform(-1, 1, (9, 2)), 1e-8 * rng.uniform(-1, 1, 9)].astype(np.float32)
    assert not _solid(Mesh(plate)) and _solid(Mesh(rng.uniform(-1, 1, (9, 3))))
