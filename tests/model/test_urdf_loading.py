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
