"""Plots: the anytime within-5 % figure from a small Planner-Arena database (sectors 0, as for other problems)."""

from __future__ import annotations

import sqlite3

import numpy as np
import pytest

from tpee_ompl.bench.plots import _progress_median, _progress_within, make_plots
from tpee_ompl.bench.report import load_runs


def make_db(path, runs, progress=()):
    """A database with OMPL's run, experiment, planner and progress tables and our extra columns.

    ``runs``: (planner, query id, budget, length or None, first solution time); ``progress``: (run id, time, cost).
    """
    con = sqlite3.connect(str(path))
    con.executescript("""
        CREATE TABLE plannerConfigs (id INTEGER PRIMARY KEY, name TEXT, settings TEXT);
        CREATE TABLE experiments (id INTEGER PRIMARY KEY, name TEXT, comparison TEXT, query_id TEXT,
            from_sector INTEGER, to_sector INTEGER, sample_cap INTEGER, time_budget REAL, motion_validator TEXT);
        CREATE TABLE runs (id INTEGER PRIMARY KEY, experimentid INTEGER, plannerid INTEGER, time REAL, solved INTEGER,
            status INTEGER, approximate_solution INTEGER, correct_solution INTEGER, solution_length REAL,
            path_valid_dense INTEGER, reaches_goal INTEGER, first_solution_time REAL);
        CREATE TABLE progress (runid INTEGER, time REAL, best_cost REAL, iterations INTEGER);
    """)
    planners, experiments = {}, {}
    for k, (pl, q, budget, length, first) in enumerate(runs, start=1):
        pid = planners.setdefault(pl, len(planners) + 1)
        eid = experiments.setdefault((q, budget), len(experiments) + 1)
        ok = length is not None
        con.execute("INSERT OR IGNORE INTO plannerConfigs VALUES (?, ?, '')", (pid, f"geometric_{pl}"))
        con.execute("INSERT OR IGNORE INTO experiments VALUES (?, ?, 'anytime', ?, 0, 0, 0, ?, 'batched')",
                    (eid, f"anytime_q{q}_T{budget}", str(q), budget))
        con.execute("INSERT INTO runs VALUES (?, ?, ?, ?, ?, ?, 0, ?, ?, ?, ?, ?)",
                    (k, eid, pid, budget, int(ok), 6 if ok else 5, int(ok), length, int(ok), int(ok), first))
    con.executemany("INSERT INTO progress VALUES (?, ?, ?, 0)", progress)
    con.commit()
    con.close()
    return path


RUNS = [  # run ids 1..8: queries 0, 1 at budgets 0.1 and 1 s; B never succeeds
    ("A", 0, 0.1, 2.2, 0.05), ("B", 0, 0.1, None, None), ("A", 1, 0.1, 3.0, 0.05), ("B", 1, 0.1, None, None),
    ("A", 0, 1.0, 2.0, 0.05), ("B", 0, 1.0, None, None), ("A", 1, 1.0, 3.0, 0.05), ("B", 1, 1.0, None, None),
]
PROGRESS = [(5, 0.05, 2.5), (5, 0.5, 2.0), (7, 0.05, 3.0), (6, 0.05, None)]


def test_progress_share_follows_the_best_cost_inside_the_longest_budget_runs(tmp_path):
    db = make_db(tmp_path / "b.db", RUNS, PROGRESS)
    runs = load_runs(db)
    t, share = _progress_within(db, runs, "A", {"0": 2.0, "1": 3.0}, 1.05)
    assert t[-1] == pytest.approx(1.0) and t[0] == pytest.approx(0.05)
    # query 1 within from 0.05 s, query 0 (2.5 > 2.1) only from 0.5 s on
    assert share[0] == pytest.approx(0.5) and share[-1] == pytest.approx(1.0)
    assert np.all(share[(t >= 0.05) & (t < 0.5)] == 0.5) and np.all(share[t >= 0.5] == 1.0)
    # B's only progress rows belong to failed runs: a flat zero; a planner without rows: no curve
    assert np.all(_progress_within(db, runs, "B", {"0": 2.0, "1": 3.0}, 1.05)[1] == 0)
    db2 = make_db(tmp_path / "c.db", RUNS)
    assert _progress_within(db2, load_runs(db2), "A", {"0": 2.0, "1": 3.0}, 1.05) == (None, None)


def test_median_cost_curve_is_the_median_of_the_runs_step_functions_inside_the_longest_budget(tmp_path):
    db = make_db(tmp_path / "b.db", RUNS, PROGRESS)
    t, med = _progress_median(db, load_runs(db), "A")
    assert t[0] == 0.0 and t[-1] == pytest.approx(1.0)
    # runs 5 (2.5 from 0.05 s, 2.0 from 0.5 s) and 7 (3.0 from 0.05 s): nothing before 0.05 s
    assert np.all(np.isnan(med[t < 0.05]))
    assert np.all(med[(t >= 0.05) & (t < 0.5)] == pytest.approx(2.75)) and np.all(med[t >= 0.5] == pytest.approx(2.5))
    # progress rows without a time say nothing: no curve, as for a planner without rows
    db2 = make_db(tmp_path / "c.db", RUNS, [(5, None, 2.5), (7, None, 3.0)])
    assert _progress_median(db2, load_runs(db2), "A") == (None, None)
    assert _progress_median(db, load_runs(db), "C") == (None, None)


def test_within_best_plot_is_its_own_file_beside_the_others(tmp_path):
    db = make_db(tmp_path / "b.db", RUNS, PROGRESS)
    out = make_plots(db, tmp_path / "plots")
    names = sorted(p.name for p in out)
    assert names == ["anytime_cost.png", "anytime_within_best.png"]
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in out)
    assert not list((tmp_path / "plots").glob("*.part")) and not list((tmp_path / "plots").glob(".*"))


def test_a_save_that_fails_halfway_leaves_the_previous_plots_untouched(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    db = make_db(tmp_path / "b.db", RUNS, PROGRESS)
    folder = tmp_path / "plots"
    before = {p.name: p.read_bytes() for p in make_plots(db, folder)}

    def half_written(self, fname, *args, **kwargs):
        open(fname, "wb").write(b"\x89PNG half")
        raise OSError("disk full")

    monkeypatch.setattr(Figure, "savefig", half_written)
    with pytest.raises(OSError):
        make_plots(db, folder)
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before


def test_plots_an_earlier_build_drew_and_this_one_cannot_are_removed_other_files_kept(tmp_path):
    folder = tmp_path / "plots"
    folder.mkdir()
    for name in ("box_time.png", "fig15_ratios_batched.png", "notes.png", "readme.txt"):
        (folder / name).write_bytes(b"earlier")
    db = make_db(tmp_path / "b.db", RUNS, PROGRESS)  # anytime runs only: no box or ratio plot
    out = make_plots(db, folder)
    assert sorted(p.name for p in folder.iterdir()) == sorted([p.name for p in out] + ["notes.png", "readme.txt"])
