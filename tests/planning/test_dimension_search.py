"""tpee_ompl.planning.dimension_search and search_checker without a planner: the batched checker and the search on a waypoint array."""

from __future__ import annotations

import itertools
from collections.abc import Iterator

import numpy as np
import pytest
from helpers.planning_spaces import box_problem
from ompl import base as ob

from tpee_ompl.planning import search_draws
from tpee_ompl.planning.dimension_search import Search, SearchSettings
from tpee_ompl.planning.grouped_space import GroupedSpace
from tpee_ompl.planning.paths import path_passes_motion_checks, set_state
from tpee_ompl.planning.search_checker import Checker, segment_key
from tpee_ompl.planning.setup import make_simple_setup


def _valid_pairs(si, rng: np.random.Generator, m: int) -> tuple[np.ndarray, np.ndarray]:
    """m motions whose two ends are valid (the checker's motions() leave the ends to the caller)."""
    s = si.allocState()
    Q = [q for q in rng.uniform(-1, 1, (8 * m, 2)) if si.isValid(set_state(s, q))]
    return np.array(Q[:m]), np.array(Q[m : 2 * m])


def test_batched_and_per_state_checkers_agree_with_check_motion(rng: np.random.Generator) -> None:
    si, _ = box_problem()
    grouped = GroupedSpace(si, [[0, 1]], 5)
    A, B = _valid_pairs(si, rng, 60)
    batched, plain = Checker(si, grouped.layout, batch=True), Checker(si, grouped.layout, batch=False)
    assert batched.batched and not plain.batched
    a, b = si.allocState(), si.allocState()
    want = np.array([si.checkMotion(set_state(a, p), set_state(b, q)) for p, q in zip(A, B)])
    assert want.any() and not want.all()
    np.testing.assert_array_equal(batched.motions(A, B), want)
    np.testing.assert_array_equal(plain.motions(A, B), want)
    C = rng.uniform(-1, 1, (60, 2))
    yes = np.ones(60, dtype=bool)
    for strict in (yes, ~yes):
        vb, lb, rb = batched.candidates(C, A, B, yes, yes, strict)
        vp, lp, rp = plain.candidates(C, A, B, yes, yes, strict)
        np.testing.assert_array_equal(vb, vp)
        np.testing.assert_array_equal(lb & rb, lp & rp)  # strict: the second motion may be skipped


def test_checker_motions_match_check_motion_and_remember_those_that_passed(robot, rng: np.random.Generator) -> None:
    si = make_simple_setup(robot).getSpaceInformation()
    grouped = GroupedSpace(si, [[0, 1], [2, 3]], 7)
    checker = Checker(si, grouped.layout, batch=True)
    Q = robot.lower + rng.random((400, robot.nq)) * (robot.upper - robot.lower)
    Q = Q[robot.are_valid(Q)]
    A, B = Q[:40], Q[40:80]
    B[:20] = A[:20] + 0.05 * (B[:20] - A[:20])  # short motions too, most of them valid
    a, b = si.allocState(), si.allocState()
    want = np.array([si.checkMotion(set_state(a, p), set_state(b, q)) for p, q in zip(A, B)])
    assert want.any() and not want.all()
    np.testing.assert_array_equal(checker.check_motions(A, B), want)
    np.testing.assert_array_equal(checker.motions(A, B), want)
    assert checker.passed == {segment_key(p, q) for p, q, w in zip(A, B, want) if w}


def test_one_strict_candidate_is_judged_as_a_batch_is_and_stops_at_an_invalid_waypoint(robot, rng: np.random.Generator) -> None:
    si = make_simple_setup(robot).getSpaceInformation()
    grouped = GroupedSpace(si, [[0, 1], [2, 3]], 7)
    checker = Checker(si, grouped.layout, batch=True)
    Q = robot.lower + rng.random((600, robot.nq)) * (robot.upper - robot.lower)
    valid = robot.are_valid(Q)
    A, B = Q[valid][:30], Q[valid][30:60]
    C = np.concatenate((0.5 * (A[:20] + B[:20]) + 0.02 * rng.standard_normal((20, robot.nq)), Q[~valid][:10]))
    yes = np.ones(1, dtype=bool)
    a, b = si.allocState(), si.allocState()
    for k in range(30):
        before = checker.counter()
        vc, left, right = checker.candidates(C[k : k + 1], A[k : k + 1], B[k : k + 1], yes, yes, yes)
        checks = checker.counter() - before
        want = bool(si.isValid(set_state(a, C[k])) and si.checkMotion(set_state(a, A[k]), set_state(b, C[k]))
                    and si.checkMotion(set_state(a, C[k]), set_state(b, B[k])))
        assert bool(vc[0] and left[0] and right[0]) == want
        if k >= 20:  # an invalid waypoint: one check, nothing of its motions
            assert not vc[0] and checks == 1
    all_at_once = checker.candidates(C, A, B, *(np.ones(30, dtype=bool),) * 3)
    one_by_one = [checker.candidates(C[k : k + 1], A[k : k + 1], B[k : k + 1], yes, yes, yes) for k in range(30)]
    np.testing.assert_array_equal(np.logical_and.reduce(all_at_once), [bool(v & l & r) for v, l, r in one_by_one])


@pytest.mark.parametrize("connect", [True, False])
@pytest.mark.parametrize("batch", [True, False])
def test_search_finds_a_valid_path_around_the_box_and_only_shortens_it(batch: bool, connect: bool) -> None:
    si, _ = box_problem(lo=(-0.2, -1.0), hi=(0.2, 0.6))  # a wall with a gap at the top
    grouped = GroupedSpace(si, [[0, 1]], 7)
    start, goal = np.array([-0.8, 0.0]), np.array([0.8, 0.0])
    search = Search(grouped, Checker(si, grouped.layout, batch), np.random.default_rng(3), start, goal,
                    settings=SearchSettings(narrow_after=200, narrowing=0.5, connect=connect),
                    range_={0: np.full(2, 0.04)})
    assert not search.valid and search.cost == pytest.approx(1.6)
    while not search.valid and search.samples < 3000:
        search.iterate()
    assert search.valid
    costs = [search.cost]
    for _ in range(400):
        search.iterate()
        costs.append(search.cost)
    assert all(b <= a + 1e-12 for a, b in zip(costs, costs[1:])) and costs[-1] < costs[0]
    assert path_passes_motion_checks(si, search.W)
    assert search.cost == pytest.approx(grouped.path_length(search.W))
    np.testing.assert_array_equal(search.W[[0, -1]], [start, goal])


@pytest.mark.parametrize("batch", [True, False])
def test_blocked_straight_path_costs_only_its_waypoints_when_the_connect_trees_start_alone(batch: bool) -> None:
    si, _ = box_problem(lo=(-0.05, -1.0), hi=(0.05, 0.6))  # the middle waypoint of 7 is in the wall
    grouped = GroupedSpace(si, [[0, 1]], 7)
    start, goal = np.array([-0.8, 0.0]), np.array([0.8, 0.0])
    checks = {}
    for connect in (True, False):
        checker = Checker(si, grouped.layout, batch)
        search = Search(grouped, checker, np.random.default_rng(3), start, goal,
                        settings=SearchSettings(narrow_after=200, narrowing=0.5, connect=connect),
                        range_={0: np.full(2, 0.04)})
        checks[connect] = checker.counter()
        np.testing.assert_array_equal(search.V, [True, True, True, False, True, True, True])
        assert not search.valid
        while not search.valid and search.samples < 3000:
            search.iterate()
        assert search.valid and path_passes_motion_checks(si, search.W)
    # the connect trees grow from the start and goal alone, so the valid motions beside the wall go unchecked
    assert checks[True] == 5 < checks[False]  # 5 states, then 4 motions of ~10 states


@pytest.mark.parametrize(("batch", "shortcuts"), [(True, False), (False, False), (True, True)])
@pytest.mark.parametrize("limit", [2, 7, 64])
def test_iterate_in_blocks_matches_one_sample_per_call(limit: int, batch: bool, shortcuts: bool) -> None:
    """Connect trees, then samples the cost test rejects: blocks give the same path after the same samples."""
    si, _ = box_problem(lo=(-0.2, -1.0), hi=(0.2, 0.6))
    grouped = GroupedSpace(si, [[0], [1]], 7)  # two groups: blocks of 100 samples each, narrowing after 50
    start, goal = np.array([-0.8, 0.0]), np.array([0.8, 0.0])

    def search() -> Search:
        return Search(grouped, Checker(si, grouped.layout, batch), np.random.default_rng(5), start, goal,
                      settings=SearchSettings(narrow_after=50, narrowing=0.5, shortcuts=shortcuts),
                      range_={0: np.full(1, 0.02), 1: np.full(1, 0.02)})

    one, many = search(), search()
    trace_one, trace_many = [], []
    while one.samples < 1500:
        one.iterate()
        trace_one.append((one.samples, one.W.tobytes()))
    while many.samples < 1500:
        many.iterate(min(limit, 1500 - many.samples))
        trace_many.append((many.samples, many.W.tobytes()))
    assert many.valid and len(trace_many) < len(trace_one)
    np.testing.assert_array_equal(many.W, one.W)
    seen = dict(trace_one)
    assert all(seen[n] == w for n, w in trace_many)  # the same path after the same number of samples
    assert many.narrow_start == one.narrow_start and many.group_samples == one.group_samples


@pytest.mark.parametrize("shortcuts", [False, True])
@pytest.mark.parametrize("ahead", [1, 3, 50, 256])
@pytest.mark.parametrize("local", [False, True])
def test_cost_test_run_ahead_passes_over_the_same_samples_as_one_sample_per_call(
        ahead: int, local: bool, shortcuts: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """One planned group: the cost test runs ahead over ``AHEAD`` samples and is kept while the path stays;
    whatever that window, and with calls of 1 to 200 samples mixed (across blocks and buffers), the path
    changes after the same samples as when they are drawn one per call."""
    monkeypatch.setattr(search_draws, "AHEAD", ahead)
    si, _ = box_problem(lo=(-0.2, -1.0), hi=(0.2, 0.6))
    grouped = GroupedSpace(si, [[0, 1]], 7)
    start, goal = np.array([-0.8, 0.0]), np.array([0.8, 0.0])

    def search() -> Search:
        return Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(3), start, goal,
                      settings=SearchSettings(narrow_after=50, narrowing=0.5, shortcuts=shortcuts),
                      range_={0: np.full(2, 0.02)}, local=local)

    one, many = search(), search()
    trace_one, trace_many = [], []
    while one.samples < 3000:
        one.iterate()
        trace_one.append((one.samples, one.W.tobytes()))
    limits = itertools.cycle([1, 1, 1, 64, 7, 1, 200, 2, 64])
    while many.samples < 3000:
        many.iterate(min(next(limits), 3000 - many.samples))
        trace_many.append((many.samples, many.W.tobytes()))
    changes = sum(a[1] != b[1] for a, b in itertools.pairwise(trace_one))
    assert many.valid and changes >= 5  # the path changed, so the test run ahead was stale several times
    np.testing.assert_array_equal(many.W, one.W)
    seen = dict(trace_one)
    assert all(seen[n] == w for n, w in trace_many)
    assert many.narrow_start == one.narrow_start and many.group_samples == one.group_samples


@pytest.mark.parametrize("group", [[0, 1], [1, 0]])
@pytest.mark.parametrize("local", [False, True])
def test_hits_checked_together_give_the_paths_of_hits_checked_one_by_one(
        local: bool, group: list[int], monkeypatch: pytest.MonkeyPatch) -> None:
    """A group of every DOF: the look-ahead checks the states of the samples its cost test lets through in one
    call; the candidates come with that validity, and the samples whose state collides are passed over with
    the ones the cost test rejects.  The path after every call is the one each sample drawn and checked on its
    own, one per call, gives after as many samples, with the hits' check and without it (the sweep due on a
    new path runs after the same sample: with seed 5 and ``local=False`` a call used to pass over samples
    tested against the path before that sweep)."""
    si, _ = box_problem(lo=(-0.2, -1.0), hi=(0.2, 0.6))
    grouped = GroupedSpace(si, [group], 7)  # [1, 0]: the group's values are the state's in another order
    start, goal = np.array([-0.8, 0.0]), np.array([0.8, 0.0])
    given = []
    candidates = Checker.candidates

    def recorded(self, C, A, B, left, right, strict, valid=None, screen_only=False):
        given.append(valid is not None)
        return candidates(self, C, A, B, left, right, strict, valid, screen_only)

    monkeypatch.setattr(Checker, "candidates", recorded)

    def trace(limits: Iterator[int]) -> tuple[list[tuple[int, bytes]], int]:
        search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(5), start, goal,
                        settings=SearchSettings(narrow_after=50, narrowing=0.5, shortcuts=True),
                        range_={0: np.full(2, 0.02)}, local=local)
        out, calls = [], 0
        while search.samples < 3000:
            search.iterate(min(next(limits), 3000 - search.samples))
            out.append((search.samples, search.W.tobytes()))
            calls += 1
        assert search.valid
        return out, calls

    together, calls = trace(itertools.cycle([1, 64, 7, 200, 2]))
    assert sum(given) > 20
    with monkeypatch.context() as m:
        m.setattr(search_draws.SampleDraws, "_hit_states", lambda self, S, last: {})
        given.clear()
        mixed, mixed_calls = trace(itertools.cycle([1, 64, 7, 200, 2]))
        alone, _ = trace(itertools.repeat(1))
        assert not any(given)
    seen = dict(alone)
    assert all(seen[n] == w for n, w in mixed), "mixed"
    assert all(seen[n] == w for n, w in together), "together"
    assert together[-1] == alone[-1] and len({w for _, w in alone}) > 5  # the path changed several times
    assert calls < mixed_calls  # the colliding samples were passed over


@pytest.mark.parametrize("local", [True, False])
def test_released_search_draws_its_narrowed_samples_around_one_waypoint_at_a_time(local: bool) -> None:
    """``local`` (the released search): once narrowed, a sample lies within ``range_`` of one intermediate
    waypoint, each in turn; without it, anywhere in the box around the whole path."""
    si, _ = box_problem()
    grouped = GroupedSpace(si, [[0, 1]], 7)
    search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(0), np.array([-0.8, -0.9]),
                    np.array([0.8, 0.9]),
                    settings=SearchSettings(narrow_after=0, narrowing=1e-3), range_={0: np.full(2, 0.02)}, local=local)
    U = np.random.default_rng(1).random((3000, 3))
    C, _ = search._group_draws(0, U)
    late = np.arange(len(U)) >= 400  # narrowing ** 4: the padding is range_ from here on
    narrowed = C[late & (U[:, 0] >= 0.1)]
    gap = np.abs(narrowed[:, None, :] - search.W[None, 1:-1, :]).max(axis=2)  # (samples, waypoints)
    near = gap.min(axis=1) <= 0.02 + 1e-12
    if local:
        assert near.all()
        assert set(gap.argmin(axis=1).tolist()) == set(range(5))  # every intermediate waypoint gets samples
    else:
        assert near.mean() < 0.2


def test_narrowed_samples_of_a_path_across_pi_stay_around_the_angles_it_sweeps() -> None:
    """The narrowed box of an angle was the path values' min and max: for a path across +-pi, the whole circle (a
    helper's probe: 47 % of the narrowed samples more than 1 rad from the path, 4 % away from the seam)."""
    from helpers.planning_spaces import free_so2_space

    si = free_so2_space(2)
    grouped = GroupedSpace(si, [[0, 1]], 7)
    search = Search(grouped, Checker(si, grouped.layout, False), np.random.default_rng(0), np.array([3.0, -0.5]),
                    np.array([-3.0, 0.5]), settings=SearchSettings(narrow_after=0, narrowing=1e-3),
                    range_={0: np.full(2, 0.02)})
    U = np.random.default_rng(1).random((3000, 3))
    C, _ = search._group_draws(0, U)
    narrowed = C[(np.arange(len(U)) >= 400) & (U[:, 0] >= 0.1)]  # padding range_ from sample 400 on
    assert len(narrowed) > 1000 and (narrowed >= -np.pi).all() and (narrowed < np.pi).all()
    assert (np.abs(narrowed[:, 0]) >= 3.0 - 0.02 - 1e-12).all()  # the short way from 3 to -3, through pi
    assert (narrowed[:, 0] > 0).any() and (narrowed[:, 0] < 0).any()  # on both sides of the seam
    assert (np.abs(narrowed[:, 1]) <= 0.5 + 0.02 + 1e-12).all()  # the other joint's box as before


@pytest.mark.parametrize("narrowing", [0.5, 0.3, 0.97, 1.0])
def test_narrowing_paddings_are_those_of_pythons_power_bit_for_bit(narrowing: float) -> None:
    """The memoised narrowing factor gives the paddings ``max(range_, span * narrowing ** (k / 100))`` the
    per-sample rule computes, past the offset where they all reached ``range_`` too."""
    si, _ = box_problem()
    grouped = GroupedSpace(si, [[0, 1]], 5)
    range_ = np.array([0.04, 0.01])
    search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(0), np.array([-0.8, 0.0]),
                    np.array([0.8, 0.0]),
                    settings=SearchSettings(narrow_after=0, narrowing=narrowing), range_={0: range_})
    lo, hi = grouped.group_bounds(0)
    for k in (np.array([3]), np.arange(0, 40), np.array([17, 900, 901]), np.arange(2500, 5000, 7), np.array([200_000])):
        got = np.maximum(range_, (hi - lo) * search._scale(k)[:, None])
        want = np.maximum(range_, (hi - lo) * np.array([narrowing ** (int(i) / 100) for i in k])[:, None])
        assert got.tolist() == want.tolist()
    assert (search._cut is None) == (narrowing == 1.0)
    assert narrowing == 1.0 or len(search._scales) < 50_000  # the memo stops growing where the paddings stop


def test_a_block_of_connect_samples_ends_when_stop_says_so() -> None:
    si, _ = box_problem(lo=(-0.05, -1.0), hi=(0.05, 1.0))  # a full wall: the trees never meet
    grouped = GroupedSpace(si, [[0, 1]], 7)
    search = Search(grouped, Checker(si, grouped.layout, False), np.random.default_rng(0),
                    np.array([-0.8, 0.0]), np.array([0.8, 0.0]),
                    settings=SearchSettings(narrow_after=50, narrowing=0.5), range_={0: np.full(2, 0.02)})
    asked: list[int] = []

    def stop() -> bool:
        asked.append(search.samples)
        return len(asked) == 5

    assert search.iterate(64, stop) == 0
    assert search.samples == 5 and not search.valid  # asked before each sample after the first
    assert search.iterate(64) == 0 and search.samples == 69


def test_fitting_a_long_connect_path_to_the_steps_stops_when_stop_says_so() -> None:
    """A helper's maze (2026-11-27): fitting a 184-point path to 7 steps took ~25,000 checks past the budget."""
    si, _ = box_problem(lo=(-0.05, -1.0), hi=(0.05, 0.5))  # a wall with a gap at the top
    grouped = GroupedSpace(si, [[0, 1]], 7)
    search = Search(grouped, Checker(si, grouped.layout, False), np.random.default_rng(0),
                    np.array([-0.8, 0.0]), np.array([0.8, 0.0]),
                    settings=SearchSettings(narrow_after=50, narrowing=0.5), range_={0: np.full(2, 0.02)})
    P = np.column_stack([np.linspace(-0.8, 0.8, 40), np.r_[np.linspace(0.0, 0.8, 20), np.linspace(0.8, 0.0, 20)]])
    before = search.checker.counter()
    assert not search._fit(P, lambda: True)
    assert search.checker.counter() == before and search.unfitted is P  # no shortcut checked; kept for a higher h
    assert search._fit(P, lambda: False)  # the same path fits when nothing stops it


class _ThinWalls(ob.StateValidityChecker):
    """3-D box with three thin walls across x (boxes invalid inside)."""

    WALLS = [((-0.31, -1, -1), (-0.30, 0.7, 1)), ((0.30, -0.7, -1), (0.31, 1, 1)), ((-0.01, -1, -1), (0.0, 0.2, 1))]

    def are_valid(self, Q: np.ndarray) -> np.ndarray:
        Q = np.atleast_2d(Q)
        ok = np.ones(len(Q), dtype=bool)
        for lo, hi in self.WALLS:
            ok &= ~np.all((Q >= lo) & (Q <= hi), axis=1)
        return ok

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL override)
        return bool(self.are_valid(np.array([[state[i] for i in range(3)]]))[0])


def test_with_a_prescribed_group_a_sample_joins_the_trees_at_every_step_it_can() -> None:
    space = ob.RealVectorStateSpace(3)
    space.setBounds(-1.0, 1.0)
    si = ob.SpaceInformation(space)
    walls = _ThinWalls(si)
    si.setStateValidityChecker(walls)
    si.setStateValidityCheckingResolution(0.002)
    si.setup()
    h = 9
    grouped = GroupedSpace(si, [[0, 1], [2]], h, {1: np.linspace(-0.5, 0.5, h)[:, None]})
    search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(6), np.array([-0.8, 0, -0.5]),
                    np.array([0.8, 0, 0.5]),
                    settings=SearchSettings(narrow_after=100, narrowing=0.5), range_={0: np.full(2, 0.02)})
    z = np.linspace(-0.5, 0.5, h)  # the prescribed DOF at each step
    checked = 0
    while not search.valid and search.samples < 400:
        before = [(len(t), t.alive[: len(t)].copy(), t.steps[: len(t)].copy()) for t in (search.trees.fwd, search.trees.bwd)] \
            if search.trees is not None else None
        search.iterate()
        if before is None or search.valid:
            continue
        for tree, (n, alive, steps), sgn in zip((search.trees.fwd, search.trees.bwd), before, (-1, 1)):
            new = np.arange(n, len(tree))
            if not len(new):
                continue
            c = tree.values[new[0]]
            assert (tree.values[new] == c).all()  # one sample per iteration
            missing = []
            d2 = ((tree.values[:n] - c) ** 2).sum(axis=1)
            for t in range(1, h - 1):
                at = alive & (steps == t + sgn)
                nearest = int(np.argmin(np.where(at, d2, np.inf))) if at.any() else -1  # its parent there
                if nearest >= 0 and tree.alive[nearest] and walls.are_valid(np.r_[c, z[t]])[0]:
                    checked += 1
                    if t not in tree.steps[new]:
                        missing.append(t)
            # only at the step whose candidate path was tried does c join through checked motions alone
            assert len(missing) <= 1, f"sample not added at steps {missing}"
    assert checked > 100  # the property was exercised


class _Band(ob.StateValidityChecker):
    """Two continuous joints; invalid where the first is within 0.5 rad of 0 (so never near +-pi)."""

    def __init__(self, si: ob.SpaceInformation) -> None:
        super().__init__(si)
        self.seen: list[np.ndarray] = []

    def are_valid(self, Q: np.ndarray) -> np.ndarray:
        Q = np.asarray(Q, dtype=float)
        self.seen.append(Q.copy())
        return np.abs(Q[:, 0]) > 0.5

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL override)
        return abs(state[0].value) > 0.5


def test_batched_checker_moves_continuous_joints_the_short_way_round() -> None:
    space = ob.CompoundStateSpace()
    for _ in range(2):
        space.addSubspace(ob.SO2StateSpace(), 1.0)
    si = ob.SpaceInformation(space)
    band = _Band(si)
    si.setStateValidityChecker(band)
    si.setup()
    grouped = GroupedSpace(si, [[0, 1]], 5)
    checker = Checker(si, grouped.layout, batch=True)
    assert checker.batched
    A, B = np.array([[3.0, -3.0]]), np.array([[-3.0, 3.0]])  # 0.28 rad apart through +-pi on both joints
    S, idx, _ = checker.interior(A, B)
    assert len(S) >= 1 and np.all(idx == 0)
    assert np.all(np.abs(S) >= 3.0 - 1e-12) and np.all((S >= -np.pi) & (S < np.pi))
    # the long way would cross the invalid band around 0; the short way is valid, as for si.checkMotion
    a, b = si.allocState(), si.allocState()
    grouped.layout.write(a, A[0])
    grouped.layout.write(b, B[0])
    assert si.checkMotion(a, b)
    band.seen.clear()
    assert checker.motions(A, B).all() and checker.coarse(A, B).all()
    assert all(np.all(np.abs(Q[:, 0]) >= 3.0 - 1e-12) for Q in band.seen)


class _LowBand(ob.StateValidityChecker):
    """SO2, SO2, RealVector(2): invalid where the first joint is within 0.5 rad of 0 and x < 0.5."""

    def are_valid(self, Q: np.ndarray) -> np.ndarray:
        Q = np.atleast_2d(Q)
        return ~((np.abs(Q[:, 0]) < 0.5) & (Q[:, 2] < 0.5))

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL override)
        return bool(self.are_valid(np.array([[state[0].value, state[1].value, state[2][0], state[2][1]]]))[0])


@pytest.mark.parametrize("groups", [[[0], [1], [2], [3]], [[2], [1], [0], [3]]])
def test_trees_over_continuous_joints_with_a_prescribed_group_find_a_valid_path(groups) -> None:
    space = ob.CompoundStateSpace()
    space.addSubspace(ob.SO2StateSpace(), 1.0)
    space.addSubspace(ob.SO2StateSpace(), 0.5)
    box = ob.RealVectorStateSpace(2)
    box.setBounds(-1.0, 1.0)
    space.addSubspace(box, 2.0)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(_LowBand(si))
    si.setup()
    grouped = GroupedSpace(si, groups, 7, {3: np.zeros((7, 1))})  # the last DOF prescribed: the trees hold 3 of 4
    search = Search(grouped, Checker(si, grouped.layout, True), np.random.default_rng(0), np.array([-1.0, 3.0, -0.8, 0.0]),
                    np.array([1.0, -3.0, 0.8, 0.0]), settings=SearchSettings(narrow_after=200, narrowing=0.5),
                    range_={gi: np.full(1, 0.02) for gi in grouped.planned})
    assert not search.valid
    while not search.valid and search.samples < 3000:
        search.iterate()
    assert search.valid
    a, b = si.allocState(), si.allocState()
    lay = grouped.layout
    assert all(si.checkMotion(lay.write(a, p), lay.write(b, q)) for p, q in zip(search.W[:-1], search.W[1:]))


class _TwoWalls(ob.StateValidityChecker):
    """2-D: a wall from the bottom at x in [-0.4, -0.3] (y < 0.6), one from the top at x in [0.3, 0.4] (y > -0.6)."""

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL override)
        x, y = state[0], state[1]
        return not ((-0.4 < x < -0.3 and y < 0.6) or (0.3 < x < 0.4 and y > -0.6))


def _two_walls_search(h: int, seed: int) -> tuple[ob.SpaceInformation, Search]:
    space = ob.RealVectorStateSpace(2)
    space.setBounds(-1.0, 1.0)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(_TwoWalls(si))
    si.setStateValidityCheckingResolution(0.005)
    si.setup()
    grouped = GroupedSpace(si, [[0], [1]], h)
    return si, Search(grouped, Checker(si, grouped.layout, False), np.random.default_rng(seed), np.array([-0.9, -0.9]),
                      np.array([0.9, 0.9]),
                      settings=SearchSettings(narrow_after=200, narrowing=0.5),
                      range_={0: np.full(1, 0.04), 1: np.full(1, 0.04)})


def test_connect_path_is_fitted_to_the_steps_with_every_step_on_it_after_the_next_sample() -> None:
    si, search = _two_walls_search(7, 0)
    while not search.valid and search.samples < 3000:
        search.iterate()
    assert search.valid and search.trees is None  # found by the connect trees, no layered trees
    assert path_passes_motion_checks(si, search.W)
    search.iterate()  # the held waypoints are spread over the path's segments
    assert path_passes_motion_checks(si, search.W)
    assert np.all(np.linalg.norm(np.diff(search.W, axis=0), axis=1) > 0)


def test_connect_path_with_more_turns_than_steps_seeds_the_layered_trees() -> None:
    si, search = _two_walls_search(3, 0)  # 2 segments; the walls need 4
    while search.trees is None and search.samples < 3000:
        search.iterate()
    assert not search.valid and search.trees is not None and search.trees.hold
    assert len(search.trees.fwd) + len(search.trees.bwd) >= 2
