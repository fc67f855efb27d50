"""A library build's per-pair work that kills its own worker process, for tests of the build's lost pairs.

Tests put :func:`collect_or_die` in place of ``tpee_ompl.library.build._collect_default_pair`` (monkeypatch): the
build passes it by name to each pair's spawned process, which imports it from here (``tests/`` is on the
inherited ``sys.path``) and reads :data:`DIE_ENV` from the inherited environment.
"""

from __future__ import annotations

import json
import os
import signal
import time
from pathlib import Path

from tpee_ompl.library.build import Collected, _collect_default_pair

DIE_ENV = "TPEE_TEST_LIBRARY_DIE"
"""Environment variable of :func:`collect_or_die`: JSON ``{"dir", "pair": [i, j], "times", "whom"}``."""


def arm(monkeypatch, folder: Path, pair: tuple[int, int], times: int = 1, whom: str = "worker") -> Path:
    """Make pair ``pair`` of the next default builds, after its work and before its result is sent, the first
    ``times`` times, SIGKILL its worker process (``whom`` "worker") or send SIGTERM to the build's process ("build",
    as ``kill PID`` does); ``folder`` (created) gets one file ``killed-<pid>`` per signal sent."""
    import tpee_ompl.library.build as build

    folder.mkdir()
    monkeypatch.setenv(DIE_ENV, json.dumps({"dir": str(folder), "pair": list(pair), "times": times, "whom": whom}))
    monkeypatch.setattr(build, "_collect_default_pair", collect_or_die)
    return folder


def collect_or_die(job: tuple) -> Collected:
    """The pair's demonstrations (the build's own function), or first the signal :data:`DIE_ENV` asks for while it
    asks for more for this pair (counted by one file ``killed-<pid>`` per signal)."""
    out = _collect_default_pair(job)
    spec = json.loads(os.environ[DIE_ENV])
    folder = Path(spec["dir"])
    if list(job[1:3]) == spec["pair"] and len(list(folder.glob("killed-*"))) < int(spec["times"]):
        (folder / f"killed-{os.getpid()}").write_text(str(job[1:3]))
        if spec["whom"] == "build":
            os.kill(os.getppid(), signal.SIGTERM)
            time.sleep(60)  # the build kills this process
        os.kill(os.getpid(), signal.SIGKILL)
    return out
