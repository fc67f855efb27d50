"""Joint query sets: round trip, the packaged Panda set, refusal of another model's set, malformed files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.helpers.panda import needs_panda
from tpee_ompl.model.joint_queries import JointQuery, load_joint_query_set, save_joint_queries
from tpee_ompl.model.queries import QuerySetError
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.paths import motion_states


def test_a_saved_set_loads_back_equal_and_refuses_another_model(tmp_path):
    robot = WearerArm()
    qs = [JointQuery(0, [0.1, 0.2, 0.3, 0.4], [0.5, 0.6, 0.7, 0.8], "a->b"), JointQuery(3, np.zeros(4), np.ones(4))]
    p = save_joint_queries(tmp_path / "s.json", qs, name="s", seed=1, checker=robot)
    back, header = load_joint_query_set(p, robot)
    assert [(q.id, q.label, q.start.tolist(), q.goal.tolist()) for q in back] == \
        [(q.id, q.label, q.start.tolist(), q.goal.tolist()) for q in qs]
    assert header["model_hash"] == robot.model_hash and header["joint_names"] == list(robot.joint_names)
    doc = json.loads(p.read_text())
    doc["model_hash"] = "0" * 16
    p.write_text(json.dumps(doc))
    with pytest.raises(QuerySetError, match="made for model_hash"):
        load_joint_query_set(p, robot)
    assert len(load_joint_query_set(p)[0]) == 2  # without a checker the hash is not checked


@pytest.mark.parametrize("text, match", [
    ("{", "not a JSON query set"),
    ('{"queries": []}', "not a joint query set"),
    ('{"format": "joint_queries/1", "queries": [{"id": 1, "label": "", "start": [1], "goal": ["x"]}]}', "list of numbers"),
    ('{"format": "joint_queries/1", "queries": [{"id": 1, "label": "", "start": [1], "goal": [1, 2]}]}', "start has 1"),
    ('{"format": "joint_queries/1", "queries": [{"id": 1, "label": "", "start": [1' + "0" * 400 + '], "goal": [1]}]}',
     "start must be finite numbers"),  # an integer too large for a float
])
def test_malformed_sets_are_refused_naming_the_problem(tmp_path, text, match):
    p = tmp_path / "bad.json"
    p.write_text(text)
    with pytest.raises(QuerySetError, match=match):
        load_joint_query_set(p)


@needs_panda
def test_the_packaged_panda_set_has_valid_ends_and_colliding_straight_motions():
    from tpee_ompl.model.robots import panda_shelf

    c = panda_shelf(n_threads=2)
    queries, header = load_joint_query_set("panda_shelf", c)
    assert len(queries) >= 24 and header["name"] == "panda_shelf"
    labels = set()
    for q in queries:
        assert c.is_valid(q.start) and c.is_valid(q.goal)
        assert not c.are_valid(motion_states(q.start, q.goal, c.max_joint_step())).all()
        a, b = q.label.split("->")
        assert a != b
        labels.add(a)
    assert len(labels) >= 5
