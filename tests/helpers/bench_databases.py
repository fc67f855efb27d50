"""Comparing two campaign databases (one run per ladder against separate runs) in the benchmark tests."""

from __future__ import annotations

import sqlite3


def schema(con: sqlite3.Connection) -> dict[str, list[str]]:
    """Table and view names -> their column names."""
    tables = [r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type IN ('table','view') ORDER BY name")]
    return {t: [r[1] for r in con.execute(f"PRAGMA table_info({t})")] for t in tables}


def assert_same_shape(a: sqlite3.Connection, b: sqlite3.Connection) -> None:
    """Same tables and columns, and as many experiments, runs and planner configurations (at least one)."""
    assert schema(a) == schema(b)
    for t in ("experiments", "runs", "plannerConfigs"):
        counts = [con.execute(f"SELECT count(*) FROM {t}").fetchone()[0] for con in (a, b)]
        assert counts[0] == counts[1] > 0, t
