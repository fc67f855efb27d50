"""Tests of the demonstrations (section 4.2.2): the default query sampler and the demo planners' margin ladder."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.library_standins import RRT_PAIRS, necessary_queries

from tpee_ompl.library import PathLibrary
from tpee_ompl.model.sectors import cross_sector_trajectory, posture_preset
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.paths import motion_is_valid


@pytest.mark.slow
def test_default_sampler_draws_planning_necessary_motions_from_the_presets(robot: WearerArm) -> None:
    from tpee_ompl.library.demos import query_sampler
    from tpee_ompl.planning.query_generation import straight_motion_valid

    sample = query_sampler(robot)
    rng = np.random.default_rng(5)
    for i, j in RRT_PAIRS:
        start, goal = sample(rng, i, j)
        np.testing.assert_allclose(start[:2], posture_preset(i))
        np.testing.assert_allclose(goal[:2], posture_preset(j))
        assert robot.is_valid(start) and robot.is_valid(goal)
        assert not straight_motion_valid(robot, start, goal, i, j)


@pytest.mark.slow
def test_dimension_rrt_builder_stores_planned_demos_that_pass_the_motion_check(robot: WearerArm, rrt_library: PathLibrary) -> None:
    assert set(rrt_library.pairs) == set(RRT_PAIRS) and len(rrt_library) == 2 * len(RRT_PAIRS)
    for (i, j), pd in rrt_library.pairs.items():
        for start, goal, W in zip(pd.starts, pd.goals, pd.waypoints):
            np.testing.assert_allclose(W[:, :2], cross_sector_trajectory(i, j), atol=1e-12)
            assert np.array_equal(W[0], start) and np.array_equal(W[-1], goal)
            assert motion_is_valid(robot, W)
    assert rrt_library.build_params["per_pair"] == 2 and rrt_library.build_params["seed"] == 3


@pytest.mark.slow
def test_demonstrations_keep_the_wider_margin_they_were_planned_with(robot: WearerArm, rrt_library: PathLibrary) -> None:
    from tpee_ompl.library.demos import DEMO_MARGINS, POINTING_LINKS

    margins = np.concatenate([pd.margins for pd in rrt_library.pairs.values()])
    assert set(margins) <= {*DEMO_MARGINS, robot.security_margin}
    assert (margins > robot.security_margin).any()
    for pd in rrt_library.pairs.values():
        for W, m in zip(pd.waypoints, pd.margins):
            wide = WearerArm(link_margins={name: float(m) for name in POINTING_LINKS})
            assert motion_is_valid(wide, W, robot.max_joint_step())
    stored = sum(v for k, v in rrt_library.build_stats.items() if k.startswith("stored_at_"))
    assert stored == rrt_library.build_stats["stored"] == len(rrt_library)


def test_demo_planner_rungs_are_never_looser_than_the_robot(rng) -> None:
    from tpee_ompl.library.demos import DemoPlanner

    strict = WearerArm(link_margins={"link4": 0.05})
    plan = DemoPlanner(strict, margins=(0.035, 0.01), max_samples=10)
    assert plan.margins == (0.035, strict.security_margin)
    Q = rng.uniform(strict.lower, strict.upper, size=(2000, 4))
    assert tuple(m for m, _ in plan.rungs) == plan.margins
    for _, rung in plan.rungs:
        assert not np.any(rung.are_valid(Q) & ~strict.are_valid(Q))


@pytest.mark.parametrize("margins", [(float("nan"),), (-0.01,), (2.0,), ("wide",)])
def test_bad_demo_margins_raise_value_error(robot: WearerArm, margins) -> None:
    from tpee_ompl.library.demos import DemoPlanner

    with pytest.raises(ValueError, match="demo margins"):
        DemoPlanner(robot, margins=margins)
    with pytest.raises(ValueError, match="demo margins"):
        PathLibrary.build_default(robot, per_pair=1, pairs=((1, 2),), demo_margins=margins)


def test_demo_planner_falls_back_to_the_robots_margin_when_the_wide_one_rejects_the_start(robot: WearerArm) -> None:
    from tpee_ompl.library.demos import POINTING_LINKS, DemoPlanner

    q = next(q for q in necessary_queries(((1, 2), (2, 1), (3, 4), (4, 3), (4, 2), (2, 4)), 120)
             if not WearerArm(link_margins={n: 0.03 for n in POINTING_LINKS}).is_valid(q.start))
    plan = DemoPlanner(robot, margins=(0.03,), max_samples=300, timeout=5.0)
    W = plan(q.start, q.goal, q.from_sector, q.to_sector)
    assert W is not None and plan.last_margin == robot.security_margin and plan.counts == {"margin_20mm": 1}


def _shifted_plan(robot: WearerArm, row: int, dof: int, by: float):
    """The straight stand-in plan with waypoint ``row``'s DOF ``dof`` moved by ``by`` rad (no motion check)."""
    from helpers.library_standins import straight_plan

    plan = straight_plan(robot)

    def shifted(start, goal, i, j):
        W = plan(start, goal, i, j)
        if W is None:
            return None
        W = W.copy()
        W[row, dof] += by
        return W

    return shifted


@pytest.mark.parametrize("row, dof, by, match", [
    (3, 2, 10.0, "plan returned a path for pair 1->2 that leaves the robot's joint limits"),
    (-1, 3, 0.01, "plan returned a path for pair 1->2 that does not run from the query's start to its goal"),
    (0, 0, 0.05, "plan returned a path for pair 1->2 that does not start at sector 1's Table-1 preset"),
])
def test_a_plan_path_a_library_file_could_not_hold_is_refused_naming_plan(robot: WearerArm, row, dof, by,
                                                                           match: str) -> None:
    """Such paths were stored: save() wrote the library and load() then refused it."""
    from helpers.library_standins import sampler

    with pytest.raises(ValueError, match=match):
        PathLibrary.build(robot, sampler(robot), _shifted_plan(robot, row, dof, by), pairs=((1, 2),), per_pair=2)


@pytest.mark.parametrize("which, dof, by, match", [
    (0, 0, 0.05, "sample_query returned a query for pair 1->2 that does not start at sector 1's Table-1 preset"),
    (1, 1, -0.05, "sample_query returned a query for pair 1->2 that does not end at sector 2's Table-1 preset"),
    (1, 3, 50.0, "sample_query returned a query for pair 1->2 that leaves the robot's joint limits"),
])
def test_a_query_off_its_presets_or_limits_is_refused_naming_sample_query(robot: WearerArm, which, dof, by,
                                                                        match: str) -> None:
    from helpers.library_standins import sampler, straight_plan

    base = sampler(robot)

    def sample(rng, i, j):
        q = [np.array(v) for v in base(rng, i, j)]
        q[which][dof] += by
        return q[0], q[1]

    with pytest.raises(ValueError, match=match):
        PathLibrary.build(robot, sample, straight_plan(robot), pairs=((1, 2),), per_pair=2)


@pytest.mark.parametrize("answer, match", [
    (None, r"sample_query must return \(start, goal\)"), ((np.zeros(4),), r"sample_query must return \(start, goal\)"),
    ((np.zeros(3), np.zeros(4)), "sample_query must return a start and a goal of 4 finite numbers"),
    ((np.full(4, np.nan), np.zeros(4)), "sample_query must return a start and a goal of 4 finite numbers"),
    ((np.zeros(4) + 1j, np.zeros(4)), r"sample_query must return \(start, goal\).*real numbers"),
])
def test_a_sample_query_answer_that_is_no_query_is_named(robot: WearerArm, answer, match: str) -> None:
    from helpers.library_standins import straight_plan

    with pytest.raises(ValueError, match=match):
        PathLibrary.build(robot, lambda rng, i, j: answer, straight_plan(robot), pairs=((1, 2),), per_pair=1)


def test_a_plan_answer_holding_nan_is_named(robot: WearerArm) -> None:
    from helpers.library_standins import sampler

    with pytest.raises(ValueError, match="plan returned a path for pair 1->2 that holds NaN or inf"):
        PathLibrary.build(robot, sampler(robot), lambda s, g, i, j: np.full((7, 4), np.nan), pairs=((1, 2),),
                          per_pair=1)
