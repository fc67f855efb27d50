"""Cross-sector query files: the stored sets, the straight motion, bad files and queries."""

from __future__ import annotations

import json
import re
from collections import Counter

import numpy as np
import pytest
from helpers.hostile_files import QUERY_DEFECTS, other_model_query_file, write_query_file

from tpee_ompl.model.pointing import aim_errors
from tpee_ompl.model.queries import FORMAT_VERSION, Query, QuerySetError, load_queries, load_query_set, straight_motion
from tpee_ompl.model.sectors import cross_sector_trajectory, in_pointing_sector, posture_preset


@pytest.mark.parametrize("name", ["planning_necessary", "paper_random"])
def test_stored_sets_have_ten_queries_per_ordered_pair(name):
    queries, header = load_query_set(name)
    assert header["format_version"] == FORMAT_VERSION and header["name"] == name
    assert isinstance(header["seed"], int)
    pairs = Counter((q.from_sector, q.to_sector) for q in queries)
    assert len(pairs) == 12 and set(pairs.values()) == {10}
    assert [q.id for q in queries] == list(range(120))


@pytest.mark.parametrize("name", ["planning_necessary", "paper_random"])
def test_stored_queries_aim_at_their_targets_collision_free(robot, name):
    queries, header = load_query_set(name)
    assert header["model_hash"] == robot.model_hash
    for q in queries:
        for conf, target, k in ((q.start, q.target_a, q.from_sector), (q.goal, q.target_b, q.to_sector)):
            np.testing.assert_allclose(conf[:2], posture_preset(k), atol=1e-12)
            perp, along, _ = aim_errors(robot, conf, target)
            assert perp < 1e-6 and along > 0
            assert robot.is_valid(conf) and robot.line_of_sight_clear(conf, target)
            assert in_pointing_sector(target, k) and target[2] >= 0.0


def test_straight_motion_follows_table3_and_interpolates_pan_tilt():
    start = np.r_[posture_preset(1), 0.3, -0.2]
    goal = np.r_[posture_preset(3), -1.0, 0.4]
    w = straight_motion(start, goal, 1, 3)
    np.testing.assert_allclose(w[:, :2], cross_sector_trajectory(1, 3))
    np.testing.assert_allclose(w[:, 2], np.linspace(0.3, -1.0, 7))
    np.testing.assert_array_equal(w[0], start)
    np.testing.assert_array_equal(w[-1], goal)


def test_bad_query_files_and_queries_raise(tmp_path):
    with pytest.raises(FileNotFoundError, match="not found"):
        load_queries("no_such_set")
    p = tmp_path / "old.json"
    p.write_text(json.dumps({"format_version": 99, "queries": []}))
    with pytest.raises(ValueError, match="format_version"):
        load_queries(p)
    with pytest.raises(ValueError, match="from_sector == to_sector"):
        Query(0, 2, 2, np.zeros(3), np.zeros(3), np.zeros(4), np.zeros(4))
    with pytest.raises(ValueError, match="finite"):
        Query(0, 1, 2, [np.nan, 0, 0], np.zeros(3), np.zeros(4), np.zeros(4))
    with pytest.raises(ValueError, match="unknown sector"):
        Query(0, 1, 7, np.zeros(3), np.zeros(3), np.zeros(4), np.zeros(4))
    at1, at2 = np.r_[posture_preset(1), 0.0, 0.0], np.r_[posture_preset(2), 0.0, 0.0]
    with pytest.raises(ValueError, match="goal DOF1/DOF2 .* is not sector 2's Table-1 preset"):
        Query(0, 1, 2, np.zeros(3), np.ones(3), at1, at1)  # a goal at sector 1's preset, declared in sector 2
    q = Query(0, 1, 2, np.zeros(3), np.ones(3), at1, at2)
    with pytest.raises(ValueError):
        q.start[0] = 1.0  # stored arrays are read-only


# ---------------------------------------------------------------------------------------- hostile files
@pytest.mark.parametrize("defect", sorted(QUERY_DEFECTS))
def test_a_malformed_query_is_refused_naming_the_field_not_coerced(tmp_path, defect):
    change, name = QUERY_DEFECTS[defect]
    f = write_query_file(tmp_path / "q.json", change)
    with pytest.raises(QuerySetError, match=re.escape(name)) as exc:
        load_queries(f)
    assert str(f) in str(exc.value)


def test_the_small_query_set_the_defects_start_from_loads(robot, tmp_path):
    assert len(load_queries(write_query_file(tmp_path / "q.json"), robot)) == 4


def test_a_query_set_for_another_model_is_refused_with_the_robot(robot, tmp_path):
    f = other_model_query_file(tmp_path / "q.json")
    assert len(load_queries(f)) == 4  # without a robot there is nothing to compare with
    with pytest.raises(QuerySetError, match="model_hash"):
        load_queries(f, robot)


@pytest.mark.parametrize("load", [load_queries, load_query_set])
@pytest.mark.parametrize("robot_arg", ["r", 5])
def test_a_robot_that_is_not_a_wearer_arm_is_refused_naming_it(load, robot_arg):
    """robot="r" was an AttributeError ("'str' object has no attribute 'model_hash'") after the file was read."""
    with pytest.raises(ValueError, match="robot must be None or a WearerArm, got (str|int)"):
        load("planning_necessary", robot_arg)


@pytest.mark.parametrize("value", [["1", "2", "3", "4"], [1, 2, 3, True], [1, 2, 3], "1234", None])
def test_query_from_dict_takes_only_json_numbers(value):
    d = load_queries("planning_necessary")[0].to_dict()
    d["start"] = value
    with pytest.raises(QuerySetError, match="'start'"):
        Query.from_dict(d)


def test_another_robots_joint_query_set_is_named_as_such_not_as_an_unknown_format(robot):
    """It said "unsupported format_version None"."""
    with pytest.raises(QuerySetError, match=r"a joint-space query set for robot 'kinova_posts', not the wearer's"):
        load_queries("kinova_posts", robot)


def test_a_query_set_given_as_a_folder_says_so(robot, tmp_path):
    with pytest.raises(IsADirectoryError, match="is a folder, not a query file"):
        load_queries(tmp_path, robot)
