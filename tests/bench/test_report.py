"""Report: per-query ratios, success counting (failures never dropped), lower-bound figures, anytime quality."""

from __future__ import annotations

import csv
import math

import pytest

from tpee_ompl.bench import report
from tpee_ompl.bench.report import (PAPER_TABLE4, anytime_quality_table, best_found, length_quality_table, ratio_table,
                                    success_table, summarize)


def run(planner, qid, cap, time, length, l12, l34, ok=True, straight=1.0, from_sector=1):
    return {"planner": planner, "query_id": qid, "comparison": "iterations", "motion_validator": "batched",
            "sample_cap": cap, "time_budget": 0.0, "time": time, "solution_length": length if ok else None,
            "length_dof12": l12, "length_dof34": l34, "success": ok, "solved": 1 if ok else 0,
            "straight_length": straight, "from_sector": from_sector}


def test_ratio_is_the_mean_of_per_query_ratios_not_the_ratio_of_means():
    runs = [run("D", 0, 500, 1.0, 2.0, 1.0, 1.0), run("R", 0, 500, 2.0, 4.0, 2.0, 2.0),
            run("D", 1, 500, 9.0, 9.0, 3.0, 6.0), run("R", 1, 500, 3.0, 3.0, 1.0, 2.0)]
    table = {r["metric"]: r for r in ratio_table(runs, "D", "R")}
    assert table["time"]["mean"] == pytest.approx((0.5 + 3.0) / 2)
    assert table["length"]["median"] == pytest.approx((0.5 + 3.0) / 2)
    assert table["length_dof12"]["mean"] == pytest.approx((0.5 + 3.0) / 2)
    assert table["length"]["paper"] == PAPER_TABLE4[500]["length"] and table["length"]["n"] == 2


def test_a_problem_without_sectors_gets_its_own_labels_and_no_paper_figures(tmp_path):
    runs = [run("D", q, 500, 1.0, 2.0, 1.0, 1.0, from_sector=0) for q in (0, 1)]
    runs += [run("R", q, 500, 2.0, 4.0, 2.0, 2.0, from_sector=0) for q in (0, 1)]
    table = {r["metric"]: r for r in ratio_table(runs, "D", "R")}
    assert math.isnan(table["length"]["paper"]) and table["length"]["label"] == "Path length"
    text = "\n".join(report._ratio_markdown(list(table.values()), "D", "R", "batched"))
    assert "DOF1" not in text and "paper" not in text and "| First group's length |" in text


def test_failed_runs_are_counted_and_excluded_from_ratios():
    runs = [run("D", 0, 500, 1.0, 2.0, 1.0, 1.0), run("R", 0, 500, 2.0, 4.0, 2.0, 2.0),
            run("D", 1, 500, 1.0, None, None, None, ok=False), run("R", 1, 500, 3.0, 3.0, 1.0, 2.0)]
    table = {r["metric"]: r for r in ratio_table(runs, "D", "R")}
    assert table["length"]["n"] == 1 and table["length"]["queries"] == 2
    counts = {r["planner"]: r for r in success_table(runs)}
    assert counts["D"]["success"] == 1 and counts["D"]["runs"] == 2 and counts["D"]["unsolved"] == 1
    assert counts["R"]["success"] == 2


def test_missing_queries_are_reported_from_the_campaign_metadata_for_every_validator_and_budget():
    import dataclasses

    from tpee_ompl.bench.config import CampaignConfig

    cfg = dataclasses.asdict(CampaignConfig(sample_caps=(500,), checkers=("batched", "discrete"), alt_checker_queries=2,
                                            anytime_budgets=(0.1,), anytime_queries=2))
    runs = [run("D", 0, 500, 1.0, 2.0, 1.0, 1.0), run("R", 0, 500, 2.0, 4.0, 2.0, 2.0),
            {**run("D", 0, 500, 1.0, 2.0, 1.0, 1.0), "motion_validator": "discrete"}]
    table = success_table(runs, {"queries": [0, 1, 2], "config": cfg})
    missing = {(r["checker"], r["setting"], r["planner"]): r["missing_queries"] for r in table}
    assert missing == {("batched", "N=500", "D"): 2, ("batched", "N=500", "R"): 2,  # 3 queries, 1 finished
                       ("discrete", "N=500", "D"): 1,  # on the first 2 queries only
                       ("batched", "T=0.1s", "(every planner)"): 2}  # the anytime comparison: not one run


def test_length_quality_is_relative_to_straight_segment_and_best_found():
    runs = [run("D", 0, 500, 1.0, 2.2, 1.0, 1.0, straight=2.0), run("R", 0, 500, 2.0, 2.0, 1.0, 1.0, straight=2.0)]
    q = {r["planner"]: r for r in length_quality_table(runs)}
    assert q["R"]["vs_straight_median"] == pytest.approx(1.0) and q["R"]["vs_best_median"] == pytest.approx(1.0)
    assert q["D"]["vs_straight_median"] == pytest.approx(1.1) and q["D"]["vs_best_median"] == pytest.approx(1.1)


def test_summarize_ignores_non_finite_values_and_handles_empty_input():
    s = summarize([1.0, 2.0, 3.0, math.inf, None])
    assert s["n"] == 3 and s["median"] == 2.0 and s["q1"] == 1.5
    assert summarize([])["n"] == 0 and math.isnan(summarize([])["mean"])


# --------------------------------------------------------------------------- anytime: first path, best found, within 5 %
def anytime(planner, qid, length, first=None, time=1.0, budget=1.0):
    """An anytime run; ``length=None`` is a failed run."""
    return {**run(planner, qid, 0, time, length, None, None, ok=length is not None), "comparison": "anytime",
            "time_budget": budget, "first_solution_time": first}


def anytime_campaign():
    """Queries 0-4 at budget 1 s; A, B and C (never succeeds); q4 has only C's run; q3's best is an iteration run."""
    return [
        anytime("A", 0, 2.0, first=0.1), anytime("B", 0, 2.1, first=0.05), anytime("C", 0, None),
        anytime("A", 1, 3.0, first=0.3), anytime("B", 1, 3.0, first=0.15), anytime("C", 1, None),
        anytime("A", 2, None), anytime("B", 2, 4.0, time=0.9), anytime("C", 2, None),
        anytime("A", 3, 5.5, first=0.2), anytime("B", 3, 5.0, time=0.5), anytime("C", 3, None),
        anytime("C", 4, None),
        run("D", 3, 500, 1.0, 4.8, 1.0, 1.0),
    ]


def test_anytime_quality_counts_failures_and_missing_runs_as_not_within_and_ties_as_within():
    t = {r["planner"]: r for r in anytime_quality_table(anytime_campaign())}
    assert {r["queries"] for r in t.values()} == {5}
    # A: q0 = best, q1 ties B at best, q2 failed, q3 5.5 / 4.8 > 1.05, q4 no run
    assert (t["A"]["success"], t["A"]["runs"], t["A"]["within"]) == (3, 4, 2)
    assert t["A"]["within_share"] == pytest.approx(2 / 5)
    assert t["A"]["vs_best_median"] == pytest.approx(1.0) and t["A"]["vs_best_q3"] == pytest.approx((1 + 5.5 / 4.8) / 2)
    # B: q0 exactly 1.05 x best (within), q1 tie, q2 its own best, q3 5.0 / 4.8
    assert t["B"]["within"] == 4 and t["B"]["within_share"] == pytest.approx(4 / 5)
    assert t["B"]["vs_best_median"] == pytest.approx((1.0 + 5.0 / 4.8) / 2)
    # C never succeeds: no medians, nothing within
    assert (t["C"]["success"], t["C"]["runs"]) == (0, 5) and t["C"]["within"] == 0 and t["C"]["within_share"] == 0
    assert math.isnan(t["C"]["first_time_median"]) and math.isnan(t["C"]["vs_best_median"])


def test_first_path_time_falls_back_to_the_run_time_and_says_how_often():
    t = {r["planner"]: r for r in anytime_quality_table(anytime_campaign())}
    assert t["A"]["first_time_median"] == pytest.approx(0.2) and t["A"]["first_time_from_run_time"] == 0
    # B: recorded 0.05 and 0.15, none for q2 and q3: their run times 0.9 and 0.5 (upper bounds)
    assert t["B"]["first_time_median"] == pytest.approx((0.15 + 0.5) / 2) and t["B"]["first_time_from_run_time"] == 2
    assert t["A"]["first_time_at_run_end"] == t["B"]["first_time_at_run_end"] == 0


def test_a_first_path_time_recorded_at_the_end_of_the_run_is_marked():
    runs = [anytime("E", 0, 2.0, first=0.5, time=0.5), anytime("E", 1, 2.0, first=0.498, time=0.5),
            anytime("E", 2, 2.0, first=0.3, time=0.5), anytime("E", 3, None, first=0.5, time=0.5)]
    (row,) = anytime_quality_table(runs)
    assert row["first_time_at_run_end"] == 2 and row["first_time_from_run_time"] == 0
    assert row["first_time_median"] == pytest.approx(0.498)


def test_successful_anytime_runs_far_over_their_budget_are_counted_and_marked():
    """A simplifier pass that does not poll the termination condition ran 0.49 s at a 0.2-s budget, unmarked."""
    from tpee_ompl.bench.report import _anytime_quality_markdown

    runs = [anytime("S", 0, 2.0, first=0.02, time=0.49, budget=0.2), anytime("S", 1, 2.0, first=0.02, time=0.29,
                                                                          budget=0.2),
            anytime("S", 2, None, time=0.9, budget=0.2)]
    (row,) = anytime_quality_table(runs)
    assert row["over_budget"] == 1  # 0.29 s is within 1.5 x; the failed run is not a success to mark
    assert "| 2/3 (1 over 1.5x budget) |" in _anytime_quality_markdown([row])


def test_within_share_averages_a_querys_runs_and_is_per_budget():
    runs = [anytime("A", 0, 2.0), anytime("A", 0, 3.0), anytime("A", 1, 1.0),
            anytime("A", 0, 2.0, budget=0.1), anytime("A", 1, None, budget=0.1)]
    t = {r["budget"]: r for r in anytime_quality_table(runs)}
    assert t[1.0]["within"] == pytest.approx(1.5) and t[1.0]["within_share"] == pytest.approx(0.75)
    assert t[0.1]["within"] == 1 and t[0.1]["within_share"] == pytest.approx(0.5)


def test_best_found_is_the_shortest_successful_path_of_any_planner_and_comparison():
    assert best_found(anytime_campaign()) == {0: 2.0, 1: 3.0, 2: 4.0, 3: 4.8}


def test_report_has_the_anytime_quality_section_and_csv(tmp_path, monkeypatch):
    runs = anytime_campaign()
    monkeypatch.setattr(report, "load_runs", lambda db: runs)
    out = report.write_report(tmp_path / "unused.db", tmp_path, planner="A", reference="B")
    text = out["markdown_text"]
    assert "## Anytime comparison: time to the first exact path and length against the best found" in text
    assert "| 1 | B | 4/4 | 0.325 (2 from run time) | 1.021 [1.000, 1.044] | 4/5 (0.80) |" in text
    assert "| 1 | C | 0/5 | – | – [–, –] | 0/5 (0.00) |" in text
    with open(out["anytime_quality"]) as f:
        rows = {r["planner"]: r for r in csv.DictReader(f)}
    assert float(rows["A"]["within_share"]) == pytest.approx(0.4) and rows["A"]["queries"] == "5"


def test_an_anytime_only_campaign_has_no_table4_heading_or_csv(tmp_path, monkeypatch):
    runs = [r for r in anytime_campaign() if r["comparison"] == "anytime"]
    monkeypatch.setattr(report, "load_runs", lambda db: runs)
    out = report.write_report(tmp_path / "unused.db", tmp_path, planner="A", reference="B")
    assert "Table 4" not in out["markdown_text"] and out["markdown_text"].startswith("## Success counts")
    assert "csv" not in out and not (tmp_path / "table4.csv").exists()


def test_a_capped_run_stopped_by_max_time_before_its_cap_is_a_failure():
    """Its path came from fewer samples than the cap: compared as a run at the cap it made Table 4 wrong."""
    base = {"comparison": "iterations", "sample_cap": 5000, "timelimit": 0.05, "solved": 1, "status": 6,
            "reaches_goal": 1, "approximate_solution": 0, "correct_solution": 1, "path_valid_dense": 1,
            "solution_length": 2.0}
    assert report._success({**base, "iterations": 5000, "time": 0.03})
    assert not report._success({**base, "iterations": 976, "time": 0.11})  # hit max_time
    assert report._success({**base, "iterations": 976, "time": 0.01})  # stopped early for another reason
    assert report._success({**base, "iterations": None, "time": 0.11})  # a planner that counts none
    cut = {**base, "iterations": 976, "time": 0.11, "planner": "R", "query_id": "0", "motion_validator": "batched",
           "time_budget": None}
    counts = success_table([{**cut, "success": report._success(cut)}])[0]
    assert (counts["success"], counts["invalid_path"], counts["unsolved"]) == (0, 0, 1)  # not at the cap, not invalid


@pytest.mark.parametrize("key, seen, want", [
    ("pf:rrtstar_k20", ["RRTstar", "RRTstarK20"], "RRTstarK20"),  # was RRTstar: a substring
    ("pf:rrtstar_k20", ["RRTstar"], "pf:rrtstar_k20"),  # no planner of that name: never another one
    ("helpers.bench_standins:make_standin", ["StandIn", "RRTstar"], "StandIn"),
    ("DimensionRRT", ["DimensionRRT", "DimensionRRTReleased"], "DimensionRRT"),
])
def test_planner_names_resolve_to_the_one_equal_name_only(key, seen, want):
    assert report.resolve_planner_name(key, seen) == want


def test_loading_a_missing_database_says_so_and_creates_nothing(tmp_path):
    with pytest.raises(FileNotFoundError, match="benchmark database not found"):
        report.load_runs(tmp_path / "none.db")
    assert not list(tmp_path.iterdir())
    odd = tmp_path / "run#2?x%41"  # a folder name a campaign may have (a URI would cut it)
    odd.mkdir()
    import sqlite3

    con = sqlite3.connect(str(odd / "b.db"))
    con.execute("CREATE TABLE x (a)")
    con.close()
    with pytest.raises(ValueError, match="not a benchmark database"):
        report.load_runs(odd / "b.db")
    assert sorted(p.name for p in odd.iterdir()) == ["b.db"]


def test_table4_says_what_the_dimension_rrt_it_compares_is():
    """The report put the paper's figures beside "DimensionRRT", which has shortcut sweeps the paper does not."""
    runs = [run("DimensionRRT", q, 500, 1.0, 2.0, 1.0, 1.0) for q in (0, 1)]
    runs += [run("RRTstar", q, 500, 2.0, 4.0, 2.0, 2.0) for q in (0, 1)]
    table = ratio_table(runs, "DimensionRRT", "RRTstar")
    text = "\n".join(report._ratio_markdown(table, "DimensionRRT", "RRTstar", "batched"))
    assert "`DimensionRRT`: the paper's dimension-RRT" in text and "DimensionRRTNoShortcuts" in text
    assert "Table 3's DOF1/DOF2 rows are kept" in text
    generic = [dict(r, from_sector=0) for r in runs]  # a problem without sectors: no Table 3, no radians promised
    text = "\n".join(report._ratio_markdown(ratio_table(generic, "DimensionRRT", "RRTstar"), "DimensionRRT",
                                             "RRTstar", "batched"))
    assert "DimensionRRTNoShortcuts" in text and "Table 3" not in text and "joint space (rad)" not in text
    at300 = [dict(r, sample_cap=300) for r in runs]  # the wearer at a cap the paper gives no figures for
    text = "\n".join(report._ratio_markdown(ratio_table(at300, "DimensionRRT", "RRTstar"), "DimensionRRT",
                                             "RRTstar", "batched"))
    assert "Table 3's DOF1/DOF2 rows are kept" in text


def test_runs_cut_by_the_time_limit_before_their_cap_are_said_under_the_success_counts():
    base = {"comparison": "iterations", "sample_cap": 5000, "timelimit": 0.05, "solved": 1, "status": 6,
            "reaches_goal": 1, "approximate_solution": 0, "correct_solution": 1, "path_valid_dense": 1,
            "solution_length": 2.0, "planner": "R", "query_id": "0", "motion_validator": "batched", "time_budget": None}
    runs = [{**base, "iterations": 976, "time": 0.11}, {**base, "iterations": 5000, "time": 0.03, "query_id": "1"}]
    runs = [{**r, "success": report._success(r)} for r in runs]
    text = report._markdown(success_table(runs), [], [])
    assert "1 sample-capped run(s) stopped at the time limit (`--max-time`) before their cap" in text


def test_a_campaign_without_the_reference_at_sample_caps_says_why_it_has_no_table4(tmp_path, monkeypatch):
    """With only dimension-RRT at sample caps the report was headed "Table 4: DimensionRRT / RRTstar" over n = 0
    and table4.csv was all NaN; a campaign without budgets wrote empty anytime CSVs."""
    runs = [run("DimensionRRT", q, 500, 1.0, 2.0, 1.0, 1.0) for q in (0, 1)]
    monkeypatch.setattr(report, "load_runs", lambda db: runs)
    out = report.write_report(tmp_path / "unused.db", tmp_path)
    assert out["markdown_text"].startswith("No Table 4: it compares DimensionRRT with RRTstar at equal sample counts, "
                                           "and the campaign ran RRTstar at no sample cap.")
    assert "## Table 4" not in out["markdown_text"] and not (tmp_path / "table4.csv").exists()
    assert not (tmp_path / "anytime.csv").exists() and not (tmp_path / "anytime_quality.csv").exists()
    assert (tmp_path / "success.csv").read_text().startswith("comparison,")


def test_table4_marks_a_metric_with_fewer_ratios_than_the_row_count():
    """A start = goal query's reference length is 0: no length ratio, yet the row said n = 2 for every column."""
    import math

    from tpee_ompl.bench.report import RATIO_METRICS, _ratio_markdown

    ratios = [{"checker": "batched", "sample_cap": 500, "metric": key, "n": 2 if key == "time" else 1, "queries": 2,
               "mean": 0.5, "median": 0.5, "q1": 0.5, "q3": 0.5, "paper": math.nan, "label": key, "tpee": False}
              for key in RATIO_METRICS]
    (row,) = [line for line in _ratio_markdown(ratios, "A", "B", "batched") if line.startswith("| 500 |")]
    cells = row.split(" | ")
    assert cells[1] == "2/2" and "(n=1)" not in cells[2] and all("(n=1)" in c for c in cells[3:])


def test_the_anytime_cost_table_has_a_row_per_budget_and_planner():
    rows = [{"budget": b, "planner": pl, "runs": 2, "success": 2, "cost_median": 1.0, "cost_q1": 1.0, "cost_q3": 1.0}
            for b in (0.1, 1.0) for pl in ("A", "B")]
    text = report._markdown([], [], rows)
    assert [line for line in text.splitlines() if line.startswith(("| 0.1 |", "| 1 |"))] == [
        f"| {b} | {pl} | 2/2 | 1.000 [1.000, 1.000] |" for b in ("0.1", "1") for pl in ("A", "B")]


def test_the_headline_is_table4_and_the_first_path_table_without_the_other_sections(tmp_path, monkeypatch):
    """What ``tpee-ompl bench`` prints: it was cut from the Markdown by section titles in the command line."""
    capped = [run(p, q, 500, t, 2.0, 1.0, 1.0) for q in (0, 1) for p, t in (("DimensionRRT", 0.1), ("RRTstar", 1.0))]
    monkeypatch.setattr(report, "load_runs", lambda db: anytime_campaign() + capped)
    out = report.write_report(tmp_path / "unused.db", tmp_path)
    shown = out["headline"]
    assert shown.startswith("## Table 4") and "## Anytime comparison: time to the first exact path" in shown
    assert "## Success counts" not in shown and "median raw cost" not in shown
    assert all(part.strip() in out["markdown_text"] for part in shown.split("\n\n"))


def test_the_headline_of_a_campaign_without_table4_says_why(tmp_path, monkeypatch):
    runs = [run("DimensionRRT", q, 500, 1.0, 2.0, 1.0, 1.0) for q in (0, 1)]
    monkeypatch.setattr(report, "load_runs", lambda db: runs)
    out = report.write_report(tmp_path / "unused.db", tmp_path)
    assert out["headline"].startswith("No Table 4: it compares DimensionRRT with RRTstar")
    assert "##" not in out["headline"]


def test_the_headline_of_an_anytime_only_campaign_is_its_first_path_table(tmp_path, monkeypatch):
    runs = [r for r in anytime_campaign() if r["comparison"] == "anytime"]
    monkeypatch.setattr(report, "load_runs", lambda db: runs)
    out = report.write_report(tmp_path / "unused.db", tmp_path, planner="A", reference="B")
    assert out["headline"].startswith("## Anytime comparison: time to the first exact path")
    assert "Success counts" not in out["headline"]
