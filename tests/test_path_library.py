"""Tests of the path library (sections 4.2.2-4.2.3): stand-in sampler/planner, then the real builders (dimension-RRT)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.planning.paths import path_to_array
from tpee_ompl.library.path_library import N_FAKE_TIME_STEPS, LibraryFileError, PathLibrary
from tpee_ompl.planning.paths import motion_is_valid, resample_waypoints
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.model.sectors import cross_sector_trajectory, posture_preset

PAIRS = ((1, 2), (2, 3))  # straight stand-in paths are often valid here (never for 3 <-> 4)


def _sampler(robot: WearerArm):
    """Stand-in for the query generator: sector presets for DOF1/2, random valid pan/tilt."""

    def sample(rng: np.random.Generator, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
        out = []
        for k in (i, j):
            while True:
                q = np.concatenate([posture_preset(k), rng.uniform(robot.lower[2:], robot.upper[2:])])
                if robot.is_valid(q):
                    out.append(q)
                    break
        return out[0], out[1]

    return sample


def _straight_plan(robot: WearerArm):
    """Stand-in for dimension-RRT: Table 3 DOF1/2, linear DOF3/4, returned only if it passes the motion check."""

    def plan(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray | None:
        u = np.linspace(0.0, 1.0, N_FAKE_TIME_STEPS)[:, None]
        W = np.hstack([cross_sector_trajectory(i, j), start[2:] + u * (goal[2:] - start[2:])])
        W[0], W[-1] = start, goal
        return W if motion_is_valid(robot, W) else None

    return plan


def _rrt_plan(robot: WearerArm):
    """The straight stand-in, else OMPL RRTConnect (simplified, re-spaced to 7 waypoints on the same segments)."""
    straight = _straight_plan(robot)
    ou.setLogLevel(ou.LOG_WARN)

    def plan(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray | None:
        W = straight(start, goal, i, j)
        if W is not None:
            return W
        ss = make_simple_setup(robot, start, goal)
        ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
        if not ss.solve(2.0) or not ss.haveExactSolutionPath():
            return None
        ss.simplifySolution(0.5)
        path = ss.getSolutionPath()
        if path.getStateCount() > N_FAKE_TIME_STEPS:
            return None
        path.interpolate(N_FAKE_TIME_STEPS)  # adds states on the existing segments only
        W = path_to_array(path, 4)
        return W if W.shape == (N_FAKE_TIME_STEPS, 4) else None

    return plan


@pytest.fixture(scope="module")
def library(robot: WearerArm) -> PathLibrary:
    return PathLibrary.build(robot, _sampler(robot), _straight_plan(robot), pairs=PAIRS, per_pair=4,
                             min_difference=0.3, seed=7)


def test_resampling_keeps_waypoints_and_segment_geometry() -> None:
    W = np.array([[0.0, 0.0], [1.0, 2.0], [3.0, 2.0]])
    R = resample_waypoints(W, per_step=10)
    assert R.shape == (21, 2)
    assert np.array_equal(R[::10], W)
    # every sample of the first segment is on the line y = 2x, between the waypoints
    np.testing.assert_allclose(R[:11, 1], 2 * R[:11, 0])
    assert np.all(np.diff(R[:11, 0]) >= 0)


def test_build_stores_distinct_demonstrations_per_pair(library: PathLibrary) -> None:
    assert set(library.pairs) == set(PAIRS)
    for pd in library.pairs.values():
        assert 1 <= len(pd.starts) <= 4
        keys = pd.keys
        d = np.linalg.norm(keys[:, None] - keys[None], axis=-1) + np.eye(len(keys)) * 1e9
        assert d.min() >= 0.3
        assert len(pd.forward) == len(pd.reverse) == len(pd.starts)
    s = library.stats()
    assert s["build_stored"] == len(library)
    assert s["build_sampled"] == s["build_stored"] + s["build_rejected_similar"] + s["build_plan_failed"]


def test_seeded_build_is_deterministic(robot: WearerArm, library: PathLibrary) -> None:
    again = PathLibrary.build(robot, _sampler(robot), _straight_plan(robot), pairs=PAIRS, per_pair=4,
                              min_difference=0.3, seed=7)
    for key, pd in library.pairs.items():
        other = again.pairs[key]
        assert np.array_equal(pd.waypoints, other.waypoints)
        for a, b in zip(pd.forward + pd.reverse, other.forward + other.reverse):
            assert np.array_equal(a.weights, b.weights)


def test_query_paths_start_and_end_exactly_and_pass_the_motion_check(robot: WearerArm, library: PathLibrary) -> None:
    library.plan = _rrt_plan(robot)
    sample = _sampler(robot)
    rng = np.random.default_rng(3)
    before = library.stats()["queries"]
    outcomes = []
    for i, j in PAIRS:
        for _ in range(4):
            start, goal = sample(rng, i, j)
            res = library.query(start, goal, i, j)
            outcomes.append(res.outcome)
            if res.outcome == "failed":
                assert res.path is None
                continue
            assert np.array_equal(res.path[0], start) and np.array_equal(res.path[-1], goal)
            assert motion_is_valid(robot, res.path)
    s = library.stats()
    assert s["queries"] - before == len(outcomes)
    assert sum(s[k] for k in ("dmp", "repaired", "fallback", "failed")) == s["queries"]
    assert "dmp" in outcomes


def test_query_at_a_demonstration_reproduces_it(library: PathLibrary) -> None:
    (i, j), pd = next(iter(library.pairs.items()))
    path = library.generate(pd.starts[0], pd.goals[0], i, j, 0)
    demo = resample_waypoints(pd.waypoints[0], library.per_step)
    assert np.abs(path - demo).max() < 1e-3


def test_colliding_dmp_path_is_never_returned(robot: WearerArm, library: PathLibrary, monkeypatch) -> None:
    import tpee_ompl.library.path_library as pl

    calls = {"n": 0}

    def reject_dmp_paths(robot_, path, step=None):  # every DMP candidate "collides"; the fallback is checked for real
        calls["n"] += 1
        return calls["n"] > library.n_candidates and motion_is_valid(robot_, path, step)

    (i, j), pd = next(iter(library.pairs.items()))
    library.plan = _straight_plan(robot)
    monkeypatch.setattr(pl, "motion_is_valid", reject_dmp_paths)
    res = library.query(pd.starts[0], pd.goals[0], i, j)
    assert res.outcome == "fallback" and res.candidates_tried == min(library.n_candidates, len(pd.starts))
    assert motion_is_valid(robot, res.path)
    library.plan = None
    calls["n"] = -10**9  # everything "collides", no planner: failed, no path
    res = library.query(pd.starts[0], pd.goals[0], i, j)
    assert res.outcome == "failed" and res.path is None


def test_fallback_starts_from_the_closest_dmp_path(robot: WearerArm, library: PathLibrary, monkeypatch) -> None:
    import tpee_ompl.library.path_library as pl

    seen = {}
    straight = _straight_plan(robot)

    def plan(start, goal, i, j, initial_waypoints=None):
        seen["initial"] = initial_waypoints
        return straight(start, goal, i, j)

    (i, j), pd = next(iter(library.pairs.items()))
    start, goal = pd.starts[0], pd.goals[0]
    monkeypatch.setattr(library, "plan", plan)
    monkeypatch.setattr(pl, "motion_is_valid", lambda robot_, path, step=None: len(path) == N_FAKE_TIME_STEPS
                        and motion_is_valid(robot_, path, step))  # every DMP candidate "collides"
    before = library.stats()["fallback_seeded"]
    res = library.query(start, goal, i, j)
    assert res.outcome == "fallback" and library.stats()["fallback_seeded"] == before + 1
    W = seen["initial"]
    assert W.shape == (N_FAKE_TIME_STEPS, 4) and np.array_equal(W[0], start) and np.array_equal(W[-1], goal)
    np.testing.assert_allclose(W, library.generate(start, goal, i, j, 0)[:: library.per_step])


@pytest.mark.parametrize(
    "args, match",
    [((np.full(4, np.nan), None, 1, 2), "NaN"), ((np.zeros(3), None, 1, 2), "shape"), ((None, None, 2, 2), "no demonstrations"),
     ((None, None, 5, 1), "sector")],
)
def test_demo_order_rejects_bad_input_clearly(library: PathLibrary, args, match: str) -> None:
    (i, j), pd = next(iter(library.pairs.items()))
    start, goal, a, b = args
    with pytest.raises(ValueError, match=match):
        library.demo_order(pd.starts[0] if start is None else start, pd.goals[0] if goal is None else goal, a, b)


def test_with_options_needs_dmp_options(library: PathLibrary) -> None:
    with pytest.raises(ValueError, match="DMPOptions"):
        library.with_options(None)  # type: ignore[arg-type]


def test_library_round_trips_through_disk(robot: WearerArm, library: PathLibrary, tmp_path) -> None:
    f = library.save(tmp_path / "lib.npz")
    loaded = PathLibrary.load(f, robot)
    assert set(loaded.pairs) == set(library.pairs) and len(loaded) == len(library)
    (i, j), pd = next(iter(library.pairs.items()))
    rng = np.random.default_rng(0)
    start = pd.starts[0] + np.r_[0, 0, rng.uniform(-0.1, 0.1, 2)]
    goal = pd.goals[-1]
    for k in range(len(pd.starts)):
        assert np.array_equal(loaded.generate(start, goal, i, j, k), library.generate(start, goal, i, j, k))


def test_truncated_library_file_is_refused(robot: WearerArm, library: PathLibrary, tmp_path) -> None:
    f = library.save(tmp_path / "lib.npz")
    data = f.read_bytes()
    f.write_bytes(data[: len(data) // 2])
    with pytest.raises(LibraryFileError, match="truncated"):
        PathLibrary.load(f, robot)


def test_library_from_another_model_or_version_is_refused(robot: WearerArm, library: PathLibrary, tmp_path, monkeypatch) -> None:
    import tpee_ompl.library.path_library as pl

    f = library.save(tmp_path / "lib.npz")

    class OtherModel:
        model_hash = "0123456789abcdef"

    with pytest.raises(LibraryFileError, match="built for model"):
        PathLibrary.load(f, OtherModel())  # type: ignore[arg-type]
    monkeypatch.setattr(pl, "FORMAT_VERSION", pl.FORMAT_VERSION + 1)
    with pytest.raises(LibraryFileError, match="format version"):
        PathLibrary.load(f, robot)


# ---------------------------------------------------------------------------------------------
# With the real builders: the query generator's sampling and dimension-RRT (small caps)
# ---------------------------------------------------------------------------------------------
RRT_PAIRS = ((1, 2), (3, 4))


@pytest.fixture(scope="module")
def rrt_library(robot: WearerArm) -> PathLibrary:
    return PathLibrary.build_default(robot, per_pair=2, seed=3, pairs=RRT_PAIRS, max_samples=300, timeout=5.0)


def _necessary_queries(pairs, n: int):
    from tpee_ompl.model.queries import load_queries

    return [q for q in load_queries("planning_necessary") if (q.from_sector, q.to_sector) in pairs][:n]


def test_polyline_motion_states_are_the_ompl_motion_states_of_every_segment(robot: WearerArm, rng) -> None:
    from tpee_ompl.planning.paths import motion_states, polyline_motion_states

    path = np.cumsum(rng.uniform(-0.05, 0.05, (30, 4)), axis=0)
    path[10] = path[9]  # a zero-length segment still checks its end state once
    step = robot.max_joint_step()
    expected = np.vstack([path[:1]] + [motion_states(a, b, step) for a, b in itertools.pairwise(path)])
    np.testing.assert_allclose(polyline_motion_states(path, step), expected, atol=1e-15)


def test_default_sampler_draws_planning_necessary_motions_from_the_presets(robot: WearerArm) -> None:
    from tpee_ompl.library.path_library import query_sampler
    from tpee_ompl.planning.query_generation import straight_motion_valid

    sample = query_sampler(robot)
    rng = np.random.default_rng(5)
    for i, j in RRT_PAIRS:
        start, goal = sample(rng, i, j)
        np.testing.assert_allclose(start[:2], posture_preset(i))
        np.testing.assert_allclose(goal[:2], posture_preset(j))
        assert robot.is_valid(start) and robot.is_valid(goal)
        assert not straight_motion_valid(robot, start, goal, i, j)


def test_dimension_rrt_builder_stores_planned_demos_that_pass_the_motion_check(robot: WearerArm, rrt_library: PathLibrary) -> None:
    assert set(rrt_library.pairs) == set(RRT_PAIRS) and len(rrt_library) == 2 * len(RRT_PAIRS)
    for (i, j), pd in rrt_library.pairs.items():
        for start, goal, W in zip(pd.starts, pd.goals, pd.waypoints):
            np.testing.assert_allclose(W[:, :2], cross_sector_trajectory(i, j), atol=1e-12)
            assert np.array_equal(W[0], start) and np.array_equal(W[-1], goal)
            assert motion_is_valid(robot, W)
    assert rrt_library.build_params["per_pair"] == 2 and rrt_library.build_params["seed"] == 3


def test_every_returned_path_passes_si_check_motion_segment_by_segment(robot: WearerArm, rrt_library: PathLibrary) -> None:
    from tpee_ompl.planning.paths import set_state
    from tpee_ompl.library.path_library import dimension_rrt_planner

    rrt_library.plan = dimension_rrt_planner(robot, max_samples=300, timeout=5.0)
    for q in _necessary_queries(RRT_PAIRS, 40)[::5]:
        res = rrt_library.query(q.start, q.goal, q.from_sector, q.to_sector)
        assert res.outcome != "failed"
        assert np.array_equal(res.path[0], q.start) and np.array_equal(res.path[-1], q.goal)
        ss = make_simple_setup(robot, q.start, q.goal)
        si = ss.getSpaceInformation()
        a, b = si.allocState(), si.allocState()
        for u, v in zip(res.path[:-1], res.path[1:]):
            set_state(a, u)
            set_state(b, v)
            assert si.checkMotion(a, b)


def test_seeded_default_build_is_deterministic_with_one_or_two_workers(robot: WearerArm, rrt_library: PathLibrary) -> None:
    again = PathLibrary.build_default(robot, per_pair=2, seed=3, pairs=RRT_PAIRS, max_samples=300, timeout=5.0, workers=2)
    for pair in RRT_PAIRS:
        a, b = rrt_library.pairs[pair], again.pairs[pair]
        assert np.array_equal(a.starts, b.starts) and np.array_equal(a.goals, b.goals)
        assert np.array_equal(a.waypoints, b.waypoints) and np.array_equal(a.margins, b.margins, equal_nan=True)
    assert again.build_stats == rrt_library.build_stats


def test_worker_processes_plan_with_the_callers_robot_and_its_margins() -> None:
    strict = WearerArm(link_margins={"link3": 0.03, "link4": 0.03})
    kw = {"per_pair": 1, "seed": 5, "pairs": ((1, 2), (2, 1)), "max_samples": 200, "timeout": 5.0, "demo_margins": ()}
    one, two = PathLibrary.build_default(strict, workers=1, **kw), PathLibrary.build_default(strict, workers=2, **kw)
    for pair in kw["pairs"]:
        assert np.array_equal(one.pairs[pair].waypoints, two.pairs[pair].waypoints)
        for W in two.pairs[pair].waypoints:
            assert motion_is_valid(strict, W)


def test_demonstrations_keep_the_wider_margin_they_were_planned_with(robot: WearerArm, rrt_library: PathLibrary) -> None:
    from tpee_ompl.library.path_library import DEMO_MARGINS, POINTING_LINKS

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
    from tpee_ompl.library.path_library import DemoPlanner

    strict = WearerArm(link_margins={"link4": 0.05})
    plan = DemoPlanner(strict, margins=(0.035, 0.01), max_samples=10)
    assert plan.margins == (0.035, strict.security_margin)
    Q = rng.uniform(strict.lower, strict.upper, size=(2000, 4))
    for _, rung, _ in plan._rungs:
        assert not np.any(rung.are_valid(Q) & ~strict.are_valid(Q))


@pytest.mark.parametrize("margins", [(float("nan"),), (-0.01,), (2.0,), ("wide",)])
def test_bad_demo_margins_raise_value_error(robot: WearerArm, margins) -> None:
    from tpee_ompl.library.path_library import DemoPlanner

    with pytest.raises(ValueError, match="demo margins"):
        DemoPlanner(robot, margins=margins)
    with pytest.raises(ValueError, match="demo margins"):
        PathLibrary.build_default(robot, per_pair=1, pairs=((1, 2),), demo_margins=margins)


def test_demo_planner_falls_back_to_the_robots_margin_when_the_wide_one_rejects_the_start(robot: WearerArm) -> None:
    from tpee_ompl.library.path_library import POINTING_LINKS, DemoPlanner

    q = next(q for q in _necessary_queries(((1, 2), (2, 1), (3, 4), (4, 3), (4, 2), (2, 4)), 120)
             if not WearerArm(link_margins={n: 0.03 for n in POINTING_LINKS}).is_valid(q.start))
    plan = DemoPlanner(robot, margins=(0.03,), max_samples=300, timeout=5.0)
    W = plan(q.start, q.goal, q.from_sector, q.to_sector)
    assert W is not None and plan.last_margin == robot.security_margin and plan.counts == {"margin_20mm": 1}


def test_build_parameters_survive_the_round_trip(robot: WearerArm, rrt_library: PathLibrary, tmp_path) -> None:
    loaded = PathLibrary.load(rrt_library.save(tmp_path / "lib.npz"), robot)
    assert loaded.build_params == rrt_library.build_params and loaded.query_stride == rrt_library.query_stride
    q = _necessary_queries(RRT_PAIRS, 1)[0]
    for k in range(2):
        assert np.array_equal(loaded.generate(q.start, q.goal, q.from_sector, q.to_sector, k, stride=10),
                              rrt_library.generate(q.start, q.goal, q.from_sector, q.to_sector, k, stride=10))


def test_strided_query_path_is_a_subsequence_of_the_dense_rollout(rrt_library: PathLibrary) -> None:
    q = _necessary_queries(RRT_PAIRS, 1)[0]
    dense = rrt_library.generate(q.start, q.goal, q.from_sector, q.to_sector, 0)
    coarse = rrt_library.generate(q.start, q.goal, q.from_sector, q.to_sector, 0, stride=7)
    assert np.array_equal(coarse[:-1], dense[:-1:7]) and np.array_equal(coarse[-1], dense[-1])


def test_planner_adapter_raises_when_nothing_valid_is_found(rrt_library: PathLibrary, monkeypatch) -> None:
    import tpee_ompl.library.path_library as pl

    monkeypatch.setattr(pl, "motion_is_valid", lambda *a, **k: False)
    monkeypatch.setattr(rrt_library, "plan", None)
    q = _necessary_queries(RRT_PAIRS, 1)[0]
    with pytest.raises(RuntimeError, match="failed"):
        rrt_library.as_planner()(q.start, q.goal, q.from_sector, q.to_sector)


def test_library_plugs_into_the_tracker_as_its_cross_sector_planner(robot: WearerArm, rrt_library: PathLibrary) -> None:
    from tpee_ompl.planning.paths import motion_states
    from tpee_ompl.model.sectors import sector_origin
    from tpee_ompl.library.tracker import Tracker

    q = _necessary_queries(((3, 4),), 1)[0]
    tracker = Tracker(robot, rrt_library.as_planner(step=0.01), initial=q.start, initial_sector=3)
    before = rrt_library.stats()["queries"]
    # a target straight out to the front-right: outside pointing sector 3, aimed from posture 4
    a = np.deg2rad(-80.0)
    result = tracker.run([(0.0, sector_origin() + np.r_[5.0 * np.cos(a), 5.0 * np.sin(a), 0.0])])
    assert [e.kind for e in result.events] == ["cross-sector"] and tracker.sector == 4
    assert rrt_library.stats()["queries"] == before + 1
    Q = np.vstack([q.start, result.configurations])
    for u, v in itertools.pairwise(Q):
        assert robot.are_valid(motion_states(u, v, 0.01)).all()


def test_benchmark_rows_report_outcome_time_and_length(robot: WearerArm, rrt_library: PathLibrary) -> None:
    from tpee_ompl.library.path_library import benchmark_queries
    from tpee_ompl.planning.paths import path_length

    qs = _necessary_queries(RRT_PAIRS, 3)
    rows = benchmark_queries(rrt_library, qs, reference=lambda s, g, i, j: np.array([s, g]))
    assert [r["id"] for r in rows] == [q.id for q in qs]
    for r, q in zip(rows, qs):
        assert r["outcome"] in ("dmp", "repaired", "fallback") and r["query_s"] > 0 and r["generation_s"] > 0
        assert r["ref_length"] == pytest.approx(path_length(np.array([q.start, q.goal])))
        assert r["length"] >= r["ref_length"] - 1e-12  # nothing is shorter than the straight line
