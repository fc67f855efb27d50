"""States of a RealVector / SO2 space or a compound of them as flat arrays: reading, writing, metric, bounds."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.planning_spaces import locked_dimension_space
from ompl import base as ob

from tpee_ompl.planning.space_layout import RealVectorLayout


def _space(n: int = 4, bound: float = 2.0) -> ob.RealVectorStateSpace:
    space = ob.RealVectorStateSpace(n)
    space.setBounds(-bound, bound)
    return space


def test_compound_layout_reads_writes_and_measures_like_ompl() -> None:
    cs = ob.CompoundStateSpace()
    a, b = ob.RealVectorStateSpace(2), ob.RealVectorStateSpace(1)
    a.setBounds(-1.0, 1.0)
    b.setBounds(0.0, 3.0)
    cs.addSubspace(a, 1.0)
    cs.addSubspace(b, 0.5)
    si = ob.SpaceInformation(cs)
    si.setStateValidityChecker(lambda s: True)
    si.setup()
    lay = RealVectorLayout(cs)
    assert lay.n == 3
    np.testing.assert_array_equal(lay.lower, [-1, -1, 0])
    x, y = si.allocState(), si.allocState()
    lay.write(x, [0.1, -0.2, 2.0])
    lay.write(y, [0.5, 0.3, 1.0])
    np.testing.assert_allclose(lay.read(x), [0.1, -0.2, 2.0])
    assert float(lay.distance(lay.read(x), lay.read(y))) == pytest.approx(si.distance(x, y))


@pytest.mark.parametrize("make", [ob.SE2StateSpace, ob.SO3StateSpace, lambda: ob.TimeStateSpace()])
def test_other_space_types_are_refused_by_name(make) -> None:
    space = make()
    with pytest.raises(ValueError, match=type(space).__name__):
        RealVectorLayout(space)
    cs = ob.CompoundStateSpace()
    cs.addSubspace(ob.SO2StateSpace(), 1.0)
    cs.addSubspace(space, 1.0)
    with pytest.raises(ValueError, match=rf"{type(space).__name__} \(subspace \[1\]\)"):
        RealVectorLayout(cs)


def test_layout_tells_when_the_space_bounds_or_weights_changed() -> None:
    space = _space(3, bound=1.0)
    lay = RealVectorLayout(space)
    assert not lay.layout_changed(space)
    space.setBounds(-1.0, 1.5)
    assert lay.layout_changed(space)
    space.setBounds(-1.0, 1.0)
    assert not lay.layout_changed(space)
    cs = ob.CompoundStateSpace()
    cs.addSubspace(ob.SO2StateSpace(), 1.0)
    r = _space(2, bound=1.0)
    cs.addSubspace(r, 1.0)
    lay = RealVectorLayout(cs)
    assert not lay.layout_changed(cs)
    r.setBounds(-0.5, 1.0)
    assert lay.layout_changed(cs)
    lay = RealVectorLayout(cs)
    cs.setSubspaceWeight(0, 10.0)  # a reused planner kept the old metric: best cost 5.07 for a path 35.49 long
    assert lay.layout_changed(cs)


def test_real_vector_space_without_bounds_is_refused() -> None:
    with pytest.raises(ValueError, match="bounds"):
        RealVectorLayout(ob.RealVectorStateSpace(3))


def test_a_space_whose_bounds_were_never_set_is_told_to_set_them() -> None:
    """OMPL's bounds start at 0 and 0: that is not a locked joint (the error used to say so)."""
    with pytest.raises(ValueError, match=r"no bounds \(every low and high is 0\): call space.setBounds") as e:
        RealVectorLayout(ob.RealVectorStateSpace(3))
    assert "locked" not in str(e.value)


def test_a_dimension_locked_by_bounds_of_width_zero_is_taken_but_a_space_of_nothing_else_is_refused() -> None:
    """OMPL users lock a joint with low == high (RRTConnect plans such a space): it was refused; a RealVector space
    (or a compound's subspace) locked in every dimension cannot move at all, and OMPL divides by its extent."""
    layout = RealVectorLayout(locked_dimension_space(3, 1))
    assert layout.lower[1] == layout.upper[1] == 0.5
    one = ob.RealVectorStateSpace(2)
    one.setBounds(0.5, 0.5)
    with pytest.raises(ValueError, match="bounds of width 0 for every dimension: nothing in it can move"):
        RealVectorLayout(one)
    cs = ob.CompoundStateSpace()
    cs.addSubspace(locked_dimension_space(2, 0), 1.0)
    cs.addSubspace(one, 1.0)
    with pytest.raises(ValueError, match=r"\(subspace \[1\]\) has bounds of width 0 for every dimension"):
        RealVectorLayout(cs)


def test_so2_leaves_wrap_around_like_the_space() -> None:
    cs = ob.CompoundStateSpace()
    cs.addSubspace(ob.SO2StateSpace(), 1.0)
    r = ob.RealVectorStateSpace(1)
    r.setBounds(-1.0, 1.0)
    cs.addSubspace(r, 0.5)
    si = ob.SpaceInformation(cs)
    si.setStateValidityChecker(lambda s: True)
    si.setup()
    lay = RealVectorLayout(cs)
    assert lay.n == 2 and list(lay.circular) == [True, False]
    a, b = np.array([3.0, 0.2]), np.array([-3.0, -0.4])
    x, y = lay.write(si.allocState(), a), lay.write(si.allocState(), b)
    np.testing.assert_allclose(lay.read(x), a)
    assert float(lay.distance(a, b)) == pytest.approx(si.distance(x, y))
    assert float(lay.distance(a, b)) < 0.3 + 0.5 * 0.6 + 1e-9  # across +-pi, not 6 rad
    m = si.allocState()
    cs.interpolate(x, y, 0.25, m)
    np.testing.assert_allclose(lay.interpolate(a, b, 0.25), lay.read(m), atol=1e-12)
    mid = lay.interpolate(a, b, 0.5)
    assert abs(abs(mid[0]) - np.pi) < 1e-9


def test_wrapped_so2_values_stay_below_pi_where_rounding_gives_pi() -> None:
    space = ob.SO2StateSpace()
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda s: True)
    si.setup()
    lay = RealVectorLayout(space)
    x = np.nextafter(-np.pi, -10.0)  # np.mod(x + pi, 2 pi) - pi rounds to +pi, outside [-pi, pi)
    w = lay.wrap(np.array([[x], [np.pi], [-np.pi], [0.5]]))[:, 0]
    assert np.all((w >= -np.pi) & (w < np.pi))
    np.testing.assert_allclose(w, [-np.pi, -np.pi, -np.pi, 0.5], atol=1e-15)
    assert si.satisfiesBounds(lay.write(si.allocState(), w[:1]))


def test_plain_layout_writes_and_reads_a_state_exactly() -> None:
    space = ob.RealVectorStateSpace(5)
    space.setBounds(-2.0, 2.0)
    lay = RealVectorLayout(space)
    assert lay.is_plain
    x = ob.SpaceInformation(space).allocState()
    q = np.array([0.1, -1.9, 1e-17, 2.0, -0.3333333333333333])
    assert lay.write(x, q) is x
    np.testing.assert_array_equal(lay.read(x), q)
    assert [x[i] for i in range(5)] == q.tolist()


def test_a_zero_dimensional_real_vector_subspace_holds_no_value_and_adds_nothing_to_the_metric():
    space = ob.CompoundStateSpace()
    rv = ob.RealVectorStateSpace(2)
    rv.setBounds(-1.0, 1.0)
    for sub in (rv, ob.RealVectorStateSpace(0), ob.SO2StateSpace(), ob.RealVectorStateSpace(0)):
        space.addSubspace(sub, 1.0)
    layout = RealVectorLayout(space)
    assert layout.n == 3 and layout.circular.tolist() == [False, False, True]
    A, B = np.zeros((2, 3)), np.array([[0.3, 0.4, 1.0], [0.0, 0.0, -3.0]])
    np.testing.assert_allclose(layout.distance(A, B), [0.5 + 1.0, 3.0])
    np.testing.assert_allclose(layout.leaf_distances(A, B), [[0.5, 1.0], [0.0, 3.0]])
