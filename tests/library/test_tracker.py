"""Fig. 10 tracking: re-aim inside a sector, plan across sectors, hysteresis, bad targets."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from tpee_ompl.library.tracker import Tracker, make_default_planner
from tpee_ompl.planning.paths import motion_is_valid
from tpee_ompl.model.pointing import aim_errors
from tpee_ompl.model.queries import straight_motion
from tpee_ompl.model.sectors import posture_sector, sector_origin
from tpee_ompl.planning.paths import motion_states


def _direction(az_deg: float, el_deg: float) -> np.ndarray:
    a, e = np.deg2rad(az_deg), np.deg2rad(el_deg)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


@pytest.fixture(scope="module")
def planner(robot):
    return make_default_planner(robot, timeout=2.0, seed=1)


def _assert_safe_and_aimed(robot, result):
    Q = result.configurations
    assert len(Q) > 0
    assert robot.are_valid(Q).all()
    for a, b in itertools.pairwise(Q):
        assert robot.are_valid(motion_states(a, b, 0.01)).all()
    assert np.all(np.diff(result.times) >= 0)
    aiming = ~np.isnan(result.targets[:, 0])
    for q, t in zip(Q[aiming], result.targets[aiming]):
        assert aim_errors(robot, q, t)[2] < 1e-6
    # every row outside a cross-sector motion aims at its target (no unreachable targets here)
    assert np.array_equal(aiming, result.sectors != 0)


def test_target_circling_the_wearer_at_three_heights(robot, planner):
    tracker = Tracker(robot, planner, initial_sector=3)
    stream, t = [], 0.0
    for height in (-1.0, 0.5, 2.5):
        for az in np.linspace(0.0, 360.0, 25)[:-1]:
            target = sector_origin() + np.r_[6.0 * _direction(az, 0.0)[:2], height]
            stream.append((t, target))
            t += 0.2
    result = tracker.run(stream)
    _assert_safe_and_aimed(robot, result)
    assert result.count("aim") + result.count("cross-sector") == len(stream)
    assert 1 <= result.count("cross-sector") <= 12
    # only aims, no planning, while the target stays in the current pointing sector
    assert result.count("aim") >= len(stream) - result.count("cross-sector")


def test_jitter_on_a_sector_boundary_switches_at_most_once(robot, planner, rng):
    for boundary_az in (0.0, 90.0, 180.0):
        tracker = Tracker(robot, planner, initial_sector=3)
        stream = [
            (0.1 * i, sector_origin() + 6.0 * _direction(boundary_az + rng.uniform(-4, 4), rng.uniform(-5, 5)))
            for i in range(40)
        ]
        result = tracker.run(stream)
        _assert_safe_and_aimed(robot, result)
        # the first sample may need one switch from the initial posture; after that, none
        first = [e for e in result.events if e.kind == "cross-sector" and e.time > 0.0]
        assert len(first) == 0 and result.count("cross-sector") <= 1


def test_target_jumping_between_sectors_switches_to_each_posture(robot, planner):
    tracker = Tracker(robot, planner, initial_sector=3)
    # each jump leaves the current pointing sector, so each needs a posture change
    points = [(-60.0, -10.0), (60.0, -10.0), (-100.0, -10.0), (100.0, -10.0), (-20.0, -10.0)]
    stream = [(float(i), sector_origin() + 6.0 * _direction(az, el), True) for i, (az, el) in enumerate(points)]
    result = tracker.run(stream)
    _assert_safe_and_aimed(robot, result)
    switched_to = [e.sector for e in result.events if e.kind == "cross-sector"]
    assert switched_to == [4, 3, 1, 2, 4]
    assert [posture_sector(t) for _, t, _ in stream] == switched_to


def test_a_cross_sector_motion_arrives_aimed_at_its_target_in_the_new_sector(robot, planner):
    tracker = Tracker(robot, planner, initial_sector=3)
    target = sector_origin() + 6.0 * _direction(-60.0, -10.0)  # out of sector 3's reach: a posture change to 4
    result = tracker.run([(0.0, sector_origin() + 6.0 * _direction(180.0, 0.0)), (10.0, target, True)])
    _assert_safe_and_aimed(robot, result)
    crossing = [e for e in result.events if e.kind == "cross-sector" and e.time == 10.0]
    assert [e.sector for e in crossing] == [4]
    # the motion's last row is the arrival: aimed at the target, in sector 4 (its other rows aim nowhere)
    assert result.sectors[-1] == 4 and np.allclose(result.targets[-1], target)
    assert aim_errors(robot, result.configurations[-1], target)[2] < 1e-6


def test_bad_targets_give_events_and_the_arm_holds_still(robot, planner):
    tracker = Tracker(robot, planner, initial_sector=3)
    good = sector_origin() + 6.0 * _direction(45.0, 5.0)
    tracker.step(0.0, good)
    q = tracker.q.copy()
    tracker.step(0.1, np.array([np.nan, 0.0, 1.0]))
    tracker.step(0.2, np.array([0.0, 0.0, 1.21]))  # inside the torso
    result = tracker.result()
    assert result.count("unreachable") == 2
    np.testing.assert_array_equal(result.configurations[-1], q)


def test_blind_area_target_triggers_a_posture_change(robot, planner):
    from tpee_ompl.model.pointing import default_geometry

    tracker = Tracker(robot, planner, initial_sector=3)
    origin, rot = default_geometry().pan_frame(np.deg2rad([-50.0, 20.0]))
    above = origin[0] + 4.0 * rot[0][:, 2]  # on the pan axis of posture 3: its blind cylinder
    tracker.step(0.0, above)
    result = tracker.result()
    assert result.count("blind-area") == 1 and result.count("cross-sector") == 1
    assert tracker.sector != 3
    _assert_safe_and_aimed(robot, result)


def test_default_planner_without_a_library_returns_straight_motion_when_it_is_free(robot):
    planner = make_default_planner(robot, timeout=2.0, seed=1, library=None)
    start = np.r_[np.deg2rad([-50.0, 160.0]), 0.0, 0.0]
    goal = np.r_[np.deg2rad([50.0, 160.0]), 0.0, 0.0]
    w = planner(start, goal, 1, 2)
    np.testing.assert_array_equal(w, straight_motion(start, goal, 1, 2))


def test_default_planner_answers_cross_sector_motions_with_the_library_pipeline(robot, planner):
    from tpee_ompl.model.queries import load_queries

    for q in load_queries("planning_necessary")[::30]:  # straight motions collide: a plain planner would need RRTConnect
        w = planner(q.start, q.goal, q.from_sector, q.to_sector)
        assert np.allclose(w[0], q.start) and np.allclose(w[-1], q.goal)
        assert motion_is_valid(robot, w, min(0.01, robot.max_joint_step()))


def test_tracker_rejects_a_colliding_planner_path(robot):
    from tpee_ompl.model.sectors import posture_preset

    into_backpack = np.r_[posture_preset(1), np.deg2rad(100.0), np.deg2rad(-50.0)]
    assert not robot.is_valid(into_backpack)

    def bad_planner(start, goal, i, j):
        return np.array([start, into_backpack, goal])

    tracker = Tracker(robot, bad_planner, initial_sector=3)
    with pytest.raises(ValueError, match="collides"):
        tracker.step(0.0, sector_origin() + 6.0 * _direction(-100.0, -10.0))


@pytest.mark.parametrize("answer, match", [
    (lambda s, g: np.array([s, s + 1e5, g]), "leaves the joint limits"),  # was 4.8 GB of motion states, 13 s
    (lambda s, g: np.array([s, s * np.nan, g]), "not finite"),
    (lambda s, g: {"path": [s, g]}, "returned dict"),
    (lambda s, g: np.array([s[:3], g[:3]]), "shape"),
])
def test_tracker_refuses_a_planner_answer_that_is_no_valid_path_at_once(robot, monkeypatch, answer, match):
    from tpee_ompl.planning import paths

    densified = []
    monkeypatch.setattr(paths, "polyline_motion_states",
                        lambda *a: densified.append(a) or pytest.fail("a bad waypoint must be refused before densifying"))
    tracker = Tracker(robot, lambda s, g, i, j: answer(s, g), initial_sector=3)
    with pytest.raises(ValueError, match=match):
        tracker.step(0.0, sector_origin() + 6.0 * _direction(-100.0, -10.0))
    assert not densified


def test_tracker_times_and_joint_speeds_are_held_to_what_time_stamps_resolve(robot, planner):
    from tpee_ompl.library.tracker import TrackerOptions

    with pytest.raises(ValueError, match="joint_speed"):
        TrackerOptions(joint_speed=5e-324)  # a motion would take inf seconds
    tracker = Tracker(robot, planner, initial_sector=3)
    with pytest.raises(ValueError, match="time t"):
        tracker.step(1e17, np.array([5.0, 2.0, 1.5]))  # time increments vanish in rounding there
    tracker.step(1.7e9, np.array([5.0, 2.0, 1.5]))  # a Unix time is fine


def test_tracker_new_target_flag_must_be_a_bool(robot, planner):
    tracker = Tracker(robot, planner, initial_sector=3)
    with pytest.raises(ValueError, match="new_target"):
        tracker.step(0.0, np.array([5.0, 2.0, 1.5]), new_target="no")  # a truthy string marked every sample new
    assert tracker.events == []
    tracker.step(0.0, np.array([5.0, 2.0, 1.5]), new_target=np.bool_(True))


def test_tracker_rejects_a_planner_path_with_wrong_ends(robot):
    tracker = Tracker(robot, lambda s, g, i, j: np.array([s, s]), initial_sector=3)
    with pytest.raises(ValueError, match="does not start"):
        tracker.step(0.0, sector_origin() + 6.0 * _direction(-100.0, -10.0))


def test_a_target_another_posture_reaches_is_not_reported_unreachable(robot, planner):
    tracker = Tracker(robot, planner, initial_sector=3)
    tracker.run([(0.0, np.array([5.0, 2.0, 1.5])), (0.4, np.array([-0.3, 0.0, 1.75]))])  # near, above the pivot
    result = tracker.result()
    assert result.count("unreachable") == 0 and result.count("cross-sector") == 1  # it used to report both
    assert "not reachable from posture" in result.events[-1].detail


def test_the_rows_times_increase_whenever_the_arm_moves(robot, planner):
    circle = [(0.05 * k, sector_origin() + 6.0 * _direction(8.0 * k, 10.0)) for k in range(60)]
    result = Tracker(robot, planner, initial_sector=3).run(circle)
    moved = np.max(np.abs(np.diff(result.configurations, axis=0)), axis=1) > 0
    dt = np.diff(result.times)
    assert np.all(dt[moved] > 0)  # re-aims right after a crossing used to share its arrival time
    assert np.all(np.max(np.abs(np.diff(result.configurations, axis=0)), axis=1)[moved] <= dt[moved] * 1.0 + 1e-9)


def test_a_planner_that_finds_no_path_gives_an_unreachable_event_and_the_arm_holds_still(robot):
    def no_path(start, goal, i, j):
        raise RuntimeError(f"no collision-free path {i}->{j}")

    tracker = Tracker(robot, no_path, initial_sector=3)
    tracker.step(0.0, sector_origin() + 6.0 * _direction(-60.0, 10.0))  # postures 1 and 4 can aim at it, 3 cannot
    result = tracker.result()
    assert result.count("unreachable") == 1 and "no collision-free path" in result.events[-1].detail
    np.testing.assert_array_equal(result.configurations[-1], tracker.q)


def test_a_target_outside_the_pointing_sector_that_only_the_current_posture_reaches_is_aimed_at_from_there(robot):
    """The tracker tried only the other postures once a target left the pointing sector, and called a target it
    could aim at from where it was "unreachable" (a helper found targets only posture 1 can aim at in sectors 3/4)."""
    from tpee_ompl.model.sectors import in_pointing_sector

    def no_path(start, goal, i, j):
        raise RuntimeError(f"no collision-free path {i}->{j}")

    target = sector_origin() + 6.0 * _direction(-100.0, -10.0)  # another posture's target that posture 3 can aim at
    tracker = Tracker(robot, no_path, initial_sector=3)
    assert not in_pointing_sector(target, 3, tracker.geometry.pivot)
    q0 = tracker.q.copy()
    result = tracker.run([(0.0, target)])
    assert [e.kind for e in result.events] == ["aim"] and tracker.sector == 3
    assert aim_errors(robot, tracker.q, target)[2] < 1e-9
    assert motion_is_valid(robot, np.array([q0, tracker.q]), tracker.check_step)


def test_an_initial_configuration_off_its_sectors_preset_is_refused_and_the_check_step_is_capped(robot, planner):
    from tpee_ompl.library.tracker import TrackerOptions
    from tpee_ompl.model.sectors import posture_preset

    with pytest.raises(ValueError, match="not sector 3's Table-1 preset"):
        Tracker(robot, planner, initial=np.r_[posture_preset(1), 0.0, 0.0], initial_sector=3)
    coarse = Tracker(robot, planner, options=TrackerOptions(check_step=10.0))
    assert coarse.check_step == robot.max_joint_step()  # never coarser than the robot's guarantee (10 rad was used)
    assert Tracker(robot, planner).check_step == min(0.01, robot.max_joint_step())


@pytest.mark.parametrize("kw", [{"timeout": 1e10}, {"timeout": float("nan")}, {"library_time": -1.0}])
def test_default_planner_refuses_a_time_limit_ompl_cannot_keep(robot, kw):
    """OMPL's timed condition overflows beyond ~1e10 s and is true at once: a limit beyond a day is refused."""
    with pytest.raises(ValueError, match=next(iter(kw))):
        make_default_planner(robot, library=None, **kw)


@pytest.mark.parametrize(("kw", "match"), [({"library": 5}, "library must be 'default', a library file's path"),
                                          ({"library": ""}, "library must be"),
                                          ({"robot": None}, "robot must be a WearerArm")])
def test_default_planner_refuses_a_library_or_robot_of_the_wrong_kind_naming_it(robot, kw, match):
    """library=5 was a TypeError "expected str, bytes or os.PathLike object", robot=None an AttributeError."""
    with pytest.raises(ValueError, match=match):
        make_default_planner(**{"robot": robot, **kw})


def test_the_default_planner_leaves_ompls_log_level_and_seeds_ompl_at_each_call(robot, monkeypatch, caplog):
    """OMPL reseeds after a later setSeed too (it only logs an error, silenced here): each call's seed takes effect,
    where a second seed used to be refused with a warning that it "changes nothing"."""
    from ompl import util as ou

    seeds = []
    monkeypatch.setattr(ou.RNG, "setSeed", staticmethod(seeds.append))
    before = ou.getLogLevel()
    try:
        ou.setLogLevel(ou.LOG_NONE)
        with caplog.at_level("WARNING"):
            for s in (5, 5, 6):
                make_default_planner(robot, seed=s, library=None)
        assert ou.getLogLevel() == ou.LOG_NONE and seeds == [5, 5, 6] and caplog.text == ""
    finally:
        ou.setLogLevel(before)


def test_the_first_re_aim_from_the_initial_configuration_takes_the_time_joint_speed_allows(robot, planner):
    """The clock started at -inf, so the first re-aim (a 2.4-rad pan swing) arrived at the sample's own time."""
    tracker = Tracker(robot, planner, initial_sector=3)
    q0 = tracker.q.copy()
    result = tracker.run([(2.0, sector_origin() + 6.0 * _direction(150.0, 0.0))])
    assert [e.kind for e in result.events] == ["aim"]
    move = float(np.max(np.abs(result.configurations[0] - q0)))
    assert move > 1.0 and result.times[0] == pytest.approx(2.0 + move / tracker.options.joint_speed)


def test_a_planned_re_aim_inside_the_sector_is_an_aim_event_not_a_posture_switch(robot, planner, monkeypatch):
    """It was logged as a "cross-sector" event 3->3 (a reviewer's reading of the code)."""
    tracker = Tracker(robot, planner, initial_sector=3)
    monkeypatch.setattr(tracker, "_motion_free", lambda a, b: False)  # every direct re-aim motion "collides"
    target = sector_origin() + np.r_[6.0 * _direction(40.0, 0.0)[:2], 0.5]
    assert posture_sector(target) == 3
    result = tracker.run([(0.0, target)])
    assert result.count("cross-sector") == 0 and result.count("aim") == 1
    (event,) = result.events
    assert event.sector == 3 and event.detail.startswith("planned: re-aim motion collides")
    _assert_safe_and_aimed(robot, result)
