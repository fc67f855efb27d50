"""Libraries shared by the path-library test modules, built once per session (tests/helpers/library_standins.py).

Tests that change a library's fallback planner do it with ``monkeypatch`` so the next module sees
the library as built.
"""

from __future__ import annotations

import pytest
from helpers.library_standins import build_rrt_library, build_standin_library

from tpee_ompl.library import PathLibrary
from tpee_ompl.model.wearer_arm import WearerArm


@pytest.fixture(scope="session")
def library(robot: WearerArm) -> PathLibrary:
    """Stand-in sampler and straight planner, pairs 1->2 and 2->3 (fast)."""
    return build_standin_library(robot)


@pytest.fixture(scope="session")
def rrt_library(robot: WearerArm) -> PathLibrary:
    """The default builders (query sampler, DemoPlanner) with small caps, pairs 1->2 and 3->4 (~5 s)."""
    return build_rrt_library(robot)
