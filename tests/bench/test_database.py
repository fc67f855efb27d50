"""The Planner-Arena database: corrupt logs are skipped by name, never a half-written database."""

from __future__ import annotations

from tpee_ompl.bench.database import build_database


def test_no_readable_log_gives_no_database(tmp_path):
    truncated, garbage = tmp_path / "a.log", tmp_path / "b.log"
    truncated.write_text("OMPL version 2.0.1\nExperiment x\n")
    garbage.write_text("not an OMPL log\n.\n")
    db, skipped = build_database([truncated, garbage], tmp_path / "benchmark.db")
    assert db is None and skipped == [truncated, garbage]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.log", "b.log"]
