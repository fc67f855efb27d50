"""Posture and pointing sectors: coverage, aimability, hysteresis; Table 3 trajectories."""

from __future__ import annotations

import numpy as np
import pytest

from tpee_ompl.model.pointing import aim_checked
from tpee_ompl.model.sectors import (
    CROSS_SECTOR_TRAJECTORIES,
    POINTING_AZIMUTH,
    POSTURE_AZIMUTH,
    POSTURE_PRESETS,
    SECTORS,
    check_sector,
    cross_sector_length_bound,
    cross_sector_trajectory,
    in_pointing_sector,
    pointing_sectors,
    posture_preset,
    posture_sector,
    sector_origin,
    select_sector,
    target_direction,
)


def _sphere(rng: np.random.Generator, n: int) -> np.ndarray:
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None]


def _direction(az_deg: float, el_deg: float) -> np.ndarray:
    a, e = np.deg2rad(az_deg), np.deg2rad(el_deg)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def test_every_direction_is_in_exactly_one_posture_sector_and_its_pointing_sector(rng):
    targets = sector_origin() + 5.0 * _sphere(rng, 20000)
    home = posture_sector(targets)
    assert set(np.unique(home)) == set(SECTORS)
    for k in SECTORS:
        assert in_pointing_sector(targets[home == k], k).all()


def test_every_direction_belongs_to_at_least_one_pointing_sector(rng):
    targets = sector_origin() + 5.0 * _sphere(rng, 20000)
    count = sum(in_pointing_sector(targets, k).astype(int) for k in SECTORS)
    assert count.min() >= 1


def test_each_posture_aims_at_99_percent_of_its_pointing_sector(robot, rng):
    """Targets 2-10 m away in pointing sector k: posture k aims collision-free with a clear line of sight."""
    for k in SECTORS:
        d = _sphere(rng, 6000)
        targets = sector_origin() + d * rng.uniform(2.0, 10.0, (6000, 1))
        targets = targets[in_pointing_sector(targets, k)][:1500]
        _, ok = aim_checked(robot, targets, k)
        assert ok.mean() >= 0.99, f"sector {k}: {100 * ok.mean():.2f}%"


@pytest.mark.parametrize("boundary_az", [0.0, 90.0, 180.0, -90.0])
def test_pointing_sectors_overlap_every_posture_boundary(boundary_az):
    """Targets within 4 deg of a posture-sector boundary lie in both neighbours' pointing sectors."""
    for el in np.linspace(-80, 80, 17):
        for daz in (-4.0, 4.0):
            t = sector_origin() + 6.0 * _direction(boundary_az + daz, el)
            left = posture_sector(sector_origin() + 6.0 * _direction(boundary_az - 4.0, el))
            right = posture_sector(sector_origin() + 6.0 * _direction(boundary_az + 4.0, el))
            assert left != right
            assert in_pointing_sector(t, left) and in_pointing_sector(t, right)


def test_target_jittering_on_a_boundary_switches_sector_at_most_once(rng):
    for boundary_az in (0.0, 90.0, 180.0, -90.0):
        for el in (-30.0, 0.0, 30.0):
            current, switches = None, 0
            for _ in range(200):
                t = sector_origin() + 6.0 * _direction(boundary_az + rng.uniform(-4, 4), el + rng.uniform(-2, 2))
                new = select_sector(t, current)
                switches += current is not None and new != current
                current = new
            assert switches <= 1


def test_select_sector_keeps_the_current_sector_inside_its_pointing_sector():
    t = sector_origin() + 6.0 * _direction(-3.0, 0.0)  # posture sector 4, pointing sectors 3 and 4
    assert posture_sector(t) == 4
    assert select_sector(t, 3) == 3 and select_sector(t, None) == 4
    far = sector_origin() + 6.0 * _direction(-100.0, 0.0)
    assert select_sector(far, 3) == 1
    assert 3 in pointing_sectors(t) and 4 in pointing_sectors(t)


def test_polar_cap_belongs_to_every_pointing_sector():
    t = sector_origin() + np.array([0.01, -0.02, 5.0])
    assert pointing_sectors(t) == (1, 2, 3, 4)


def test_pointing_azimuths_contain_posture_azimuths_with_margin():
    for k in SECTORS:
        (plo, phi), (qlo, qhi) = POSTURE_AZIMUTH[k], POINTING_AZIMUTH[k]
        assert qlo <= plo - np.deg2rad(5) + 1e-12 and qhi >= phi + np.deg2rad(5) - 1e-12


def test_table3_trajectories_start_and_end_at_their_presets():
    assert len(CROSS_SECTOR_TRAJECTORIES) == 12
    for (i, j), w in CROSS_SECTOR_TRAJECTORIES.items():
        assert w.shape == (7, 2)
        np.testing.assert_allclose(w[0], POSTURE_PRESETS[i])
        np.testing.assert_allclose(w[-1], POSTURE_PRESETS[j])
    np.testing.assert_allclose(np.rad2deg(cross_sector_trajectory(1, 4)[-1]), [50.0, 20.0])


def test_presets_put_the_pointing_system_where_documented(robot):
    y_side = {1: -1, 2: 1, 3: 1, 4: -1}
    for k in SECTORS:
        q = np.r_[posture_preset(k), 0.0, 0.0]
        p = robot.joint_placement(q, "j3").translation
        assert np.sign(p[1]) == y_side[k]
        assert (p[2] > sector_origin()[2]) == (k in (3, 4))
        assert robot.is_valid(q)


@pytest.mark.parametrize("bad", [0, 5, -1, True, 1.0, "2", None])
def test_unknown_sector_numbers_raise(bad):
    with pytest.raises(ValueError, match="unknown sector"):
        check_sector(bad)
    with pytest.raises(ValueError, match="unknown sector"):
        in_pointing_sector(np.array([5.0, 0.0, 1.0]), bad)


def test_bad_targets_raise():
    with pytest.raises(ValueError, match="NaN or inf"):
        posture_sector(np.array([np.nan, 0.0, 1.0]))
    with pytest.raises(ValueError, match="no direction"):
        target_direction(sector_origin())
    with pytest.raises(ValueError, match="shape"):
        in_pointing_sector(np.zeros(2), 1)
    with pytest.raises(ValueError, match="itself"):
        cross_sector_trajectory(2, 2)


def _length(W: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(W, axis=0), axis=1).sum())


def _along_row(i: int, j: int, rest: np.ndarray) -> np.ndarray:
    """Path (7, 2 + k): DOF1/DOF2 on the Table 3 row, the other joints at the given 7 rows."""
    return np.hstack([cross_sector_trajectory(i, j), rest])


@pytest.mark.parametrize("pair", [(1, 2), (3, 4), (1, 4), (2, 4)])
def test_length_bound_is_attained_by_the_other_joints_moving_with_the_rows_arc_length(pair, rng):
    i, j = pair
    row = cross_sector_trajectory(i, j)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(row, axis=0), axis=1))])
    a, b = rng.uniform(-1.0, 1.0, 2), rng.uniform(-1.0, 1.0, 2)
    W = _along_row(i, j, a + (s / s[-1])[:, None] * (b - a))
    assert _length(W) == pytest.approx(cross_sector_length_bound(W[0], W[-1], i, j), rel=1e-12)


def test_no_path_along_a_row_is_shorter_than_its_length_bound(rng):
    for _ in range(500):
        i, j = (int(k) for k in rng.choice(SECTORS, 2, replace=False))
        rest = rng.uniform(-2.0, 2.0, (7, 2))
        W = _along_row(i, j, rest)
        bound = cross_sector_length_bound(W[0], W[-1], i, j)
        straight = float(np.linalg.norm(W[-1] - W[0]))
        assert straight - 1e-12 <= bound <= _length(W) + 1e-12


def test_length_bound_refuses_a_start_off_the_row():
    row = cross_sector_trajectory(1, 2)
    start, goal = np.r_[row[0] + 0.1, 0.0, 0.0], np.r_[row[-1], 0.0, 0.0]
    with pytest.raises(ValueError, match="start's DOF1/DOF2"):
        cross_sector_length_bound(start, goal, 1, 2)
    with pytest.raises(ValueError, match="same size"):
        cross_sector_length_bound(goal, goal[:3], 1, 2)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), 1e308])
def test_the_length_bound_refuses_joint_values_that_are_no_angles(bad):
    start = np.r_[posture_preset(1), bad, 0.0]
    goal = np.r_[posture_preset(2), 0.0, 0.0]
    with pytest.raises(ValueError, match="finite joint angles"):
        cross_sector_length_bound(start, goal, 1, 2)


@pytest.mark.parametrize("target", [np.array([[5.0, 2.0, 1.5]]), np.array([5.0, 2.0]), np.zeros((2, 3))])
def test_select_sector_takes_one_target_and_names_another_shape(target):
    with pytest.raises(ValueError, match=r"one point of shape \(3,\)"):
        select_sector(target, current=3)
