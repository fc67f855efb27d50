"""Where the tasks of a benchmark campaign run: this process, a local process pool, or Dask.

A campaign is a list of plain-data tasks (one per query, see :func:`tpee_ompl.bench.experiment.run_query_task`), each run
in a **fresh process** so that ``ompl.util.RNG.setSeed`` (which works once per process) gives every
task the same seed whichever machine runs it.  The executors differ only in who starts that process:

* :class:`InProcessExecutor`: this process, one task after the other (tests; OMPL seeded once).
* :class:`ProcessPoolExecutor`: ``multiprocessing`` spawn pool, ``maxtasksperchild=1`` (default).
* :class:`DaskExecutor`: one Dask task per query on a ``distributed`` cluster (an existing
  scheduler ``tcp://host:port`` or a :class:`distributed.LocalCluster`); each Dask task runs the
  query in a fresh Python subprocess (:func:`run_task_in_subprocess`) and returns its OMPL logs as
  text plus per-run extras, so workers need no shared filesystem.  A worker that dies mid-task has
  its task rescheduled by the scheduler; ``retries`` covers tasks that raise.

Every executor yields each task's result (a plain dict) exactly once, in completion order.
"""

from __future__ import annotations

import contextlib
import json
import logging
import multiprocessing as mp
import os
import signal
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Protocol

__all__ = [
    "DASK_INSTALL_HINT",
    "CampaignExecutor",
    "DaskExecutor",
    "InProcessExecutor",
    "ProcessPoolExecutor",
    "make_executor",
    "run_task_in_subprocess",
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

    def run(self, fn: TaskFn, tasks: Sequence[dict]) -> Iterator[dict]:  # noqa: D102
        for t in tasks:
            yield fn(t)

    def shutdown(self, cancel: bool = False) -> None:  # noqa: D102
        pass


def _pool_init() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C goes to the parent, which terminates us


class ProcessPoolExecutor:
    """A spawn pool with one fresh process per task (``maxtasksperchild=1``)."""

    fresh_process_per_task = True
    shares_filesystem = True

    def __init__(self, workers: int) -> None:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        self.workers = int(workers)
        self.description = f"local process pool ({self.workers} workers)"
        self._pool = None

    def run(self, fn: TaskFn, tasks: Sequence[dict]) -> Iterator[dict]:  # noqa: D102
        ctx = mp.get_context("spawn")
        self._pool = ctx.Pool(processes=self.workers, maxtasksperchild=1, initializer=_pool_init)
        yield from self._pool.imap_unordered(fn, tasks)
        self._pool.close()
        self._pool.join()
        self._pool = None

    def shutdown(self, cancel: bool = False) -> None:  # noqa: D102
        if self._pool is not None:
            if cancel:
                self._pool.terminate()
            else:
                self._pool.close()
            self._pool.join()
            self._pool = None


# --------------------------------------------------------------------------- fresh subprocess per task
def _die_with_parent() -> None:
    """Linux: get SIGKILL when the parent (the Dask worker) dies, so no orphan keeps running."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):
            import ctypes

            ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def run_task_in_subprocess(task: dict, fn_path: str = "tpee_ompl.bench.experiment:run_query_task") -> dict:
    """Run ``fn(task)`` in a fresh Python process and return its (JSON) result.

    ``task["sys_path"]`` entries that exist here are put on the child's ``sys.path`` (so planner
    factories given as ``module:function`` resolve as on the client).  Raises ``RuntimeError`` with
    the child's stderr tail when it fails.
    """
    with tempfile.TemporaryDirectory(prefix="tpee_task_") as tmp:
        src, dst = Path(tmp) / "task.json", Path(tmp) / "result.json"
        src.write_text(json.dumps(task))
        env = dict(os.environ)
        extra = [p for p in task.get("sys_path", []) if p and os.path.isdir(p)]
        if extra:
            env["PYTHONPATH"] = os.pathsep.join(extra + [env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
        proc = subprocess.run(
            [sys.executable, "-m", "tpee_ompl.bench.executors", fn_path, str(src), str(dst)],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=False,
        )
        if proc.returncode != 0 or not dst.is_file():
            tail = "\n".join(proc.stderr.splitlines()[-20:])
            raise RuntimeError(f"task subprocess exited with {proc.returncode}:\n{tail}")
        return json.loads(dst.read_text())


def _subprocess_main(argv: Sequence[str]) -> int:
    import importlib

    _die_with_parent()
    fn_path, src, dst = argv
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
            self._cluster = distributed.LocalCluster(n_workers=int(n_workers), threads_per_worker=1, processes=True,
                                                     dashboard_address=":0")
            self.client = distributed.Client(self._cluster)
            self.description = f"Dask LocalCluster ({n_workers} workers)"
        else:
            self.client = distributed.Client(scheduler)
            self.description = f"Dask scheduler {scheduler}"
        self._futures: list = []

    def run(self, fn: TaskFn, tasks: Sequence[dict]) -> Iterator[dict]:  # noqa: D102
        import uuid

        from distributed import as_completed

        tag = uuid.uuid4().hex[:8]
        self._futures = [
            self.client.submit(fn, t, key=f"tpee-task-{tag}-{k}", pure=False, retries=self.retries)
            for k, t in enumerate(tasks)
        ]
        for fut in as_completed(self._futures):
            yield fut.result()
            fut.release()

    def shutdown(self, cancel: bool = False) -> None:  # noqa: D102
        with contextlib.suppress(Exception):
            if cancel and self._futures:
                self.client.cancel(self._futures)
        if self._own_client:
            with contextlib.suppress(Exception):
                self.client.close()
        if self._cluster is not None:
            with contextlib.suppress(Exception):
                self._cluster.close()


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
