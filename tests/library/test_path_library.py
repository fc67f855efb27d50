"""Tests of :class:`PathLibrary` (sections 4.2.2-4.2.3): building with stand-ins, queries, repair, fallback.

The stand-in library (``library``) and the small dimension-RRT one (``rrt_library``) are built once
per session in tests/library/conftest.py (tests marked slow use the latter, ~5 s to build).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from helpers.library_standins import PAIRS, RRT_PAIRS, necessary_queries, rrt_plan, sampler, straight_plan

from tpee_ompl.library import N_FAKE_TIME_STEPS, PathLibrary
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.paths import motion_is_valid, resample_waypoints
from tpee_ompl.planning.setup import make_simple_setup


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
    again = PathLibrary.build(robot, sampler(robot), straight_plan(robot), pairs=PAIRS, per_pair=4,
                              min_difference=0.3, seed=7)
    for key, pd in library.pairs.items():
        other = again.pairs[key]
        assert np.array_equal(pd.waypoints, other.waypoints)
        for a, b in zip(pd.forward + pd.reverse, other.forward + other.reverse):
            assert np.array_equal(a.weights, b.weights)


def test_query_paths_start_and_end_exactly_and_pass_the_motion_check(robot: WearerArm, library: PathLibrary,
                                                                    monkeypatch) -> None:
    monkeypatch.setattr(library, "plan", rrt_plan(robot))
    sample = sampler(robot)
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
    monkeypatch.setattr(library, "plan", straight_plan(robot))
    monkeypatch.setattr(pl, "motion_is_valid", reject_dmp_paths)
    res = library.query(pd.starts[0], pd.goals[0], i, j)
    assert res.outcome == "fallback" and res.candidates_tried == min(library.n_candidates, len(pd.starts))
    assert motion_is_valid(robot, res.path)
    monkeypatch.setattr(library, "plan", None)
    calls["n"] = -10**9  # everything "collides", no planner: failed, no path
    res = library.query(pd.starts[0], pd.goals[0], i, j)
    assert res.outcome == "failed" and res.path is None


def test_fallback_starts_from_the_closest_dmp_path(robot: WearerArm, library: PathLibrary, monkeypatch) -> None:
    import tpee_ompl.library.path_library as pl

    seen = {}
    straight = straight_plan(robot)

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


@pytest.mark.parametrize("kw, match", [
    ({"per_step": 0}, "per_step"), ({"per_step": 50}, "per_step 50 gives DMPs of 301"),
    ({"options": "x"}, "options must be DMPOptions"), ({"plan": 5}, "plan must be"),
    ({"query_stride": 1.5}, "query_stride"), ({"query_stride": "2"}, "query_stride"),
    ({"query_stride": 10**9}, "query_stride"),
])
def test_the_constructor_refuses_settings_that_would_fail_later(robot: WearerArm, library: PathLibrary, kw,
                                                                match: str) -> None:
    """per_step=50 on 100-step DMPs was taken, then a query failed in numpy's concatenate and save in a reshape."""
    with pytest.raises(ValueError, match=match):
        PathLibrary(robot, library.pairs, **{"per_step": library.per_step, **kw})


def test_save_takes_force_as_a_bool_only(library: PathLibrary, tmp_path) -> None:
    f = library.save(tmp_path / "lib.npz")
    with pytest.raises(ValueError, match="force"):
        library.save(f, force="no")  # a string was true: the file was replaced


def test_with_options_needs_dmp_options(library: PathLibrary) -> None:
    with pytest.raises(ValueError, match="DMPOptions"):
        library.with_options(None)  # type: ignore[arg-type]


def test_polyline_motion_states_are_the_ompl_motion_states_of_every_segment(robot: WearerArm, rng) -> None:
    from tpee_ompl.planning.paths import motion_states, polyline_motion_states

    path = np.cumsum(rng.uniform(-0.05, 0.05, (30, 4)), axis=0)
    path[10] = path[9]  # a zero-length segment still checks its end state once
    step = robot.max_joint_step()
    expected = np.vstack([path[:1]] + [motion_states(a, b, step) for a, b in itertools.pairwise(path)])
    np.testing.assert_allclose(polyline_motion_states(path, step), expected, atol=1e-15)


@pytest.mark.slow
def test_every_returned_path_passes_si_check_motion_segment_by_segment(robot: WearerArm, rrt_library: PathLibrary,
                                                                     monkeypatch) -> None:
    from tpee_ompl.library.demos import dimension_rrt_planner
    from tpee_ompl.planning.paths import set_state

    monkeypatch.setattr(rrt_library, "plan", dimension_rrt_planner(robot, max_samples=300, timeout=5.0))
    for q in necessary_queries(RRT_PAIRS, 40)[::5]:
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


@pytest.mark.slow
def test_strided_query_path_is_a_subsequence_of_the_dense_rollout(rrt_library: PathLibrary) -> None:
    q = necessary_queries(RRT_PAIRS, 1)[0]
    dense = rrt_library.generate(q.start, q.goal, q.from_sector, q.to_sector, 0)
    coarse = rrt_library.generate(q.start, q.goal, q.from_sector, q.to_sector, 0, stride=7)
    assert np.array_equal(coarse[:-1], dense[:-1:7]) and np.array_equal(coarse[-1], dense[-1])


@pytest.mark.slow
def test_planner_adapter_raises_when_nothing_valid_is_found(rrt_library: PathLibrary, monkeypatch) -> None:
    import tpee_ompl.library.path_library as pl

    monkeypatch.setattr(pl, "motion_is_valid", lambda *a, **k: False)
    monkeypatch.setattr(rrt_library, "plan", None)
    q = necessary_queries(RRT_PAIRS, 1)[0]
    with pytest.raises(RuntimeError, match="failed"):
        rrt_library.as_planner()(q.start, q.goal, q.from_sector, q.to_sector)


@pytest.mark.slow
def test_library_plugs_into_the_tracker_as_its_cross_sector_planner(robot: WearerArm, rrt_library: PathLibrary) -> None:
    from tpee_ompl.library.tracker import Tracker
    from tpee_ompl.model.sectors import sector_origin
    from tpee_ompl.planning.paths import motion_states

    q = necessary_queries(((3, 4),), 1)[0]
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


def test_build_takes_options_or_keyword_overrides_alike(robot: WearerArm, library: PathLibrary) -> None:
    from tpee_ompl.library import LibraryBuildOptions

    opts = LibraryBuildOptions(pairs=PAIRS[:1], per_pair=4, min_difference=0.3, seed=7, max_attempts=80)
    again = PathLibrary.build(robot, sampler(robot), straight_plan(robot), opts)
    assert np.array_equal(again.pairs[PAIRS[0]].waypoints, library.pairs[PAIRS[0]].waypoints)
    with pytest.raises(TypeError):
        PathLibrary.build(robot, sampler(robot), straight_plan(robot), opts, per_pairs=3)
    with pytest.raises(ValueError, match="LibraryBuildOptions"):
        PathLibrary.build(robot, sampler(robot), straight_plan(robot), {"per_pair": 3})



def test_generate_refuses_a_pair_without_demonstrations_a_bad_index_or_a_non_finite_end(library):
    import numpy as np

    (i, j), pd = next(iter(library.pairs.items()))
    start, goal = pd.starts[0].copy(), pd.goals[0].copy()
    assert library.generate(start, goal, i, j, 0).shape[1] == 4
    with pytest.raises(ValueError, match="demo_index must be"):  # was a bare IndexError
        library.generate(start, goal, i, j, len(pd.starts))
    missing = next((a, b) for a in range(1, 5) for b in range(1, 5) if a != b and (a, b) not in library.pairs) \
        if len(library.pairs) < 12 else None
    if missing is not None:
        with pytest.raises(ValueError, match="no demonstrations"):  # was a KeyError
            library.generate(start, goal, *missing, 0)
    bad = start.copy()
    bad[2] = np.nan
    with pytest.raises(ValueError, match="NaN"):  # it returned a path of NaN
        library.generate(bad, goal, i, j, 0)


@pytest.mark.parametrize("step", [1e-7, 0.0, float("inf"), float("nan"), "0.01"])
def test_query_refuses_a_check_step_that_would_hang_or_skip_the_check(library, step) -> None:
    (i, j), pd = next(iter(library.pairs.items()))
    with pytest.raises(ValueError, match="step"):
        library.query(pd.starts[0], pd.goals[0], i, j, step=step)


def test_a_coarse_check_step_is_capped_at_the_robots_motion_step(robot, library, monkeypatch) -> None:
    from tpee_ompl.library import path_library

    seen = []
    monkeypatch.setattr(path_library, "motion_is_valid", lambda r, p, step: seen.append(step) or True)
    (i, j), pd = next(iter(library.pairs.items()))
    library.query(pd.starts[0], pd.goals[0], i, j, step=1.0)
    assert seen == [robot.max_joint_step()]


@pytest.mark.parametrize("answer, match", [(lambda s, g: np.array([s, s * np.nan, g]), "not finite"),
                                           (lambda s, g: np.zeros((0, 4)), "shape"),
                                           (lambda s, g: np.array([s[:3], g[:3]]), "shape")])
def test_a_fallback_planner_answer_that_is_no_path_is_named(robot, library, answer, match) -> None:
    lib = PathLibrary(robot, library.pairs, library.per_step, library.options, plan=lambda s, g, i, j: answer(s, g))
    lib.n_candidates = 0  # straight to the fallback
    (i, j), pd = next(iter(library.pairs.items()))
    with pytest.raises(ValueError, match=f"the fallback planner returned .*{match}"):
        lib.query(pd.starts[0], pd.goals[0], i, j)


@pytest.mark.parametrize("stride", [0, -1, 1.5, "3", float("nan")])
def test_generate_refuses_a_stride_that_is_not_a_positive_integer(library, stride) -> None:
    (i, j), pd = next(iter(library.pairs.items()))
    with pytest.raises(ValueError, match="stride"):
        library.generate(pd.starts[0], pd.goals[0], i, j, 0, stride=stride)


def test_a_library_tries_at_least_one_candidate(robot: WearerArm) -> None:
    with pytest.raises(ValueError, match="n_candidates"):
        PathLibrary(robot, {}, n_candidates=0)


@pytest.mark.parametrize("robot", [None, "wearer", 4])
def test_load_names_a_robot_that_is_not_a_wearer_arm(robot) -> None:
    from tpee_ompl.resources import default_library_path

    with pytest.raises(ValueError, match="^robot must be a WearerArm"):
        PathLibrary.load(default_library_path(), robot)


@pytest.mark.parametrize("path", [None, 5, b"lib.npz", ""])
def test_save_and_load_name_a_path_that_is_no_file_path(robot: WearerArm, library: PathLibrary, path) -> None:
    """None was numpy's and pathlib's "expected str, bytes or os.PathLike object, not NoneType"."""
    from tpee_ompl.library.storage import library_model_hash

    for call in (lambda: library.save(path), lambda: PathLibrary.load(path, robot), lambda: library_model_hash(path)):
        with pytest.raises(ValueError, match=r"^path must be a file path \(str or os.PathLike\), got "):
            call()
