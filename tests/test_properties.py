"""Property-based tests (hypothesis) over the public API: adversarial inputs work or raise one documented error.

For every input the rule is the same: a correct result, or the documented exception type
(``ValueError`` and its subclasses ``AimingError``/``QuerySetError``, ``FileNotFoundError`` for
missing files) with a message that names the bad value or parameter.  Never a crash, a hang or a
silently wrong answer: results are checked against independent computations (Pinocchio FK for
aiming, the joint limits, the sector tables).
"""

from __future__ import annotations

import gc
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from ompl import base as ob

from tpee_ompl.planning.dimension_rrt import DimensionRRT
from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.planning.paths import MIN_JOINT_STEP, set_state
from tpee_ompl.planning.setup import make_simple_setup
from tpee_ompl.model.pointing import (
    AimingError,
    UnreachableTargetError,
    aim,
    aim_batch,
    aim_checked,
    aim_errors,
    check_target,
    default_geometry,
)
from tpee_ompl.model.queries import QuerySetError, load_queries, save_queries
from tpee_ompl.model.wearer_arm import MAX_TARGET_DISTANCE, WearerArm
from tpee_ompl.resources import model_file as find_model_file
from tpee_ompl.resources import query_set_path
from tpee_ompl.model.sectors import (
    SECTORS,
    cross_sector_trajectory,
    in_pointing_sector,
    posture_preset,
    posture_sector,
    select_sector,
)
from tpee_ompl.library.tracker import Tracker, TrackerOptions

SETTINGS = settings(
    max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
FEW = settings(SETTINGS, max_examples=25)

SPECIAL = [math.nan, math.inf, -math.inf, 1e300, -1e300, 1e308, -0.0, 5e-324, MAX_TARGET_DISTANCE * 1.01]
numbers = st.one_of(st.floats(-10, 10), st.sampled_from(SPECIAL), st.floats(allow_nan=True, allow_infinity=True))


def _names_bad_value(msg: str, value: np.ndarray) -> bool:
    """The message shows a non-finite value, or the offending number, or the failing rule."""
    low = msg.lower()
    if "shape" in low:
        return True
    if not np.all(np.isfinite(value)):
        return "nan" in low or "inf" in low
    return any(k in low for k in ("shape", "farther", "max_target_distance", "limits", "finite"))


# ---------------------------------------------------------------------------------------- robot
configs = st.one_of(
    hnp.arrays(float, st.sampled_from([(4,), (3,), (5,), (0,), (2, 2), (1, 4)]), elements=numbers),
    hnp.arrays(float, (4,), elements=st.floats(-4, 4)),
)


@SETTINGS
@given(q=configs)
def test_single_configuration_queries_answer_or_raise_value_error_naming_it(robot: WearerArm, q: np.ndarray) -> None:
    for fn in (robot.is_valid, robot.clearance, robot.muzzle):
        try:
            out = fn(q)
        except ValueError as exc:
            assert q.shape != (4,) or not np.all(np.isfinite(q))
            assert _names_bad_value(str(exc), q), str(exc)
            continue
        assert q.shape == (4,) and np.all(np.isfinite(q))
        if fn == robot.is_valid:
            assert out == bool(robot.are_valid(q[None])[0])
            if not robot.within_limits(q):
                assert out is False  # out of limits is never valid
        elif fn == robot.clearance:
            assert math.isfinite(out)
        else:
            p, u = out
            assert np.all(np.isfinite(p)) and np.linalg.norm(u) == pytest.approx(1.0)


@SETTINGS
@given(Q=hnp.arrays(float, st.tuples(st.integers(0, 6), st.sampled_from([3, 4, 5])), elements=numbers))
def test_batched_validity_matches_single_checks_or_raises(robot: WearerArm, Q: np.ndarray) -> None:
    try:
        ok = robot.are_valid(Q)
    except ValueError as exc:
        assert Q.shape[1] != 4 or not np.all(np.isfinite(Q))
        assert _names_bad_value(str(exc), Q), str(exc)
        return
    assert ok.shape == (len(Q),) and ok.dtype == bool
    assert [robot.is_valid(q) for q in Q] == ok.tolist()


targets = st.one_of(
    hnp.arrays(float, (3,), elements=numbers),
    hnp.arrays(float, (3,), elements=st.floats(-15, 15)),
    st.sampled_from(["pivot", "torso", "head", "blind"]),
)


def _target(robot: WearerArm, t: np.ndarray | str, k: int = 3) -> np.ndarray:
    """Resolve the named adversarial targets: the pivot, inside the body, in posture k's blind area."""
    if not isinstance(t, str):
        return t
    g = default_geometry()
    if t == "pivot":
        return g.pivot.copy()
    if t == "blind":
        origin, rot = g.pan_frame(posture_preset(k))
        return origin[0] + rot[0][:, 2] * 2.0  # on the pan axis, 2 m out
    go = robot.gmodel.geometryObjects[robot.gmodel.getGeometryId(f"{t}_0")]
    return go.placement.translation.copy()


@SETTINGS
@given(t=targets, q=hnp.arrays(float, (4,), elements=st.floats(-1.5, 1.5)))
def test_line_of_sight_answers_or_raises_value_error_naming_target(robot: WearerArm, t, q: np.ndarray) -> None:
    t = _target(robot, t)
    try:
        clear = robot.line_of_sight_clear(q, t)
    except ValueError as exc:
        assert not np.all(np.isfinite(t)) or np.max(np.abs(t)) > MAX_TARGET_DISTANCE
        assert _names_bad_value(str(exc), t), str(exc)
        return
    assert isinstance(clear, bool)


@FEW
@given(margin=st.one_of(numbers, st.integers(-3, 3), st.sampled_from([None, "0.02", True, [0.02]])))
def test_wearer_arm_security_margin_is_validated(margin) -> None:
    try:
        arm = WearerArm(security_margin=margin)
    except ValueError as exc:
        assert "security_margin" in str(exc)
        return
    assert arm.security_margin == float(margin) and 0 <= arm.security_margin <= 1.0


# ---------------------------------------------------------------------------------------- files
URDF_TEXT = find_model_file("wearer_arm.urdf").read_text()
SRDF_TEXT = find_model_file("wearer_arm.srdf").read_text()


@FEW
@given(cut=st.integers(0, len(URDF_TEXT) - 1))
def test_truncated_urdf_raises_value_error_naming_the_file(tmp_path_factory, cut: int) -> None:
    p = tmp_path_factory.mktemp("urdf") / "cut.urdf"
    p.write_text(URDF_TEXT[:cut])
    with pytest.raises(ValueError, match=re.escape(str(p))):
        WearerArm(p, False)


@FEW
@given(cut=st.integers(0, len(SRDF_TEXT) - 20))
def test_truncated_srdf_raises_value_error_naming_the_file(tmp_path_factory, cut: int) -> None:
    p = tmp_path_factory.mktemp("srdf") / "cut.srdf"
    p.write_text(SRDF_TEXT[:cut])
    with pytest.raises(ValueError, match=re.escape(str(p))):
        WearerArm(find_model_file("wearer_arm.urdf"), p)


@FEW
@given(link=st.text(st.characters(min_codepoint=97, max_codepoint=122), min_size=1, max_size=12))
def test_srdf_with_unknown_link_raises_value_error_naming_it(tmp_path_factory, robot: WearerArm, link: str) -> None:
    assume(link not in {f.name for f in robot.model.frames})
    p = tmp_path_factory.mktemp("srdf") / "bad.srdf"
    p.write_text(f'<robot name="x"><disable_collisions link1="link1" link2="{link}"/></robot>')
    with pytest.raises(ValueError, match=f"unknown link '{link}'"):
        WearerArm(find_model_file("wearer_arm.urdf"), p)


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (lambda s: s.replace('name="j2"', 'name="jx"'), "j2"),
        (lambda s: s.replace('<joint name="j3" type="revolute"', '<joint name="j3" type="continuous"'), "j3"),
        (lambda s: s.replace('lower="-3.300000000000" upper="3.300000000000"', 'lower="3.3" upper="-3.3"'), "j3"),
        (lambda s: re.sub(r'radius="([0-9.]+)"', r'radius="-\1"', s, count=1), "size of -"),
        (lambda s: s.replace('<link name="muzzle"', '<link name="nozzle"').replace('"muzzle"', '"nozzle"'), "muzzle"),
        (lambda s: "\ufeff\x00" + s, "URDF"),
    ],
)
def test_urdf_with_wrong_joints_or_shapes_raises_value_error(tmp_path: Path, edit, match: str) -> None:
    p = tmp_path / "bad.urdf"
    p.write_text(edit(URDF_TEXT))
    with pytest.raises(ValueError, match=match):
        WearerArm(p, False)


@pytest.mark.parametrize("which", ["urdf", "srdf"])
def test_missing_or_binary_model_files_raise_documented_errors(tmp_path: Path, which: str) -> None:
    urdf, srdf = find_model_file("wearer_arm.urdf"), find_model_file("wearer_arm.srdf")
    missing = tmp_path / "nope.xml"
    with pytest.raises(FileNotFoundError, match="nope.xml"):
        WearerArm(missing, srdf) if which == "urdf" else WearerArm(urdf, missing)
    binary = tmp_path / "bin.xml"
    binary.write_bytes(b"\xff\xfe\x00\x81garbage")
    with pytest.raises(ValueError, match="bin.xml"):
        WearerArm(binary, srdf) if which == "urdf" else WearerArm(urdf, binary)


# ---------------------------------------------------------------------------------------- setup
@SETTINGS
@given(step=st.one_of(numbers, st.integers(-2, 20), st.sampled_from([None, "0.01", True])))
def test_make_simple_setup_joint_step_is_validated(robot: WearerArm, step) -> None:
    try:
        ss = make_simple_setup(robot, joint_step=step)
    except ValueError as exc:
        assert "joint_step" in str(exc)
        assert step is not None
        return
    got = ss._tpee_refs[2].step
    assert got == (robot.max_joint_step() if step is None else float(step)) and got >= MIN_JOINT_STEP


@SETTINGS
@given(start=configs)
def test_make_simple_setup_refuses_bad_start_with_value_error(robot: WearerArm, start: np.ndarray) -> None:
    goal = np.r_[posture_preset(3), 0.0, 0.0]
    try:
        make_simple_setup(robot, start, goal)
    except ValueError as exc:
        assert "start" in str(exc) or _names_bad_value(str(exc), start), str(exc)
        return
    assert robot.is_valid(start)


# ---------------------------------------------------------------------------------------- aiming
postures = st.one_of(
    st.sampled_from(SECTORS),
    st.integers(-2, 7),
    hnp.arrays(float, (2,), elements=st.one_of(st.floats(-4, 4), st.sampled_from([math.nan, math.inf]))),
)


@SETTINGS
@given(t=targets, posture=postures, ref=st.one_of(st.floats(-10, 10), st.sampled_from([1e300, -1e300, math.nan])))
def test_aim_returns_a_correct_aim_or_raises_aiming_error(robot: WearerArm, t, posture, ref: float) -> None:
    k = posture if isinstance(posture, int) and posture in SECTORS else 3
    t = _target(robot, t, k)
    try:
        q = aim(t, posture, pan_reference=ref)
    except AimingError as exc:
        assert isinstance(exc, ValueError)
        if not (np.all(np.isfinite(t)) and math.isfinite(ref)):
            assert "nan" in str(exc) or "inf" in str(exc), str(exc)
        return
    except ValueError as exc:  # a bad posture, never a bad target
        assert re.search("sector|posture", str(exc)), str(exc)
        return
    assert q.shape == (4,) and np.all(np.isfinite(q)) and robot.within_limits(q)
    _, along, angle = aim_errors(robot, q, t)
    assert along > 0 and angle < 1e-6  # the target really is on the barrel's ray (Pinocchio FK)
    row = aim_batch(t[None], posture, pan_reference=ref, strict=False)[0]
    np.testing.assert_array_equal(row, q)


@SETTINGS
@given(T=hnp.arrays(float, st.tuples(st.integers(1, 5), st.just(3)), elements=numbers), k=st.sampled_from(SECTORS))
def test_non_strict_aim_rows_are_nan_or_correct_and_checked_rows_are_collision_free(robot: WearerArm, T, k) -> None:
    Q = aim_batch(T, k, strict=False)
    Qc, ok = aim_checked(robot, T, k)
    np.testing.assert_array_equal(Q, Qc)
    for t, q, good in zip(T, Q, ok):
        if np.any(np.isnan(q)):
            assert not good and np.all(np.isnan(q))
            continue
        assert np.all(np.isfinite(t)) and np.max(np.abs(t)) <= MAX_TARGET_DISTANCE
        assert aim_errors(robot, q, t)[2] < 1e-6
        if good:
            assert robot.is_valid(q) and robot.line_of_sight_clear(q, t)


@SETTINGS
@given(t=targets)
def test_check_target_refuses_non_finite_far_and_inside_body_targets(robot: WearerArm, t) -> None:
    named = t if isinstance(t, str) else None
    t = _target(robot, t)
    try:
        out = check_target(t, robot)
    except UnreachableTargetError as exc:
        assert _names_bad_value(str(exc), t) or "inside" in str(exc), str(exc)
        return
    assert named not in ("torso", "head")
    assert np.all(np.isfinite(out)) and np.max(np.abs(out)) <= MAX_TARGET_DISTANCE


# ---------------------------------------------------------------------------------------- sectors
@SETTINGS
@given(t=targets, current=st.one_of(st.none(), st.sampled_from(SECTORS)))
def test_sector_functions_agree_with_each_other_for_any_finite_target(robot: WearerArm, t, current) -> None:
    t = _target(robot, t)
    try:
        home = posture_sector(t)
    except ValueError as exc:
        assert not np.all(np.isfinite(t)) or np.allclose(t, default_geometry().pivot)
        assert "nan" in str(exc) or "inf" in str(exc) or "origin" in str(exc), str(exc)
        return
    assert home in SECTORS
    assert in_pointing_sector(t, home)  # a pointing sector contains its posture sector
    chosen = select_sector(t, current)
    if current is not None and in_pointing_sector(t, current):
        assert chosen == current
    else:
        assert chosen == home


@SETTINGS
@given(scale=st.sampled_from([1.0, 1e6, 1e100, 1e300, 1e307]), d=hnp.arrays(float, (3,), elements=st.floats(-1, 1)))
def test_sector_of_a_direction_does_not_depend_on_distance(d: np.ndarray, scale: float) -> None:
    assume(np.max(np.abs(d)) > 1e-3)
    pivot = default_geometry().pivot
    assert posture_sector(pivot + d) == posture_sector(pivot + d * scale)
    assert [in_pointing_sector(pivot + d, k) for k in SECTORS] == [in_pointing_sector(pivot + d * scale, k) for k in SECTORS]


@SETTINGS
@given(i=st.one_of(st.integers(-3, 8), st.sampled_from([1.0, "1", None, True])), j=st.integers(-3, 8))
def test_sector_numbers_are_validated(i, j: int) -> None:
    try:
        traj = cross_sector_trajectory(i, j)
    except ValueError as exc:
        assert "sector" in str(exc)
        return
    assert traj.shape == (7, 2)
    np.testing.assert_array_equal(traj[0], posture_preset(i))
    np.testing.assert_array_equal(traj[-1], posture_preset(j))


# ---------------------------------------------------------------------------------------- planner parameters
BAD_PARAMETERS = {
    "groups": (st.one_of(
        st.lists(st.lists(st.integers(-1, 5), max_size=4), max_size=3),
        st.lists(st.lists(st.sampled_from([0.5, "1", None, 2]), min_size=1, max_size=2), min_size=1, max_size=2),
        st.sampled_from(["01", 3, [[0, 1], [2, 3.0]]]),
    ), "group|DOF"),
    "h": (st.one_of(st.integers(-5, 2), st.sampled_from([7.0, "7", True, 10**9])), "h "),
    "max_samples": (st.one_of(st.integers(-5, 0), st.sampled_from([1.5, "10", True, math.nan])), "max_samples"),
    "narrowing": (st.one_of(numbers.filter(lambda v: not 0 < v <= 1), st.sampled_from(["0.5", True])), "narrowing"),
    "narrow_after": (st.one_of(st.integers(-5, -1), st.sampled_from([2.5, "3"])), "narrow_after"),
    "seed": (st.one_of(st.integers(-5, -1), st.sampled_from([1.5, "1", True])), "seed"),
    "range_": (st.one_of(numbers.filter(lambda v: not (math.isfinite(v) and v > 0)),
                         st.sampled_from(["x", [0.1, 0.1], [[0.1] * 4]])), "range_"),
    "prescribed": (st.one_of(
        st.builds(lambda n: {0: np.zeros((n, 2))}, st.integers(0, 6)),
        st.sampled_from([{0: [[math.nan, 0]] * 7}, {0: "abc"}, {9: np.zeros((7, 2))}, {"0": np.zeros((7, 2))}, [1]]),
    ), "prescribed"),
    "name": (st.sampled_from(["", 3, None]), "name"),
}


@pytest.fixture(scope="module")
def plain_si(robot: WearerArm) -> ob.SpaceInformation:
    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    si._keep = ss  # type: ignore[attr-defined]
    return si


@SETTINGS
@given(data=st.data(), param=st.sampled_from(sorted(BAD_PARAMETERS)))
def test_bad_dimension_rrt_parameters_raise_value_error_naming_them(plain_si, data, param: str) -> None:
    strategy, match = BAD_PARAMETERS[param]
    value = data.draw(strategy)
    try:
        planner = DimensionRRT(plain_si, **{param: value})
    except ValueError as exc:
        assert re.search(match, str(exc)), (param, value, str(exc))
    else:  # only a value that happens to be valid may construct
        assert param == "groups" and planner.groups == [[int(d) for d in g] for g in value]
    gc.collect()


def test_many_bad_constructions_then_gc_do_not_crash(plain_si) -> None:
    """A ValueError raised after Planner.__init__ left a half-built trampoline that crashed at collection."""
    bad = [{"h": 2}, {"max_samples": 0}, {"narrowing": 2.0}, {"seed": -1}, {"groups": [[0, 0]]},
           {"range_": -1.0}, {"prescribed": {0: np.zeros((3, 2))}}, {"name": ""}]
    for round_ in range(300):
        with pytest.raises(ValueError):
            DimensionRRT(plain_si, **bad[round_ % len(bad)])
        if round_ % 50 == 0:
            gc.collect()
    gc.collect()
    ok = DimensionRRT(plain_si, max_samples=5)  # the class still works afterwards
    assert ok.getName() == "DimensionRRT"


def _solve_status(robot: WearerArm, start, goal, i: int, j: int, **setup_kw) -> ob.PlannerStatus:
    ss = make_simple_setup(robot, start, goal, check_endpoints=False, **setup_kw)
    ss.setPlanner(tpee_dimension_rrt(ss.getSpaceInformation(), i, j, max_samples=20, seed=0))
    return ss.solve(5.0)


@FEW
@given(
    dq=hnp.arrays(float, (4,), elements=st.sampled_from([0.0, 0.3, -0.3, 5.0, -5.0])),
    which=st.sampled_from(["start", "goal"]),
)
def test_dimension_rrt_reports_invalid_endpoints_as_statuses(robot: WearerArm, dq: np.ndarray, which: str) -> None:
    i, j = 1, 4
    start, goal = np.r_[posture_preset(i), 0.0, 0.0], np.r_[posture_preset(j), 0.0, 0.0]
    bad = (start if which == "start" else goal) + dq
    s0, s1 = (bad, goal) if which == "start" else (start, bad)
    status = _solve_status(robot, s0, s1, i, j)
    on_table3 = np.allclose(dq[:2], 0)
    if on_table3 and robot.is_valid(bad):
        assert status in (ob.PlannerStatus.EXACT_SOLUTION, ob.PlannerStatus.TIMEOUT)
    else:
        expected = ob.PlannerStatus.INVALID_START if which == "start" else ob.PlannerStatus.INVALID_GOAL
        assert status == expected, (dq, status)


# ---------------------------------------------------------------------------------------- query files
@FEW
@given(cut=st.integers(0, 4000))
def test_truncated_query_file_raises_query_set_error_naming_the_file(tmp_path_factory, robot, cut: int) -> None:
    text = query_set_path("planning_necessary").read_text()
    p = tmp_path_factory.mktemp("q") / "cut.json"
    p.write_text(text[:cut])
    with pytest.raises(QuerySetError, match=re.escape(str(p))):
        load_queries(p, robot)


@FEW
@given(version=st.one_of(st.integers(-3, 5).filter(lambda v: v != 1), st.sampled_from([True, "1", 1.5, None])))
def test_query_file_with_wrong_version_raises_naming_it(tmp_path_factory, version) -> None:
    p = tmp_path_factory.mktemp("q") / "v.json"
    p.write_text(json.dumps({"format_version": version, "queries": []}))
    with pytest.raises(QuerySetError, match=re.escape(f"format_version {version!r}")):
        load_queries(p)


def test_query_set_for_another_model_is_refused_when_a_robot_is_given(tmp_path: Path, robot: WearerArm) -> None:
    queries = load_queries("planning_necessary", robot)[:2]
    p = save_queries(tmp_path / "other.json", queries, name="x", seed=0, model_hash="0123456789abcdef")
    assert len(load_queries(p)) == 2  # no robot: no model check
    with pytest.raises(QuerySetError, match="0123456789abcdef"):
        load_queries(p, robot)
    for doc in ([], {"format_version": 1, "queries": [{"id": 0}]}, {"format_version": 1, "queries": "x"}):
        p.write_text(json.dumps(doc))
        with pytest.raises(QuerySetError, match="other.json"):
            load_queries(p)


# ---------------------------------------------------------------------------------------- tracker
def _no_planner(*_args) -> np.ndarray:
    raise RuntimeError("planning not expected")


@SETTINGS
@given(t=st.one_of(hnp.arrays(float, (3,), elements=st.sampled_from(SPECIAL)), st.sampled_from(["pivot", "torso", "head"])),
       time=st.one_of(st.floats(0, 10), st.sampled_from([math.nan, math.inf, "1"])))
def test_tracker_records_bad_targets_as_unreachable_and_refuses_bad_times(robot: WearerArm, t, time) -> None:
    t = _target(robot, t)
    tracker = Tracker(robot, _no_planner)
    q0 = tracker.q.copy()
    try:
        tracker.step(time, t)
    except ValueError as exc:
        assert "time" in str(exc) and not (isinstance(time, float) and math.isfinite(time))
        return
    except RuntimeError:  # a finite target it could aim at from another sector (planner stub)
        assert np.all(np.isfinite(t))
        return
    res = tracker.result()
    assert res.events[-1].kind in ("unreachable", "blind-area", "aim")
    if res.events[-1].kind == "unreachable":
        np.testing.assert_array_equal(tracker.q, q0)  # holds still


@FEW
@given(shape=st.sampled_from([(2,), (4,), (1, 3), ()]))
def test_tracker_refuses_targets_of_the_wrong_shape(robot: WearerArm, shape) -> None:
    with pytest.raises(ValueError, match="shape"):
        Tracker(robot, _no_planner).step(0.0, np.zeros(shape))


@FEW
@given(speed=numbers, step=st.one_of(numbers, st.just(1e-9)))
def test_tracker_options_are_validated(speed: float, step: float) -> None:
    try:
        opts = TrackerOptions(joint_speed=speed, check_step=step)
    except ValueError as exc:
        assert re.search("joint_speed|check_step", str(exc))
        return
    assert opts.joint_speed > 0 and opts.check_step >= MIN_JOINT_STEP


def test_set_state_round_trip_survives_property_run(plain_si) -> None:
    """Sanity: the module-scoped setup is still usable after all the bad constructions above."""
    s = plain_si.allocState()
    set_state(s, [0.1, 0.2, 0.3, 0.4])
    assert [s[i] for i in range(4)] == pytest.approx([0.1, 0.2, 0.3, 0.4])
