"""Damaged and hostile input files for the refusal tests: path libraries, query sets, path JSON.

Each maker writes one small file derived from a packaged one (so everything but the named defect
is valid) and returns its path.  The tables name, per defect, the field the refusal must name.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from tpee_ompl.resources import default_library_path, query_set_path

PAIR = "p12_"


def library_arrays() -> dict[str, Any]:
    """The packaged library cut to its first pair (1->2): ``meta`` as a dict, the pair's arrays."""
    with np.load(default_library_path(), allow_pickle=False) as z:
        arrays: dict[str, Any] = {k: z[k] for k in z.files if k.startswith(PAIR)}
        meta = json.loads(str(z["meta"]))
    meta["pairs"] = [[1, 2]]
    arrays["meta"] = meta
    return arrays


def write_library_file(path: Path, change: Callable[[dict[str, Any]], None] | None = None) -> Path:
    """A one-pair library file, with ``change(arrays)`` applied first (``arrays["meta"]`` is the meta dict)."""
    arrays = library_arrays()
    if change is not None:
        change(arrays)
    meta = arrays.pop("meta")
    np.savez_compressed(path, meta=np.array(meta if isinstance(meta, str) else json.dumps(meta)), **arrays)
    return path


def _set(d: dict, key: str, value: Any) -> None:
    d[key] = value


def _nan_weights(a: dict) -> None:
    w = a[PAIR + "fwd_weights"].copy()
    w[0, 0, 0] = np.nan
    a[PAIR + "fwd_weights"] = w


def _scaled(name: str, value: float) -> Callable[[dict], None]:
    """A change setting one value of pair (1, 2)'s array ``name`` to ``value`` (finite, but out of any range)."""
    def change(a: dict) -> None:
        x = a[PAIR + name].copy()
        x.flat[0] = value
        a[PAIR + name] = x
    return change


def _shifted(name: str, dof: int, by: float) -> Callable[[dict], None]:
    """A change adding ``by`` to DOF ``dof`` (0-based) of every row of pair (1, 2)'s array ``name``."""
    def change(a: dict) -> None:
        x = a[PAIR + name].copy()
        x[..., dof] += by
        a[PAIR + name] = x
    return change


def _other_presets(a: dict) -> None:
    """Pair (1, 2)'s demonstrations moved to start at sector 3's Table-1 preset (another pair's)."""
    from tpee_ompl.model.sectors import posture_preset

    x = a[PAIR + "starts"].copy()
    x[:, :2] = posture_preset(3)
    a[PAIR + "starts"] = x


LIBRARY_DEFECTS: dict[str, tuple[Callable[[dict], None], str]] = {
    # name: (change, what the refusal must name)
    "meta-is-a-list": (lambda a: _set(a, "meta", json.dumps([1, 2, 3])), "meta"),
    "meta-not-json": (lambda a: _set(a, "meta", "{not json"), "metadata"),
    "unknown-dmp-option": (lambda a: a["meta"]["options"].update(bogus=1), "bogus"),
    "unknown-meta-field": (lambda a: a["meta"].update(extra=1), "extra"),
    "pairs-is-5": (lambda a: _set(a["meta"], "pairs", 5), "pairs"),
    "pair-of-strings": (lambda a: _set(a["meta"], "pairs", [["1", "2"]]), "pairs"),
    "pair-not-cross-sector": (lambda a: _set(a["meta"], "pairs", [[1, 1]]), "pairs"),
    "1-d-waypoints": (lambda a: _set(a, PAIR + "waypoints", a[PAIR + "waypoints"].ravel()), "p12_waypoints"),
    "nan-weights": (_nan_weights, "p12_fwd_weights"),
    "huge-waypoints": (_scaled("waypoints", 1e300), "p12_waypoints"),
    "huge-weights": (_scaled("fwd_weights", 1e300), "p12_fwd_weights"),
    "n-candidates-negative": (lambda a: _set(a["meta"], "n_candidates", -5), "n_candidates"),
    "n-candidates-a-string": (lambda a: _set(a["meta"], "n_candidates", "3"), "n_candidates"),
    "per-step-huge": (lambda a: _set(a["meta"], "per_step", 10**12), "per_step"),
    "per-step-float": (lambda a: _set(a["meta"], "per_step", 100.5), "per_step"),
    "query-stride-zero": (lambda a: _set(a["meta"], "query_stride", 0), "query_stride"),
    "bad-dmp-option-value": (lambda a: a["meta"]["options"].update(alpha_y=-1.0), "alpha_y"),
    "missing-array": (lambda a: a.pop(PAIR + "goals"), "p12_goals"),
    "scaled-not-bool": (lambda a: _set(a, PAIR + "fwd_scaled", a[PAIR + "fwd_scaled"].astype(float)), "p12_fwd_scaled"),
    "format-version-true": (lambda a: _set(a["meta"], "format_version", True), "format version"),
    "build-stats-a-list": (lambda a: _set(a["meta"], "build_stats", [1]), "build_stats"),
    "build-stats-count-null": (lambda a: a["meta"]["build_stats"].update(stored=None), "build_stats"),
    "build-stats-count-a-string": (lambda a: a["meta"]["build_stats"].update(stored="x"), "build_stats"),
    "query-stride-beyond-the-rollout": (lambda a: _set(a["meta"], "query_stride", 10**9), "query_stride"),
    "waypoints-off-the-joint-limits": (_shifted("waypoints", 3, 50.0), "p12_waypoints"),
    "starts-of-another-sector": (_other_presets, "p12_starts"),
    "starts-not-the-waypoints-first": (_shifted("starts", 3, 0.01), "p12_waypoints"),
}


def truncated_library_file(path: Path) -> Path:
    """The first half of a valid one-pair library file."""
    data = write_library_file(path).read_bytes()
    path.write_bytes(data[: len(data) // 2])
    return path


# ---------------------------------------------------------------------------------------- query sets
def query_doc(n: int = 4) -> dict[str, Any]:
    """The packaged ``planning_necessary`` set cut to its first ``n`` queries."""
    doc = json.loads(query_set_path("planning_necessary").read_text(encoding="utf-8"))
    doc["queries"] = doc["queries"][:n]
    return doc


def write_query_file(path: Path, change: Callable[[dict[str, Any]], None] | None = None) -> Path:
    """A small query set file, with ``change(doc)`` applied first."""
    doc = query_doc()
    if change is not None:
        change(doc)
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def _first(doc: dict, key: str, value: Any) -> None:
    doc["queries"][0][key] = value


QUERY_DEFECTS: dict[str, tuple[Callable[[dict], None], str]] = {
    "start-strings": (lambda d: _first(d, "start", ["1", "2", "3", "4"]), "start"),
    "from-sector-true": (lambda d: _first(d, "from_sector", True), "from_sector"),
    "to-sector-float": (lambda d: _first(d, "to_sector", 2.0), "to_sector"),
    "id-string": (lambda d: _first(d, "id", "0"), "id"),
    "goal-three-values": (lambda d: _first(d, "goal", [0.0, 0.0, 0.0]), "goal"),
    "target-with-bool": (lambda d: _first(d, "target_a", [1.0, True, 2.0]), "target_a"),
    "missing-goal": (lambda d: d["queries"][0].pop("goal"), "goal"),
    "unknown-field": (lambda d: _first(d, "colour", "red"), "colour"),
    "same-sectors": (lambda d: _first(d, "to_sector", d["queries"][0]["from_sector"]), "from_sector"),
    "duplicate-id": (lambda d: d["queries"][1].update(id=d["queries"][0]["id"]), "twice"),
    "query-not-an-object": (lambda d: d["queries"].__setitem__(0, [1, 2]), "object"),
    "target-integer-too-big": (lambda d: _first(d, "target_a", [10**400, 0, 0]), "target_a"),  # no float holds it
}


def other_model_query_file(path: Path) -> Path:
    """A valid query set made for another model (its ``model_hash`` differs)."""
    return write_query_file(path, lambda d: d.update(model_hash="0123456789abcdef"))


def write_path_file(path: Path, waypoints: Any) -> Path:
    """A ``plan --json``-like file whose ``path`` is ``waypoints``."""
    path.write_text(json.dumps({"path": waypoints}), encoding="utf-8")
    return path


def make_unreadable(path: Path | str, monkeypatch: Any) -> None:
    """Make ``path`` a file this process may not read: mode 000, and for root (who reads it anyway) an ``open``
    that fails on it as the system does for another user (``monkeypatch``: pytest's fixture)."""
    import builtins
    import errno
    import os

    path = os.fspath(path)
    os.chmod(path, 0)
    if os.access(path, os.R_OK):
        real_open = builtins.open

        def refusing_open(file, *args, **kwargs):
            if isinstance(file, (str, os.PathLike)) and os.path.abspath(file) == os.path.abspath(path):
                raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), os.fspath(file))
            return real_open(file, *args, **kwargs)

        monkeypatch.setattr(builtins, "open", refusing_open)
