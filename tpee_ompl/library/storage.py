"""A path library on disk: one compressed ``.npz`` file, format :data:`FORMAT_VERSION`, model hash included.

Layout: ``meta`` (JSON: format version, model hash, per_step, n_candidates, DMP options, pairs,
build counters and parameters, query stride) and, per pair ``p<i><j>_``, the demos' ``starts``,
``goals``, ``waypoints``, ``margins`` and the forward/reverse DMPs' ``*_weights`` and ``*_scaled``.
The DMPs' response profiles are recomputed on reading (:meth:`tpee_ompl.library.dmp.DMP.from_weights`).
:meth:`PathLibrary.save` and :meth:`PathLibrary.load` use :func:`write_library` and :func:`read_library`.
"""

from __future__ import annotations

import dataclasses
import json
import zipfile
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..files import OutputExistsError, atomic_path
from ..model.sectors import SECTOR_PAIRS
from ..model.wearer_arm import WearerArm
from ..validation import check_int
from .demos import MAX_PER_STEP, N_FAKE_TIME_STEPS, PairDemos
from .dmp import DMP, DMPOptions

if TYPE_CHECKING:
    from .path_library import PathLibrary

__all__ = ["FORMAT_VERSION", "MAX_CANDIDATES", "MAX_PER_STEP", "LibraryFileError", "read_library", "write_library"]

FORMAT_VERSION = 2
"""Version of the ``.npz`` layout written by :func:`write_library` (2: per-demo planning margins)."""


class LibraryFileError(ValueError):
    """A library file that cannot be used: truncated, wrong format version, another model, or a malformed
    field or array (the message names it)."""


MAX_CANDIDATES = 10_000
"""Largest ``n_candidates`` a file may give."""
_META_KEYS = frozenset({"format_version", "model_hash", "per_step", "n_candidates", "options", "pairs", "build_stats",
                        "build_params", "query_stride"})
_PAIR_ARRAYS = ("starts", "goals", "waypoints", "margins", "fwd_weights", "fwd_scaled", "rev_weights", "rev_scaled")


def write_library(library: PathLibrary, path: str | Path, *, force: bool = True) -> Path:
    """Write ``library`` to one ``.npz`` file (format :data:`FORMAT_VERSION`, model hash included); returns the path.

    The file is written atomically (:func:`tpee_ompl.files.atomic_path`): an interrupted write leaves
    the old file (or none), never a truncated one.  With ``force=False`` an existing file raises
    :class:`~tpee_ompl.files.OutputExistsError` and is left unchanged.
    """
    path = Path(path)
    if path.exists() and not force:
        raise OutputExistsError(f"path library {path} exists; pass --force to replace it")
    meta = {
        "format_version": FORMAT_VERSION,
        "model_hash": library.robot.model_hash,
        "per_step": library.per_step,
        "n_candidates": library.n_candidates,
        "options": asdict(library.options),
        "pairs": [list(p) for p in sorted(library.pairs)],
        "build_stats": library.build_stats,
        "build_params": library.build_params,
        "query_stride": library.query_stride,
    }
    arrays: dict[str, np.ndarray] = {"meta": np.array(json.dumps(meta))}
    n_basis = library.options.basis_count((N_FAKE_TIME_STEPS - 1) * library.per_step + 1)
    for (i, j), pd in sorted(library.pairs.items()):
        p = f"p{i}{j}_"
        arrays[p + "starts"], arrays[p + "goals"], arrays[p + "waypoints"] = pd.starts, pd.goals, pd.waypoints
        arrays[p + "margins"] = pd.margins if pd.margins is not None else np.full(len(pd.starts), np.nan)
        for name, dmps in (("fwd", pd.forward), ("rev", pd.reverse)):
            arrays[p + name + "_weights"] = np.array([d.weights for d in dmps]).reshape(len(dmps), 2, n_basis)
            arrays[p + name + "_scaled"] = np.array([d.scaled for d in dmps], dtype=bool).reshape(len(dmps), 2)
    for key, x in arrays.items():  # what read_library would refuse is not written
        too_big = _beyond_limit(key.partition("_")[2], x)
        if too_big:
            raise ValueError(f"path library {path}: array {key!r} {too_big}: not saved (its loader would refuse it)")
    with atomic_path(path, force=force) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    return path


def _check_meta(meta: Any, path: Path) -> dict[str, Any]:
    """The library settings of the ``meta`` record, every field checked; LibraryFileError naming the field."""
    def bad(field_: str, why: str) -> LibraryFileError:
        return LibraryFileError(f"path library {path}: meta field {field_!r} {why}")

    if not isinstance(meta, dict):
        raise LibraryFileError(f"path library {path}: meta must be a JSON object, got {type(meta).__name__}")
    unknown = sorted(set(meta) - _META_KEYS)
    if unknown:
        raise bad(unknown[0], f"is unknown (the fields are {', '.join(sorted(_META_KEYS))})")
    for name, top in (("per_step", MAX_PER_STEP), ("n_candidates", MAX_CANDIDATES), ("query_stride", None)):
        if name == "query_stride" and name not in meta:
            continue
        try:
            check_int(name, meta.get(name), minimum=1, maximum=top)
        except ValueError as exc:
            raise bad(name, f"is invalid: {exc}") from None
    options = meta.get("options")
    fields = {f.name for f in dataclasses.fields(DMPOptions)}
    if not isinstance(options, dict):
        raise bad("options", f"must be a JSON object of DMP options, got {options!r}")
    unknown = sorted(set(options) - fields)
    if unknown:
        raise bad("options", f"has an unknown DMP option {unknown[0]!r} (known: {', '.join(sorted(fields))})")
    try:
        dmp_options = DMPOptions(**options)
    except (TypeError, ValueError) as exc:
        raise bad("options", f"is invalid: {exc}") from None
    pairs = meta.get("pairs")
    if not isinstance(pairs, list) or not all(
            isinstance(p, list) and len(p) == 2 and all(type(v) is int for v in p) and tuple(p) in SECTOR_PAIRS
            for p in pairs):
        raise bad("pairs", f"must be a list of [i, j] sector pairs, i != j in 1..4, got {pairs!r}"[:300])
    if len({tuple(p) for p in pairs}) != len(pairs):
        raise bad("pairs", f"lists a pair twice: {pairs!r}")
    for name in ("build_stats", "build_params"):
        if not isinstance(meta.get(name), (dict, type(None))):
            raise bad(name, f"must be a JSON object, got {type(meta.get(name)).__name__}")
    return {"per_step": meta["per_step"], "options": dmp_options, "n_candidates": meta["n_candidates"],
            "build_stats": meta.get("build_stats"), "query_stride": meta.get("query_stride", 10),
            "build_params": meta.get("build_params"), "pairs": [tuple(p) for p in pairs]}


_ANGLES = ("starts", "goals", "waypoints")
_MAX_ABS = {**dict.fromkeys(_ANGLES, 100.0), "fwd_weights": 1e9, "rev_weights": 1e9}
"""Largest magnitude a library array may hold: far beyond any joint angle (rad) or DMP weight a build gives
(the packaged library: 3.3 rad, weights 2.1e4), short of what overflows the DMP's arithmetic."""


def _pair_arrays(arrays: dict[str, np.ndarray], i: int, j: int, n_basis: int, path: Path) -> dict[str, np.ndarray]:
    """Pair (i, j)'s arrays, shapes, dtypes and values checked; LibraryFileError naming the array."""
    p = f"p{i}{j}_"
    missing = [p + n for n in _PAIR_ARRAYS if p + n not in arrays]
    if missing:
        raise LibraryFileError(f"path library {path}: array {missing[0]!r} is missing")
    a = {n: arrays[p + n] for n in _PAIR_ARRAYS}
    m = a["starts"].shape[0] if a["starts"].ndim else -1
    shapes = {"starts": (m, 4), "goals": (m, 4), "waypoints": (m, N_FAKE_TIME_STEPS, 4), "margins": (m,),
              "fwd_weights": (m, 2, n_basis), "rev_weights": (m, 2, n_basis), "fwd_scaled": (m, 2), "rev_scaled": (m, 2)}
    for name, shape in shapes.items():
        x = a[name]
        if x.shape != shape:
            raise LibraryFileError(f"path library {path}: array {p + name!r} has shape {x.shape}, expected {shape}")
        if name.endswith("_scaled"):
            if x.dtype != bool:
                raise LibraryFileError(f"path library {path}: array {p + name!r} must be booleans, got {x.dtype}")
            continue
        if x.dtype.kind != "f":
            raise LibraryFileError(f"path library {path}: array {p + name!r} must be floats, got {x.dtype}")
        if name != "margins" and not np.all(np.isfinite(x)):
            raise LibraryFileError(f"path library {path}: array {p + name!r} holds NaN or inf")
        too_big = _beyond_limit(name, x)
        if too_big:
            raise LibraryFileError(f"path library {path}: array {p + name!r} {too_big}")
    return a


def _beyond_limit(name: str, x: np.ndarray) -> str | None:
    """What is wrong when the library array ``name`` (``waypoints``, ``fwd_weights``, ...) holds a value beyond
    :data:`_MAX_ABS`, else None."""
    if name not in _MAX_ABS or not x.size:
        return None
    m = float(np.nanmax(np.abs(x)))
    if m <= _MAX_ABS[name]:
        return None
    return f"holds {m:g}, beyond +/-{_MAX_ABS[name]:g} ({'joint angles, rad' if name in _ANGLES else 'DMP weights'})"


def read_library(path: str | Path, robot: WearerArm) -> tuple[dict[tuple[int, int], PairDemos], dict[str, Any]]:
    """The demos per pair and the library's settings (``PathLibrary`` keyword arguments) of a file written by :func:`write_library`.

    Every field of the metadata and every array is checked (type, shape, finite values) before use.

    Raises
    ------
    FileNotFoundError
        If there is no such file.
    LibraryFileError
        If the file is damaged, has another format version, was built for another model, or a field
        or array is malformed (the message names it).
    """
    path = Path(path)
    if path.is_file() and not zipfile.is_zipfile(path):  # numpy's own message would advise loading it with pickle
        raise LibraryFileError(f"path library {path} is unreadable (truncated or not a library file): not an .npz archive")
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise
    except (zipfile.BadZipFile, EOFError, OSError, ValueError, KeyError) as exc:
        raise LibraryFileError(f"path library {path} is unreadable (truncated or not a library file): {exc}") from exc
    try:
        meta = json.loads(str(arrays["meta"]))
    except (KeyError, json.JSONDecodeError, RecursionError) as exc:
        raise LibraryFileError(f"path library {path} has no valid metadata: {exc}") from exc
    version = meta.get("format_version") if isinstance(meta, dict) else None
    if isinstance(meta, dict) and (type(version) is not int or version != FORMAT_VERSION):
        raise LibraryFileError(
            f"path library {path} has format version {version!r}; "
            f"this code reads version {FORMAT_VERSION}: rebuild the library"
        )
    if isinstance(meta, dict) and meta.get("model_hash") != robot.model_hash:
        raise LibraryFileError(
            f"path library {path} was built for model {meta.get('model_hash')!r}, but the robot is "
            f"model {robot.model_hash!r}: rebuild the library for this URDF/SRDF"
        )
    settings = _check_meta(meta, path)
    options, per_step = settings["options"], settings["per_step"]
    n_steps = (N_FAKE_TIME_STEPS - 1) * per_step + 1
    n_basis = options.basis_count(n_steps)
    data: dict[tuple[int, int], PairDemos] = {}
    for i, j in settings.pop("pairs"):
        a = _pair_arrays(arrays, i, j, n_basis, path)
        pd = PairDemos(a["starts"], a["goals"], a["waypoints"], a["margins"])
        try:
            for W, fw, fs, rw, rs in zip(pd.waypoints, a["fwd_weights"], a["fwd_scaled"], a["rev_weights"],
                                         a["rev_scaled"], strict=True):
                pd.forward.append(DMP.from_weights(fw, W[0, 2:], W[-1, 2:], fs, n_steps, options))
                pd.reverse.append(DMP.from_weights(rw, W[-1, 2:], W[0, 2:], rs, n_steps, options))
        except ValueError as exc:
            raise LibraryFileError(f"path library {path} is inconsistent: pair {i}->{j}: {exc}") from exc
        data[(i, j)] = pd
    return data, settings
