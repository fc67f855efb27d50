"""Tests of the build settings and the default build: :class:`LibraryBuildOptions`, workers, determinism."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from helpers.library_standins import RRT_PAIRS

from tpee_ompl.library import DEMO_MARGINS, LIBRARY_DMP_OPTIONS, LibraryBuildOptions, PathLibrary
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.paths import motion_is_valid


@pytest.mark.slow
def test_seeded_default_build_is_deterministic_with_one_or_two_workers(robot: WearerArm, rrt_library: PathLibrary) -> None:
    again = PathLibrary.build_default(robot, per_pair=2, seed=3, pairs=RRT_PAIRS, max_samples=300, timeout=5.0, workers=2)
    for pair in RRT_PAIRS:
        a, b = rrt_library.pairs[pair], again.pairs[pair]
        assert np.array_equal(a.starts, b.starts) and np.array_equal(a.goals, b.goals)
        assert np.array_equal(a.waypoints, b.waypoints) and np.array_equal(a.margins, b.margins, equal_nan=True)
    assert again.build_stats == rrt_library.build_stats


@pytest.mark.slow
def test_worker_processes_plan_with_the_callers_robot_and_its_margins() -> None:
    strict = WearerArm(link_margins={"link3": 0.03, "link4": 0.03})
    kw = {"per_pair": 1, "seed": 5, "pairs": ((1, 2), (2, 1)), "max_samples": 200, "timeout": 5.0, "demo_margins": ()}
    one, two = PathLibrary.build_default(strict, workers=1, **kw), PathLibrary.build_default(strict, workers=2, **kw)
    for pair in kw["pairs"]:
        assert np.array_equal(one.pairs[pair].waypoints, two.pairs[pair].waypoints)
        for W in two.pairs[pair].waypoints:
            assert motion_is_valid(strict, W)


def test_default_options_are_the_packaged_librarys_settings() -> None:
    opts = LibraryBuildOptions()
    assert (opts.per_pair, opts.seed, len(opts.pairs), opts.min_difference) == (20, 0, 12, 0.15)
    assert opts.max_attempts is None and opts.draws_per_pair == 60
    assert opts.demo_margins == DEMO_MARGINS and opts.dmp_options == LIBRARY_DMP_OPTIONS
    assert dataclasses.replace(opts, per_pair=4).draws_per_pair == 12
    assert dataclasses.replace(opts, max_attempts=5).draws_per_pair == 5


@pytest.mark.parametrize(
    "field, value, match",
    [("per_pair", 0, "per_pair"), ("per_pair", 2.0, "per_pair"), ("per_pair", True, "per_pair"),
     ("seed", -1, "seed"), ("min_difference", float("nan"), "min_difference"), ("min_difference", -0.1, "min_difference"),
     ("max_attempts", 0, "max_attempts"), ("per_step", 0, "per_step"), ("max_samples", 0, "max_samples"),
     ("timeout", 0.0, "timeout"), ("require_planning", 1, "require_planning"), ("demo_margins", (2.0,), "demo margins"),
     ("demo_margins", ("wide",), "demo margins"), ("workers", 0, "workers"), ("dmp_options", None, "dmp_options"),
     ("pairs", ((2, 2),), "not a cross-sector motion"), ("pairs", ((1, 5),), "sector"), ("pairs", 3, "pairs")],
)
def test_bad_build_options_are_refused_naming_the_field(field: str, value, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        LibraryBuildOptions(**{field: value})


def test_options_are_normalised_once() -> None:
    opts = LibraryBuildOptions(pairs=[[np.int64(1), 2]], demo_margins=[0.03], min_difference=1, timeout=5)
    assert opts.pairs == ((1, 2),) and opts.demo_margins == (0.03,)
    assert isinstance(opts.min_difference, float) and isinstance(opts.timeout, float)


def test_build_default_refuses_options_of_another_type(robot: WearerArm) -> None:
    with pytest.raises(ValueError, match="LibraryBuildOptions"):
        PathLibrary.build_default(robot, LIBRARY_DMP_OPTIONS)  # type: ignore[arg-type]



def test_a_per_step_too_coarse_for_the_dmps_is_refused_naming_per_step_and_the_smallest_that_works() -> None:
    """LibraryBuildOptions(per_step=5) was accepted; the build then failed after planning every demonstration."""
    with pytest.raises(ValueError, match=r"^per_step 5 gives DMPs of 31 samples; .* at least 50: per_step must be "
                                         r"at least 9$"):
        LibraryBuildOptions(per_step=5)
    with pytest.raises(ValueError, match="per_step must be at least 9"):
        LibraryBuildOptions(per_step=8)
    assert LibraryBuildOptions(per_step=9).per_step == 9


def test_the_smallest_per_step_accepted_learns_its_dmps() -> None:
    from collections import Counter

    from tpee_ompl.library.build import learn_demos
    from tpee_ompl.model.sectors import cross_sector_trajectory

    W = np.hstack([cross_sector_trajectory(1, 4), np.linspace([0.0, 0.0], [0.3, -0.6], 7)])
    opts = LibraryBuildOptions(per_step=9)
    collected = {(1, 4): (W[:1], W[-1:], W[None], np.zeros(1), Counter())}
    pd = learn_demos(collected, opts.per_step, opts.dmp_options)[(1, 4)]
    assert pd.forward[0].n_steps == pd.reverse[0].n_steps == 55


@pytest.mark.slow
def test_a_pair_whose_worker_is_killed_is_run_again_and_gives_the_demos_of_an_uninterrupted_build(
        robot: WearerArm, rrt_library: PathLibrary, tmp_path, monkeypatch, caplog) -> None:
    """A worker killed mid-build (kill -9, the OOM killer) broke the whole pool: the build failed with "A process
    in the process pool was terminated abruptly ...", the pairs already done were thrown away, nothing resumable."""
    import multiprocessing as mp

    from helpers.library_killers import arm

    kills = arm(monkeypatch, tmp_path / "kills", pair=(3, 4), times=1)
    again = PathLibrary.build_default(robot, per_pair=2, seed=3, pairs=RRT_PAIRS, max_samples=300, timeout=5.0,
                                      workers=2)
    assert len(list(kills.iterdir())) == 1  # the worker of 3->4 really died once
    assert "pair 3->4: worker process killed by SIGKILL; running the pair again in a fresh process" in caplog.text
    for pair in RRT_PAIRS:
        a, b = rrt_library.pairs[pair], again.pairs[pair]
        assert np.array_equal(a.starts, b.starts) and np.array_equal(a.goals, b.goals)
        assert np.array_equal(a.waypoints, b.waypoints) and np.array_equal(a.margins, b.margins, equal_nan=True)
    assert again.build_stats == rrt_library.build_stats
    assert mp.active_children() == []


_TWO_QUICK_PAIRS = {"per_pair": 1, "seed": 5, "pairs": ((1, 2), (2, 1)), "max_samples": 200, "timeout": 5.0,
                    "demo_margins": (), "workers": 2}


def test_a_pair_whose_worker_dies_again_when_run_again_fails_the_build_naming_the_pair(
        robot: WearerArm, tmp_path, monkeypatch) -> None:
    """A killed worker gave the pool's "A process in the process pool was terminated abruptly while the future was
    running or pending": no pair, no cause; its processes must not outlive the failure either."""
    import multiprocessing as mp

    from helpers.library_killers import arm

    kills = arm(monkeypatch, tmp_path / "kills", pair=(2, 1), times=2)
    with pytest.raises(RuntimeError, match=r"^pair 2->1 \(worker process killed by SIGKILL, retry in a fresh process "
                                           r"killed by SIGKILL\) lost: no library built \(a library needs every pair\)$"):
        PathLibrary.build_default(robot, **_TWO_QUICK_PAIRS)
    assert len(list(kills.iterdir())) == 2
    assert mp.active_children() == []
