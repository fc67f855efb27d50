"""Where the tasks of a benchmark campaign run: this process, a local process pool, or Dask.

A campaign is a list of plain-data tasks (one per query, see :func:`tpee_ompl.bench.experiment.run_query_task`), each run
in a **fresh process** (a worker that dies or hangs takes nothing else with it; OMPL's seed generator is set before
each planner is made, so a task draws the same numbers whichever process or machine runs it).  The executors differ
only in who starts that process:

* :class:`InProcessExecutor`: this process, one task after the other (tests).
* :class:`ProcessPoolExecutor` (default): one fresh spawned process per task, ``workers`` at a time;
  a task whose process dies (SIGKILL, segfault, OOM killer) or outlives its time limit is run
  once more in a fresh process, then yielded as a failure (:func:`task_failure`): nothing hangs.
* :class:`DaskExecutor`: one Dask task per query on a ``distributed`` cluster (an existing
  scheduler ``tcp://host:port`` or a :class:`distributed.LocalCluster`); each Dask task runs the
  query in a fresh Python subprocess (:func:`run_task_in_subprocess`) and returns its OMPL logs as
  text plus per-run extras, so workers need no shared filesystem.  A worker that dies mid-task has
  its task rescheduled by the scheduler; ``retries`` covers tasks that raise; a task that outlives its
  time limit is run once more, then reported as failed (as in the local pool).

Every executor yields each task's result (a plain dict) exactly once, in completion order; a task
it could not finish is yielded as :func:`task_failure` (a dict with ``failed``, the reason).
"""

from __future__ import annotations

import contextlib
import json
import logging
import multiprocessing as mp
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import Protocol

from ..signals import child_sigint, die_with_parent, exit_reason, sigint_blocked_for_children

__all__ = [
    "DASK_INSTALL_HINT",
    "CampaignExecutor",
    "DaskExecutor",
    "InProcessExecutor",
    "ProcessPoolExecutor",
    "make_executor",
    "run_task_in_subprocess",
    "task_failure",
]

log = logging.getLogger(__name__)

DASK_INSTALL_HINT = ("the Dask executor needs dask.distributed: pip install 'tpee_ompl[dask]' "
                     "(or pip install 'dask[distributed]')")

TaskFn = Callable[[dict], dict]


class CampaignExecutor(Protocol):
    """Runs plain-data tasks and yields their plain-data results as they finish."""

    description: str

    def run(self, fn: TaskFn, tasks: Sequence[dict]) -> Iterator[dict]:
        """Yield ``fn(task)`` for every task, each exactly once, in completion order."""
        ...

    def shutdown(self, cancel: bool = False) -> None:
        """Release workers; ``cancel`` drops tasks not finished yet."""
        ...


class InProcessExecutor:
    """Run every task in this process, in order (no isolation: OMPL is seeded once)."""

    description = "in-process"
    fresh_process_per_task = False
    shares_filesystem = True

    def run(self, fn: TaskFn, tasks: Sequence[dict]) -> Iterator[dict]:
        """Run ``fn`` on each task here, in order; yield each result (a task that raises: :func:`task_failure`)."""
        for t in tasks:
            try:
                yield fn(t)
            except Exception as exc:  # noqa: BLE001 (recorded as the pools record it; the other queries go on)
                yield task_failure(t, f"{type(exc).__name__}: {exc}", 1)

    def shutdown(self, cancel: bool = False) -> None:
        """Nothing to release: the tasks ran in this process."""


def _child_main(fn: TaskFn, task: dict, conn, parent: int) -> None:
    """A pool child: run ``fn(task)`` and send ``("ok", result)`` or ``("error", message)`` to the parent
    (process ``parent``)."""
    child_sigint(signal.SIG_IGN)  # Ctrl-C goes to the parent, which ends us
    die_with_parent(parent)
    try:
        msg = ("ok", fn(task))
    except BaseException as exc:  # noqa: BLE001 (reported to the parent, which records the task as failed)
        msg = ("error", f"{type(exc).__name__}: {exc}")
    try:
        conn.send(msg)
    finally:
        conn.close()
    # Leave without interpreter finalisation: the result is sent and every log written, and
    # finalisation only makes the nanobind-based bindings (OMPL) list their "leaked" instances on stderr.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


def task_failure(task: dict, reason: str, attempts: int) -> dict:
    """What an executor yields for a task it could not finish: ``failed`` (the reason) and ``attempts``."""
    query = task.get("query") or {}
    return {"failed": reason, "attempts": int(attempts), "qpos": task.get("qpos"), "query_id": query.get("id"),
            "logs": {}, "extras": {}, "errors": {}}


@dataclass
class _Running:
    proc: mp.process.BaseProcess
    conn: Connection
    task: dict
    attempt: int
    deadline: float | None
    message: tuple | None = None


class ProcessPoolExecutor:
    """One fresh spawned process per task, at most ``workers`` at a time, watched until it ends.

    A task whose process dies without a result (SIGKILL, segfault, OOM killer) or outlives the
    task's ``time_limit_s`` (then it is killed) is *lost*: it is run once more in a fresh process
    (``lost_task_retries``), then yielded as a failure (:func:`task_failure`): the campaign lists it
    with the reason and goes on.  A task that raises is a failure at once (it would raise again).
    Every wait is bounded: the monitor wakes at least every ``poll`` seconds.
    """

    fresh_process_per_task = True
    shares_filesystem = True

    def __init__(self, workers: int, lost_task_retries: int = 1, poll: float = 1.0) -> None:
        from ..validation import check_int

        self.workers = check_int("workers", workers, minimum=1)
        self.lost_task_retries = check_int("lost_task_retries", lost_task_retries, minimum=0)
        self.poll = float(poll)
        self.description = f"local process pool ({self.workers} workers)"
        self.lost: list[dict] = []
        """One entry per lost attempt: ``qpos``, ``attempt``, ``reason``, ``pid``."""
        self._running: list[_Running] = []

    def _start(self, ctx, fn: TaskFn, task: dict, attempt: int) -> None:
        recv, send = ctx.Pipe(duplex=False)
        proc = ctx.Process(target=_child_main, args=(fn, task, send, os.getpid()), daemon=True)
        limit = task.get("time_limit_s")
        # a Ctrl-C now must not reach the child's imports; one held until the block ends finds it registered
        with sigint_blocked_for_children():
            proc.start()
            send.close()  # the child holds the only write end: EOF when it dies
            self._running.append(_Running(proc, recv, task, attempt,
                                          None if limit is None else time.monotonic() + float(limit)))

    def run(self, fn: TaskFn, tasks: Sequence[dict]) -> Iterator[dict]:
        """Run ``fn`` on each task in a fresh spawned process; yield each result as it finishes."""
        ctx = mp.get_context("spawn")
        queue = deque((t, 1) for t in tasks)
        try:
            while queue or self._running:
                while queue and len(self._running) < self.workers:
                    self._start(ctx, fn, *queue.popleft())
                now = time.monotonic()
                deadlines = [r.deadline - now for r in self._running if r.deadline is not None]
                timeout = max(0.0, min([self.poll, *deadlines]))
                wait([r.conn for r in self._running] + [r.proc.sentinel for r in self._running], timeout)
                for r in list(self._running):
                    out = self._check(r)
                    if out is None:
                        continue
                    self._running.remove(r)
                    if out.get("lost"):
                        reason = out["lost"]
                        self.lost.append({"qpos": r.task.get("qpos"), "attempt": r.attempt, "reason": reason,
                                          "pid": r.proc.pid})
                        if r.attempt <= self.lost_task_retries:
                            log.warning("task %s lost (%s): running it again in a fresh process",
                                        r.task.get("qpos"), reason)
                            queue.appendleft((r.task, r.attempt + 1))
                            continue
                        log.error("task %s lost again (%s): recorded as failed", r.task.get("qpos"), reason)
                        out = task_failure(r.task, reason, r.attempt)
                    yield out
        finally:
            self.shutdown(cancel=True)

    def _check(self, r: _Running) -> dict | None:
        """The finished task's result, ``{"lost": reason}``, a failure, or None while it runs."""
        if r.message is None and r.conn.poll():
            try:
                r.message = r.conn.recv()
            except (EOFError, OSError):
                r.message = ("lost", None)
        if r.message is not None and r.message[0] != "lost":
            r.proc.join(timeout=30)
            if r.proc.is_alive():
                r.proc.kill()
                r.proc.join(timeout=5)
            r.conn.close()
            kind, value = r.message
            return value if kind == "ok" else task_failure(r.task, value, r.attempt)
        timed_out = r.deadline is not None and time.monotonic() > r.deadline
        if r.proc.is_alive() and not timed_out and r.message is None:
            return None
        if r.proc.is_alive():
            r.proc.kill()
        r.proc.join(timeout=5)
        r.conn.close()
        reason = (f"no result within its time limit ({r.task.get('time_limit_s'):g} s): killed" if timed_out
                  else "worker " + exit_reason(r.proc.exitcode))
        return {"lost": reason}

    def shutdown(self, cancel: bool = False) -> None:
        """Kill the task processes still running and close their pipes (whatever ``cancel`` is)."""
        for r in self._running:
            if r.proc.is_alive():
                r.proc.kill()
        for r in self._running:
            r.proc.join(timeout=5)
            r.conn.close()
        self._running = []


# --------------------------------------------------------------------------- fresh subprocess per task
def run_task_in_subprocess(task: dict, fn_path: str = "tpee_ompl.bench.experiment:run_query_task") -> dict:
    """Run ``fn(task)`` in a fresh Python process and return its (JSON) result.

    ``task["sys_path"]`` entries that exist here are put on the child's ``sys.path`` (so planner
    factories given as ``module:function`` resolve as on the client).  Raises ``RuntimeError`` with
    the child's stderr tail when it fails (Dask's ``retries`` then run it again).  A child that gives no
    result within ``task["time_limit_s"]`` is killed and run once more in a fresh process, then the task is
    returned as a failure (:func:`task_failure`, 2 attempts) instead of raised: as a local pool treats a hung
    task, where Dask's retries would hold the campaign for three time limits.
    """
    limit = task.get("time_limit_s")
    for attempt in (1, 2):
        try:
            return _run_child(task, fn_path)
        except subprocess.TimeoutExpired:  # (subprocess.run kills the child) as the local pool does
            log.warning("task %s gave no result within its time limit (%g s): killed%s", task.get("qpos"),
                        float(limit), ", running it again in a fresh process" if attempt == 1 else "")
    return task_failure(task, f"no result within its time limit ({float(limit):g} s): killed", 2)


_TASK_DIR = "tpee_task_"
"""Prefix of a task's folder in the temporary folder, followed by the pid of the process that made it."""


def sweep_task_dirs() -> int:
    """Remove the task folders (``tpee_task_<pid>_*`` in the temporary folder) whose process is gone: a Dask worker
    killed or interrupted mid-task cannot remove its own.  Called before each task and when a Dask executor shuts
    down; returns how many were removed."""
    removed = 0
    for folder in Path(tempfile.gettempdir()).glob(f"{_TASK_DIR}*_*"):
        pid = folder.name[len(_TASK_DIR):].split("_", 1)[0]
        if pid.isdigit() and not _alive(int(pid)):
            shutil.rmtree(folder, ignore_errors=True)
            removed += 1
    return removed


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's process: alive
        return True
    return True


def _run_child(task: dict, fn_path: str) -> dict:
    """One fresh Python process running ``fn(task)``; raises ``subprocess.TimeoutExpired`` at the time limit."""
    sweep_task_dirs()
    with tempfile.TemporaryDirectory(prefix=f"{_TASK_DIR}{os.getpid()}_") as tmp:
        src, dst = Path(tmp) / "task.json", Path(tmp) / "result.json"
        src.write_text(json.dumps(task))
        env = dict(os.environ)
        extra = [p for p in task.get("sys_path", []) if p and os.path.isdir(p)]
        if extra:
            env["PYTHONPATH"] = os.pathsep.join(extra + [env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
        limit = task.get("time_limit_s")
        proc = subprocess.run(
            [sys.executable, "-m", "tpee_ompl.bench.executors", fn_path, str(src), str(dst), str(os.getpid())],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=False,
            timeout=None if limit is None else float(limit),
        )
        if proc.returncode != 0 or not dst.is_file():
            tail = "\n".join(proc.stderr.splitlines()[-20:])
            raise RuntimeError(f"task subprocess exited with {proc.returncode}:\n{tail}")
        return json.loads(dst.read_text())


def _subprocess_main(argv: Sequence[str]) -> int:
    import importlib

    fn_path, src, dst, parent = argv
    die_with_parent(int(parent))
    mod, _, attr = fn_path.partition(":")
    fn = getattr(importlib.import_module(mod), attr)
    result = fn(json.loads(Path(src).read_text()))
    tmp = Path(dst).with_suffix(".part")
    tmp.write_text(json.dumps(result))
    os.replace(tmp, dst)
    return 0


# --------------------------------------------------------------------------- Dask
def _import_distributed():
    try:
        import distributed
    except ImportError as exc:
        raise ImportError(DASK_INSTALL_HINT) from exc
    return distributed


@contextlib.contextmanager
def _quiet_dask_logs() -> Iterator[None]:
    """Dask's own lines only when the root logger shows INFO (``tpee-ompl -v``): a local cluster printed some 30
    (scheduler and workers starting, plugins, addresses) per campaign, and its workers' warnings about the tasks
    cancelled at a Ctrl-C.  A lost task is the campaign's to report (it lists them), not Dask's."""
    if logging.getLogger().isEnabledFor(logging.INFO):
        yield
        return
    # critical: a task whose process was killed is an ERROR record with a traceback ("Compute Failed")
    logging.getLogger("distributed").setLevel(logging.CRITICAL)  # back at the executor's shutdown
    key, before = "DASK_LOGGING__DISTRIBUTED", os.environ.get("DASK_LOGGING__DISTRIBUTED")
    os.environ[key] = "critical"  # the worker processes started within the block configure their logging from it
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = before


class DaskExecutor:
    """One Dask task per campaign task, each in a fresh subprocess on a worker.

    Parameters
    ----------
    scheduler : str
        ``tcp://host:port`` of a running scheduler, or ``"local"`` to start a
        ``LocalCluster(n_workers, threads_per_worker=1, processes=True)`` here.
    n_workers : int
        Workers of the local cluster (ignored for an existing scheduler).
    retries : int
        Extra attempts of a task that raises.  A task whose worker dies is rescheduled by the
        scheduler (up to ``distributed.scheduler.allowed-failures`` times) without using these.
    client : distributed.Client, optional
        Use this client (``scheduler`` is then ignored); :meth:`shutdown` leaves it open.
    """

    fresh_process_per_task = True
    shares_filesystem = False  # workers may be other machines: logs come back as text

    def __init__(self, scheduler: str = "local", n_workers: int = 2, retries: int = 2, client=None) -> None:
        distributed = _import_distributed()
        self.retries = int(retries)
        self._cluster = None
        self._own_client = client is None
        if client is not None:
            self.client = client
            self.description = f"Dask client {client.scheduler.address}"
        elif scheduler == "local":
            self._log_level = logging.getLogger("distributed").level
            with _quiet_dask_logs(), sigint_blocked_for_children():  # Ctrl-C is ours: shutdown() closes the cluster
                self._cluster = distributed.LocalCluster(n_workers=int(n_workers), threads_per_worker=1, processes=True,
                                                         dashboard_address=":0")
            self.client = distributed.Client(self._cluster)
            self.description = f"Dask LocalCluster ({n_workers} workers)"
        else:
            try:
                self.client = distributed.Client(scheduler)
            except ValueError as exc:  # a malformed address ("missing port number in address 'foo'")
                raise ValueError(f"scheduler {scheduler!r}: {exc} (give local, or tcp://host:port of a running Dask "
                                 "scheduler)") from None
            self.description = f"Dask scheduler {scheduler}"
        self._futures: list = []
        self.lost: list[dict] = []
        """One entry per time a task was given to a worker that died (``qpos``, ``attempt``, ``reason``, ``pid`` None),
        read from the scheduler's story once the tasks are done: the scheduler reruns such a task without telling the
        client, and cannot say whether it had started on that worker."""

    def _record_losses(self, task_of: dict[str, dict]) -> None:
        """Read from the scheduler's story (one call for all the tasks, the scheduler alone) how many times each task
        was under way on a worker that died, and list each time in :attr:`lost` with a warning."""
        def story(dask_scheduler, keys: list[str]) -> list[tuple]:  # (runs on the scheduler)
            return [tuple(ev) for ev in dask_scheduler.story(*keys)]

        try:
            events = self.client.run_on_scheduler(story, keys=list(task_of))
        except Exception:  # noqa: BLE001 (a diagnostic: an older scheduler, a dropped connection)
            return
        attempts: dict[str, int] = {}
        for ev in events:  # (key, start, finish, recommendations, stimulus_id, time): a dead worker's cleanup
            if len(ev) >= 5 and ev[1] == "processing" and ev[2] in ("released", "waiting") and \
                    str(ev[4]).startswith(("handle-worker-cleanup", "worker-died")):
                attempts[ev[0]] = attempts.get(ev[0], 0) + 1
                qpos = task_of[ev[0]].get("qpos")
                self.lost.append({"qpos": qpos, "attempt": attempts[ev[0]], "reason": "the Dask worker it was given "
                                  "to died (the scheduler ran it again; it may not have started there)", "pid": None})
                log.warning("task %s: the Dask worker it was given to died; the scheduler ran it again", qpos)

    def run(self, fn: TaskFn, tasks: Sequence[dict]) -> Iterator[dict]:
        """Submit one Dask task per task; yield each result as it completes."""
        import uuid

        from distributed import as_completed

        tag = uuid.uuid4().hex[:8]
        self._futures = [
            self.client.submit(fn, t, key=f"tpee-task-{tag}-{k}", pure=False, retries=self.retries)
            for k, t in enumerate(tasks)
        ]
        task_of = {fut.key: t for fut, t in zip(self._futures, tasks)}
        for fut in as_completed(self._futures):
            try:
                res = fut.result()
            except Exception as exc:  # noqa: BLE001 (raised after its retries, or KilledWorker: recorded as failed)
                log.error("Dask task %s failed: %s", fut.key, exc)
                res = task_failure(task_of[fut.key], f"{type(exc).__name__}: {exc}", self.retries + 1)
            yield res
            fut.release()
        self._record_losses(task_of)  # (as the local pool lists its lost tasks)

    def shutdown(self, cancel: bool = False) -> None:
        """Cancel unfinished tasks when ``cancel``; close the client and the local cluster this executor started."""
        with contextlib.suppress(Exception):
            if cancel and self._futures:
                self.client.cancel(self._futures)
        if self._own_client:
            with contextlib.suppress(Exception):
                self.client.close()
        if self._cluster is not None:
            with contextlib.suppress(Exception):
                self._cluster.close()
            logging.getLogger("distributed").setLevel(self._log_level)
            sweep_task_dirs()  # what its workers, stopped mid-task, left in this host's temporary folder


def make_executor(workers: int = 1, dask: str | None = None, dask_workers: int = 2,
                  retries: int = 2) -> CampaignExecutor:
    """The executor for ``--workers`` / ``--dask local`` / ``--scheduler tcp://...`` (``dask`` wins)."""
    if dask:
        return DaskExecutor(dask, n_workers=dask_workers, retries=retries)
    if workers == 0:
        return InProcessExecutor()
    return ProcessPoolExecutor(workers)


if __name__ == "__main__":
    sys.exit(_subprocess_main(sys.argv[1:]))
