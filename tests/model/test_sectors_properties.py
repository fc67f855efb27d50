"""Property-based tests (hypothesis) of the sector functions: adversarial inputs work or raise one documented error."""

from __future__ import annotations

import numpy as np
from helpers.strategies import (
    SETTINGS,
    resolve_target,
    targets,
)
from hypothesis import assume, given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tpee_ompl.model.pointing import (
    default_geometry,
)
from tpee_ompl.model.sectors import (
    SECTORS,
    cross_sector_trajectory,
    in_pointing_sector,
    posture_preset,
    posture_sector,
    select_sector,
)
from tpee_ompl.model.wearer_arm import WearerArm


@SETTINGS
@given(t=targets, current=st.one_of(st.none(), st.sampled_from(SECTORS)))
def test_sector_functions_agree_with_each_other_for_any_finiteresolve_target(robot: WearerArm, t, current) -> None:
    t = resolve_target(robot, t)
    try:
        home = posture_sector(t)
    except ValueError as exc:
        assert not np.all(np.isfinite(t)) or np.allclose(t, default_geometry().pivot)
        assert "nan" in str(exc) or "inf" in str(exc) or "origin" in str(exc), str(exc)
        return
    assert home in SECTORS
    assert in_pointing_sector(t, home)  # a pointing sector contains its posture sector
    chosen = select_sector(t, current)
    if current is not None and in_pointing_sector(t, current):
        assert chosen == current
    else:
        assert chosen == home


@SETTINGS
@given(scale=st.sampled_from([1.0, 1e6, 1e100, 1e300, 1e307]), d=hnp.arrays(float, (3,), elements=st.floats(-1, 1)))
def test_sector_of_a_direction_does_not_depend_on_distance(d: np.ndarray, scale: float) -> None:
    assume(np.max(np.abs(d)) > 1e-3)
    pivot = default_geometry().pivot
    assert posture_sector(pivot + d) == posture_sector(pivot + d * scale)
    assert [in_pointing_sector(pivot + d, k) for k in SECTORS] == [in_pointing_sector(pivot + d * scale, k) for k in SECTORS]


@SETTINGS
@given(i=st.one_of(st.integers(-3, 8), st.sampled_from([1.0, "1", None, True])), j=st.integers(-3, 8))
def test_sector_numbers_are_validated(i, j: int) -> None:
    try:
        traj = cross_sector_trajectory(i, j)
    except ValueError as exc:
        assert "sector" in str(exc)
        return
    assert traj.shape == (7, 2)
    np.testing.assert_array_equal(traj[0], posture_preset(i))
    np.testing.assert_array_equal(traj[-1], posture_preset(j))
