"""Aiming IK (eqs. 1-11): exactness against Pinocchio FK, branch choice, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from tpee_ompl.model.pointing import (
    AimingError,
    BlindAreaError,
    PointingGeometry,
    UnreachableTargetError,
    aim,
    aim_batch,
    aim_checked,
    aim_errors,
    check_target,
    default_geometry,
    pointing_frame,
)
from tpee_ompl.model.sectors import SECTORS, in_pointing_sector, sector_origin


def _targets_in_sector(rng: np.random.Generator, k: int, n: int, lo: float, hi: float) -> np.ndarray:
    out = []
    while sum(len(o) for o in out) < n:
        d = rng.normal(size=(4 * n, 3))
        d /= np.linalg.norm(d, axis=1)[:, None]
        t = sector_origin() + d * rng.uniform(lo, hi, (4 * n, 1))
        out.append(t[in_pointing_sector(t, k)])
    return np.concatenate(out)[:n]


def test_constants_are_read_from_the_model(robot):
    g = PointingGeometry.from_robot(robot)
    np.testing.assert_allclose(g.boom, [0.1545, 0.0, 0.468])
    np.testing.assert_allclose(g.pivot, [-0.30, 0.0, 1.51])
    assert g.offset == pytest.approx(0.10) and g.barrel == pytest.approx(0.45)
    np.testing.assert_allclose(g.axis2, [0, -1, 0], atol=1e-12)


def test_pan_frame_matches_pinocchio_joint_placement(robot, rng):
    g = default_geometry()
    for _ in range(20):
        q = rng.uniform(robot.lower, robot.upper)
        q[2:] = 0.0
        origin, rot = g.pan_frame(q[:2])
        m = robot.joint_placement(q, "j3")
        np.testing.assert_allclose(origin[0], m.translation, atol=1e-12)
        np.testing.assert_allclose(rot[0], m.rotation, atol=1e-12)


def test_aim_puts_10000_targets_on_the_barrel_ray(robot, rng):
    """2,500 targets 1-20 m away in each pointing sector: FK puts each on the +x ray within 1e-6 m."""
    g = default_geometry()
    worst = 0.0
    for k in SECTORS:
        targets = _targets_in_sector(rng, k, 2500, 1.0, 20.0)
        Q = aim_batch(targets, k, strict=False)
        s = pointing_frame(targets, k)
        blind = np.hypot(s[:, 0], s[:, 1]) <= g.offset + 1e-9
        solved = np.all(np.isfinite(Q), axis=1)
        assert np.array_equal(solved, ~blind), "only blind-area targets may fail"
        assert blind.mean() < 0.01
        for q, t in zip(Q[solved], targets[solved]):
            perp, along, _ = aim_errors(robot, q, t)
            assert along > 0.0
            worst = max(worst, perp)
        assert np.all((Q[solved] >= robot.lower - 1e-12) & (Q[solved] <= robot.upper + 1e-12))
    assert worst < 1e-6


def test_single_and_batch_forms_agree(rng):
    targets = _targets_in_sector(rng, 3, 50, 2.0, 10.0)
    Q = aim_batch(targets, 3)
    for q, t in zip(Q, targets):
        np.testing.assert_array_equal(aim(t, 3), q)


def test_pan_reference_selects_the_closest_of_the_2pi_equivalent_solutions(robot):
    g = default_geometry()
    # find a target whose pan solution lies within 3.3 - pi of +-pi (two representations in the limits)
    for az in np.linspace(-np.pi, np.pi, 721):
        t = sector_origin() + 5.0 * np.array([np.cos(az), np.sin(az), 0.3])
        q = aim(t, 1)
        if abs(abs(q[2]) - np.pi) < 0.1:
            break
    else:
        pytest.fail("no target with a pan near +-pi")
    hi = aim(t, 1, pan_reference=3.3)
    lo = aim(t, 1, pan_reference=-3.3)
    assert hi[2] - lo[2] == pytest.approx(2 * np.pi)
    assert g.pan_limits[0] <= lo[2] and hi[2] <= g.pan_limits[1]
    for q in (hi, lo):
        assert aim_errors(robot, q, t)[0] < 1e-9


def test_target_on_the_pan_axis_is_in_the_blind_area():
    g = default_geometry()
    origin, rot = g.pan_frame(np.deg2rad([-50.0, 20.0]))
    above = origin[0] + 3.0 * rot[0][:, 2]
    with pytest.raises(BlindAreaError, match="blind cylinder"):
        aim(above, 3)
    near_axis = above + 0.05 * rot[0][:, 0]
    with pytest.raises(BlindAreaError):
        aim(near_axis, 3)


def test_target_at_the_pan_pivot_is_refused():
    g = default_geometry()
    origin, _ = g.pan_frame(np.deg2rad([50.0, 160.0]))
    with pytest.raises(AimingError):
        aim(origin[0], 2)


def test_target_between_tilt_joint_and_muzzle_is_unreachable():
    g = default_geometry()
    origin, rot = g.pan_frame(np.deg2rad([50.0, 20.0]))
    close = origin[0] + rot[0] @ np.array([0.2, 0.1, 0.0])  # on the barrel line, 0.2 m from the tilt axis
    with pytest.raises(UnreachableTargetError, match="not beyond the muzzle"):
        aim(close, 4)


def test_a_target_at_the_muzzle_is_refused_whatever_the_rounding():
    """Half the targets exactly at the muzzle were accepted (reach <= L4 decided by rounding), aims off by up to 3 rad."""
    from tpee_ompl.model.wearer_arm import default_robot

    robot, rng = default_robot(), np.random.default_rng(0)
    refused = 0
    for k in SECTORS:
        for _ in range(25):
            q = aim(sector_origin() + rng.normal(size=3) * 3.0 + [0.0, 0.0, 1.0], k, pan_reference=rng.uniform(-3, 3))
            muzzle, _ = robot.muzzle(q)
            with pytest.raises(UnreachableTargetError, match="not beyond the muzzle"):
                aim(muzzle, k, pan_reference=q[2])
            refused += 1
    assert refused == 100


@pytest.mark.parametrize("bad", [[np.nan, 0, 1], [np.inf, 2, 1], [1, -np.inf, 0]])
def test_non_finite_targets_raise_a_dedicated_value_error(bad):
    with pytest.raises(UnreachableTargetError, match="not finite"):
        aim(np.array(bad), 1)
    assert issubclass(UnreachableTargetError, ValueError) and issubclass(BlindAreaError, ValueError)


def test_batch_marks_failures_as_nan_when_not_strict():
    g = default_geometry()
    origin, rot = g.pan_frame(np.deg2rad([-50.0, 20.0]))
    targets = np.array([[5.0, 0.0, 1.5], origin[0] + 2.0 * rot[0][:, 2], [np.nan, 0.0, 0.0]])
    Q = aim_batch(targets, 3, strict=False)
    assert np.all(np.isfinite(Q[0])) and np.isnan(Q[1:, 2:]).all()


@pytest.mark.parametrize("sector", [0, 5, -1, True, 2.5, "1"])
def test_unknown_sector_numbers_raise(sector):
    with pytest.raises(ValueError, match="sector|posture"):
        aim(np.array([5.0, 0.0, 1.5]), sector)


def test_wrong_shapes_raise():
    with pytest.raises(ValueError, match="shape"):
        aim(np.zeros(2), 1)
    with pytest.raises(ValueError, match="shape"):
        aim_batch(np.zeros((3, 2)), 1)


def test_targets_inside_the_body_or_at_the_pivot_are_refused(robot):
    with pytest.raises(UnreachableTargetError, match="inside torso"):
        check_target(np.array([0.0, 0.0, 1.21]), robot)
    with pytest.raises(UnreachableTargetError, match="inside (head|helmet)"):
        check_target(np.array([0.0, 0.0, 1.70]), robot)
    with pytest.raises(UnreachableTargetError, match="inside link1"):
        check_target(sector_origin(), robot)
    np.testing.assert_array_equal(check_target([5.0, 0.0, 1.0], robot), [5.0, 0.0, 1.0])


@pytest.mark.parametrize("kw, match", [({"strict": "no"}, "strict"), ({"geometry": "x"}, "geometry")])
def test_aim_batch_refuses_a_flag_or_geometry_of_the_wrong_type(kw, match):
    with pytest.raises(ValueError, match=match):
        aim_batch(np.array([[5.0, 2.0, 1.5]]), 3, **kw)


def test_aiming_another_robot_is_a_value_error_naming_what_it_lacks(tmp_path):
    """It was a bare IndexError ("Index out of range") from inside the geometry's reading (a helper's README run)."""
    from tpee_ompl.model.pointing import PointingGeometry
    from tpee_ompl.model.robot_checker import RobotChecker

    urdf = tmp_path / "other.urdf"
    urdf.write_text('<robot name="o"><link name="base"/><link name="a"><collision><geometry><sphere radius="0.05"/>'
                    '</geometry></collision></link><joint name="shoulder" type="revolute"><parent link="base"/>'
                    '<child link="a"/><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>'
                    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    with pytest.raises(ValueError, match=r"aiming needs the wearer arm .* this robot has the joints \['shoulder'\]"):
        PointingGeometry.from_robot(RobotChecker(urdf))


@pytest.mark.parametrize("call", [
    lambda robot: aim_checked(None, [[5.0, 2.0, 1.5]], 3),
    lambda robot: aim_checked(None, [[5.0, 2.0, 1.5]], 3, geometry=PointingGeometry.from_robot(robot)),
    lambda robot: aim_errors("r", np.zeros(4), [5.0, 2.0, 1.5]),
    lambda robot: check_target([5.0, 2.0, 1.5], "r"),
    lambda robot: PointingGeometry.from_robot(None),
], ids=["aim_checked", "aim_checked_with_geometry", "aim_errors", "check_target", "from_robot"])
def test_a_robot_that_is_not_a_wearer_arm_is_a_value_error_naming_it(robot, call):
    """It was an AttributeError from inside ("'NoneType' object has no attribute 'model'")."""
    with pytest.raises(ValueError, match="robot must be a WearerArm, got (NoneType|str)"):
        call(robot)
