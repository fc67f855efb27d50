"""The planners' shared helpers: status names the bindings leave unnamed."""

from __future__ import annotations

import numpy as np
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


def _wall_planner() -> object:
    """DimensionRRT (a PythonPlanner) on a 2-D wall problem."""
    from tpee_ompl import DimensionRRT

    sp = ob.RealVectorStateSpace(2)
    sp.setBounds(0, 1)
    si = ob.SpaceInformation(sp)
    si.setStateValidityChecker(lambda s: not (0.4 < s[0] < 0.6 and s[1] < 0.8))
    si.setup()
    a, b = si.allocState(), si.allocState()
    a[0], a[1], b[0], b[1] = 0.1, 0.2, 0.9, 0.2
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(a, b)
    planner = DimensionRRT(si, seed=1)
    planner.setProblemDefinition(pdef)
    return planner


@pytest.mark.parametrize("ptc", ["x", None, True, [1.0]])
def test_solve_refuses_what_is_neither_a_termination_condition_nor_seconds_naming_ptc(ptc: object) -> None:
    """A str was called as the condition inside the run: CRASH, with "'str' object is not callable" logged."""
    with pytest.raises(TypeError, match="ptc must be an ompl.base.PlannerTerminationCondition or a number of seconds"):
        _wall_planner().solve(ptc)


@pytest.mark.parametrize("ptc", [1, 1.0, np.float32(1.0), "condition"])
def test_solve_takes_seconds_of_any_number_type_or_a_termination_condition(ptc: object) -> None:
    ptc = ob.timedPlannerTerminationCondition(1.0) if ptc == "condition" else ptc
    assert _wall_planner().solve(ptc) == ob.PlannerStatus.EXACT_SOLUTION
