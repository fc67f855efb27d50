"""Fixtures shared by the rendering tests."""

from __future__ import annotations

import numpy as np
import pytest

from tpee_ompl.model.sectors import posture_preset


@pytest.fixture(scope="module")
def aimed(robot):
    """Sector-4 posture aiming up and forward, with a target 3 m along the barrel."""
    q = np.concatenate([posture_preset(4), [0.3, -0.6]])
    p, u = robot.muzzle(q)
    return q, p + 3.0 * u
