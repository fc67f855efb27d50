"""The wearer + arm model: loading, kinematics, collision checking, bad input."""

from __future__ import annotations

import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import coal
import numpy as np
import pytest

from tpee_ompl.model.sectors import SECTORS, posture_preset
from tpee_ompl.model.wearer_arm import ARM_JOINTS, WearerArm
from tpee_ompl.resources import model_file as find_model_file

MOUNT = np.array([-0.30, 0.0, 1.51])  # urdf/build_urdf.py
T = np.array([0.1545, 0.0, 0.468])
L3, L4 = 0.10, 0.45


def rx(a: float) -> np.ndarray:  # eq. 2
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a: float) -> np.ndarray:  # a right-handed rotation about y; eq. 3 is ry(-DOF2)
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def test_packaged_model_loads_with_four_revolute_arm_joints(robot):
    assert robot.joint_names == ARM_JOINTS
    assert robot.nq == 4
    np.testing.assert_allclose(robot.lower[:2], np.deg2rad([-70, 0]))
    np.testing.assert_allclose(robot.upper[:2], np.deg2rad([70, 180]))
    for k in SECTORS:  # Table 1 presets inside the limits
        assert np.all(posture_preset(k) >= robot.lower[:2]) and np.all(posture_preset(k) <= robot.upper[:2])


def test_model_loads_from_an_explicit_path(tmp_path):
    for name in ("wearer_arm.urdf", "wearer_arm.srdf"):
        shutil.copy(find_model_file(name), tmp_path / name)
    r = WearerArm(tmp_path / "wearer_arm.urdf", tmp_path / "wearer_arm.srdf")
    assert r.files.urdf == tmp_path / "wearer_arm.urdf"
    assert len(r.gmodel.collisionPairs) == len(WearerArm().gmodel.collisionPairs)


def test_every_collision_element_is_loaded_and_cylinders_become_capsules(robot):
    root = ET.parse(find_model_file("wearer_arm.urdf")).getroot()
    links_with_geometry = {link.get("name") for link in root.iter("link") if link.find("collision") is not None}
    assert robot.gmodel.ngeoms == sum(1 for _ in root.iter("collision"))
    loaded_links = {go.name.rsplit("_", 1)[0] for go in robot.gmodel.geometryObjects}
    assert loaded_links == links_with_geometry
    assert {"helmet", "backpack", "rifle", "forearm_l", "link2", "link4"} <= loaded_links
    n_cyl = sum(1 for _ in root.iter("cylinder"))
    assert sum(isinstance(go.geometry, coal.Capsule) for go in robot.gmodel.geometryObjects) == n_cyl
    assert not any(isinstance(go.geometry, coal.Cylinder) for go in robot.gmodel.geometryObjects)


@pytest.mark.parametrize("sector", SECTORS)
def test_pointing_system_position_matches_eqs_2_to_6_at_each_preset(robot, sector):
    d1, d2 = posture_preset(sector)
    M = rx(d1) @ ry(-d2)  # eq. 4 with the sign of eq. 3 corrected
    q = np.array([d1, d2, 0.0, 0.0])
    np.testing.assert_allclose(robot.joint_placement(q, "j3").translation, MOUNT + M @ T, atol=1e-9)
    np.testing.assert_allclose(robot.joint_placement(q, "j3").rotation, M, atol=1e-9)
    p, u = robot.muzzle(q)
    np.testing.assert_allclose(p, MOUNT + M @ (T + np.array([L4, L3, 0.0])), atol=1e-9)
    np.testing.assert_allclose(u, M[:, 0], atol=1e-9)


@pytest.mark.parametrize(
    ("q", "parts"),
    [
        ([-0.085, 0.299, -0.799, -1.202], {"helmet", "link4"}),  # barrel through the helmet
        ([0.028, 0.002, -2.409, 0.92], {"helmet", "link2"}),  # boom through the helmet
        ([-0.041, 3.056, 2.586, -0.419], {"backpack", "link4"}),  # barrel through the backpack
        ([-0.521, 0.368, 1.526, -1.581], {"link2", "link4"}),  # barrel against its own boom
    ],
)
def test_hand_picked_collisions_are_invalid(robot, q, parts):
    q = np.array(q)
    assert not robot.is_valid(q)
    a, b, dist = robot.closest_pair(q)
    assert {a.rsplit("_", 1)[0], b.rsplit("_", 1)[0]} == parts
    assert dist < 0


@pytest.mark.parametrize("sector", SECTORS)
def test_presets_pointing_outward_are_valid_with_two_cm_clearance(robot, sector):
    q = np.r_[posture_preset(sector), 0.0, 0.0]  # barrel along the boom-tip x axis, away from the body
    assert robot.is_valid(q)
    assert robot.clearance(q) >= 0.02


def test_configurations_outside_the_limits_are_invalid(robot):
    q = np.r_[posture_preset(3), 0.0, 0.0]
    q[3] = robot.upper[3] + 0.01
    assert not robot.is_valid(q)
    assert not robot.are_valid(q[None])[0]


def test_batched_and_single_checks_agree_on_10000_random_configurations(robot, rng):
    Q = rng.uniform(robot.lower - 0.05, robot.upper + 0.05, size=(10_000, 4))
    batched = robot.are_valid(Q)
    single = np.array([robot.is_valid(q) for q in Q])
    np.testing.assert_array_equal(batched, single)
    assert 0.1 < batched.mean() < 0.95  # both outcomes are well represented


def test_security_margin_makes_near_contacts_invalid(robot, rng):
    Q = rng.uniform(robot.lower, robot.upper, size=(3000, 4))
    d = np.array([robot.clearance(q) for q in Q])
    np.testing.assert_array_equal(robot.are_valid(Q), d >= robot.security_margin)


def test_link_margins_widen_only_the_named_links_wearer_pairs(robot, rng):
    Q = rng.uniform(robot.lower, robot.upper, size=(600, 4))
    wide = WearerArm(link_margins={"link3": 0.035, "link4": 0.035})
    d_wide, d_other = np.array([_split_clearance(robot, q) for q in Q]).T
    expected = (d_wide >= 0.035) & (d_other >= robot.security_margin)
    clear_of_edges = (np.abs(d_wide - 0.035) > 1e-4) & (np.abs(d_other - robot.security_margin) > 1e-4)
    np.testing.assert_array_equal(wide.are_valid(Q)[clear_of_edges], expected[clear_of_edges])
    # both kinds of configuration occur: valid at 2 cm but not with the wider margin, and valid with it
    # although another pair (not link 3/4 - wearer) is closer than 3.5 cm
    assert np.any(clear_of_edges & robot.are_valid(Q) & ~expected)
    assert np.any(clear_of_edges & expected & (d_other < 0.035))


def _split_clearance(robot: WearerArm, q: np.ndarray) -> tuple[float, float]:
    """Smallest distance of the link3/link4 - wearer pairs, and of every other checked pair (Coal)."""
    import pinocchio as pin

    pin.updateGeometryPlacements(robot.model, robot.data, robot.gmodel, robot.gdata, q)
    out = [np.inf, np.inf]
    for k, cp in enumerate(robot.gmodel.collisionPairs):
        a, b = robot.gmodel.geometryObjects[cp.first], robot.gmodel.geometryObjects[cp.second]
        arm = b if a.parentJoint == 0 else a if b.parentJoint == 0 else None
        kind = 0 if arm is not None and arm.name.startswith(("link3", "link4")) else 1
        out[kind] = min(out[kind], pin.computeDistance(robot.gmodel, robot.gdata, k).min_distance)
    return out[0], out[1]


@pytest.mark.parametrize(
    "link_margins, match",
    [({"link4": 0.01}, "link_margins"), ({"link4": float("nan")}, "link_margins"), ({"tentacle": 0.03}, "unknown link"),
     ([("link4", 0.03)], "mapping"), ({"muzzle": 0.03}, "without collision geometry")],
)
def test_bad_link_margins_raise_value_error(link_margins, match):
    with pytest.raises(ValueError, match=match):
        WearerArm(link_margins=link_margins)


def test_collision_checks_are_counted(robot, rng):
    before = robot.collision_checks
    robot.are_valid(rng.uniform(robot.lower, robot.upper, size=(25, 4)))
    robot.is_valid(np.r_[posture_preset(1), 0.0, 0.0])
    assert robot.collision_checks - before == 26


def test_line_of_sight_is_blocked_by_the_helmet_and_clear_away_from_the_body(robot):
    q = np.r_[posture_preset(3), 0.0, 0.0]
    p, u = robot.muzzle(q)
    assert robot.line_of_sight_clear(q, p + 5.0 * u)
    assert not robot.line_of_sight_clear(q, np.array([0.0, 0.0, 1.69]) + (np.array([0.0, 0.0, 1.69]) - p))
    assert not robot.line_of_sight_clear(q, np.array([0.3, -0.6, 0.6]))  # through the rifle arm / torso region


@pytest.mark.parametrize("q", [[0.0, 1.0, 0.0], [[0.0] * 4], [0.0, np.nan, 0.0, 0.0], [np.inf, 0, 0, 0]])
def test_wrong_shaped_or_non_finite_configurations_raise_value_error(robot, q):
    with pytest.raises(ValueError, match="configuration"):
        robot.is_valid(np.array(q, dtype=float))


@pytest.mark.parametrize("q", [np.zeros(4) + 0j, np.zeros(4) + 1e-3j, ["0", "0", "0", "0"], np.array(["0.1"] * 4)])
def test_complex_or_string_configurations_are_refused_not_coerced(robot, q, recwarn):
    for check in (robot.is_valid, robot.check_config, robot.muzzle, robot.are_valid):
        with pytest.raises(ValueError, match="real numbers"):
            check(q)
    assert not [w for w in recwarn if "imaginary" in str(w.message)]


@pytest.mark.parametrize("n", [0, 3, 5])
def test_is_valid_values_with_another_number_of_values_names_the_length(robot, n):
    with pytest.raises(ValueError, match=f"needs 4 values.*got {n}"):
        robot.is_valid_values([0.1] * n)


def test_is_valid_values_agrees_with_is_valid(robot, rng):
    Q = rng.uniform(robot.lower, robot.upper, size=(200, 4))
    assert [robot.is_valid_values(q.tolist()) for q in Q] == [robot.is_valid(q) for q in Q]


def test_batch_of_wrong_shape_raises_value_error(robot):
    with pytest.raises(ValueError, match=r"shape \(N, 4\)"):
        robot.are_valid(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="NaN or inf"):
        robot.are_valid(np.full((2, 4), np.nan))


def test_line_of_sight_rejects_non_finite_targets(robot):
    with pytest.raises(ValueError, match="target"):
        robot.line_of_sight_clear(np.zeros(4), np.array([np.nan, 0.0, 1.0]))


def test_missing_urdf_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="URDF file not found"):
        WearerArm(tmp_path / "nope.urdf")


def test_missing_srdf_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="SRDF file not found"):
        WearerArm(find_model_file("wearer_arm.urdf"), tmp_path / "nope.srdf")


def test_truncated_urdf_raises_value_error(tmp_path):
    text = find_model_file("wearer_arm.urdf").read_text()
    bad = tmp_path / "bad.urdf"
    bad.write_text(text[: len(text) // 2])
    with pytest.raises(ValueError, match="malformed URDF"):
        WearerArm(bad)


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        ('name="j4" type="revolute"', 'name="j4" type="fixed"', "revolute joint 'j4'"),
        ('<sphere radius="0.145"/>', '<capsule radius="0.1" length="0.2"/>', "capsule"),
    ],
    ids=["tilt joint fixed", "capsule element"],
)
def test_urdf_without_the_tilt_joint_or_with_a_capsule_is_refused(tmp_path, old, new, match):
    text = find_model_file("wearer_arm.urdf").read_text()
    assert old in text
    bad = tmp_path / "edited.urdf"
    bad.write_text(text.replace(old, new))
    with pytest.raises(ValueError, match=match):
        WearerArm(bad)


def test_srdf_naming_an_unknown_link_raises_value_error(tmp_path):
    srdf = tmp_path / "bad.srdf"
    srdf.write_text('<robot name="x"><disable_collisions link1="link1" link2="tentacle" reason="x"/></robot>')
    with pytest.raises(ValueError, match="unknown link 'tentacle'"):
        WearerArm(find_model_file("wearer_arm.urdf"), srdf)


def test_negative_security_margin_raises_value_error():
    with pytest.raises(ValueError, match="security_margin"):
        WearerArm(security_margin=-0.01)


def test_packaged_model_files_are_package_data_with_the_urdf_folders_content():
    root = Path(__file__).resolve().parents[2]
    for name in ("wearer_arm.urdf", "wearer_arm.srdf"):
        packaged = find_model_file(name)
        assert packaged.parent.name == "model" and packaged.parent.parent.name == "data"
        assert packaged.read_bytes() == (root / "urdf" / name).read_bytes()
