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


def test_a_plain_ompl_setup_solves_without_loading_the_robot_model_stack() -> None:
    """The validator check of every solve imported the package's motion validator, and with it Pinocchio and Coal:
    0.3-0.4 s inside a first solve's time budget (a 0.01-s solve of a 2-D wall gave TIMEOUT, the second one EXACT)."""
    import subprocess
    import sys

    code = """
import sys
from ompl import base as ob
from tpee_ompl import DimensionRRT
sp = ob.RealVectorStateSpace(2); sp.setBounds(0, 1); si = ob.SpaceInformation(sp)
si.setStateValidityChecker(lambda s: not (0.4 < s[0] < 0.6 and s[1] < 0.8)); si.setup()
a = si.allocState(); a[0] = 0.1; a[1] = 0.2
b = si.allocState(); b[0] = 0.9; b[1] = 0.2
pdef = ob.ProblemDefinition(si); pdef.setStartAndGoalStates(a, b)
pl = DimensionRRT(si, seed=1); pl.setProblemDefinition(pdef); pl.setup()
status = pl.solve(1.0)
print(status, sorted(m for m in ("pinocchio", "coal", "hppfcl") if m in sys.modules))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[0] == "Exact solution []"
