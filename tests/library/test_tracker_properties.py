"""Property-based tests (hypothesis) of the tracker: adversarial inputs work or raise one documented error."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from helpers.strategies import (
    FEW,
    SETTINGS,
    SPECIAL,
    numbers,
    resolve_target,
)
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tpee_ompl.library.tracker import Tracker, TrackerOptions
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.paths import MIN_JOINT_STEP


def _no_planner(*_args) -> np.ndarray:
    raise RuntimeError("planning not expected")


@SETTINGS
@given(t=st.one_of(hnp.arrays(float, (3,), elements=st.sampled_from(SPECIAL)), st.sampled_from(["pivot", "torso", "head"])),
       time=st.one_of(st.floats(0, 10), st.sampled_from([math.nan, math.inf, "1"])))
def test_tracker_records_bad_targets_as_unreachable_and_refuses_bad_times(robot: WearerArm, t, time) -> None:
    t = resolve_target(robot, t)
    tracker = Tracker(robot, _no_planner)
    q0 = tracker.q.copy()
    try:
        tracker.step(time, t)
    except ValueError as exc:
        assert "time" in str(exc) and not (isinstance(time, float) and math.isfinite(time))
        return
    except RuntimeError:  # a finite target it could aim at from another sector (planner stub)
        assert np.all(np.isfinite(t))
        return
    res = tracker.result()
    assert res.events[-1].kind in ("unreachable", "blind-area", "aim")
    if res.events[-1].kind == "unreachable":
        np.testing.assert_array_equal(tracker.q, q0)  # holds still


@FEW
@given(shape=st.sampled_from([(2,), (4,), (1, 3), ()]))
def test_tracker_refuses_targets_of_the_wrong_shape(robot: WearerArm, shape) -> None:
    with pytest.raises(ValueError, match="shape"):
        Tracker(robot, _no_planner).step(0.0, np.zeros(shape))


@FEW
@given(speed=numbers, step=st.one_of(numbers, st.just(1e-9)))
def test_tracker_options_are_validated(speed: float, step: float) -> None:
    try:
        opts = TrackerOptions(joint_speed=speed, check_step=step)
    except ValueError as exc:
        assert re.search("joint_speed|check_step", str(exc))
        return
    assert opts.joint_speed > 0 and opts.check_step >= MIN_JOINT_STEP
