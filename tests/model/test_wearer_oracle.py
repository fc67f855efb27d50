"""The wearer's checking answers are bit-for-bit those recorded before the generic checker existed.

The oracle (tests/model/data/wearer_oracle.npz) was written by experiments/record_wearer_oracle.py
on the code before :class:`~tpee_ompl.model.robot_checker.RobotChecker`; rerun it only on purpose.

Its pair lists (``*_pairs``) alone were written again on 2026-11-27, when the pruning was found to remove the wrong
pairs (views into Pinocchio's pair vector, shifted by each removal): five forearm-arm pairs are checked now and
five foot-arm pairs (out of reach) are not; every verdict, clearance and closest pair of the oracle is unchanged.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

from tpee_ompl.model.wearer_arm import WearerArm

ROOT = Path(__file__).resolve().parents[2]
ORACLE = Path(__file__).parent / "data" / "wearer_oracle.npz"


def _recorder():
    """The recording script as a module (it imports ``_common`` from its own folder, as a script run does)."""
    spec = importlib.util.spec_from_file_location("record_wearer_oracle", ROOT / "experiments/record_wearer_oracle.py")
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(ROOT / "experiments"))
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(ROOT / "experiments"))
    return module


@pytest.fixture(scope="module")
def oracle():
    with np.load(ORACLE) as data:
        return dict(data)


@pytest.mark.parametrize("setting", ["default", "margin0", "links"])
def test_wearer_answers_match_the_recorded_oracle_bit_for_bit(oracle, setting):
    rec = _recorder()
    robot = WearerArm(n_threads=2, **rec.SETTINGS[setting])
    now = rec.record(robot, oracle["Q"], setting)
    for key, value in now.items():
        want = oracle[key]
        assert value.shape == want.shape, key
        if value.dtype.kind == "f":
            np.testing.assert_array_equal(value, want, err_msg=key)  # exact, NaN == NaN
        else:
            assert (value == want).all(), key
