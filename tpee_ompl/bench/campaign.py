"""Benchmark campaigns: dimension-RRT against OMPL's planners through ``ompl.tools.Benchmark``.

Orchestration only: choose the queries, make the results folder, hand one task per query to an
executor (:mod:`tpee_ompl.bench.executors`), store the logs as they come back, then build the
database (:mod:`tpee_ompl.bench.database`), the report and the plots.  Ctrl-C or SIGTERM stops a
campaign cleanly and :func:`resume_campaign` finishes it later.

Where the rest lives:

* :mod:`tpee_ompl.bench.config`: :class:`~tpee_ompl.bench.config.CampaignConfig`, the names, and
  :func:`~tpee_ompl.bench.config.load_campaign` (a folder's saved configuration, checked for a resume);
* :mod:`tpee_ompl.bench.planners`: planner factories and the recording wrapper;
* :mod:`tpee_ompl.bench.experiment`: one query's experiments (in a worker process);
* :mod:`tpee_ompl.bench.database`: patching the recorded data, the SQLite database;
* :mod:`tpee_ompl.bench.results`: results folders and files that never overwrite anything;
* :mod:`tpee_ompl.cli.bench`: the command line (``experiments/run_benchmark.py``, ``tpee-ompl bench``).

``solution_length`` in the database is the raw planner output (OMPL's default ``simplify=True``
only adds the ``simplified_*`` columns); the report uses the raw length, like the paper.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import os
import shutil
import socket
import sqlite3
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from .config import CampaignConfig, CampaignResult, default_workers, load_campaign
from .database import build_database, set_aside_broken_logs
from .experiment import experiment_specs, log_name, run_query_task
from ..files import check_writable_folder, write_new_file
from ..signals import interrupts, sigterm_as_keyboard_interrupt
from .._version import code_version
from .results import append_json_line, make_results_dir, package_versions, utc_now, write_json

if TYPE_CHECKING:  # hints only: the model imports pinocchio, the executors are imported when a campaign runs
    from ..model.wearer_arm import WearerArm
    from .executors import CampaignExecutor

__all__ = ["CampaignPlan", "load_campaign", "prepare_campaign", "query_rows", "resume_campaign", "run_campaign",
           "stratified_subset"]

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- queries
def query_rows(name_or_path: str, robot: WearerArm | None = None) -> tuple[str, list[dict]]:
    """The query set's name and its queries as plain (picklable, JSON-able) dicts.

    Each row: ``id``, ``from_sector``, ``to_sector``, ``start``, ``goal`` (lists of floats).  The set
    is read by :func:`tpee_ompl.model.queries.load_query_set` (a packaged name or a JSON file; with
    ``robot``, a set made for another model is refused); its name is the file's ``name`` field,
    else the file's stem.
    """
    from ..model.queries import load_query_set

    queries, header = load_query_set(name_or_path, robot)
    rows = [
        {
            "id": q.id,
            "from_sector": int(q.from_sector),
            "to_sector": int(q.to_sector),
            "start": [float(x) for x in q.start],
            "goal": [float(x) for x in q.goal],
        }
        for q in queries
    ]
    name = header.get("name")
    return name if isinstance(name, str) and name else Path(name_or_path).stem, rows


def stratified_subset(queries: list[dict], k: int | None) -> list[dict]:
    """All queries reordered round-robin over (from, to) sector pairs (if they have them), then the first k.

    The first k of a set ordered pair by pair would cover only a few pairs; round-robin keeps every
    pair represented (24 of the 120 planning-necessary queries = 2 per ordered pair).
    """
    from ..validation import check_int

    k = check_int("max_queries", k, minimum=1, optional=True)
    groups: dict[tuple[int, int], list[dict]] = {}
    for q in queries:  # problems without sectors: one group, the set's order
        groups.setdefault((q.get("from_sector"), q.get("to_sector")), []).append(q)
    out: list[dict] = []
    lists = list(groups.values())
    for i in range(max((len(g) for g in lists), default=0)):
        out += [g[i] for g in lists if i < len(g)]
    return out if k is None else out[:k]


# --------------------------------------------------------------------------- campaign
class CampaignInterrupted(KeyboardInterrupt):
    """A second interrupt (Ctrl-C, SIGTERM) while the database was built from the finished logs: ``directory``
    is the campaign to finish with ``--resume``."""

    def __init__(self, directory: Path) -> None:
        super().__init__(str(directory))
        self.directory = directory


@contextlib.contextmanager
def _campaign_lock(directory: Path):
    """Hold ``directory/.lock`` for the block: a second process running the same campaign (two ``--resume``
    at once) is refused with ValueError instead of writing the same logs and ``tasks.jsonl`` lines twice."""
    import fcntl

    with open(directory / ".lock", "a") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise ValueError(f"campaign {directory} is being run by another process (its .lock is held)") from None
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


@dataclasses.dataclass(frozen=True)
class CampaignPlan:
    """A checked campaign, ready to run: the query set's name and the queries it will use."""

    config: CampaignConfig
    query_set: str
    queries: list[dict]


def prepare_campaign(config: CampaignConfig) -> CampaignPlan:
    """Check everything a campaign needs before anything is created; raise ValueError/FileNotFoundError if not.

    The problem's query set loads and was made for its model (``model_hash``), every planner factory
    imports, query k's seed ``seed + k`` stays in OMPL's range, and ``out`` can hold a new folder.
    """
    from ..validation import MAX_SEED
    from .planners import planner_factory
    from .problems import get_problem

    check_writable_folder(config.out, "out")
    for field_name in ("iteration_planners", "anytime_planners"):
        for name in getattr(config, field_name):
            try:
                planner_factory(name)
            except ValueError as exc:
                raise ValueError(f"{field_name}: {exc}") from None
    problem = get_problem(config.problem)
    what = config.queries or problem.default_queries or problem.name
    try:
        set_name, queries = problem.queries(config.queries)
    except ImportError as exc:  # a robot-checker problem whose model this install lacks
        raise ValueError(str(exc)) from None
    except (OSError, ValueError) as exc:  # missing, unreadable, not a query set, made for another model
        from ..model.queries import QuerySetError

        msg = str(exc).removeprefix(f"{what}: ")
        kind = QuerySetError if isinstance(exc, QuerySetError) else ValueError  # damaged: a runtime error to the CLI
        raise kind(msg if msg.startswith("queries") else f"queries {what}: {msg}") from None
    queries = stratified_subset(queries, config.max_queries)
    if not queries:
        raise ValueError(f"query set {what!r} has no queries")
    if config.max_queries is not None and len(queries) < config.max_queries:
        log.warning("query set %s has %d queries: all of them run (max_queries %d)", what, len(queries),
                    config.max_queries)
    if config.seed + len(queries) - 1 > MAX_SEED:
        raise ValueError(f"seed {config.seed}: query k uses seed + k, which must stay <= {MAX_SEED} "
                         f"for {len(queries)} queries")
    return CampaignPlan(config, set_name, queries)


def run_campaign(
    config: CampaignConfig,
    *,
    on_task_done: Callable[[list[str]], None] | None = None,
    report: bool = True,
    progress_bar: bool = True,
    executor: CampaignExecutor | None = None,
    plan: CampaignPlan | None = None,
) -> CampaignResult:
    """Run a campaign into a new timestamped folder, build the DB, the report and the plots.

    The campaign is checked first (:func:`prepare_campaign`, or the given ``plan``): a bad one
    raises before anything is created.  ``executor`` (:mod:`tpee_ompl.bench.executors`) runs the
    per-query tasks; default: a local pool of ``config.workers`` processes (0 = this process).
    ``on_task_done`` is called in this process with each finished query's log paths.  Ctrl-C or
    SIGTERM (or a KeyboardInterrupt from ``on_task_done``) stops the campaign: finished logs are
    kept, the database is still built from them, and :func:`resume_campaign` runs the rest later.
    A query whose worker died twice is listed in ``CampaignResult.failed_tasks``.
    """
    plan = plan if plan is not None else prepare_campaign(config)
    if plan.config != config:
        raise ValueError("plan was prepared for another configuration")
    with sigterm_as_keyboard_interrupt():
        return _run_campaign(plan, on_task_done, report, progress_bar, executor)


def _run_campaign(plan: CampaignPlan, on_task_done, report: bool, progress_bar: bool, executor) -> CampaignResult:
    config, queries = plan.config, plan.queries
    cfg = dataclasses.asdict(config)
    meta = {
        "config": cfg,
        "problem": config.problem,
        "query_set": plan.query_set,
        "queries": [q["id"] for q in queries],
        "query_data": queries,
        "expected_experiments": sum(len(experiment_specs(cfg, k)) for k in range(len(queries))),
        "seed": config.seed,
        "process_seeds": {str(q["id"]): config.seed + k for k, q in enumerate(queries)},
        "versions": package_versions(),
        "hostname": socket.gethostname(),
        "cpu_count": os.cpu_count(),
        "command": sys.argv,
        "started_utc": utc_now(),
        "interrupted": True,  # until the campaign ends (a killed campaign stays marked)
    }
    directory = None  # (the folder is made last, and within the try: an interrupt in the ~40 ms the versions take
    # to read came between them and left an empty folder that --resume refused)
    try:
        directory = make_results_dir(config.out, config.name)
        (directory / "logs").mkdir()
        write_json(directory / "campaign.json", meta)
    except BaseException:  # a folder without campaign.json could not be resumed: leave none
        if directory is not None:
            shutil.rmtree(directory, ignore_errors=True)
        raise
    return _execute(directory, meta, executor, on_task_done, report, progress_bar, int(config.workers))


def resume_campaign(
    directory: str | os.PathLike,
    *,
    executor: CampaignExecutor | None = None,
    workers: int | None = None,
    on_task_done: Callable[[list[str]], None] | None = None,
    report: bool = True,
    progress_bar: bool = True,
) -> CampaignResult:
    """Run only the experiments of an interrupted campaign that have no log yet, into its folder.

    Finished logs are kept; a log that OMPL's reader cannot read (truncated, corrupt) is moved to
    ``logs/broken/`` and its experiment runs again.  The database and report are rebuilt from all logs.  The
    configuration and queries come from the folder's ``campaign.json``; ``workers`` sets this resume's
    pool size (default: the campaign's; ``campaign.json``'s ``resumes`` records each resume's count and executor,
    its ``config`` keeps the campaign's own).  A query resumed part-way runs its missing experiments in a fresh
    process with the planners' own seeds (a ladder with a missing member runs whole), so iteration-capped rows are
    those of an uninterrupted campaign.
    """
    directory = Path(directory)
    meta = load_campaign(directory)
    if workers is not None:  # this resume's; the configuration keeps the count the campaign ran with
        from ..validation import check_int

        workers = check_int("workers", workers, minimum=0)
    else:
        workers = int(meta["config"].get("workers", default_workers()))  # older campaign.json: the default
    meta.setdefault("resumes", []).append({"utc": utc_now(), "workers": workers})
    (directory / "logs").mkdir(exist_ok=True)
    return _execute(directory, meta, executor, on_task_done, report, progress_bar, workers)


def task_time_limit(cfg: dict, specs: list[dict]) -> float:
    """A query task's safety time limit (s): twice the sum of its runs' time limits, plus 300 s.

    Only a hung worker reaches it (each run is stopped by OMPL at its own limit); the executor then
    kills the worker and treats the task as lost.
    """
    total = 0.0
    for s in specs:
        planners = cfg["iteration_planners"] if s["comparison"] == "iterations" else cfg["anytime_planners"]
        limit = float(cfg["max_time"]) if s["cap"] is not None else float(s["budget"])
        total += len(planners) * int(cfg["runs"]) * limit
    return 2.0 * total + 300.0


def _tasks(meta: dict, log_dir: Path, done_names: set[str], n_threads, shared_fs: bool) -> list[dict]:
    """One task per query that still has experiments without a log."""
    cfg = meta["config"]
    tasks = []
    for k, q in enumerate(meta["query_data"]):
        specs = [s for s in experiment_specs(cfg, k) if log_name(q, k, s) not in done_names]
        if specs:
            tasks.append({"config": cfg, "query": q, "qpos": k, "query_set": meta["query_set"], "code_version": code_version(),
                          "seed": cfg["seed"] + k, "specs": specs, "n_threads": n_threads,
                          "log_dir": str(log_dir) if shared_fs else None, "time_limit_s": task_time_limit(cfg, specs),
                          "sys_path": [p for p in sys.path if p]})
    return tasks


def _execute(directory: Path, meta: dict, executor, on_task_done, report: bool, progress_bar: bool,
             workers: int) -> CampaignResult:
    with _campaign_lock(directory):
        return _execute_locked(directory, meta, executor, on_task_done, report, progress_bar, workers)


def _execute_locked(directory: Path, meta: dict, executor, on_task_done, report: bool, show_progress: bool,
                    workers: int) -> CampaignResult:
    cfg = meta["config"]
    log_dir = directory / "logs"
    interrupted = False
    failed: list[dict] = []
    broken: list[tuple[Path, str]] = []
    t0 = time.perf_counter()
    with sigterm_as_keyboard_interrupt():
        try:
            from ..progress import progress_bar
            from .executors import make_executor, run_task_in_subprocess

            for part in log_dir.glob("*.part"):  # left by a process killed while writing
                part.unlink()
            broken = set_aside_broken_logs(log_dir)
            if broken:
                meta.setdefault("broken_logs", []).extend(
                    {"log": p.name, "moved_to": str(p.relative_to(directory)), "reason": r, "utc": utc_now()}
                    for p, r in broken)
            done_names = {p.name for p in log_dir.glob("*.log")}
            executor = executor if executor is not None else make_executor(workers)
            in_process = not getattr(executor, "fresh_process_per_task", True)
            shared_fs = getattr(executor, "shares_filesystem", True)
            n_threads = None if in_process or workers == 1 and shared_fs else 1
            tasks = _tasks(meta, log_dir, done_names, n_threads, shared_fs)
            fn = run_query_task if shared_fs else run_task_in_subprocess
            if meta.get("resumes") and "executor" in meta:  # the campaign's own executor stays on record
                meta["resumes"][-1]["executor"] = executor.description
            else:
                meta["executor"] = executor.description
            log.info("campaign %s: %d queries, %d experiments (%d to run) on %s", directory, len(meta["query_data"]),
                     meta["expected_experiments"], sum(len(t["specs"]) for t in tasks), executor.description)
            with progress_bar(total=len(tasks), desc=f"{cfg['name']} queries", unit="query",
                              enabled=show_progress) as bar:
                for res in executor.run(fn, tasks):
                    written = _store_task_result(directory, res)
                    if res.get("failed"):
                        failed.append(_failure_entry(meta, log_dir, res))
                    bar.update(1)
                    if on_task_done:
                        on_task_done(written)
            executor.shutdown()
        except KeyboardInterrupt:
            interrupted = True
            log.warning("interrupted: building the database from the finished logs")
        finally:
            if executor is not None:
                try:
                    executor.shutdown(cancel=True)
                except KeyboardInterrupt as exc:  # a second interrupt: say which campaign to resume
                    raise CampaignInterrupted(directory) from exc
        seen = interrupts()
        try:
            result = _finish(directory, meta, executor, failed, broken, interrupted, report, time.perf_counter() - t0)
        except KeyboardInterrupt as exc:  # a second interrupt: say which campaign to resume
            _mark_interrupted(directory, meta)
            raise CampaignInterrupted(directory) from exc
        if interrupts() > seen:  # one whose KeyboardInterrupt Python dropped (raised in matplotlib's weakref callbacks)
            _mark_interrupted(directory, meta)
            raise CampaignInterrupted(directory)
        return result


def _mark_interrupted(directory: Path, meta: dict) -> None:
    """Say in ``campaign.json`` that the campaign was interrupted while its database, report or plots were made
    (``--resume`` makes them again)."""
    meta["interrupted"] = True
    with contextlib.suppress(OSError):
        write_json(directory / "campaign.json", meta)


class CampaignOutputError(RuntimeError):
    """The campaign's experiments ran, but its database, report or plots could not be written (a full disk,
    a file-size limit): its logs are kept, ``campaign.json`` says it did not finish, ``--resume`` makes them."""

    def __init__(self, directory: Path, what: str, exc: BaseException) -> None:
        self.directory = directory
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        super().__init__(f"{what} not written ({reason}); the experiments' logs are kept: make it with --resume "
                         f"{directory}")


def _finish(directory: Path, meta: dict, executor, failed: list[dict], broken: list, interrupted: bool, report: bool,
            wall_time: float) -> CampaignResult:
    """After the tasks: the database from the finished logs, ``campaign.json``, the report and the plots
    (:class:`CampaignOutputError` when one cannot be written)."""
    log_dir = directory / "logs"
    for part in log_dir.glob("*.part"):
        part.unlink()
    for part in (*directory.glob(".*.part*"), *directory.glob("plots/.*.part*")):  # of a process killed writing
        part.unlink(missing_ok=True)
    ours = {log_name(q, k, spec) for k, q in enumerate(meta["query_data"])
            for spec in experiment_specs(meta["config"], k)}
    logs = sorted(p for p in log_dir.glob("*.log") if p.name in ours)
    strays = sorted(p.name for p in log_dir.glob("*.log") if p.name not in ours)
    if strays:  # another campaign's, or one of this campaign's settings before its campaign.json was edited
        log.warning("%d log(s) in %s are none of this campaign's experiments, left out of the database: %s",
                    len(strays), log_dir, ", ".join(strays[:5]) + (", ..." if len(strays) > 5 else ""))
    meta["stray_logs"] = strays
    lost_attempts = list(getattr(executor, "lost", []) or [])
    if lost_attempts:
        meta.setdefault("lost_attempts", []).extend({**a, "utc": utc_now()} for a in lost_attempts)
    spent = meta.get("wall_time_s")  # a resume adds its time to the campaign's
    meta.update({"finished_utc": utc_now(), "interrupted": interrupted, "failed_tasks": failed,
                 "finished_experiments": len(logs),
                 "wall_time_s": wall_time + (float(spent) if isinstance(spent, (int, float)) and spent >= 0 else 0.0)})
    result = CampaignResult(directory=directory, logs=logs, database=None, interrupted=interrupted,
                            failed_tasks=failed, broken_logs=[p for p, _ in broken])
    what = f"the database {directory / 'benchmark.db'}"
    try:
        if logs:
            result.database, result.skipped_logs = build_database(logs, directory / "benchmark.db")
            meta["corrupt_logs"] = [p.name for p in result.skipped_logs]
        if result.database is not None and report:
            from . import plots
            from . import report as rep

            what = f"the report in {directory}"
            result.report = rep.write_report(result.database, directory, expected=meta)
            what = f"the plots in {directory / 'plots'}"
            result.plots = plots.make_plots(result.database, directory / "plots", result.report["planner"],
                                            result.report["reference"])  # the planners the report compared
        what = f"{directory / 'campaign.json'}"
        write_json(directory / "campaign.json", meta)  # last: it says the campaign finished
    except (OSError, sqlite3.Error) as exc:
        _mark_interrupted(directory, meta)
        raise CampaignOutputError(directory, what, exc) from exc
    return result


def _failure_entry(meta: dict, log_dir: Path, res: dict) -> dict:
    """``campaign.json``'s record of a query the executor could not finish: reason and the logs it lacks."""
    k = int(res["qpos"])
    q = meta["query_data"][k]
    missing = [n for n in (log_name(q, k, s) for s in experiment_specs(meta["config"], k)) if not (log_dir / n).is_file()]
    log.info("query %s (position %d) lost after %d attempts (%s): %d experiment(s) have no log",
              q["id"], k, res.get("attempts", 1), res["failed"], len(missing))
    return {"qpos": k, "query_id": q["id"], "reason": res["failed"], "attempts": res.get("attempts", 1),
            "missing_logs": missing, "utc": utc_now()}


def _store_task_result(directory: Path, res: dict) -> list[str]:
    """Write a task's logs into the campaign folder (never over a different existing log); add its ``tasks.jsonl`` line."""
    log_dir = directory / "logs"
    written = []
    for fname, text in res["logs"].items():
        target = log_dir / Path(fname).name
        if not write_new_file(target, text) and target.read_text() != text:
            log.warning("%s exists with other content: kept the existing log", target.name)
        written.append(str(target))
    line = {k: res.get(k) for k in ("qpos", "query_id", "pid", "host", "elapsed", "errors")}
    if res.get("failed"):
        line.update(failed=res["failed"], attempts=res.get("attempts"))
    line["logs"] = sorted(res["logs"])
    append_json_line(directory / "tasks.jsonl", line)
    return written
