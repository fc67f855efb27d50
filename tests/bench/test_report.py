"""Report: per-query ratios, success counting (failures never dropped), lower-bound figures."""

from __future__ import annotations

import math

import pytest

from tpee_ompl.bench.report import PAPER_TABLE4, length_quality_table, ratio_table, success_table, summarize


def run(planner, qid, cap, time, length, l12, l34, ok=True, straight=1.0):
    return {"planner": planner, "query_id": str(qid), "comparison": "iterations", "motion_validator": "batched",
            "sample_cap": cap, "time_budget": 0.0, "time": time, "solution_length": length if ok else None,
            "length_dof12": l12, "length_dof34": l34, "success": ok, "solved": 1 if ok else 0,
            "straight_length": straight}


def test_ratio_is_the_mean_of_per_query_ratios_not_the_ratio_of_means():
    runs = [run("D", 0, 500, 1.0, 2.0, 1.0, 1.0), run("R", 0, 500, 2.0, 4.0, 2.0, 2.0),
            run("D", 1, 500, 9.0, 9.0, 3.0, 6.0), run("R", 1, 500, 3.0, 3.0, 1.0, 2.0)]
    table = {r["metric"]: r for r in ratio_table(runs, "D", "R")}
    assert table["time"]["mean"] == pytest.approx((0.5 + 3.0) / 2)
    assert table["length"]["median"] == pytest.approx((0.5 + 3.0) / 2)
    assert table["length_dof12"]["mean"] == pytest.approx((0.5 + 3.0) / 2)
    assert table["length"]["paper"] == PAPER_TABLE4[500]["length"] and table["length"]["n"] == 2


def test_failed_runs_are_counted_and_excluded_from_ratios():
    runs = [run("D", 0, 500, 1.0, 2.0, 1.0, 1.0), run("R", 0, 500, 2.0, 4.0, 2.0, 2.0),
            run("D", 1, 500, 1.0, None, None, None, ok=False), run("R", 1, 500, 3.0, 3.0, 1.0, 2.0)]
    table = {r["metric"]: r for r in ratio_table(runs, "D", "R")}
    assert table["length"]["n"] == 1 and table["length"]["queries"] == 2
    counts = {r["planner"]: r for r in success_table(runs)}
    assert counts["D"]["success"] == 1 and counts["D"]["runs"] == 2 and counts["D"]["unsolved"] == 1
    assert counts["R"]["success"] == 2


def test_missing_queries_are_reported_from_the_campaign_metadata():
    runs = [run("D", 0, 500, 1.0, 2.0, 1.0, 1.0), run("R", 0, 500, 2.0, 4.0, 2.0, 2.0)]
    expected = {"queries": [0, 1, 2], "config": {"checkers": ["batched"]}}
    assert all(r["missing_queries"] == 2 for r in success_table(runs, expected))


def test_length_quality_is_relative_to_straight_segment_and_best_found():
    runs = [run("D", 0, 500, 1.0, 2.2, 1.0, 1.0, straight=2.0), run("R", 0, 500, 2.0, 2.0, 1.0, 1.0, straight=2.0)]
    q = {r["planner"]: r for r in length_quality_table(runs)}
    assert q["R"]["vs_straight_median"] == pytest.approx(1.0) and q["R"]["vs_best_median"] == pytest.approx(1.0)
    assert q["D"]["vs_straight_median"] == pytest.approx(1.1) and q["D"]["vs_best_median"] == pytest.approx(1.1)


def test_summarize_ignores_non_finite_values_and_handles_empty_input():
    s = summarize([1.0, 2.0, 3.0, math.inf, None])
    assert s["n"] == 3 and s["median"] == 2.0 and s["q1"] == 1.5
    assert summarize([])["n"] == 0 and math.isnan(summarize([])["mean"])
