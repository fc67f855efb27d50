"""Benchmark campaigns: smoke campaign, interruption, isolation of campaigns, configuration, query rows."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import pytest
from helpers.bench_standins import tiny_config, write_query_file

from tpee_ompl.bench.campaign import query_rows, run_campaign, stratified_subset
from tpee_ompl.bench.config import CampaignConfig, default_workers


@pytest.fixture(scope="module")
def query_file(tmp_path_factory, robot) -> Path:
    return write_query_file(tmp_path_factory.mktemp("q") / "tiny.json", robot)


def test_query_file_loads_as_plain_dicts(query_file):
    name, qs = query_rows(str(query_file))
    assert name == "tiny" and len(qs) == 2
    assert qs[0]["from_sector"] == 1 and len(qs[0]["start"]) == 4
    assert json.loads(json.dumps(qs)) == qs  # plain data: goes to worker processes and campaign.json


def test_packaged_query_set_is_found_by_name():
    name, qs = query_rows("planning_necessary")
    assert name == "planning_necessary" and len(qs) == 120


def test_stratified_subset_covers_every_sector_pair():
    qs = [{"id": 10 * p + k, "from_sector": p, "to_sector": p + 1} for p in range(1, 4) for k in range(3)]
    sub = stratified_subset(qs, 3)
    assert {q["from_sector"] for q in sub} == {1, 2, 3}
    assert len(stratified_subset(qs, None)) == 9


@pytest.mark.slow
def test_smoke_campaign_fills_the_database(query_file, tmp_path):
    res = run_campaign(tiny_config(query_file, tmp_path), progress_bar=False)
    assert not res.interrupted
    assert res.directory.parent == tmp_path and res.directory.name.endswith("_smoke")
    assert len(res.logs) == 2 * 3 and all(p.suffix == ".log" for p in res.logs)
    con = sqlite3.connect(res.database)
    rows = con.execute(
        "SELECT plannerConfigs.name, runs.correct_solution, runs.best_cost, runs.iterations, runs.collision_checks, "
        "runs.length_dof12, runs.length_dof34, runs.path_valid_dense, runs.solution_length, runs.reaches_goal "
        "FROM runs JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id "
        "JOIN experiments ON runs.experimentid = experiments.id WHERE experiments.comparison = 'iterations'").fetchall()
    planners = {r[0] for r in rows}
    assert planners == {"geometric_StandIn", "geometric_RRTstar"}
    for name, correct, best, iters, checks, l12, l34, dense, length, reaches in rows:
        assert correct is not None and iters is not None and checks > 0  # filled for every run
        if length is not None:  # a path: every column of the raw path is there
            assert correct == 1 and dense == 1 and l12 + l34 >= length - 1e-6  # triangle inequality per segment
            # its best cost when it reaches the goal; RRT* at 30 iterations can end with an approximate path
            assert best == pytest.approx(length, rel=1e-4) if reaches else best is None
    assert {r[0] for r in rows if r[9]} == planners  # each planner solved something
    caps = dict(con.execute("SELECT sample_cap, COUNT(*) FROM experiments WHERE comparison='iterations' "
                            "GROUP BY sample_cap").fetchall())
    assert caps == {30: 2, 60: 2}
    rrt_iters = {r[0] for r in con.execute(
        "SELECT runs.iterations FROM runs JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id "
        "JOIN experiments ON runs.experimentid = experiments.id "
        "WHERE plannerConfigs.name='geometric_RRTstar' AND experiments.comparison='iterations'")}
    assert rrt_iters <= {30, 60}
    n_prog = con.execute(
        "SELECT COUNT(*) FROM progress JOIN runs ON progress.runid = runs.id "
        "JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id WHERE plannerConfigs.name='geometric_StandIn'"
    ).fetchone()[0]
    assert n_prog > 0
    settings = con.execute("SELECT settings FROM plannerConfigs WHERE name='geometric_StandIn'").fetchone()[0]
    assert "planner.kind" in settings and "iteration_cap" in settings
    # one configuration per planner and cap, shared by every query (Planner Arena groups runs by it)
    configs = con.execute("SELECT name, COUNT(*) FROM plannerConfigs GROUP BY name").fetchall()
    experiments = con.execute("SELECT COUNT(*) FROM experiments").fetchone()[0]
    assert experiments > 2 and all(n <= 3 for _, n in configs), configs  # <= one per cap and the anytime run
    assert not any("projection.cellsize" in s or "planner.seed" in s
                   for (s,) in con.execute("SELECT settings FROM plannerConfigs"))
    # OMPL's graph columns are filled for a native planner run through the recording wrapper
    graph = con.execute("SELECT MAX(runs.graph_states), MAX(runs.graph_motions) FROM runs JOIN plannerConfigs "
                        "ON runs.plannerid = plannerConfigs.id WHERE plannerConfigs.name='geometric_RRTstar'").fetchone()
    assert graph[0] > 0 and graph[1] > 0
    params = con.execute("SELECT query_id, from_sector, to_sector, query_set FROM experiments").fetchall()
    assert (0, 1, 2, "tiny") in params  # numbers as numbers: Planner Arena compares a numeric-looking filter as one
    # one experiment name per comparison, cap or budget and validator, its queries told apart by query_id
    names = con.execute("SELECT name, COUNT(DISTINCT query_id) FROM experiments GROUP BY name").fetchall()
    assert sorted(names) == [("anytime_tiny_T0.05s_batched", 2), ("iterations_tiny_N30_batched", 2),
                             ("iterations_tiny_N60_batched", 2)]
    # each progress row carries its run's experiment parameters (Planner Arena filters progress rows by them)
    assert con.execute("SELECT COUNT(*) FROM progress JOIN runs ON progress.runid = runs.id JOIN experiments "
                       "ON runs.experimentid = experiments.id WHERE progress.query_id IS NOT experiments.query_id "
                       "OR progress.sample_cap IS NOT experiments.sample_cap").fetchone()[0] == 0
    assert con.execute("SELECT COUNT(*) FROM progress WHERE tpee_ompl_version IS NULL").fetchone()[0] == 0
    con.close()
    table = (res.directory / "table4.csv").read_text()
    assert table.splitlines()[0].endswith(",paper") and "length_dof12" in table
    assert "StandIn / RRTstar" in (res.directory / "report.md").read_text()
    assert res.plots and all(p.suffix == ".png" and p.stat().st_size > 0 for p in res.plots)
    meta = json.loads((res.directory / "campaign.json").read_text())
    assert meta["seed"] == 3 and "ompl" in meta["versions"]


def test_ompls_columns_the_wrapper_cannot_fill_say_what_the_run_did_or_null(query_file, tmp_path):
    """``valid segment fraction``: the run's own share of valid motions (OMPL's counters read 0 under the
    batched validator, a Python ``checkMotion``); graph sizes NULL for a planner without an OMPL graph;
    ``best_cost`` NULL for a run without an exact path (not its approximate path's length)."""
    cfg = CampaignConfig(name="columns", queries=str(query_file), sample_caps=(3, 400), anytime_budgets=(),
                         iteration_planners=("DimensionRRT", "RRTstar"), checkers=("batched",), workers=0, seed=3,
                         out=str(tmp_path))
    res = run_campaign(cfg, progress_bar=False, report=False)
    con = sqlite3.connect(res.database)
    rows = con.execute(
        "SELECT p.name, e.sample_cap, r.solved, r.valid_segment_fraction, r.graph_states, r.best_cost, r.raw_length "
        "FROM runs r JOIN plannerConfigs p ON r.plannerid = p.id JOIN experiments e ON r.experimentid = e.id").fetchall()
    con.close()
    assert len(rows) == 2 * 2 * 2
    for name, cap, solved, fraction, graph, best, raw in rows:
        if cap == 400:  # both check motions through the validator, most of them valid
            assert 0.0 < fraction <= 1.0, (name, fraction)
        assert (graph is None) == (name == "geometric_DimensionRRT"), (name, graph)
        if not solved:
            assert best is None, (name, cap, raw)
        else:
            assert best == pytest.approx(raw, rel=1e-9) or best <= raw
    assert any(not r[2] and r[6] is not None for r in rows)  # an approximate path was there, without a best cost


def test_a_cap_read_at_a_checkpoint_has_the_settings_of_a_run_capped_there(query_file, tmp_path):
    """One configuration per planner and cap: the 3-sample row, read during the 400-sample run, says 3 samples."""
    cfg = CampaignConfig(name="configs", queries=str(query_file), sample_caps=(3, 400), anytime_budgets=(),
                         iteration_planners=("DimensionRRT",), checkers=("batched",), workers=0, seed=3,
                         out=str(tmp_path))
    con = sqlite3.connect(run_campaign(cfg, progress_bar=False, report=False).database)
    settings = [s for (s,) in con.execute("SELECT settings FROM plannerConfigs ORDER BY id")]
    con.close()
    for cap, text in zip((3, 400), settings):
        assert f"iteration_cap = {cap}" in text and f"planner.max_samples = {cap}" in text, text


@pytest.mark.slow
def test_aorrtc_runs_again_in_one_experiment_with_a_fresh_planner_per_run(query_file, tmp_path):
    """ompl 2.0.1's AORRTC segfaults when solved again after ``clear()`` (``--runs 2``): each run after the
    first gets a fresh one (``SINGLE_USE_PLANNERS``).  A worker process, so a crash is a lost query, not pytest's."""
    cfg = tiny_config(query_file, tmp_path, sample_caps=(), anytime_planners=("AORRTC",), runs=3, workers=1)
    res = run_campaign(cfg, progress_bar=False)
    assert not res.failed_tasks and res.database is not None
    con = sqlite3.connect(res.database)
    statuses = [r[0] for r in con.execute("SELECT status FROM runs")]
    crash = con.execute("SELECT value FROM enums WHERE name = 'status' AND description = 'Crash'").fetchone()[0]
    assert len(statuses) == 2 * 3 and crash not in statuses


def test_interrupted_campaign_keeps_finished_logs_and_builds_the_db(query_file, tmp_path):
    def stop_after_first(logs):
        raise KeyboardInterrupt

    cfg = tiny_config(query_file, tmp_path, sample_caps=(30,), anytime_budgets=())
    res = run_campaign(cfg, on_task_done=stop_after_first, progress_bar=False)
    assert res.interrupted
    assert len(res.logs) == 1 and res.logs[0].is_file()
    assert not list((res.directory / "logs").glob("*.part"))
    con = sqlite3.connect(res.database)
    assert con.execute("SELECT COUNT(*) FROM experiments").fetchone()[0] == 1
    con.close()
    success = (res.directory / "success.csv").read_text()
    assert "missing" in success.splitlines()[0]


def test_second_campaign_leaves_the_first_untouched(query_file, tmp_path):
    cfg = tiny_config(query_file, tmp_path, sample_caps=(20,), anytime_budgets=(), max_queries=1)
    first = run_campaign(cfg, progress_bar=False, report=False)
    before = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in first.directory.rglob("*") if p.is_file()}
    second = run_campaign(cfg, progress_bar=False, report=False)
    assert second.directory != first.directory
    after = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in first.directory.rglob("*") if p.is_file()}
    assert before == after


def test_bad_config_is_rejected():
    with pytest.raises(ValueError, match="motion validator"):
        CampaignConfig(checkers=("fast",))
    with pytest.raises(ValueError, match="caps"):
        CampaignConfig(sample_caps=(0,))


def test_default_workers_is_at_most_two():
    assert CampaignConfig().workers == default_workers() and 1 <= default_workers() <= 2


def test_config_numbers_become_plain_python_values_and_duplicates_are_refused():
    import numpy as np

    from tpee_ompl.bench.config import KNOWN_PLANNERS, CampaignConfig

    c = CampaignConfig(sample_caps=(np.int64(20),), anytime_budgets=(np.float32(0.02),), runs=np.int64(1),
                       seed=np.int64(3), simplify=np.bool_(True))
    assert [type(v) for v in (c.sample_caps[0], c.anytime_budgets[0], c.runs, c.seed, c.simplify)] == [int, float, int,
                                                                                                       int, bool]
    for kw, match in (({"sample_caps": (20, 20)}, "twice"), ({"anytime_budgets": (0.02, 0.0200000001)}, "twice"),
                      ({"sample_caps": (), "anytime_queries": 0}, "nothing to run"),
                      ({"sample_caps": (10**30,)}, "sample_caps"), ({"anytime_planners": ("PRMstar",)}, "PRMstar")):
        with pytest.raises(ValueError, match=match):
            CampaignConfig(**kw)
    assert "PRMstar" not in KNOWN_PLANNERS  # deadlocks with a Python termination condition


def test_asking_for_more_queries_than_a_set_has_says_so(query_file, tmp_path, caplog):
    """narrow3 --max-queries 25 ran its 10 queries without a word."""
    import logging

    from helpers.bench_standins import tiny_config

    from tpee_ompl.bench.campaign import prepare_campaign

    with caplog.at_level(logging.WARNING):
        plan = prepare_campaign(tiny_config(query_file, tmp_path, max_queries=500))
    assert any(f"has {len(plan.queries)} queries: all of them run" in r.getMessage() for r in caplog.records)


def test_a_campaign_of_one_planner_at_sample_caps_says_so_and_draws_no_ratio_plot(query_file, tmp_path):
    """``--planners RRTstar``: the report said it "ran one planner at no sample cap" (it ran at 30 samples) and
    fig15_ratios_batched.png was an empty axis labelled RRTstar / RRTstar."""
    cfg = tiny_config(query_file, tmp_path, sample_caps=(30,), iteration_planners=("RRTstar",), anytime_budgets=())
    res = run_campaign(cfg, progress_bar=False)
    text = (res.directory / "report.md").read_text()
    assert text.startswith("No Table 4: it compares two planners at equal sample counts, and the campaign ran only "
                           "RRTstar at its sample caps.")
    assert not list(res.directory.rglob("fig15_ratios_*.png"))


def test_a_campaign_json_edited_to_endless_runs_is_refused_on_resume(query_file, tmp_path):
    """runs: 10**9 in campaign.json was accepted by --resume (the command line caps counts at 1e7) and ran for ever."""
    from tpee_ompl.bench.config import load_campaign

    res = run_campaign(tiny_config(query_file, tmp_path, sample_caps=(30,), anytime_budgets=()), report=False,
                       progress_bar=False)
    path = res.directory / "campaign.json"
    meta = json.loads(path.read_text())
    meta["config"]["runs"] = 10**9
    path.write_text(json.dumps(meta))
    with pytest.raises(ValueError, match=r"campaign.json has a bad config \(runs must be .*10000000"):
        load_campaign(res.directory)


def test_a_campaign_logged_to_a_file_shows_its_progress_as_lines(query_file, tmp_path, capsys):
    """A campaign's log held its progress bar as one line of carriage returns with every state redrawn in it."""
    cfg = tiny_config(query_file, tmp_path, sample_caps=(30,), anytime_budgets=())
    run_campaign(cfg, report=False, progress_bar=True)
    err = capsys.readouterr().err  # (not a terminal: tpee_ompl.progress writes lines)
    assert "\r" not in err
    assert [line for line in err.splitlines() if line.startswith("smoke queries: ")][-1].startswith(
        "smoke queries: 2/2 query (100 %)")
