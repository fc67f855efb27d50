"""Result files that never overwrite anything: new folders, new names, atomic writes; and what goes in them.

* :func:`make_results_dir`: a new ``<out>/<UTC timestamp>_<name>/`` campaign folder.
* :func:`new_output_stem`: a free file stem for scripts writing ``<stem>.csv`` / ``<stem>.json``.
* :func:`write_json`: atomic replace (a campaign's own ``campaign.json``); :func:`append_json_line` (``tasks.jsonl``).
* :func:`package_versions`, :func:`format_value`: what the logs and metadata record, as text.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
from collections.abc import Sequence
from pathlib import Path

import numpy as np

__all__ = [
    "append_json_line",
    "format_value",
    "make_results_dir",
    "new_output_stem",
    "package_versions",
    "planner_name",
    "utc_now",
    "write_json",
]


def planner_name(recorded_name: str) -> str:
    """``geometric_RRTstar`` -> ``RRTstar``: a planner's name without the prefix OMPL's benchmark records it with."""
    return recorded_name.removeprefix("geometric_")


def utc_now() -> str:
    """The current UTC time, ISO 8601."""
    return _dt.datetime.now(_dt.timezone.utc).isoformat()


def _utc_stamp() -> str:
    return _dt.datetime.now(_dt.timezone.utc).strftime("%Y%m%dT%H%M%SZ")


def make_results_dir(out: str | os.PathLike, name: str) -> Path:
    """A new ``<out>/<UTC timestamp>_<name>/`` folder; never an existing one."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stamp = _utc_stamp()
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in name)
    for k in range(1000):
        d = out / (f"{stamp}_{safe}" if k == 0 else f"{stamp}_{safe}_{k}")
        try:
            d.mkdir()
            return d
        except FileExistsError:
            continue
    raise RuntimeError(f"could not create a new results folder under {out}")


def new_output_stem(stem: str | os.PathLike, suffixes: Sequence[str] = (".csv", ".json")) -> Path:
    """``stem`` if none of ``stem + suffix`` exists, else ``<stem>_<UTC timestamp>[_k]``: results are never overwritten."""
    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    if not any(stem.with_name(stem.name + s).exists() for s in suffixes):
        return stem
    stamp = _utc_stamp()
    for k in range(1000):
        cand = stem.with_name(f"{stem.name}_{stamp}" if k == 0 else f"{stem.name}_{stamp}_{k}")
        if not any(cand.with_name(cand.name + s).exists() for s in suffixes):
            return cand
    raise RuntimeError(f"no free output name for {stem}")


def write_json(path: Path, data: dict) -> None:
    """Write ``data`` as indented JSON, replacing ``path`` atomically (:func:`tpee_ompl.files.atomic_write_text`).

    Non-finite floats are refused (``NaN`` is not JSON).
    """
    from ..files import atomic_write_text

    atomic_write_text(path, json.dumps(data, indent=2, allow_nan=False))


def append_json_line(path: Path, data: dict) -> None:
    """Add ``data`` as one JSON line to ``path``; the file is rewritten atomically (never half a line)."""
    from ..files import atomic_write_text

    old = Path(path).read_text() if Path(path).is_file() else ""
    if old and not old.endswith("\n"):  # a last line cut short elsewhere (an editor, a full disk): not glued to it
        old += "\n"
    atomic_write_text(path, old + json.dumps(data, allow_nan=False) + "\n")


def package_versions() -> dict[str, str]:
    """Versions of Python and the packages the results depend on."""
    from importlib import metadata

    from .._version import code_version

    out = {"python": platform.python_version(), "platform": platform.platform(), "tpee_ompl": code_version()}
    for dist in ("ompl", "pin", "coal", "numpy", "matplotlib"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"
    return out


def format_value(v: object) -> str:
    """A value as OMPL log text: '' for None, 0/1 for booleans, ``repr`` for floats, 'nan'/'inf'."""
    if v is None:
        return ""
    if isinstance(v, str):
        return v
    if isinstance(v, (bool, np.bool_)):
        return str(int(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    v = float(v)
    if math.isnan(v):
        return "nan"
    if math.isinf(v):
        return "inf"
    return repr(v)
