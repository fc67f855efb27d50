"""OMPL's recorded experiment data, patched before saving; and the Planner-Arena database built from logs.

After ``Benchmark.benchmark()`` and before ``saveResultsToFile``, :func:`patch_recorded_data` writes
each run's post-run record (``best_cost``, ``iterations``, ``samples``, ``collision_checks``,
``length_dof12``, ``length_dof34``, ``path_valid_dense``, ``first_solution_time``, ...) into the
runs, the wrapped planner's settings into the planner's common properties and the recorded progress
into the progress data; :func:`pad_aborted_runs` adds a failed run for each run an aborted
``benchmark()`` never finished.

:func:`build_database` turns the ``.log`` files into one SQLite database with
``ompl.tools.readBenchmarkLog``/``computeViews`` (what ``ompl_benchmark_statistics`` runs),
skipping corrupt logs by name.
"""

from __future__ import annotations

import builtins
import contextlib
import io
import logging
import os
import re
import sqlite3
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

from ompl import base as ob
from ompl import tools as ot

from .config import PROGRESS_PROPERTIES
from .planners import planner_settings
from .results import format_value, planner_name

__all__ = ["NO_PATH_COLUMNS", "SOLUTION_KEYS", "build_database", "check_log", "failed_run_properties", "log_text",
           "pad_aborted_runs", "patch_recorded_data", "progress_rows", "set_aside_broken_logs"]

log = logging.getLogger(__name__)


NO_PATH_COLUMNS = {"best_cost REAL": None, "length_dof12 REAL": None, "length_dof34 REAL": None, "raw_length REAL": None,
                   "path_valid_dense INTEGER": None, "reaches_goal INTEGER": 0}
"""The path columns of a run before its path is read (NULL; ``path_valid_dense`` 0 would be a path that failed)."""


def failed_run_properties(error: str) -> dict:
    """The extra run properties of a run that failed with ``error`` (a planner or callback exception)."""
    return {"planner_error INTEGER": 1, "path_valid_dense INTEGER": None, "reaches_goal INTEGER": 0,
            "error_message TEXT": error[:200].replace("\n", " ").replace(";", ",")}


def pad_aborted_runs(bench: ot.Benchmark, records: dict, run_count: int, error: str) -> None:
    """After an aborted ``benchmark()``: add a failed run (status *crash*) for every run that never finished."""
    crash = str(ob.PlannerStatus.CRASH.value)
    for pl in bench.getRecordedExperimentData().planners:
        recs = records.setdefault(planner_name(pl.name), [])
        runs = list(pl.runs)
        del recs[len(runs):]  # a record whose run was not stored (the abort came after the post-run event)
        while len(runs) < run_count:
            run = ot.RunProperties()
            for k, v in {"status ENUM": crash, "solved BOOLEAN": "0", "approximate solution BOOLEAN": "0",
                         "correct solution BOOLEAN": "0", "time REAL": "0", "memory REAL": "0"}.items():
                run[k] = v
            runs.append(run)
            recs.append({"props": failed_run_properties(error), "progress": []})
        pl.runs = runs


PER_QUERY_SETTINGS = ("seed", "pair")
"""Planner settings that change from query to query (the seed, the sector pair).  Kept out of the planner's
configuration, so one planner has one configuration across queries: the pair is in the ``experiments`` table's
query columns, and a planner's seed is ``sub_seed(campaign seed, query position, planner's index in the
comparison, cap or budget in ms)`` (:func:`tpee_ompl.validation.sub_seed`; the campaign seed is in
``campaign.json``, and the experiments table's ``process_seed`` is the campaign seed plus the query position)."""


SAMPLED_SPACE_SETTINGS = ("projection.cellsize",)
"""OMPL's recorded space settings estimated by random sampling at each set-up (the default projection's
cell sizes): they differ from experiment to experiment and would split one planner's configuration."""


SOLUTION_KEYS = ("approximate solution", "solution ", "correct solution", "simplif")
"""Prefixes of OMPL's run columns written only when the run has a path."""


def patch_recorded_data(bench: ot.Benchmark, wrappers: dict, records: dict, cap: int | None,
                        seed: int | None = None) -> None:
    """Write the post-run records into the recorded experiment data (in place, before saving).

    ``seed``: the experiment's process seed, written as OMPL's recorded ``seed`` (OMPL keeps the seed set last
    before its first random draw: with a set-up that draws nothing, a planner's own seed, set as it was made).

    ``wrappers``: planner name -> its :class:`~tpee_ompl.bench.planners.RecordingPlanner`;
    ``records``: planner name -> one ``{"props": {column: value}, "progress": [(t, cost, n)]}`` per run.
    A run OMPL counts as solved whose path stops short of the goal (``reaches_goal`` 0) is written unsolved.
    """
    data = bench.getRecordedExperimentData()
    if seed is not None:
        data.seed = int(seed)
    for pl in data.planners:
        name = planner_name(pl.name)
        recs = records.get(name, [])
        runs = list(pl.runs)
        for i, (run, rec) in enumerate(zip(runs, recs)):
            for k, v in rec["props"].items():
                run[k] = format_value(v)
            if rec["props"].get("reaches_goal INTEGER") == 0 and run.to_dict().get("solved BOOLEAN") == "1":
                runs[i] = _unsolved(run)
        pl.runs = runs
        settings = planner_settings(wrappers[name].inner)
        for k in PER_QUERY_SETTINGS:  # per query, not per planner: in the experiments table and the runs
            settings.pop(k, None)
        common = ot.RunProperties()
        for k, v in pl.common.to_dict().items():
            if not k.startswith(SAMPLED_SPACE_SETTINGS):
                common[k] = v
        pl.common = common
        for k, v in settings.items():
            pl.common[f"planner.{k}"] = v
        pl.common["iteration_cap"] = str(cap) if cap is not None else "none"
        pl.common["wrapper"] = "RecordingPlanner"
        pl.progressPropertyNames = list(PROGRESS_PROPERTIES)
        pl.runsProgressData = [progress_rows(rec["progress"]) for rec in recs]


def _unsolved(run: ot.RunProperties) -> ot.RunProperties:
    """``run`` as a run without a solution: solved 0, no solution columns (NULL).  OMPL records a planner's
    answer that stops short of the goal as solved when the planner calls it exact: AORRTC's start state alone
    with status *invalid goal* (ompl/ompl#1420), solved 1 with length 0, which Planner Arena and OMPL's
    ``bestPlannerConfigs`` would rank best."""
    out = ot.RunProperties()
    for k, v in run.to_dict().items():
        if not k.startswith(SOLUTION_KEYS):
            out[k] = v
    out["solved BOOLEAN"] = "0"
    return out


def progress_rows(progress: Sequence[tuple[float, float, int | None]]) -> list[dict[str, str]]:
    """A run's progress [(time, best cost, iterations), ...] as the rows of OMPL's recorded progress data
    (:data:`~tpee_ompl.bench.config.PROGRESS_PROPERTIES`), one per printed time (the last entry at each)."""
    return [{"best cost REAL": format_value(c), "iterations INTEGER": format_value(n), "time REAL": format_value(t)}
            for t, c, n in _dedupe_times(progress)]


def log_text(bench: ot.Benchmark) -> str:
    """The OMPL log of the benchmark's recorded data, as text (``saveResultsToFile`` into a temporary folder)."""
    with tempfile.TemporaryDirectory(prefix="tpee_log_") as tmp:
        path = Path(tmp) / "experiment.log"
        bench.saveResultsToFile(str(path))
        return path.read_text()


def _dedupe_times(progress: Sequence[tuple[float, float, int]]) -> list[tuple[float, float, int]]:
    """Keep the last entry per printed time (the progress table's key is (runid, time))."""
    out: dict[str, tuple[float, float, int]] = {}
    for t, c, n in progress:
        out[format_value(float(t))] = (float(t), float(c), None if n is None else int(n))
    return sorted(out.values())


def check_log(path: os.PathLike) -> str | None:
    """Why the OMPL ``.log`` at ``path`` is unreadable (truncated, corrupt), or None when OMPL's reader takes it.

    The log is parsed with ``ompl.tools.readBenchmarkLog`` into an in-memory database, the way
    :func:`build_database` reads it.
    """
    try:
        with contextlib.redirect_stdout(io.StringIO()), _eof_guard(ot.readBenchmarkLog):  # it prints per planner
            if not Path(path).read_text().rstrip().endswith("\n."):  # every planner block ends with "."
                raise ValueError("truncated (no final '.')")
            ot.readBenchmarkLog(":memory:", [str(path)], False)
    except Exception as exc:  # noqa: BLE001 (any parse error: the file is corrupt)
        return f"{type(exc).__name__}: {exc}"
    return None


def set_aside_broken_logs(log_dir: os.PathLike) -> list[tuple[Path, str]]:
    """Move every unreadable ``*.log`` of ``log_dir`` to ``log_dir/broken/`` (never deleted); return (new path, reason)."""
    log_dir = Path(log_dir)
    moved = []
    for p in sorted(log_dir.glob("*.log")):
        reason = check_log(p)
        if reason is None:
            continue
        broken = log_dir / "broken"
        broken.mkdir(exist_ok=True)
        target = broken / p.name
        k = 1
        while target.exists():
            target, k = broken / f"{p.stem}.{k}{p.suffix}", k + 1
        os.replace(p, target)
        log.warning("log %s is unreadable (%s): moved aside to %s", p.name, reason, target)
        moved.append((target, reason))
    return moved


def build_database(logs: Sequence[os.PathLike], db_path: os.PathLike) -> tuple[Path | None, list[Path]]:
    """Build a Planner Arena SQLite database from OMPL ``.log`` files (ompl_benchmark_statistics).

    Each log is first checked on its own (:func:`check_log`); a log that fails is reported by name
    and skipped.  The database is written to a temporary file beside ``db_path`` and moved over it
    only when complete (:func:`tpee_ompl.files.atomic_path`), so an interruption never leaves a
    half-written database.  Returns the database (None when no log was readable) and the skipped logs.
    """
    from ..files import atomic_path

    db_path = Path(db_path)
    good, bad = [], []
    for p in logs:
        reason = check_log(p)
        if reason is None:
            good.append(Path(p))
        else:
            log.error("skipping corrupt log %s: %s", Path(p).name, reason)
            bad.append(Path(p))
    if not good:
        return None, bad
    with atomic_path(db_path) as tmp, contextlib.redirect_stdout(io.StringIO()), \
            tempfile.TemporaryDirectory(prefix="tpee_logs_") as folder:
        tmp.unlink()  # readBenchmarkLog creates the database itself
        ot.readBenchmarkLog(str(tmp), [str(_in_current_format(p, Path(folder))) for p in good], False)
        ot.computeViews(str(tmp), False)
        _parameters_on_progress_rows(tmp)
    return db_path, bad


_QUERY_SET = re.compile(r"^query_set TEXT = (.*)$", re.MULTILINE)
_OLD_QUERY_ID = re.compile(r"^query_id TEXT = ", re.MULTILINE)


def _without_query_in_name(text: str) -> str:
    """``text`` with an experiment name of the earlier format (``<comparison>_<query set>_qNNN_<setting>_...``) in
    today's; a query set whose own name ends in ``_qNNN`` is told apart by the log's ``query_set`` parameter."""
    qs = _QUERY_SET.search(text)
    if qs is None:
        return text
    old = re.compile(rf"^(Experiment [a-z]+_{re.escape(qs.group(1))})_q\d{{3}}(_(?:N\d+|T\S+s)_\S+)$", re.MULTILINE)
    return old.sub(r"\1\2", text, count=1)


def _in_current_format(path: Path, folder: Path) -> Path:
    """``path``, or for a log written before 2026-11-26 (a resumed campaign's) a copy in ``folder`` in today's format.

    Those logs named the experiment after its query (``..._q007_N500_batched``) and wrote ``query_id`` as TEXT.
    OMPL's reader types a parameter's column by the first log that has it, so one such log first would make
    ``query_id`` text for the whole database, and Planner Arena fails on a numeric-looking text parameter."""
    text = path.read_text()
    new = _OLD_QUERY_ID.sub("query_id INTEGER = ", _without_query_in_name(text), count=1)
    if new == text:
        return path
    copy = folder / f"{len(list(folder.iterdir()))}_{path.name}"
    copy.write_text(new)
    return copy


OMPL_EXPERIMENT_COLUMNS = ("id", "name", "totaltime", "timelimit", "memorylimit", "runcount", "version", "hostname",
                           "cpuinfo", "date", "seed", "setup")
"""The ``experiments`` table's own columns; the others are the experiment parameters."""


def _parameters_on_progress_rows(db: Path) -> None:
    """Repeat each run's experiment parameters on its ``progress`` rows (one UPDATE, declared types kept).

    Planner Arena (1.0.1) filters the progress rows by every experiment parameter, as it does the runs, but
    joins them with the runs' id and planner only: without the parameters there, its progress tab fails on
    any database with experiment parameters (``ColumnNotFoundError``)."""
    con = sqlite3.connect(str(db))
    try:
        have = {r[1] for r in con.execute("PRAGMA table_info(progress)")}
        params = [(r[1], r[2]) for r in con.execute("PRAGMA table_info(experiments)")
                  if r[1] not in OMPL_EXPERIMENT_COLUMNS and r[1] not in have]
        if not params:
            return
        for name, kind in params:
            con.execute(f'ALTER TABLE progress ADD COLUMN "{name}" {kind}')
        names = ", ".join(f'"{n}"' for n, _ in params)
        values = ", ".join(f'experiments."{n}"' for n, _ in params)
        con.execute(f"UPDATE progress SET ({names}) = (SELECT {values} FROM runs JOIN experiments "
                    "ON runs.experimentid = experiments.id WHERE runs.id = progress.runid)")
        con.commit()
    finally:
        con.close()


class _EofGuardedFile:
    """A text file whose ``readline`` raises after many reads at end of file.

    OMPL's ``readBenchmarkLog`` loops forever on some truncated logs (it keeps reading ``''``).
    """

    def __init__(self, f, limit: int = 1000) -> None:
        self._f, self._limit, self._eof_reads = f, limit, 0

    def readline(self, *args) -> str:
        line = self._f.readline(*args)
        if line == "":
            self._eof_reads += 1
            if self._eof_reads > self._limit:
                raise ValueError(f"unexpected end of file in {self._f.name}")
        return line

    def __getattr__(self, name: str):
        return getattr(self._f, name)

    def __iter__(self):
        return iter(self._f)


@contextlib.contextmanager
def _eof_guard(reader: Callable):
    """Within the block, files opened by ``reader``'s module are :class:`_EofGuardedFile`."""
    mod = sys.modules[reader.__module__]
    had = "open" in vars(mod)
    previous = vars(mod).get("open")
    mod.open = lambda *a, **k: _EofGuardedFile(builtins.open(*a, **k))
    try:
        yield
    finally:
        if had:
            mod.open = previous
        else:
            del mod.open
