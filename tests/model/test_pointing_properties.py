"""Property-based tests (hypothesis) of aiming: adversarial inputs work or raise one documented error."""

from __future__ import annotations

import math
import re

import numpy as np
from helpers.strategies import (
    SETTINGS,
    names_bad_value,
    numbers,
    postures,
    resolve_target,
    targets,
)
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tpee_ompl.model.pointing import (
    AimingError,
    UnreachableTargetError,
    aim,
    aim_batch,
    aim_checked,
    aim_errors,
    check_target,
)
from tpee_ompl.model.sectors import (
    SECTORS,
)
from tpee_ompl.model.wearer_arm import MAX_TARGET_DISTANCE, WearerArm


@SETTINGS
@given(t=targets, posture=postures, ref=st.one_of(st.floats(-10, 10), st.sampled_from([1e300, -1e300, math.nan])))
def test_aim_returns_a_correct_aim_or_raises_aiming_error(robot: WearerArm, t, posture, ref: float) -> None:
    k = posture if isinstance(posture, int) and posture in SECTORS else 3
    t = resolve_target(robot, t, k)
    try:
        q = aim(t, posture, pan_reference=ref)
    except AimingError as exc:
        assert isinstance(exc, ValueError)
        if not (np.all(np.isfinite(t)) and math.isfinite(ref)):
            assert "nan" in str(exc) or "inf" in str(exc), str(exc)
        return
    except ValueError as exc:  # a bad posture, never a bad target
        assert re.search("sector|posture", str(exc)), str(exc)
        return
    assert q.shape == (4,) and np.all(np.isfinite(q)) and robot.within_limits(q)
    _, along, angle = aim_errors(robot, q, t)
    assert along > 0 and angle < 1e-6  # the target really is on the barrel's ray (Pinocchio FK)
    row = aim_batch(t[None], posture, pan_reference=ref, strict=False)[0]
    np.testing.assert_array_equal(row, q)


@SETTINGS
@given(T=hnp.arrays(float, st.tuples(st.integers(1, 5), st.just(3)), elements=numbers), k=st.sampled_from(SECTORS))
def test_non_strict_aim_rows_are_nan_or_correct_and_checked_rows_are_collision_free(robot: WearerArm, T, k) -> None:
    Q = aim_batch(T, k, strict=False)
    Qc, ok = aim_checked(robot, T, k)
    np.testing.assert_array_equal(Q, Qc)
    for t, q, good in zip(T, Q, ok):
        if np.any(np.isnan(q)):
            assert not good and np.all(np.isnan(q))
            continue
        assert np.all(np.isfinite(t)) and np.max(np.abs(t)) <= MAX_TARGET_DISTANCE
        assert aim_errors(robot, q, t)[2] < 1e-6
        if good:
            assert robot.is_valid(q) and robot.line_of_sight_clear(q, t)


@SETTINGS
@given(t=targets)
def test_check_target_refuses_non_finite_far_and_inside_body_targets(robot: WearerArm, t) -> None:
    named = t if isinstance(t, str) else None
    t = resolve_target(robot, t)
    try:
        out = check_target(t, robot)
    except UnreachableTargetError as exc:
        assert names_bad_value(str(exc), t) or "inside" in str(exc), str(exc)
        return
    assert named not in ("torso", "head")
    assert np.all(np.isfinite(out)) and np.max(np.abs(out)) <= MAX_TARGET_DISTANCE
