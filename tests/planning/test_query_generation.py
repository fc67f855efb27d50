"""Query generation: planning necessity of the stored sets, generator determinism, JSON round trip."""

from __future__ import annotations

import numpy as np
import pytest

from tpee_ompl.model.queries import load_queries, load_query_set, save_queries
from tpee_ompl.planning.query_generation import generate_queries, planning_necessity


@pytest.fixture(scope="module")
def necessary():
    return load_query_set("planning_necessary")


@pytest.fixture(scope="module")
def paper_random():
    return load_query_set("paper_random")


def test_default_set_makes_planning_necessary(robot, necessary):
    queries, header = necessary
    rate, per_pair = planning_necessity(robot, queries)
    assert rate >= 0.5 and min(per_pair.values()) >= 3
    assert rate == pytest.approx(header["planning_necessity_rate"])


def test_paper_random_rate_matches_its_header(robot, paper_random):
    queries, header = paper_random
    rate, per_pair = planning_necessity(robot, queries)
    assert rate == pytest.approx(header["planning_necessity_rate"])
    assert {f"{i}->{j}": n for (i, j), n in per_pair.items()} == header["planning_necessary_per_pair"]


def test_generator_is_deterministic_and_round_trips_through_json(robot, tmp_path):
    a, stats = generate_queries(robot, n_per_pair=1, seed=7, require_planning=False)
    b, _ = generate_queries(robot, n_per_pair=1, seed=7, require_planning=False)
    assert len(a) == 12 and stats["drawn"] >= 12
    for qa, qb in zip(a, b):
        np.testing.assert_array_equal(qa.start, qb.start)
        np.testing.assert_array_equal(qa.target_b, qb.target_b)
    path = save_queries(tmp_path / "x.json", a, name="x", seed=7, model_hash=robot.model_hash)
    loaded = load_queries(path)
    assert [q.to_dict() for q in loaded] == [q.to_dict() for q in a]
