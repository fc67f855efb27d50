"""The local executor survives worker death: a lost task is retried once, then listed; nothing hangs or doubles."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import pytest
from helpers import bench_tasks
from helpers.bench_standins import SELF_KILL_ENV, tiny_config, write_query_file

from tpee_ompl.bench.campaign import resume_campaign, run_campaign
from tpee_ompl.bench.executors import ProcessPoolExecutor
from tpee_ompl.cli.bench import main

KILLER = "helpers.bench_standins:make_self_killer"


@pytest.fixture(scope="module")
def query_file(tmp_path_factory, robot) -> Path:
    return write_query_file(tmp_path_factory.mktemp("q") / "tiny.json", robot, n=3)


def _experiments(db: Path) -> list[tuple[str, int]]:
    """("experiment name/qNNN", runs) per experiment of the database (one name is shared by the queries)."""
    con = sqlite3.connect(db)
    try:
        return con.execute("SELECT printf('%s/q%03d', experiments.name, experiments.query_id), COUNT(runs.id) "
                           "FROM experiments LEFT JOIN runs ON runs.experimentid = experiments.id "
                           "GROUP BY experiments.id").fetchall()
    finally:
        con.close()


def _arm_killer(monkeypatch, folder: Path, times: int, cap: int) -> Path:
    """Query id 1 kills its worker at ``cap`` the first ``times`` times (spawned workers inherit the env)."""
    folder.mkdir()
    monkeypatch.setenv(SELF_KILL_ENV, json.dumps({"dir": str(folder), "query_id": 1, "cap": cap, "times": times}))
    return folder


@pytest.mark.parametrize("workers", [1, 2])
def test_a_worker_killed_mid_task_costs_one_retry_and_loses_or_doubles_nothing(query_file, tmp_path, monkeypatch,
                                                                                workers):
    kills = _arm_killer(monkeypatch, tmp_path / "kills", times=1, cap=60)  # dies after its N30 log is written
    cfg = tiny_config(query_file, tmp_path, sample_caps=(30, 60), anytime_budgets=(), workers=workers,
                      iteration_planners=(KILLER, "RRTstar"))
    executor = ProcessPoolExecutor(workers)
    res = run_campaign(cfg, executor=executor, report=False, progress_bar=False)
    assert len(list(kills.iterdir())) == 1  # a worker really died
    assert [a["qpos"] for a in executor.lost] == [1] and "SIGKILL" in executor.lost[0]["reason"]
    assert not res.interrupted and res.failed_tasks == []
    assert len(res.logs) == 3 * 2
    per_exp = _experiments(res.database)
    assert len(per_exp) == len({name for name, _ in per_exp}) == 6 and all(n == 2 for _, n in per_exp)
    tasks = [json.loads(line) for line in (res.directory / "tasks.jsonl").read_text().splitlines()]
    assert sorted(t["qpos"] for t in tasks) == [0, 1, 2]
    retried = next(t for t in tasks if t["qpos"] == 1)
    assert retried["logs"] == ["q001_iterations_batched_N60.log"]  # the retry ran only what the dead worker had not
    meta = json.loads((res.directory / "campaign.json").read_text())
    assert meta["failed_tasks"] == [] and [a["qpos"] for a in meta["lost_attempts"]] == [1]


@pytest.mark.parametrize("workers", [1, 2])
def test_a_query_whose_worker_always_dies_is_listed_exit_1_and_resume_runs_it(query_file, tmp_path, monkeypatch,
                                                                               capsys, workers):
    kills = _arm_killer(monkeypatch, tmp_path / "kills", times=99, cap=30)
    args = ["--queries", str(query_file), "--name", "lost", "--samples", "30", "60", "--anytime",
            "--planners", KILLER, "RRTstar", "--checkers", "batched", "--workers", str(workers), "--seed", "3",
            "--out", str(tmp_path), "--no-progress"]
    assert main(args) == 1
    out = capsys.readouterr()
    assert "lost" in out.err and "--resume" in out.err and "Traceback" not in out.err
    assert len(list(kills.iterdir())) == 2  # tried, retried once, then given up
    (directory,) = tmp_path.glob("*_lost")
    meta = json.loads((directory / "campaign.json").read_text())
    (failed,) = meta["failed_tasks"]
    assert failed["qpos"] == 1 and failed["attempts"] == 2 and "SIGKILL" in failed["reason"]
    assert failed["missing_logs"] == ["q001_iterations_batched_N30.log", "q001_iterations_batched_N60.log"]
    assert meta["interrupted"] is False and meta["finished_experiments"] == 4
    names = [n for n, _ in _experiments(directory / "benchmark.db")]
    assert len(names) == len(set(names)) == 4 and not any("q001" in n for n in names)
    assert "Lost queries" in (directory / "report.md").read_text()

    monkeypatch.delenv(SELF_KILL_ENV)  # the fault is gone: resume finishes the campaign
    monkeypatch.setenv(SELF_KILL_ENV, json.dumps({"dir": str(kills), "query_id": 1, "cap": 30, "times": 0}))
    again = resume_campaign(directory, executor=ProcessPoolExecutor(workers), report=False, progress_bar=False)
    assert again.failed_tasks == [] and len(again.logs) == 6
    names = [n for n, _ in _experiments(again.database)]
    assert len(names) == len(set(names)) == 6


def _rrtstar_rows(db: Path) -> list[tuple]:
    con = sqlite3.connect(db)
    try:
        return con.execute("SELECT experiments.query_id, experiments.sample_cap, runs.status, runs.iterations, "
                           "runs.best_cost, runs.solution_length FROM runs JOIN experiments ON runs.experimentid = "
                           "experiments.id JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id WHERE "
                           "plannerConfigs.name LIKE '%RRTstar' ORDER BY 1, 2, runs.id").fetchall()
    finally:
        con.close()


def test_the_experiments_a_retried_task_runs_give_the_rows_of_an_uninterrupted_run(query_file, tmp_path, monkeypatch):
    """The retry skips the experiments its dead predecessor logged; OMPL's planners used to draw, in the ones it ran,
    the random numbers the skipped ones had drawn (RRT*'s rows changed without a word)."""
    rows = []
    for times in (0, 1):
        kills = _arm_killer(monkeypatch, tmp_path / f"kills{times}", times=times, cap=60)
        cfg = tiny_config(query_file, tmp_path / f"out{times}", sample_caps=(30, 60), anytime_budgets=(), workers=1,
                          iteration_planners=(KILLER, "RRTstar"))
        executor = ProcessPoolExecutor(1)
        res = run_campaign(cfg, executor=executor, report=False, progress_bar=False)
        assert len(list(kills.iterdir())) == times and len(executor.lost) == times and not res.failed_tasks
        rows.append(_rrtstar_rows(res.database))
    assert len(rows[0]) == 3 * 2 and rows[1] == rows[0]


def test_a_hung_task_is_killed_at_its_time_limit_retried_once_then_reported():
    ex = ProcessPoolExecutor(2, poll=0.2)
    tasks = [{"qpos": 0, "time_limit_s": 0.5}, {"qpos": 1, "time_limit_s": 60}]
    out = list(ex.run(bench_tasks.hang, tasks[:1])) + list(ex.run(bench_tasks.echo, tasks[1:]))
    assert out[0]["failed"].startswith("no result within its time limit") and out[0]["attempts"] == 2
    assert out[1]["qpos"] == 1 and "failed" not in out[1]
    assert [a["attempt"] for a in ex.lost] == [1, 2]


def test_a_task_that_raises_is_a_failure_without_retry_and_the_others_finish():
    ex = ProcessPoolExecutor(2)
    out = sorted(ex.run(bench_tasks.boom, [{"qpos": 0}]), key=lambda r: r["qpos"])
    assert out[0]["failed"] == "ValueError: task 0 exploded" and out[0]["attempts"] == 1 and ex.lost == []
    many = [{"qpos": k, "die": k == 2} for k in range(5)]
    res = list(ProcessPoolExecutor(2).run(bench_tasks.die, many))
    assert sorted(r["qpos"] for r in res) == list(range(5))  # each exactly once
    assert [r["qpos"] for r in res if r.get("failed")] == [2]
    assert len({r["pid"] for r in res if not r.get("failed")}) == 4  # a fresh process per task


def test_in_process_a_task_that_raises_is_recorded_and_the_others_run():
    from tpee_ompl.bench.executors import InProcessExecutor

    out = list(InProcessExecutor().run(bench_tasks.boom, [{"qpos": 0}, {"qpos": 1}]))
    assert [r.get("failed", "").startswith("ValueError: task") for r in out] == [True, True]


def test_a_task_run_in_a_subprocess_is_killed_at_its_time_limit_run_once_more_then_reported(tmp_path):
    """The Dask executor's tasks: a hang used to hold the campaign for ever, then for three time limits (Dask's
    retries of a raised timeout); now two, as in the local pool, and it comes back as a failure, not raised."""
    from tpee_ompl.bench.executors import run_task_in_subprocess

    tests_dir = str(Path(__file__).resolve().parents[1])
    starts = tmp_path / "starts.txt"
    task = {"qpos": 3, "seconds": 60, "time_limit_s": 5.0, "sys_path": [tests_dir],  # 5 s: a loaded machine's import
            "starts": str(starts)}
    out = run_task_in_subprocess(task, "helpers.bench_tasks:sleep")
    assert out["failed"] == "no result within its time limit (5 s): killed" and out["attempts"] == 2
    assert out["qpos"] == 3 and starts.read_text().splitlines() == ["start", "start"]  # two fresh processes
    assert run_task_in_subprocess({**task, "seconds": 0}, "helpers.bench_tasks:sleep")["seconds"] == 0


def test_task_folders_of_processes_that_are_gone_are_swept_and_the_others_kept(tmp_path, monkeypatch):
    """A Dask worker killed or interrupted mid-task left its ``tpee_task_*`` folder in /tmp for good."""
    import os
    import subprocess
    import sys
    import tempfile

    from tpee_ompl.bench.executors import sweep_task_dirs

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    (tmp_path / f"tpee_task_{gone.pid}_x1").mkdir()
    (tmp_path / f"tpee_task_{gone.pid}_x1" / "task.json").write_text("{}")
    (tmp_path / f"tpee_task_{os.getpid()}_x2").mkdir()  # a task running in this process
    (tmp_path / "tpee_task_x3").mkdir()  # no pid in its name: not this module's to judge
    assert sweep_task_dirs() == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([f"tpee_task_{os.getpid()}_x2", "tpee_task_x3"])
