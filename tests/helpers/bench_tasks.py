"""Plain task functions for the local executor's own tests (importable by its spawned processes)."""

from __future__ import annotations

import os
import signal
import time


def echo(task: dict) -> dict:
    """Return the task with this process's pid."""
    return {**task, "pid": os.getpid()}


def hang(task: dict) -> dict:
    """Never return (until killed)."""
    while True:
        time.sleep(1)


def die(task: dict) -> dict:
    """SIGKILL this process when ``task["die"]``, else echo."""
    if task.get("die"):
        os.kill(os.getpid(), signal.SIGKILL)
    return echo(task)


def boom(task: dict) -> dict:
    """Raise."""
    raise ValueError(f"task {task.get('qpos')} exploded")


def sleep(task: dict) -> dict:
    """Sleep ``task["seconds"]``, then echo; with ``task["starts"]`` (a file) first append a line to it."""
    if task.get("starts"):
        with open(task["starts"], "a", encoding="utf-8") as f:
            f.write("start\n")
    time.sleep(float(task["seconds"]))
    return echo(task)
