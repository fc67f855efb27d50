"""Shared fixtures: the packaged model, loaded once per test session.

Test modules are imported with ``--import-mode=importlib`` (see pyproject.toml), so they never
import each other; what several modules share lives in ``tests/helpers/`` (importable as
``helpers.<name>``: this folder is put on ``sys.path`` here, also for worker processes that
inherit it).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

TESTS_DIR = Path(__file__).resolve().parent
if str(TESTS_DIR) not in sys.path:
    sys.path.insert(0, str(TESTS_DIR))
os.environ.setdefault("MPLBACKEND", "Agg")

from ompl import util as ou  # noqa: E402

from tpee_ompl.model.wearer_arm import WearerArm, default_robot  # noqa: E402

ou.setLogLevel(ou.LOG_WARN)


@pytest.fixture(scope="session")
def robot() -> WearerArm:
    """The packaged wearer + arm model (shared, read-only)."""
    return default_robot()


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator, fresh for each test."""
    return np.random.default_rng(12345)


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    session.config._tpee_exit_status = int(exitstatus)  # type: ignore[attr-defined]


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config: pytest.Config) -> None:
    """Leave without interpreter finalisation, keeping pytest's exit status: finalisation only makes the
    nanobind-based OMPL bindings list their "leaked" instances (30 lines after every run)."""
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(getattr(config, "_tpee_exit_status", 0))
