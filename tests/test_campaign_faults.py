"""Campaign faults: callback exceptions, corrupt logs, SIGINT/SIGTERM at random moments, resume, no Dask."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
from ompl import base as ob
from ompl import util as ou
from test_benchmark import StandInPlanner, tiny_config, write_query_file

from tpee_ompl.bench.campaign import (
    PlannerContext,
    build_database,
    main,
    resume_campaign,
    run_campaign,
    write_new_file,
)

TESTS = Path(__file__).resolve().parent


class SolveRaises(StandInPlanner):
    """Raises inside ``solve`` (called by OMPL's Benchmark from C++)."""

    def __init__(self, si, max_samples=None, seed=None):
        super().__init__(si, max_samples, seed)
        self.setName("SolveRaises")

    def solve(self, ptc):
        raise ValueError("solve exploded")


class SetupRaises(StandInPlanner):
    """Raises inside ``setup``."""

    def __init__(self, si, max_samples=None, seed=None):
        super().__init__(si, max_samples, seed)
        self.setName("SetupRaises")

    def setup(self):
        raise ValueError("setup exploded")


class _RaisingMotionValidator(ob.MotionValidator):
    def __init__(self, si):
        super().__init__(si)

    def checkMotion(self, s1, s2):  # noqa: N802 (OMPL override)
        raise RuntimeError("motion validator exploded")


class AbortsBenchmark(StandInPlanner):
    """Solves, then leaves a raising Python motion validator: OMPL's own path check aborts ``benchmark()``."""

    def solve(self, ptc):
        status = super().solve(ptc)
        si = self.getSpaceInformation()
        si.setMotionValidator(_RaisingMotionValidator(si))
        return status


def make_solve_raises(si, ctx: PlannerContext):
    return SolveRaises(si, max_samples=ctx.max_samples, seed=ctx.seed)


def make_setup_raises(si, ctx: PlannerContext):
    return SetupRaises(si, max_samples=ctx.max_samples, seed=ctx.seed)


def make_aborts_benchmark(si, ctx: PlannerContext):
    return AbortsBenchmark(si, max_samples=ctx.max_samples, seed=ctx.seed)


@pytest.fixture(scope="module")
def query_file(tmp_path_factory, robot) -> Path:
    return write_query_file(tmp_path_factory.mktemp("q") / "tiny.json", robot, n=3)


def _runs(db: Path) -> list[tuple]:
    con = sqlite3.connect(db)
    try:
        return con.execute(
            "SELECT plannerConfigs.name, runs.status, runs.solved, runs.planner_error FROM runs "
            "JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id ORDER BY runs.id").fetchall()
    finally:
        con.close()


def test_exceptions_in_planner_callbacks_are_failed_runs_and_ompl_logging_stays_on(query_file, tmp_path):
    cfg = tiny_config(query_file, tmp_path, sample_caps=(20,), anytime_budgets=(), max_queries=1,
                      iteration_planners=("test_campaign_faults:make_solve_raises",
                                          "test_campaign_faults:make_setup_raises", "RRTstar"))
    res = run_campaign(cfg, report=False, progress_bar=False)
    rows = {name: (status, solved, err) for name, status, solved, err in _runs(res.database)}
    assert rows["geometric_SolveRaises"] == (7, 0, 1) and rows["geometric_SetupRaises"] == (7, 0, 1)
    status, _, err = rows["geometric_RRTstar"]
    assert status in (4, 5, 6) and err == 0  # the rest of the experiment ran (20 iterations may not solve)
    assert len(_runs(res.database)) == 3
    assert ou.getOutputHandler() is not None


def test_benchmark_aborted_by_a_python_callback_records_failed_runs_and_restores_logging(query_file, tmp_path):
    cfg = tiny_config(query_file, tmp_path, sample_caps=(20,), anytime_budgets=(), max_queries=2,
                      iteration_planners=("test_campaign_faults:make_aborts_benchmark", "RRTstar"))
    res = run_campaign(cfg, report=False, progress_bar=False)
    assert ou.getOutputHandler() is not None  # Benchmark had switched it off when it was aborted
    runs = _runs(res.database)
    assert len(runs) == 2 * 2  # every planner of both experiments has its run, recorded as failed
    assert all(status == 7 and solved == 0 and err == 1 for _, status, solved, err in runs)
    tasks = [json.loads(line) for line in (res.directory / "tasks.jsonl").read_text().splitlines()]
    assert all("motion validator exploded" in next(iter(t["errors"].values())) for t in tasks)


def test_corrupt_log_is_reported_by_name_and_skipped(query_file, tmp_path, caplog):
    cfg = tiny_config(query_file, tmp_path, sample_caps=(20, 40), anytime_budgets=(), max_queries=1)
    res = run_campaign(cfg, report=False, progress_bar=False)
    bad = res.logs[0]
    text = bad.read_text()
    bad.write_text(text[: len(text) // 3])
    (res.directory / "logs" / "q009_garbage.log").write_text("not an OMPL log\n")
    again = resume_campaign(res.directory, report=True, progress_bar=False)
    assert sorted(p.name for p in again.skipped_logs) == sorted([bad.name, "q009_garbage.log"])
    assert bad.name in caplog.text
    con = sqlite3.connect(again.database)
    assert con.execute("SELECT COUNT(*) FROM experiments").fetchone()[0] == 1
    con.close()
    meta = json.loads((res.directory / "campaign.json").read_text())
    assert bad.name in meta["corrupt_logs"]
    assert bad.read_text() == text[: len(text) // 3]  # reported, not deleted or rewritten


def test_write_new_file_never_overwrites(tmp_path):
    target = tmp_path / "a.log"
    assert write_new_file(target, "first")
    assert not write_new_file(target, "second")
    assert target.read_text() == "first" and [p.name for p in tmp_path.iterdir()] == ["a.log"]


def test_missing_dask_gives_a_clear_error(monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    code = main(["--dask", "local", "--samples", "10", "--anytime", "--out", str(tmp_path), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and "pip install" in err and "dask" in err
    assert not list(tmp_path.iterdir())  # nothing started


def _launch(query_file: Path, out: Path) -> subprocess.Popen:
    code = ("import sys; sys.path.insert(0, sys.argv[1]); from tpee_ompl.bench.campaign import main; "
            "sys.exit(main(sys.argv[2:]))")
    args = ["--queries", str(query_file), "--name", "sig", "--samples", "30", "60", "--anytime", "0.05",
            "--planners", "test_benchmark:make_standin", "RRTstar",
            "--anytime-planners", "test_benchmark:make_standin", "RRTConnect",
            "--checkers", "batched", "--workers", "1", "--seed", "5", "--out", str(out), "--no-progress"]
    return subprocess.Popen([sys.executable, "-c", code, str(TESTS), *args], cwd=str(TESTS.parent),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_for(pred, timeout: float = 60.0) -> None:
    t0 = time.monotonic()
    while not pred():
        if time.monotonic() - t0 > timeout:
            raise TimeoutError
        time.sleep(0.02)


@pytest.mark.parametrize(("sig", "moment"), [(signal.SIGINT, "first_log"), (signal.SIGTERM, "start")])
def test_signal_keeps_finished_runs_never_half_writes_the_db_and_resume_completes(query_file, tmp_path, sig, moment):
    proc = _launch(query_file, tmp_path)
    folders = lambda: list(tmp_path.glob("*_sig"))  # noqa: E731
    try:
        _wait_for(lambda: folders() and (folders()[0] / "campaign.json").is_file())
        directory = folders()[0]
        if moment == "first_log":
            _wait_for(lambda: list((directory / "logs").glob("*.log")))
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    assert "--resume" in out + err
    assert not list(directory.rglob("*.part"))
    meta = json.loads((directory / "campaign.json").read_text())
    assert meta["interrupted"] is True
    kept = {p.name: p.read_bytes() for p in (directory / "logs").glob("*.log")}
    assert len(kept) < meta["expected_experiments"]
    db = directory / "benchmark.db"
    if kept:
        con = sqlite3.connect(db)
        assert con.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
        assert con.execute("SELECT COUNT(*) FROM experiments").fetchone()[0] == len(kept)
        con.close()
    else:
        assert not db.exists()
    assert main(["--resume", str(directory), "--workers", "0", "--no-progress"]) == 0
    logs = {p.name: p.read_bytes() for p in (directory / "logs").glob("*.log")}
    assert len(logs) == meta["expected_experiments"]
    assert all(logs[name] == data for name, data in kept.items())  # finished logs untouched
    con = sqlite3.connect(db)
    names = [r[0] for r in con.execute("SELECT name FROM experiments")]
    con.close()
    assert len(names) == len(set(names)) == meta["expected_experiments"]
    assert len(list(tmp_path.glob("*_sig"))) == 1  # resumed in place, no new folder
