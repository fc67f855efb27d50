"""tpee_ompl.planning.paths: states <-> arrays, motion states, the whole-path check, lengths, resampling."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.planning_spaces import box_problem
from ompl import base as ob
from ompl import geometric as og

from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.paths import (
    array_to_path,
    batched_motion_states,
    motion_interior_states,
    motion_is_valid,
    motion_states,
    path_length,
    path_passes_motion_checks,
    path_to_array,
    polyline_motion_states,
    resample_waypoints,
    set_state,
    state_to_array,
    straight_segment_counts,
    unchecked_motion_states,
)
from tpee_ompl.planning.setup import make_simple_setup, motion_check_step
from tpee_ompl.planning.space_layout import RealVectorLayout


# ------------------------------------------------------------------------------- states <-> arrays
def test_state_and_path_round_trips() -> None:
    si, _ = box_problem()
    s = set_state(si.allocState(), [0.25, -0.5])
    np.testing.assert_array_equal(state_to_array(s, 2), [0.25, -0.5])
    W = np.array([[0.0, 0.0], [0.1, 0.2], [-0.3, 0.9]])
    path = array_to_path(si, W)
    assert isinstance(path, og.PathGeometric) and path.getStateCount() == 3
    np.testing.assert_array_equal(path_to_array(path, 2), W)
    assert path.length() == pytest.approx(path_length(W))


def test_read_and_write_hooks_handle_a_compound_space() -> None:
    cs = ob.CompoundStateSpace()
    for dim, weight in ((2, 1.0), (1, 0.5)):
        sub = ob.RealVectorStateSpace(dim)
        sub.setBounds(-1.0, 1.0)
        cs.addSubspace(sub, weight)
    si = ob.SpaceInformation(cs)
    si.setStateValidityChecker(ob.AllValidStateValidityChecker(si))
    si.setup()
    layout = RealVectorLayout(cs)
    W = np.array([[0.0, 0.1, 0.2], [0.3, -0.4, 0.5]])
    path = array_to_path(si, W, write=layout.write)
    np.testing.assert_array_equal(path_to_array(path, 3, read=layout.read), W)
    assert path.length() == pytest.approx(layout.path_length(W))  # the weighted metric, not path_length's


def test_array_to_path_gives_a_user_writer_array_rows_and_keeps_a_copy_of_each_state() -> None:
    si, _ = box_problem()
    seen = []

    def write(state, w):
        seen.append(type(w))
        return set_state(state, 0.5 * w)  # array arithmetic on the row

    W = np.array([[0.0, 0.0], [0.2, 0.4], [-0.6, 0.8]])
    path = array_to_path(si, W, write=write)
    assert seen == [np.ndarray] * 3
    np.testing.assert_array_equal(path_to_array(path, 2), 0.5 * W)  # three distinct states, not the last one thrice


# ------------------------------------------------------------------------------- motion states
def test_motion_states_match_ompl_subdivision() -> None:
    s = motion_states(np.zeros(4), np.array([1.0, 0, 0, 0]), 0.3)
    np.testing.assert_allclose(s[:, 0], [0.25, 0.5, 0.75, 1.0])
    s0 = motion_states(np.zeros(4), np.array([1.0, 0, 0, 0]), 0.3, include_start=True)
    np.testing.assert_allclose(s0[:, 0], [0.0, 0.25, 0.5, 0.75, 1.0])


def test_interior_and_polyline_states_are_motion_states(rng: np.random.Generator) -> None:
    A, B = rng.uniform(-1, 1, (20, 3)), rng.uniform(-1, 1, (20, 3))
    B[3] = A[3]  # a zero-length motion: one segment, no interior state
    S, k, j = motion_interior_states(A, B, 0.07)
    for m in range(len(A)):
        want = motion_states(A[m], B[m], 0.07)[:-1]  # without the end state
        np.testing.assert_array_equal(S[k == m], want)
        np.testing.assert_array_equal(j[k == m], np.arange(1, len(want) + 1))
    S8, k8, j8 = motion_interior_states(A, B, 0.07, stride=8)  # the multiples of 8 only, the same numbers
    every8 = j % 8 == 0
    np.testing.assert_array_equal(S8, S[every8])
    np.testing.assert_array_equal(k8, k[every8])
    np.testing.assert_array_equal(j8, j[every8])
    S2, k2, _ = motion_interior_states(A, B, 0.07, lengths=2 * np.sqrt(((B - A) ** 2).sum(-1)))
    assert len(S2) > len(S)  # another metric, other segment counts
    P = rng.uniform(-1, 1, (6, 3))
    want = np.vstack([P[:1]] + [motion_states(a, b, 0.05) for a, b in zip(P[:-1], P[1:])])
    np.testing.assert_allclose(polyline_motion_states(P, 0.05), want, rtol=0, atol=1e-15)


def test_batched_motion_states_are_each_motions_states_bit_for_bit(rng: np.random.Generator) -> None:
    A, B = rng.uniform(-1, 1, (30, 4)), rng.uniform(-1, 1, (30, 4))
    B[5] = A[5]  # zero length: one state, the end
    S, counts = batched_motion_states(A, B, 0.037)
    want = [motion_states(a, b, 0.037) for a, b in zip(A, B)]
    assert counts.tolist() == [len(w) for w in want]
    np.testing.assert_array_equal(S, np.concatenate(want))


def test_straight_segment_counts_match_one_motions_count_with_the_factor(rng: np.random.Generator) -> None:
    D = rng.standard_normal((400, 4)) * rng.choice([1e-4, 0.01, 0.5, 3.0], (400, 1))
    D[7] = 0.0  # zero length: one segment
    for factor in (1, 4):
        want = [len(unchecked_motion_states(np.zeros(4), d, 0.0122, factor=factor)) for d in D]
        assert straight_segment_counts(D, 0.0122, factor).tolist() == want


@pytest.mark.parametrize("bad, error", [(np.inf, OverflowError), (np.nan, ValueError), (1e200, OverflowError)])
def test_straight_segment_counts_raise_for_a_motion_without_a_count(bad, error) -> None:
    with np.errstate(over="ignore"), pytest.raises(error):
        straight_segment_counts(np.array([[0.1, 0.2], [bad, 0.0]]), 0.01)


@pytest.mark.parametrize("A, B, step", [
    (np.zeros((2, 3)), np.zeros((2, 4)), 0.1),  # shapes differ
    (np.zeros(3), np.ones(3), 0.1),  # one motion as vectors, not (K, n)
    (np.full((1, 2), np.nan), np.ones((1, 2)), 0.1),
    (np.zeros((1, 2)), np.ones((1, 2)), 0.0),
])
def test_batched_motion_states_refuse_bad_ends_or_step(A, B, step) -> None:
    with pytest.raises(ValueError, match="motion ends|step"):
        batched_motion_states(A, B, step)


@pytest.mark.parametrize("step", [0.0, -1.0, float("nan"), "0.1"])
def test_motion_states_refuse_a_bad_step(step) -> None:
    with pytest.raises(ValueError, match="step"):
        motion_states(np.zeros(2), np.ones(2), step)


# ------------------------------------------------------------------------------- whole-path check
def test_valid_path_passes_and_a_segment_through_the_obstacle_fails() -> None:
    si, _ = box_problem()
    around = np.array([[0.0, 0.0], [0.5, 0.5], [1.0, 0.0]])
    through = np.array([[0.0, 0.0], [1.0, 0.0]])  # both ends valid, the middle in the box
    assert path_passes_motion_checks(si, around)
    assert not path_passes_motion_checks(si, through)
    assert si.isValid(set_state(si.allocState(), through[0])) and si.isValid(set_state(si.allocState(), through[1]))
    for form in (array_to_path(si, through), array_to_path(si, through).getStates()):
        assert not path_passes_motion_checks(si, form)


def test_first_state_is_checked_unless_told_otherwise() -> None:
    si, _ = box_problem(lo=(0.95, -1.0), hi=(1.0, 1.0))
    out_of_the_box = np.array([[0.97, 0.0], [0.5, 0.0]])  # starts invalid; the motion's checked states are valid
    assert not path_passes_motion_checks(si, out_of_the_box)
    assert path_passes_motion_checks(si, out_of_the_box, check_first=False)
    assert not array_to_path(si, out_of_the_box).check()


def test_in_bounds_also_requires_every_state_within_the_spaces_bounds() -> None:
    si, _ = box_problem()  # [-1, 1]^2; the checker tests the box obstacle only, as a user's checker may
    outside = np.array([[-0.5, 0.8], [0.0, 1.3], [0.5, 0.8]])  # round the obstacle, through y = 1.3
    assert path_passes_motion_checks(si, outside) and array_to_path(si, outside).check()
    assert not path_passes_motion_checks(si, outside, in_bounds=True)
    assert path_passes_motion_checks(si, np.array([[-0.5, 0.8], [0.0, 1.0], [0.5, 0.8]]), in_bounds=True)


def test_agrees_with_path_geometric_check_and_makes_the_same_checks(rng: np.random.Generator) -> None:
    si, checker = box_problem()
    verdicts = set()
    for _ in range(200):
        path = array_to_path(si, rng.uniform(-1, 1, (int(rng.integers(1, 5)), 2)))
        checker.calls = 0
        want = path.check()
        calls = checker.calls
        checker.calls = 0
        assert path_passes_motion_checks(si, path) == want
        assert checker.calls == calls
        verdicts.add(want)
    assert verdicts == {True, False}
    empty = og.PathGeometric(si)
    assert empty.check() and path_passes_motion_checks(si, empty) and path_passes_motion_checks(si, np.zeros((0, 2)))


def test_sets_up_the_space_information_like_check_does() -> None:
    space = ob.RealVectorStateSpace(2)
    space.setBounds(-1.0, 1.0)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(ob.AllValidStateValidityChecker(si))
    assert not si.isSetup()
    assert path_passes_motion_checks(si, np.array([[0.0, 0.0], [0.5, 0.5]]))
    assert si.isSetup()


@pytest.mark.parametrize("bad", [np.zeros((2, 3)), np.zeros(2), np.full((2, 2), np.nan), [["a", "b"]]])
def test_bad_waypoint_arrays_raise(bad) -> None:
    si, _ = box_problem()
    with pytest.raises(ValueError, match="waypoints"):
        path_passes_motion_checks(si, bad)


def test_arrays_need_a_real_vector_space() -> None:
    cs = ob.CompoundStateSpace()
    sub = ob.RealVectorStateSpace(2)
    sub.setBounds(-1.0, 1.0)
    cs.addSubspace(sub, 1.0)
    si = ob.SpaceInformation(cs)
    si.setStateValidityChecker(ob.AllValidStateValidityChecker(si))
    si.setup()
    with pytest.raises(ValueError, match="RealVectorStateSpace"):
        path_passes_motion_checks(si, np.zeros((2, 2)))


def test_batched_motion_is_valid_agrees_with_the_setups_motion_checks(robot: WearerArm, rng: np.random.Generator) -> None:
    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    verdicts = []
    for _ in range(40):
        W = rng.uniform(robot.lower, robot.upper, (3, 4))
        W[1:] = np.clip(W[0] + rng.normal(scale=0.15, size=(2, 4)), robot.lower, robot.upper)
        got = motion_is_valid(robot, W, motion_check_step(ss))
        assert got == path_passes_motion_checks(si, W)
        verdicts.append(got)
    assert any(verdicts) and not all(verdicts)


def test_an_array_gets_the_verdict_of_its_path_through_the_projects_validator(robot: WearerArm,
                                                                             rng: np.random.Generator) -> None:
    """An array goes to the project's validator as it is (no OMPL state per waypoint): the same verdict as its
    PathGeometric, with the bounds' own tolerance and without the first state when told."""
    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    si.setup()
    high = np.array(si.getStateSpace().getBounds().high)
    verdicts = set()
    for k in range(60):
        W = np.clip(rng.uniform(robot.lower, robot.upper) + np.cumsum(rng.normal(scale=0.1, size=(5, 4)), axis=0),
                    robot.lower, robot.upper)
        if k % 4 == 0:
            W[2, 3] = high[3] + 1e-9 if k % 8 == 0 else np.nextafter(high[3], np.inf)  # outside; within tolerance
        for first in (True, False):
            want = path_passes_motion_checks(si, array_to_path(si, W), in_bounds=True, check_first=first)
            assert path_passes_motion_checks(si, W, in_bounds=True, check_first=first) == want
            verdicts.add(want)
    assert verdicts == {True, False}


# ------------------------------------------------------------------------------- lengths, resampling
def test_path_length_and_resampling_keep_the_geometry() -> None:
    W = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 0.0]])
    assert path_length(W) == pytest.approx(9.0)
    R = resample_waypoints(W, per_step=10)
    assert R.shape == (21, 2)
    np.testing.assert_array_equal(R[[0, 10, 20]], W)
    assert path_length(R) == pytest.approx(9.0)
    with pytest.raises(ValueError, match="per_step"):
        resample_waypoints(W, per_step=0)


@pytest.mark.parametrize("factor", [1, 4])
@pytest.mark.parametrize("segments", [None, [0, 2], [2, 1], []])
def test_batched_whole_path_check_agrees_with_checkmotion_segment_by_segment(robot, factor, segments):
    from tpee_ompl.planning.setup import make_simple_setup

    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    si.getStateSpace().setValidSegmentCountFactor(factor)
    si.setup()
    rng = np.random.default_rng(factor)
    verdicts = set()
    for _ in range(40):
        W = rng.uniform(robot.lower, robot.upper, (4, 4))
        W = W[[robot.is_valid(w) for w in W]]
        if len(W) < 4:
            continue
        states = [set_state(si.allocState(), w) for w in W]
        ks = range(len(W) - 1) if segments is None else segments
        expected = all(si.checkMotion(states[k], states[k + 1]) for k in ks)
        assert path_passes_motion_checks(si, W, segments=segments) == expected
        verdicts.add(expected)
    assert verdicts == ({True} if segments == [] else {True, False})  # both verdicts were compared (none to check: True)


def test_path_to_array_and_array_to_path_name_their_argument_order_when_given_the_other() -> None:
    """A helper setting up Baxter's arm called path_to_array(si, path) and got an AttributeError from the bindings."""
    si, _ = box_problem()
    path = array_to_path(si, np.array([[0.0, 0.0], [0.1, 0.1]]))
    with pytest.raises(ValueError, match=r"path_to_array\(path, n\) takes an og.PathGeometric first"):
        path_to_array(si, path)
    with pytest.raises(ValueError, match=r"array_to_path\(si, waypoints\) takes an ob.SpaceInformation first"):
        array_to_path(path, si)
