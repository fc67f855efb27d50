"""Certified motion checking (tpee_ompl.planning.certified): never accepts what the dense check rejects."""

from __future__ import annotations

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from tests.helpers.panda import needs_panda
from tpee_ompl.model.queries import load_queries
from tpee_ompl.planning.certified import CertifiedMotionOptions, CertifiedMotionValidator
from tpee_ompl.planning.paths import motion_states, path_to_array
from tpee_ompl.planning.setup import BatchedMotionValidator, make_simple_setup, motion_check_step


@pytest.fixture(scope="module")
def panda():
    from tpee_ompl.model.robots import panda_shelf

    return panda_shelf()


def _certified(robot, **options) -> CertifiedMotionValidator:
    opts = CertifiedMotionOptions(**options) if options else None
    return make_simple_setup(robot, motion_validator="certified", certified_options=opts).getSpaceInformation().getMotionValidator()


def _dense_ok(robot, a: np.ndarray, b: np.ndarray, step: float) -> bool:
    S = motion_states(a, b, step)
    S[-1] = b  # the end state itself, as OMPL's validators check it (a + 1 * (b - a) can miss b by an ulp)
    return bool(robot.are_valid(S).all())


def _random_motions(robot, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    A = rng.uniform(robot.lower, robot.upper, (2 * n, robot.nq))
    A = A[robot.are_valid(A)][:n]
    D = rng.normal(size=A.shape)
    D /= np.linalg.norm(D, axis=1)[:, None]
    return A, np.clip(A + D * rng.uniform(0.01, 0.8, (len(A), 1)), robot.lower, robot.upper)


def _assert_sound(robot, mv: CertifiedMotionValidator, A: np.ndarray, B: np.ndarray) -> None:
    """Accepted: the dense re-check at the step accepts (at step/8 too when no fallback was needed).
    Rejected: a state found invalid, or the fallback's dense states contain an invalid one."""
    step = mv.step
    verdicts = {"certified": 0, "dense": 0, "rejected": 0}
    for a, b in zip(A, B):
        v = mv.certify(a, b)
        if v is False:
            assert mv.last_rejection is not None and not robot.is_valid(mv.last_rejection)
            verdicts["rejected"] += 1
            continue
        certified = v is True or len(v) == 0
        accepted = mv._decide([v])[0]
        assert accepted == (certified or bool(robot.are_valid(v).all()))
        if accepted:
            assert _dense_ok(robot, a, b, step)
        if certified:
            assert _dense_ok(robot, a, b, step / 8)
            verdicts["certified"] += 1
        else:
            verdicts["dense"] += 1
    assert min(verdicts.values()) > 0, verdicts  # every outcome occurs


@pytest.mark.parametrize("n", [300, pytest.param(3000, marks=pytest.mark.slow)])
def test_random_wearer_motions_certified_only_when_dense_check_agrees(robot, n):
    A, B = _random_motions(robot, n, np.random.default_rng(21))
    _assert_sound(robot, _certified(robot), A, B)


@needs_panda
@pytest.mark.parametrize("n", [300, pytest.param(3000, marks=pytest.mark.slow)])
def test_random_panda_motions_certified_only_when_dense_check_agrees(panda, n):
    A, B = _random_motions(panda, n, np.random.default_rng(22))
    _assert_sound(panda, _certified(panda), A, B)


def _planned_path_motions(robot, start, goal, validator: str) -> np.ndarray:
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_ERROR)
    ss = make_simple_setup(robot, start, goal, motion_validator=validator)
    ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
    assert ss.solve(5.0) and ss.haveExactSolutionPath()
    return path_to_array(ss.getSolutionPath(), robot.nq)


def test_paths_planned_with_certified_motions_pass_the_dense_check(robot):
    for q in load_queries("planning_necessary", robot)[:3]:
        P = _planned_path_motions(robot, q.start, q.goal, "certified")
        np.testing.assert_allclose(P[0], q.start)
        np.testing.assert_allclose(P[-1], q.goal)
        assert all(_dense_ok(robot, a, b, robot.max_joint_step()) for a, b in zip(P[:-1], P[1:]))


def test_edges_of_paths_planned_densely_get_the_same_verdict_or_a_witness(robot):
    mv = _certified(robot)
    for q in load_queries("planning_necessary", robot)[3:5]:
        P = _planned_path_motions(robot, q.start, q.goal, "batched")
        _edges = np.stack([P[:-1], P[1:]], axis=1)
        for a, b in _edges:
            v = mv.certify(a, b)
            assert v is not False or not robot.is_valid(mv.last_rejection)
        assert mv.check_motions(P[:-1], P[1:]).all()  # valid paths stay valid: the margin is met densely


def test_end_state_distances_are_cached_and_the_cache_stays_bounded(robot):
    mv = _certified(robot, cache_size=3)
    rng = np.random.default_rng(5)
    A, B = _random_motions(robot, 6, rng)
    mv.check_motions(A[:1], B[:1])
    hits, evals = mv.cache_hits, mv.distance_evaluations
    mv.check_motions(A[:1], B[:1])
    assert mv.cache_hits == hits + 2 and mv.distance_evaluations - evals <= evals - 2
    np.testing.assert_allclose(mv._cache[A[0].tobytes()], mv.groups.slack(A[0]), atol=1e-9)
    mv.check_motions(A, B)
    assert len(mv._cache) == 3
    no_cache = _certified(robot, cache_size=0)
    assert (no_cache.check_motions(A, B) == mv.check_motions(A, B)).all() and len(no_cache._cache) == 0


def test_check_motion_and_check_motions_agree_and_count(robot):
    ss = make_simple_setup(robot, motion_validator="certified")
    si, mv = ss.getSpaceInformation(), ss.getSpaceInformation().getMotionValidator()
    assert isinstance(mv, BatchedMotionValidator) and motion_check_step(ss) == pytest.approx(robot.max_joint_step())
    A, B = _random_motions(robot, 40, np.random.default_rng(6))
    batch = mv.check_motions(A, B)
    s1, s2 = si.allocState(), si.allocState()
    single = []
    for a, b in zip(A, B):
        for s, q in ((s1, a), (s2, b)):
            for i, v in enumerate(q):
                s[i] = float(v)
        single.append(si.checkMotion(s1, s2))
    assert single == batch.tolist() and mv.motions_checked == 80 and mv.distance_evaluations > 0


def test_bad_validator_settings_raise_naming_the_setting(robot):
    with pytest.raises(ValueError, match="motion_validator"):
        make_simple_setup(robot, motion_validator="sparse")
    with pytest.raises(ValueError, match="contradicts"):
        make_simple_setup(robot, batched_motion_validator=False, motion_validator="certified")
    with pytest.raises(ValueError, match="certified_options"):
        make_simple_setup(robot, certified_options=CertifiedMotionOptions())
    with pytest.raises(ValueError, match="min_gain"):
        CertifiedMotionOptions(min_gain=-1.0)
    with pytest.raises(ValueError, match="cache_size"):
        CertifiedMotionOptions(cache_size=1.5)
    with pytest.raises(ValueError, match="batched_motion_validator"):
        make_simple_setup(robot, batched_motion_validator="yes")
    assert type(make_simple_setup(robot, motion_validator="discrete").getSpaceInformation().getMotionValidator()) is ob.MotionValidator


def test_an_uncertified_stretch_shorter_than_a_step_is_checked_and_counted_as_a_fallback(tmp_path):
    """Both ends certify only near themselves and no dense grid state falls between the fronts: the gap's
    midpoint is checked (it used to pass unchecked, counted as certified: a 2-mm dip below the margin)."""
    from ompl import util as ou

    from tpee_ompl.model.obstacles import Obstacle
    from tpee_ompl.model.robot_checker import RobotChecker
    from tpee_ompl.planning.paths import set_state
    from tpee_ompl.planning.setup import make_simple_setup

    ou.setLogLevel(ou.LOG_WARN)
    urdf = tmp_path / "arm1.urdf"
    urdf.write_text("""<robot name="r"><link name="base"/>
      <link name="l1"><collision><origin xyz="1 0 0"/><geometry><sphere radius="0.001"/></geometry></collision></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>""")
    r = RobotChecker(urdf, obstacles=[Obstacle("pin", "sphere", (0.001,), (1.02, 0.0, 0.0))])
    si = make_simple_setup(r, motion_validator="certified").getSpaceInformation()
    mv = si.getMotionValidator()
    h = 0.4995 * r.max_joint_step()  # the motion is one step long: its only grid state is its end
    x, y = si.allocState(), si.allocState()
    set_state(x, [-h])
    set_state(y, [h])
    v = mv.certify(np.array([-h]), np.array([h]))
    assert isinstance(v, np.ndarray) and len(v) == 1 and abs(float(v[0, 0])) < h  # the gap's midpoint
    before = mv.fallbacks
    assert not si.checkMotion(x, y)  # the midpoint keeps 18 mm where the margin is 20 mm
    assert mv.fallbacks == before + 1


@pytest.mark.parametrize("factor", [1, 4])
def test_a_motion_the_certificates_cannot_cover_gets_ompls_dense_states(robot, factor):
    """Out of the limits the certificates do not apply: the dense check takes the ``f * ceil(d / step)`` states
    OMPL's discrete validator would (5 instead of 8 for 1.2 steps at f = 4, before)."""
    mv = _certified(robot)
    mv._space.setValidSegmentCountFactor(factor)
    a = robot.lower + 0.5 * (robot.upper - robot.lower)
    a[1] = robot.upper[1] + 1e-3  # the start outside the limits: nothing is certified
    b = a + np.r_[1.2 * mv.step, 0.0, 0.0, 0.0]
    v = mv.certify(a, b)
    assert isinstance(v, np.ndarray) and len(v) == factor * 2
