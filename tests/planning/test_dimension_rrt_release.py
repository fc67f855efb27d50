"""DimensionRRTOptions.release_after: a converged path leaves its prescribed rows and gets shorter than any path along them."""

from __future__ import annotations

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.planning.dimension_rrt import DimensionRRT, DimensionRRTOptions
from tpee_ompl.planning.paths import path_passes_motion_checks

# DOF0/DOF1 prescribed on a wide detour around a small square at the origin of the (x0, x1) plane
ROW = np.array([(-0.8, 0.0), (-0.5, 0.4), (-0.2, 0.6), (0.0, 0.6), (0.2, 0.6), (0.5, 0.4), (0.8, 0.0)])
START, GOAL = (-0.8, 0.0, 0.0, 0.0), (0.8, 0.0, 0.3, -0.2)


def _setup() -> og.SimpleSetup:
    space = ob.RealVectorStateSpace(4)
    space.setBounds(-1.0, 1.0)
    ss = og.SimpleSetup(space)

    def valid(s: ob.State) -> bool:
        return not (abs(s[0]) < 0.1 and abs(s[1]) < 0.1)

    ss.setStateValidityChecker(valid)
    si = ss.getSpaceInformation()
    si.setStateValidityCheckingResolution(0.005)
    a, b = si.allocState(), si.allocState()
    for i in range(4):
        a[i], b[i] = START[i], GOAL[i]
    ss.setStartAndGoalStates(a, b)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    ss._keep = (valid, a, b)
    si.setup()
    return ss


def _row_bound() -> float:
    """Shortest length of any path whose DOF0/DOF1 follow ROW (Minkowski: hypot of the two parts)."""
    rest = np.linalg.norm(np.subtract(GOAL, START)[2:])
    return float(np.hypot(np.linalg.norm(np.diff(ROW, axis=0), axis=1).sum(), rest))


def _solve(**kw) -> tuple[og.SimpleSetup, DimensionRRT]:
    ss = _setup()
    kw.setdefault("max_samples", 3000)
    planner = DimensionRRT(ss.getSpaceInformation(), groups=[[0, 1], [2, 3]], prescribed={0: ROW}, seed=0, **kw)
    ss.setPlanner(planner)
    assert ss.solve(30.0) == ob.PlannerStatus.EXACT_SOLUTION
    return ss, planner


def _waypoints(ss: og.SimpleSetup) -> np.ndarray:
    return np.array([[s[i] for i in range(4)] for s in ss.getSolutionPath().getStates()])


def test_without_release_the_path_keeps_its_prescribed_rows():
    ss, planner = _solve()
    np.testing.assert_array_equal(_waypoints(ss)[:, :2], ROW)
    assert planner.last_run_stats()["released_at"] is None
    assert ss.getSolutionPath().length() >= _row_bound() - 1e-9


def test_released_rows_give_a_proven_path_shorter_than_any_path_along_them():
    ss, planner = _solve(release_after=100)
    stats = planner.last_run_stats()
    assert stats["released_at"] is not None and stats["released_at"] < stats["samples"]
    W = _waypoints(ss)
    assert not np.array_equal(W[:, :2], ROW)
    assert ss.getSolutionPath().length() < 0.9 * _row_bound()
    assert path_passes_motion_checks(ss.getSpaceInformation(), ss.getSolutionPath())


def test_release_is_deterministic_under_a_seed_and_a_sample_cap():
    (a, pa), (b, pb) = _solve(release_after=100), _solve(release_after=100)
    assert pa.last_run_stats()["released_at"] is not None
    assert pa.last_run_stats()["released_at"] == pb.last_run_stats()["released_at"]
    np.testing.assert_array_equal(_waypoints(a), _waypoints(b))


def test_release_happens_exactly_after_release_after_samples_without_a_shorter_path():
    _, planner = _solve(release_after=37, max_samples=3000)
    progress = planner.last_run_stats()["progress"]
    released = planner.last_run_stats()["released_at"]
    best = min(cost for _, cost, n in progress if n <= released)
    last_gain = min(n for _, cost, n in progress if cost == best)  # the trace's entry where that cost came
    assert released - last_gain == 37


def test_stall_counts_on_across_the_release():
    _, planner = _solve(release_after=50, stall_samples=40)  # stall first: no release
    assert planner.last_run_stats()["released_at"] is None


@pytest.mark.parametrize("bad", [0, -5, 2.5, "300"])
def test_release_after_must_be_a_positive_count(bad):
    with pytest.raises(ValueError, match="release_after"):
        DimensionRRTOptions(release_after=bad)


def test_release_after_is_reported_in_the_settings():
    ss = _setup()
    assert DimensionRRT(ss.getSpaceInformation(), release_after=300).settings()["release_after"] == "300"
