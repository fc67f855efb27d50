"""Property-based tests (hypothesis) of query files: adversarial inputs work or raise one documented error."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from helpers.strategies import (
    FEW,
)
from hypothesis import given
from hypothesis import strategies as st

from tpee_ompl.model.queries import QuerySetError, load_queries, save_queries
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.resources import query_set_path


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
