"""The Planner-Arena database: corrupt logs are skipped by name, never a half-written database; logs of the
earlier format join today's."""

from __future__ import annotations

import re
import sqlite3

from helpers.bench_standins import tiny_config, write_query_file

from tpee_ompl.bench.campaign import run_campaign
from tpee_ompl.bench.database import build_database


def test_no_readable_log_gives_no_database(tmp_path):
    truncated, garbage = tmp_path / "a.log", tmp_path / "b.log"
    truncated.write_text("OMPL version 2.0.1\nExperiment x\n")
    garbage.write_text("not an OMPL log\n.\n")
    db, skipped = build_database([truncated, garbage], tmp_path / "benchmark.db")
    assert db is None and skipped == [truncated, garbage]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.log", "b.log"]


def test_a_log_of_the_earlier_format_read_first_joins_todays_names_and_integer_query_ids(tmp_path, robot):
    query_file = write_query_file(tmp_path / "tiny.json", robot, n=2)
    res = run_campaign(tiny_config(query_file, tmp_path, sample_caps=(20,), anytime_budgets=(), max_queries=2),
                       report=False, progress_bar=False)
    logs = sorted(res.logs)
    first = logs[0]
    text = first.read_text()
    # as logs were written before 2026-11-26 (a resumed campaign's): the query in the name, query_id as text
    old = re.sub(r"^(Experiment \S+?)(_N\d+_)", r"\1_q000\2", text, count=1, flags=re.MULTILINE)
    old = old.replace("query_id INTEGER = ", "query_id TEXT = ", 1)
    assert old != text and "_q000_N20_" in old
    first.write_text(old)
    db, skipped = build_database(logs, tmp_path / "mixed.db")
    assert not skipped and first.read_text() == old  # the log itself is left as it was
    con = sqlite3.connect(db)
    try:
        assert {r[0] for r in con.execute("SELECT typeof(query_id) FROM experiments")} == {"integer"}
        assert con.execute("SELECT name, COUNT(*) FROM experiments GROUP BY name").fetchall() == \
            [("iterations_tiny_N20_batched", 2)]
        assert {r[0] for r in con.execute("SELECT typeof(query_id) FROM progress")} <= {"integer"}
    finally:
        con.close()


def test_a_query_set_named_like_an_old_query_suffix_keeps_its_experiment_name():
    """``_q001`` in a query set's own name was taken for the query number of the earlier format and cut: the
    database said ``iterations_pn_N300_batched`` where the log said ``iterations_pn_q001_N300_batched``."""
    from tpee_ompl.bench.database import _without_query_in_name

    today = "Experiment iterations_pn_q001_N300_batched\nquery_set TEXT = pn_q001\n"
    assert _without_query_in_name(today) == today
    earlier = "Experiment iterations_pn_q001_q007_T0.5s_batched\nquery_set TEXT = pn_q001\n"
    assert _without_query_in_name(earlier).startswith("Experiment iterations_pn_q001_T0.5s_batched\n")
