"""DimensionRRT in a plain OMPL SimpleSetup: a planar 4-link arm among circles, no prescribed group."""

from __future__ import annotations

import numpy as np
import pytest
from ompl import base as ob

from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.examples.planar_arm import PlanarArm, make_planar_arm_setup
from tpee_ompl.planning.paths import path_passes_motion_checks, path_to_array


def test_finds_valid_paths_in_a_plain_ompl_setup() -> None:
    ss = make_planar_arm_setup()
    si = ss.getSpaceInformation()
    for seed in range(3):
        ss.clear()
        planner = DimensionRRT(si, seed=seed, max_samples=600)
        assert planner.groups == [[0, 1], [2, 3]] and not planner.prescribed
        ss.setPlanner(planner)
        assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
        path = ss.getSolutionPath()
        assert path_passes_motion_checks(si, path)
        assert path.getStateCount() == 7
        stats = planner.last_run_stats()
        assert stats["collision_checks"] > 0 and stats["best_cost"] == path.length()


def test_straight_motion_is_blocked_so_planning_is_needed() -> None:
    ss = make_planar_arm_setup()
    checker = ss.getStateValidityChecker()
    assert isinstance(checker, PlanarArm)
    Q = np.linspace([0.3, 0, 0, 0], [2.6, 0, 0, 0], 200)
    assert not checker.are_valid(Q).all()


def test_per_state_fallback_gives_the_same_path() -> None:
    paths = []
    for batch in (True, False):
        ss = make_planar_arm_setup()
        planner = DimensionRRT(ss.getSpaceInformation(), seed=4, max_samples=300, batch=batch)
        ss.setPlanner(planner)
        assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
        paths.append(path_to_array(ss.getSolutionPath(), 4))
    np.testing.assert_array_equal(paths[0], paths[1])


def test_second_solve_without_clear_still_finds_the_start() -> None:
    ss = make_planar_arm_setup()
    planner = DimensionRRT(ss.getSpaceInformation(), seed=1, max_samples=200)
    ss.setPlanner(planner)
    assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
    assert ob.Planner.solve(planner, 10.0) == ob.PlannerStatus.EXACT_SOLUTION


@pytest.mark.slow  # a subprocess and a 1 s solve
def test_the_example_runs_as_a_module_and_reports_both_planners() -> None:
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "tpee_ompl.examples.planar_arm"], capture_output=True, text=True,
                         timeout=120, check=True).stdout.splitlines()
    assert [line.split()[0] for line in out] == ["DimensionRRT", "RRTConnect"]
    assert all("Exact solution" in line and "valid True" in line for line in out)


@pytest.mark.parametrize("kw, match", [({"start": (float("nan"), 0, 0, 0)}, "start"), ({"start": (10.0, 0, 0, 0)}, "start"),
                                       ({"goal": (0.0, 0.0, 0.0)}, "goal"), ({"link_length": float("nan")}, "link_length"),
                                       ({"resolution": 0.0}, "resolution"), ({"obstacles": [1, 2]}, "obstacles")])
def test_the_example_setup_names_a_bad_argument(kw, match):
    with pytest.raises(ValueError, match=match):
        make_planar_arm_setup(**kw)
