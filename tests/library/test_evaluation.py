"""Tests of :func:`tpee_ompl.library.evaluation.benchmark_queries`."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.library_standins import RRT_PAIRS, necessary_queries

from tpee_ompl.library import PathLibrary
from tpee_ompl.model.wearer_arm import WearerArm


@pytest.mark.slow
def test_benchmark_rows_report_outcome_time_and_length(robot: WearerArm, rrt_library: PathLibrary) -> None:
    from tpee_ompl.library.evaluation import benchmark_queries
    from tpee_ompl.planning.paths import path_length

    qs = necessary_queries(RRT_PAIRS, 3)
    rows = benchmark_queries(rrt_library, qs, reference=lambda s, g, i, j: np.array([s, g]))
    assert [r["id"] for r in rows] == [q.id for q in qs]
    for r, q in zip(rows, qs):
        assert r["outcome"] in ("dmp", "repaired", "fallback") and r["query_s"] > 0 and r["generation_s"] > 0
        assert r["ref_length"] == pytest.approx(path_length(np.array([q.start, q.goal])))
        assert r["length"] >= r["ref_length"] - 1e-12  # nothing is shorter than the straight line
