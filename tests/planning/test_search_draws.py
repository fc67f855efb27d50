"""tpee_ompl.planning.search_draws: where the feasibility phase's layered trees draw their samples."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.planning_spaces import box_problem, free_so2_space

from tpee_ompl.planning import search_draws
from tpee_ompl.planning.dimension_search import Search, SearchSettings
from tpee_ompl.planning.grouped_space import GroupedSpace
from tpee_ompl.planning.search_checker import Checker


def _layered_search() -> tuple[Search, object]:
    """x, y planned past a wall with a gap at the top, z prescribed (0 at every step): the straight path from
    (-0.8, 0, 0) to (0.8, 0, 0) is blocked; the search is past the first sample of its layered trees.  Keep the
    obstacle (second item) alive with the search."""
    si, box = box_problem(lo=(-0.2, -1.0, -1.0), hi=(0.2, 0.6, 1.0))
    grouped = GroupedSpace(si, [[0, 1], [2]], 7, {1: np.zeros((7, 1))})
    search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(5), np.array([-0.8, 0.0, 0.0]),
                    np.array([0.8, 0.0, 0.0]), settings=SearchSettings(narrow_after=200, narrowing=0.5),
                    range_={0: np.full(2, 0.04)})
    assert not search.valid
    search.iterate()
    assert search.trees is not None
    return search, box


def _draws(search: Search, n: int) -> np.ndarray:
    return np.array([search.draw(None) for _ in range(n)])


def test_layered_trees_draw_most_samples_near_the_blocked_line_and_widen_the_region_as_they_go() -> None:
    search, _box = _layered_search()  # the line sweeps y = 0 only
    search.samples = 1  # padding 0.25 x 2 x 2^(1/16) = 0.52 around y = 0
    near = np.abs(_draws(search, 400)[:, 1]) <= 0.25 * 2 * 2 ** (1 / 16) + 1e-12
    assert near.mean() > 0.85  # all but the uniform tenth (which falls there a quarter of the time)
    search.samples = 1 + 3 * search_draws.FEASIBILITY_DOUBLING  # padding 8x: the region covers the bounds
    assert np.abs(_draws(search, 400)[:, 1]).max() > 0.9
    assert (np.abs(_draws(search, 400)[:, 1]) <= 0.52).mean() < 0.5


def test_feasibility_region_switched_off_gives_the_papers_uniform_samples(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(search_draws, "FEASIBILITY_PAD", None)
    search, _box = _layered_search()
    rng = np.random.default_rng(11)
    search.rng, search._ui, search._uniform = rng, 0, np.empty((0, 0))
    want = np.random.default_rng(11).random((1024, 3))[:300, 1:] * 2.0 - 1.0  # one buffer: 1 + 2 uniforms a sample
    np.testing.assert_allclose(_draws(search, 300), want, rtol=0, atol=1e-15)


def test_feasibility_region_of_continuous_joints_wraps_round_pi() -> None:
    si = free_so2_space(2)
    grouped = GroupedSpace(si, [[0], [1]], 7, {1: np.zeros((7, 1))})
    search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(5), np.array([3.0, 0.0]),
                    np.array([-3.0, 0.0]), settings=SearchSettings(narrow_after=200, narrowing=0.5, connect=False),
                    range_={0: np.full(1, 0.04)})
    search._feasibility_region(np.array([[3.0, 0.0], [3.1, 0.0], [-3.1, 0.0], [-3.0, 0.0]]))  # the short way, across +-pi
    search.samples = 0
    a = _draws(search, 400)[:, 0]
    pad = 0.25 * 2 * math.pi
    arc = (a >= 3.0 - pad - 1e-12) | (a <= -3.0 + pad + 1e-12)  # [3 - pad, pi) and [-pi, -3 + pad]
    assert ((a >= -math.pi) & (a < math.pi)).all()
    assert arc.mean() > 0.85 and (~arc).any()  # the uniform tenth also falls on the far side


def test_without_a_prescribed_group_the_layered_trees_keep_uniform_samples() -> None:
    si, _ = box_problem(lo=(-0.2, -1.0), hi=(0.2, 0.6))
    grouped = GroupedSpace(si, [[0, 1]], 7)
    search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(5), np.array([-0.8, 0.0]),
                    np.array([0.8, 0.0]), settings=SearchSettings(narrow_after=200, narrowing=0.5, connect=False),
                    range_={0: np.full(2, 0.04)})
    search.iterate()
    assert search.trees is not None and search._fregion is None


def test_an_angles_region_covers_the_whole_circle_once_the_padded_arc_is_as_long() -> None:
    """The path 3.0 -> -3.0 sweeps [3.0, 3.28] unwrapped; at 16 samples the padding (pi) makes the arc longer than
    the circle, and the box was cut at pi: only the uniform tenth of the samples fell in [-pi, -0.5)."""
    si = free_so2_space(2)
    grouped = GroupedSpace(si, [[0], [1]], 7, {1: np.zeros((7, 1))})
    search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(5), np.array([3.0, 0.0]),
                    np.array([-3.0, 0.0]), settings=SearchSettings(narrow_after=200, narrowing=0.5),
                    range_={0: np.full(1, 0.04)})
    search._feasibility_region(np.array([[3.0, 0.0], [3.1, 0.0], [-3.1, 0.0], [-3.0, 0.0]]))
    search.samples = search_draws.FEASIBILITY_DOUBLING
    a = _draws(search, 2000)[:, 0]
    far = ((a >= -math.pi) & (a < -0.5)).mean()
    assert abs(far - (math.pi - 0.5) / (2 * math.pi)) < 0.05
