"""The fake-time grouped view: validation, group path-space points, paths, metric."""

from __future__ import annotations

import numpy as np
import pytest
from ompl import base as ob

from tpee_ompl.planning.grouped_space import GroupedSpace, default_groups, interpolate_waypoints
from tpee_ompl.model.sectors import cross_sector_trajectory


def _space(n: int = 4, bound: float = 2.0) -> ob.RealVectorStateSpace:
    space = ob.RealVectorStateSpace(n)
    space.setBounds(-bound, bound)
    return space


def test_default_groups_are_pairs() -> None:
    assert default_groups(4) == [[0, 1], [2, 3]]
    assert default_groups(5) == [[0, 1], [2, 3], [4]]


@pytest.mark.parametrize(
    ("groups", "h", "match"),
    [([[0, 1], [1, 2, 3]], 7, "more than one group"), ([[0, 1], [3]], 7, "in no group"), ([[0, 1], [2, 4]], 7, "out of range"), ([[0, 1, 2, 3]], 2, "h")],
)
def test_bad_groups_and_h_raise(groups, h, match) -> None:
    with pytest.raises(ValueError, match=match):
        GroupedSpace(_space(), groups, h)


def test_group_point_round_trip_and_initial_path() -> None:
    T = cross_sector_trajectory(1, 4)
    gs = GroupedSpace(_space(bound=3.2), [[0, 1], [2, 3]], 7, {0: T})  # Table 3 rows reach 2.79 rad
    start, goal = np.r_[T[0], 0.5, -0.5], np.r_[T[-1], -1.0, 1.0]
    W = gs.initial_waypoints(start, goal)
    assert W.shape == (7, 4) and gs.planned == [1]
    np.testing.assert_allclose(W[:, :2], T)
    np.testing.assert_allclose(W[:, 2:], interpolate_waypoints(start[2:], goal[2:], 7))
    x = gs.group_point(W, 1)
    assert x.shape == (10,)  # (h - 2) * k = 5 * 2, the paper's 10-D path space
    W2 = gs.with_group_point(W, 1, x + 0.1)
    np.testing.assert_allclose(W2[1:-1, 2:], W[1:-1, 2:] + 0.1)
    np.testing.assert_array_equal(W2[[0, -1]], W[[0, -1]])
    assert gs.endpoint_mismatch(start, goal) is None
    assert gs.endpoint_mismatch(np.r_[0.0, 0.0, 0.5, -0.5], goal) == "start"


def test_released_space_plans_every_dof_in_one_group_with_nothing_prescribed() -> None:
    gs = GroupedSpace(_space(bound=3.2), [[0, 1], [2, 3]], 7, {0: cross_sector_trajectory(1, 4)})
    released = gs.released()
    assert released.groups == [[0, 1, 2, 3]] and released.planned == [0] and not released.prescribed
    assert released.h == gs.h


def test_path_round_trip_and_metric_match_ompl() -> None:
    space = _space()
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda s: True)
    si.setup()
    gs = GroupedSpace(si)
    W = np.random.default_rng(0).uniform(-2, 2, (7, 4))
    path = gs.to_path(si, W)
    np.testing.assert_allclose(gs.from_path(path), W)
    assert gs.path_length(W) == pytest.approx(path.length())


def test_group_dims_bounds_and_planned_dims_are_shared_read_only() -> None:
    T = cross_sector_trajectory(1, 4)
    gs = GroupedSpace(_space(bound=3.2), [[0, 1], [3, 2]], 7, {0: T})
    np.testing.assert_array_equal(gs.group_dims(1), [3, 2])
    np.testing.assert_array_equal(gs.planned_dims, [2, 3])  # in index order
    lo, hi = gs.group_bounds(1)
    np.testing.assert_array_equal(lo, [-3.2, -3.2])
    for arr in (gs.group_dims(1), lo, hi, gs.planned_dims):
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 0


def test_groups_given_as_a_numpy_array_are_taken_as_lists() -> None:
    space = ob.RealVectorStateSpace(4)
    space.setBounds(-1.0, 1.0)
    si = ob.SpaceInformation(space)
    assert GroupedSpace(si, np.array([[0, 1], [2, 3]]), 7).groups == [[0, 1], [2, 3]]


