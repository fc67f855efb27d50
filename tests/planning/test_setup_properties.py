"""Property-based tests (hypothesis) of the OMPL set-up: adversarial inputs work or raise one documented error."""

from __future__ import annotations

import numpy as np
from helpers.strategies import (
    SETTINGS,
    configs,
    names_bad_value,
    numbers,
)
from hypothesis import given
from hypothesis import strategies as st

from tpee_ompl.model.sectors import (
    posture_preset,
)
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.paths import MIN_JOINT_STEP
from tpee_ompl.planning.setup import make_simple_setup, motion_check_step


@SETTINGS
@given(step=st.one_of(numbers, st.integers(-2, 20), st.sampled_from([None, "0.01", True])))
def test_make_simple_setup_joint_step_is_validated(robot: WearerArm, step) -> None:
    try:
        ss = make_simple_setup(robot, joint_step=step)
    except ValueError as exc:
        assert "joint_step" in str(exc)
        assert step is not None
        return
    got = motion_check_step(ss)
    assert got == (robot.max_joint_step() if step is None else float(step)) and got >= MIN_JOINT_STEP


@SETTINGS
@given(start=configs)
def test_make_simple_setup_refuses_bad_start_with_value_error(robot: WearerArm, start: np.ndarray) -> None:
    goal = np.r_[posture_preset(3), 0.0, 0.0]
    try:
        make_simple_setup(robot, start, goal)
    except ValueError as exc:
        assert "start" in str(exc) or names_bad_value(str(exc), start), str(exc)
        return
    assert robot.is_valid(start)
