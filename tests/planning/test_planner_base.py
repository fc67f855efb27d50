"""The planners' shared helpers: status names the bindings leave unnamed."""

from __future__ import annotations

import pytest
from ompl import base as ob

from tpee_ompl.planning.planner_base import planner_status, status_text


@pytest.mark.parametrize(("code", "text"), [(ob.PlannerStatus.ABORT, "Abort"),
                                            (ob.PlannerStatus.INFEASIBLE, "Infeasible"),
                                            (ob.PlannerStatus.EXACT_SOLUTION, "Exact solution"),
                                            (ob.PlannerStatus.TIMEOUT, "Timeout"),
                                            (ob.PlannerStatus.CRASH, "Crash")])
def test_status_text_names_every_status_the_package_returns(code: object, text: str) -> None:
    assert status_text(planner_status(code)) == text
