"""Shared fixtures: the packaged model, loaded once per test session."""

from __future__ import annotations

import os

import numpy as np
import pytest

os.environ.setdefault("MPLBACKEND", "Agg")

from ompl import util as ou  # noqa: E402

from tpee_ompl.model.wearer_arm import WearerArm, default_robot

ou.setLogLevel(ou.LOG_WARN)


@pytest.fixture(scope="session")
def robot() -> WearerArm:
    """The packaged wearer + arm model (shared, read-only)."""
    return default_robot()


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator, fresh for each test."""
    return np.random.default_rng(12345)
