"""Property-based tests (hypothesis) of dimension-RRT's parameters and statuses: adversarial inputs work or raise one documented error."""

from __future__ import annotations

import gc
import math
import re
from collections.abc import Iterator

import numpy as np
import pytest
from helpers.strategies import (
    FEW,
    SETTINGS,
    numbers,
)
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from ompl import base as ob

from tpee_ompl.model.sectors import (
    posture_preset,
)
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.paths import set_state
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.planning.tpee import tpee_dimension_rrt

BAD_PARAMETERS = {
    "groups": (st.one_of(
        st.lists(st.lists(st.integers(-1, 5), max_size=4), max_size=3),
        st.lists(st.lists(st.sampled_from([0.5, "1", None, 2]), min_size=1, max_size=2), min_size=1, max_size=2),
        st.sampled_from(["01", 3, [[0, 1], [2, 3.0]]]),
    ), "group|DOF"),
    "h": (st.one_of(st.integers(-5, 2), st.sampled_from([7.0, "7", True, 10**9])), "h "),
    "max_samples": (st.one_of(st.integers(-5, 0), st.sampled_from([1.5, "10", True, math.nan])), "max_samples"),
    "narrowing": (st.one_of(numbers.filter(lambda v: not 0 < v <= 1), st.sampled_from(["0.5", True])), "narrowing"),
    "narrow_after": (st.one_of(st.integers(-5, -1), st.sampled_from([2.5, "3"])), "narrow_after"),
    "seed": (st.one_of(st.integers(-5, -1), st.sampled_from([1.5, "1", True])), "seed"),
    "range_": (st.one_of(numbers.filter(lambda v: not (math.isfinite(v) and v > 0)),
                         st.sampled_from(["x", [0.1, 0.1], [[0.1] * 4]])), "range_"),
    "prescribed": (st.one_of(
        st.builds(lambda n: {0: np.zeros((n, 2))}, st.integers(0, 6)),
        st.sampled_from([{0: [[math.nan, 0]] * 7}, {0: "abc"}, {9: np.zeros((7, 2))}, {"0": np.zeros((7, 2))}, [1]]),
    ), "prescribed"),
    "name": (st.sampled_from(["", 3, None]), "name"),
}


@pytest.fixture(scope="module")
def plain_si(robot: WearerArm) -> Iterator[ob.SpaceInformation]:
    ss = make_simple_setup(robot)
    yield ss.getSpaceInformation()  # ss stays alive (it owns the checkers) until the module ends


@SETTINGS
@given(data=st.data(), param=st.sampled_from(sorted(BAD_PARAMETERS)))
def test_bad_dimension_rrt_parameters_raise_value_error_naming_them(plain_si, data, param: str) -> None:
    strategy, match = BAD_PARAMETERS[param]
    value = data.draw(strategy)
    try:
        planner = DimensionRRT(plain_si, **{param: value})
    except ValueError as exc:
        assert re.search(match, str(exc)), (param, value, str(exc))
    else:  # only a value that happens to be valid may construct
        assert param == "groups" and planner.groups == [[int(d) for d in g] for g in value]
    gc.collect()


def test_many_bad_constructions_then_gc_do_not_crash(plain_si) -> None:
    """A ValueError raised after Planner.__init__ left a half-built trampoline that crashed at collection."""
    bad = [{"h": 2}, {"max_samples": 0}, {"narrowing": 2.0}, {"seed": -1}, {"groups": [[0, 0]]},
           {"range_": -1.0}, {"prescribed": {0: np.zeros((3, 2))}}, {"name": ""}]
    for round_ in range(300):
        with pytest.raises(ValueError):
            DimensionRRT(plain_si, **bad[round_ % len(bad)])
        if round_ % 50 == 0:
            gc.collect()
    gc.collect()
    ok = DimensionRRT(plain_si, max_samples=5)  # the class still works afterwards
    assert ok.getName() == "DimensionRRT"


def _solve_status(robot: WearerArm, start, goal, i: int, j: int, **setup_kw) -> ob.PlannerStatus:
    ss = make_simple_setup(robot, start, goal, check_endpoints=False, **setup_kw)
    ss.setPlanner(tpee_dimension_rrt(ss.getSpaceInformation(), i, j, max_samples=20, seed=0))
    return ss.solve(5.0)


@FEW
@given(
    dq=hnp.arrays(float, (4,), elements=st.sampled_from([0.0, 0.3, -0.3, 5.0, -5.0])),
    which=st.sampled_from(["start", "goal"]),
)
def test_dimension_rrt_reports_invalid_endpoints_as_statuses(robot: WearerArm, dq: np.ndarray, which: str) -> None:
    i, j = 1, 4
    start, goal = np.r_[posture_preset(i), 0.0, 0.0], np.r_[posture_preset(j), 0.0, 0.0]
    bad = (start if which == "start" else goal) + dq
    s0, s1 = (bad, goal) if which == "start" else (start, bad)
    status = _solve_status(robot, s0, s1, i, j)
    on_table3 = np.allclose(dq[:2], 0)
    if on_table3 and robot.is_valid(bad):
        assert status in (ob.PlannerStatus.EXACT_SOLUTION, ob.PlannerStatus.TIMEOUT)
    else:
        expected = ob.PlannerStatus.INVALID_START if which == "start" else ob.PlannerStatus.INVALID_GOAL
        assert status == expected, (dq, status)


def test_set_state_round_trip_survives_property_run(plain_si) -> None:
    """Sanity: the module-scoped setup is still usable after all the bad constructions above."""
    s = plain_si.allocState()
    set_state(s, [0.1, 0.2, 0.3, 0.4])
    assert [s[i] for i in range(4)] == pytest.approx([0.1, 0.2, 0.3, 0.4])
