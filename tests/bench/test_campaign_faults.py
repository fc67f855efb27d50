"""Campaign faults: callback exceptions, corrupt logs, SIGINT/SIGTERM at random moments, resume."""

from __future__ import annotations

import json
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.bench_standins import STANDIN, tiny_config, write_query_file
from ompl import base as ob
from ompl import util as ou

from tpee_ompl.bench.campaign import resume_campaign, run_campaign
from tpee_ompl.bench.database import build_database
from tpee_ompl.cli.bench import main

TESTS = Path(__file__).resolve().parents[1]
"""``tests/``: put on the campaign subprocess's ``sys.path`` so it imports ``helpers.bench_standins``."""
FAULTS = "helpers.bench_standins:"
CRASH = int(ob.PlannerStatus.CRASH.value)
UNSOLVED_OR_SOLVED = {int(s.value) for s in (ob.PlannerStatus.TIMEOUT, ob.PlannerStatus.APPROXIMATE_SOLUTION,
                                             ob.PlannerStatus.EXACT_SOLUTION)}


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
                      iteration_planners=(FAULTS + "make_solve_raises", FAULTS + "make_setup_raises",
                                          FAULTS + "make_package_planner_raises", "RRTstar"))
    res = run_campaign(cfg, report=False, progress_bar=False)
    rows = {name: (status, solved, err) for name, status, solved, err in _runs(res.database)}
    assert rows["geometric_SolveRaises"] == (CRASH, 0, 1) and rows["geometric_SetupRaises"] == (CRASH, 0, 1)
    assert rows["geometric_PackagePlannerRaises"] == (CRASH, 0, 1)  # its solve() returns CRASH: still an error
    status, _, err = rows["geometric_RRTstar"]
    assert status in UNSOLVED_OR_SOLVED and err == 0  # the rest of the experiment ran (20 iterations may not solve)
    assert len(_runs(res.database)) == 4
    assert ou.getOutputHandler() is not None


def test_benchmark_aborted_by_a_python_callback_records_failed_runs_and_restores_logging(query_file, tmp_path):
    cfg = tiny_config(query_file, tmp_path, sample_caps=(20,), anytime_budgets=(), max_queries=2,
                      iteration_planners=(FAULTS + "make_aborts_benchmark", "RRTstar"))
    res = run_campaign(cfg, report=False, progress_bar=False)
    assert ou.getOutputHandler() is not None  # Benchmark had switched it off when it was aborted
    runs = _runs(res.database)
    assert len(runs) == 2 * 2  # every planner of both experiments has its run, recorded as failed
    assert all(status == CRASH and solved == 0 and err == 1 for _, status, solved, err in runs)
    tasks = [json.loads(line) for line in (res.directory / "tasks.jsonl").read_text().splitlines()]
    assert all("motion validator exploded" in next(iter(t["errors"].values())) for t in tasks)


def _experiment_names(db: Path) -> list[str]:
    """"experiment name/qNNN" per experiment (one name is shared by the queries)."""
    con = sqlite3.connect(db)
    try:
        return [r[0] for r in con.execute("SELECT printf('%s/q%03d', name, query_id) FROM experiments")]
    finally:
        con.close()


def test_resume_moves_truncated_and_corrupt_logs_aside_and_runs_their_experiments_again(query_file, tmp_path, caplog):
    cfg = tiny_config(query_file, tmp_path, sample_caps=(20, 40), anytime_budgets=(), max_queries=2)
    res = run_campaign(cfg, report=False, progress_bar=False)
    assert len(res.logs) == 4
    truncated, corrupt = res.logs[0], res.logs[3]
    cut = truncated.read_text()[: len(truncated.read_text()) // 3]
    truncated.write_text(cut)
    garbled = corrupt.read_text().replace("\n2 planners\n", "\ntwo planners\n")
    assert garbled != corrupt.read_text()
    corrupt.write_text(garbled)
    (res.directory / "logs" / "q009_garbage.log").write_text("not an OMPL log\n")  # no experiment of the campaign

    again = resume_campaign(res.directory, report=True, progress_bar=False)

    broken = res.directory / "logs" / "broken"
    assert sorted(p.name for p in again.broken_logs) == sorted([truncated.name, corrupt.name, "q009_garbage.log"])
    assert (broken / truncated.name).read_text() == cut and (broken / corrupt.name).read_text() == garbled  # kept
    assert truncated.name in caplog.text and corrupt.name in caplog.text
    assert again.skipped_logs == [] and not again.failed_tasks
    assert sorted(p.name for p in again.logs) == sorted(p.name for p in res.logs)  # both re-ran, nothing else
    names = _experiment_names(again.database)
    assert len(names) == len(set(names)) == 4  # every experiment exactly once
    tasks = [json.loads(line) for line in (res.directory / "tasks.jsonl").read_text().splitlines()]
    assert sorted(n for t in tasks[2:] for n in t["logs"]) == sorted([truncated.name, corrupt.name])
    meta = json.loads((res.directory / "campaign.json").read_text())
    assert sorted(b["log"] for b in meta["broken_logs"]) == sorted([truncated.name, corrupt.name, "q009_garbage.log"])
    assert meta["interrupted"] is False and meta["finished_experiments"] == 4


def test_a_valid_log_of_another_experiment_is_left_out_of_the_database_and_a_resume_adds_its_time(
        query_file, tmp_path, caplog):
    """A helper's resume took another campaign's log into the database ("expected 4, finished 5"), and a resume that
    ran nothing replaced the campaign's 13-s wall time with its own 0.1 s."""
    other = run_campaign(tiny_config(query_file, tmp_path / "other", sample_caps=(30,), anytime_budgets=(),
                                     max_queries=1), report=False, progress_bar=False)
    res = run_campaign(tiny_config(query_file, tmp_path, sample_caps=(20,), anytime_budgets=(), max_queries=2),
                       report=False, progress_bar=False)
    before = json.loads((res.directory / "campaign.json").read_text())["wall_time_s"]
    stray = other.logs[0]
    assert stray.name not in {p.name for p in res.logs}
    (res.directory / "logs" / stray.name).write_bytes(stray.read_bytes())

    again = resume_campaign(res.directory, report=False, progress_bar=False)

    assert sorted(p.name for p in again.logs) == sorted(p.name for p in res.logs)
    assert len(_experiment_names(again.database)) == 2 and stray.name in caplog.text
    meta = json.loads((res.directory / "campaign.json").read_text())
    assert meta["stray_logs"] == [stray.name] and meta["finished_experiments"] == 2
    assert meta["wall_time_s"] > before


def test_a_resume_with_another_worker_count_records_it_and_keeps_the_campaigns_own(query_file, tmp_path):
    """``--resume --workers N`` rewrote ``config.workers`` (and the executor): the record then said every run was
    made with the resume's set-up."""
    res = run_campaign(tiny_config(query_file, tmp_path, sample_caps=(20,), anytime_budgets=(), max_queries=1),
                       report=False, progress_bar=False)
    meta = json.loads((res.directory / "campaign.json").read_text())
    assert meta["config"]["workers"] == 0 and "resumes" not in meta
    resume_campaign(res.directory, workers=1, report=False, progress_bar=False)
    again = json.loads((res.directory / "campaign.json").read_text())
    assert again["config"]["workers"] == 0 and again["executor"] == meta["executor"]
    assert [r["workers"] for r in again["resumes"]] == [1] and "1 worker" in again["resumes"][0]["executor"]


def test_database_build_skips_a_corrupt_log_by_name(query_file, tmp_path, caplog):
    cfg = tiny_config(query_file, tmp_path, sample_caps=(20, 40), anytime_budgets=(), max_queries=1)
    res = run_campaign(cfg, report=False, progress_bar=False)
    bad = res.logs[0]
    bad.write_text(bad.read_text()[:200])
    db, skipped = build_database(res.logs, tmp_path / "again.db")
    assert skipped == [bad] and bad.name in caplog.text
    assert len(_experiment_names(db)) == 1


def _launch(query_file: Path, out: Path) -> subprocess.Popen:
    code = ("import sys; sys.path.insert(0, sys.argv[1]); from tpee_ompl.cli.bench import main; "
            "sys.exit(main(sys.argv[2:]))")
    # a 1 s budget per query keeps the campaign running well after its first log (the signal must not
    # arrive after the end: workers that exit at once made that race visible)
    args = ["--queries", str(query_file), "--name", "sig", "--samples", "30", "60", "--anytime", "0.05", "1",
            "--planners", STANDIN, "RRTstar",
            "--anytime-planners", STANDIN, "RRTConnect",
            "--checkers", "batched", "--workers", "1", "--seed", "5", "--out", str(out), "--no-progress"]
    # SIGINT back to its default in the child: a test run started in the background of a non-interactive
    # shell inherits SIGINT ignored, and Python then never raises KeyboardInterrupt
    return subprocess.Popen([sys.executable, "-c", code, str(TESTS), *args], cwd=str(TESTS.parent),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _wait_for(pred, timeout: float = 60.0) -> None:
    t0 = time.monotonic()
    while not pred():
        if time.monotonic() - t0 > timeout:
            raise TimeoutError
        time.sleep(0.02)


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "moment"), [(signal.SIGINT, "first_log"), (signal.SIGTERM, "start"),
                                             (signal.SIGHUP, "first_log")])  # (SIGHUP killed it without a word)
def test_signal_keeps_finished_runs_never_half_writes_the_db_and_resume_completes(query_file, tmp_path, sig, moment,
                                                                                  capsys):
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
    assert main(["--resume", str(directory), "--workers", "1", "--no-progress"]) == 0
    printed = capsys.readouterr().out  # the headline tables and a count; the other tables are in report.md
    assert "runs: " in printed and f"results: {directory}" in printed and "## Success counts" not in printed
    logs = {p.name: p.read_bytes() for p in (directory / "logs").glob("*.log")}
    assert len(logs) == meta["expected_experiments"]
    assert all(logs[name] == data for name, data in kept.items())  # finished logs untouched
    con = sqlite3.connect(db)
    names = [r[0] for r in con.execute("SELECT printf('%s/q%03d', name, query_id) FROM experiments")]
    con.close()
    assert len(names) == len(set(names)) == meta["expected_experiments"]
    assert len(list(tmp_path.glob("*_sig"))) == 1  # resumed in place, no new folder


def test_a_campaign_already_running_in_another_process_is_not_resumed_a_second_time(query_file, tmp_path):
    import fcntl

    cfg = tiny_config(query_file, tmp_path, sample_caps=(20,), anytime_budgets=(), max_queries=1)
    res = run_campaign(cfg, report=False, progress_bar=False)
    before = (res.directory / "tasks.jsonl").read_text()
    with open(res.directory / ".lock", "a") as held:  # what a running campaign holds
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(ValueError, match="being run by another process"):
            resume_campaign(res.directory, report=False, progress_bar=False)
    assert (res.directory / "tasks.jsonl").read_text() == before  # nothing ran
    assert resume_campaign(res.directory, report=False, progress_bar=False).database is not None  # once free


def _one_query_campaign(query_file: Path, out: Path) -> list[str]:
    """``tpee-ompl bench`` arguments of a campaign of one query, 20 samples, the stand-in planner and RRT*."""
    return ["--queries", str(query_file), "--max-queries", "1", "--samples", "20", "--anytime", "--planners", STANDIN,
            "RRTstar", "--checkers", "batched", "--workers", "1", "--out", str(out), "--no-progress"]


def test_an_interrupt_while_the_database_is_built_names_the_campaign_to_resume(query_file, tmp_path, monkeypatch, capsys):
    from tpee_ompl.bench import campaign

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(campaign, "build_database", interrupted)
    code = main(_one_query_campaign(query_file, tmp_path))
    (folder,) = tmp_path.iterdir()
    assert code == 130 and f"--resume {folder}" in capsys.readouterr().err


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # Python's "Exception ignored"
def test_an_interrupt_python_drops_while_plots_are_drawn_still_ends_the_campaign_as_interrupted(
        query_file, tmp_path, monkeypatch, capsys):
    """A SIGTERM whose KeyboardInterrupt lands in a weakref callback (matplotlib's) was lost: exit 0, and
    ``campaign.json`` said "interrupted": false with the plots missing."""
    from helpers.interrupts import interrupt_in_a_weakref_callback

    from tpee_ompl.bench import plots

    def make_plots(*args, **kwargs):
        interrupt_in_a_weakref_callback()
        return []

    monkeypatch.setattr(plots, "make_plots", make_plots)
    code = main(_one_query_campaign(query_file, tmp_path))
    (folder,) = tmp_path.iterdir()
    assert code == 130 and f"--resume {folder}" in capsys.readouterr().err
    assert json.loads((folder / "campaign.json").read_text())["interrupted"] is True


@pytest.mark.parametrize("stage", ["build_database", "make_plots"])
def test_a_full_disk_after_the_runs_names_what_was_not_written_and_resume_makes_it(
        query_file, tmp_path, monkeypatch, capsys, stage):
    """A database or plots that could not be written said "OperationalError: disk I/O error" or "[Errno 28]" with no
    file nor folder to resume, and campaign.json said the campaign had finished."""
    import errno

    from tpee_ompl.bench import campaign, plots

    def no_space(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(*((campaign, "build_database") if stage == "build_database" else (plots, "make_plots")),
                        no_space)
    code = main(_one_query_campaign(query_file, tmp_path / "out"))
    (folder,) = (tmp_path / "out").iterdir()
    err = capsys.readouterr().err
    where = "the database" if stage == "build_database" else "the plots"
    assert code == 1 and err.count("\n") == 1 and "Traceback" not in err
    assert f"{where} " in err and "No space left on device" in err and f"--resume {folder}" in err
    assert json.loads((folder / "campaign.json").read_text())["interrupted"] is True
    monkeypatch.undo()
    (folder / ".benchmark.db.k3j9.db.part").write_text("x")  # what a process killed while writing leaves
    (folder / ".benchmark.db.k3j9.db.part-journal").write_text("x")
    (folder / "plots").mkdir(exist_ok=True)
    (folder / "plots" / ".fig15_ratios_batched.png.2een.png.part").write_text("x")
    res = resume_campaign(folder, progress_bar=False)
    assert res.database is not None and res.plots and not res.interrupted
    assert json.loads((folder / "campaign.json").read_text())["interrupted"] is False
    assert not list(folder.glob(".*part*")) and not list((folder / "plots").glob(".*"))  # (.lock stays)


def test_a_campaign_whose_first_file_cannot_be_written_leaves_no_folder_that_cannot_be_resumed(
        query_file, tmp_path, monkeypatch, capsys):
    import errno

    from tpee_ompl.bench import campaign

    def too_large(*args, **kwargs):
        raise OSError(errno.EFBIG, "File too large", "campaign.json")

    monkeypatch.setattr(campaign, "write_json", too_large)
    assert main(_one_query_campaign(query_file, tmp_path / "out")) == 1
    assert "File too large" in capsys.readouterr().err
    assert not list((tmp_path / "out").iterdir())


def _workers(pid: int) -> list[int]:
    """The spawned worker processes whose parent is ``pid`` (Linux /proc; not multiprocessing's resource tracker)."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            spawned = b"spawn_main" in (stat.parent / "cmdline").read_bytes()
        except OSError:
            continue
        if int(fields[1]) == pid and spawned:
            out.append(int(stat.parent.name))
    return out


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and PR_SET_PDEATHSIG are Linux's")
def test_a_worker_whose_campaign_is_killed_while_it_starts_exits_without_running_its_task(query_file, tmp_path):
    """A worker asked to die with its parent only after its imports (~1 s): a SIGKILL of the campaign in that
    window left it running its whole task and writing logs into a campaign no one ran any more."""
    proc = _launch(query_file, tmp_path)
    try:
        _wait_for(lambda: _workers(proc.pid))
        workers = _workers(proc.pid)
        proc.kill()  # while the worker still imports
        proc.wait(timeout=60)
        _wait_for(lambda: not any(Path(f"/proc/{w}").exists() for w in workers), timeout=120)
    finally:
        proc.kill()
    (directory,) = tmp_path.glob("*_sig")
    assert not list((directory / "logs").glob("*.log"))  # the orphan ran nothing


@pytest.mark.parametrize("when", ["versions", "folder"])
def test_an_interrupt_as_the_campaign_starts_leaves_no_folder_and_says_nothing_was_written(
        query_file, tmp_path, monkeypatch, capsys, when):
    """A SIGTERM in the ~40 ms the package versions take to read (after the folder was made, before the cleanup's
    try) left an empty folder that --resume refused ("no campaign.json there"), and the message said "--resume DIR"."""
    import tpee_ompl.bench.campaign as campaign

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(campaign, "package_versions" if when == "versions" else "write_json", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_campaign(tiny_config(query_file, tmp_path / "a"), report=False, progress_bar=False)
    assert not (tmp_path / "a").exists() or not any((tmp_path / "a").iterdir())
    code = main(["--queries", str(query_file), "--samples", "30", "--planners", STANDIN, "RRTstar", "--workers", "1",
                 "--out", str(tmp_path / "b"), "--no-progress"])
    assert code == 130 and "interrupted before the campaign started; nothing was written" in capsys.readouterr().err
    assert not (tmp_path / "b").exists() or not any((tmp_path / "b").iterdir())
