"""A path library on disk: one compressed ``.npz`` file, format :data:`FORMAT_VERSION`, model hash included.

Layout: ``meta`` (JSON: format version, model hash, per_step, n_candidates, DMP options, pairs,
build counters and parameters, query stride) and, per pair ``p<i><j>_``, the demos' ``starts``,
``goals``, ``waypoints``, ``margins`` and the forward/reverse DMPs' ``*_weights`` and ``*_scaled``.
The DMPs' response profiles are recomputed on reading (:meth:`tpee_ompl.library.dmp.DMP.from_weights`).
:meth:`PathLibrary.save` and :meth:`PathLibrary.load` use :func:`write_library` and :func:`read_library`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import zipfile
import zlib
from dataclasses import asdict
from pathlib import Path
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

from ..files import OutputExistsError, atomic_path
from ..model.sectors import SECTOR_PAIRS
from ..model.wearer_arm import WearerArm
from ..validation import check_int
from .demos import MAX_PER_STEP, N_FAKE_TIME_STEPS, PairDemos, demo_problem, max_query_stride
from .dmp import DMP, DMPOptions

if TYPE_CHECKING:
    from .path_library import PathLibrary

__all__ = ["FORMAT_VERSION", "MAX_CANDIDATES", "MAX_PER_STEP", "LibraryFileError", "library_model_hash",
           "packaged_library_for", "read_library", "write_library"]

FORMAT_VERSION = 2
"""Version of the ``.npz`` layout written by :func:`write_library` (2: per-demo planning margins)."""


class LibraryFileError(ValueError):
    """A library file that cannot be used: truncated, wrong format version, another model, or a malformed
    field or array (the message names it)."""


MAX_CANDIDATES = 10_000
"""Largest ``n_candidates`` a file may give."""
MAX_LIBRARY_BYTES = 2**31
"""Most bytes the arrays of a library file may unpack to (the packaged library: about 9 MB); a file whose
array headers declare more is refused before any of them is unpacked."""
_MAX_META_BYTES = 2**20
"""Most bytes of the ``meta`` record (the packaged library's: about 2 kB)."""
_BUILD_STAT_MAX = 10**12
"""Largest count a library's ``build_stats`` may hold."""
_META_KEYS = frozenset({"format_version", "model_hash", "per_step", "n_candidates", "options", "pairs", "build_stats",
                        "build_params", "query_stride"})
_PAIR_ARRAYS = ("starts", "goals", "waypoints", "margins", "fwd_weights", "fwd_scaled", "rev_weights", "rev_scaled")


def write_library(library: PathLibrary, path: str | Path, *, force: bool = True) -> Path:
    """Write ``library`` to one ``.npz`` file (format :data:`FORMAT_VERSION`, model hash included); returns the path.

    The file is written atomically (:func:`tpee_ompl.files.atomic_path`): an interrupted write leaves
    the old file (or none), never a truncated one.  With ``force=False`` an existing file raises
    :class:`~tpee_ompl.files.OutputExistsError` and is left unchanged.
    """
    path = _file_path(path)
    if path.exists() and not force:
        raise OutputExistsError(f"path library {path} exists; pass --force (in Python: force=True) to replace it")
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
    for (i, j) in sorted(library.pairs):  # what read_library would refuse is not written
        p = f"p{i}{j}_"
        problem = _pair_problem(i, j, {name: arrays[p + name] for name in _PAIR_ARRAYS}, n_basis, library.robot)
        if problem is not None:
            raise ValueError(f"path library {path}: pair {i}->{j}: array {p + problem[0]!r} {problem[1]}: not saved "
                             "(its loader would refuse it)")
    with atomic_path(path, force=force) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    return path


def _file_path(path: object) -> Path:
    """``path`` as a Path, else ValueError: a library file is named by a non-empty str or os.PathLike."""
    raw = os.fspath(path) if isinstance(path, (str, os.PathLike)) else None
    if not isinstance(raw, str) or not raw:
        raise ValueError(f"path must be a file path (str or os.PathLike), got {path!r}"[:300])
    return Path(path)


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
        if name == "query_stride":
            if name not in meta:
                continue
            top = max_query_stride(meta["per_step"])  # a stride past the rollout's length leaves its two ends
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
    for k, v in (meta.get("build_stats") or {}).items():
        if type(v) is not int or not 0 <= v <= _BUILD_STAT_MAX:
            raise bad("build_stats", f"entry {k!r} must be a count in [0, {_BUILD_STAT_MAX:g}], got {v!r}"[:300])
    return {"per_step": meta["per_step"], "options": dmp_options, "n_candidates": meta["n_candidates"],
            "build_stats": meta.get("build_stats"), "query_stride": meta.get("query_stride"),
            "build_params": meta.get("build_params"), "pairs": [tuple(p) for p in pairs]}


_ANGLES = ("starts", "goals", "waypoints")
_MAX_ABS = {**dict.fromkeys(_ANGLES, 100.0), "fwd_weights": 1e9, "rev_weights": 1e9}
"""Largest magnitude a library array may hold: far beyond any joint angle (rad) or DMP weight a build gives
(the packaged library: 3.3 rad, weights 2.1e4), short of what overflows the DMP's arithmetic."""


def _pair_shapes(m: int, n_basis: int) -> dict[str, tuple[int, ...]]:
    """The shape of each array of a pair of ``m`` demonstrations whose DMPs have ``n_basis`` basis functions."""
    return {"starts": (m, 4), "goals": (m, 4), "waypoints": (m, N_FAKE_TIME_STEPS, 4), "margins": (m,),
            "fwd_weights": (m, 2, n_basis), "rev_weights": (m, 2, n_basis), "fwd_scaled": (m, 2), "rev_scaled": (m, 2)}


def _pair_problem(i: int, j: int, a: dict[str, np.ndarray], n_basis: int, robot: WearerArm) -> tuple[str, str] | None:
    """What a library file may not hold in pair (i, j)'s arrays ``a`` (keyed as :data:`_PAIR_ARRAYS`): ``(array,
    why)`` for the first problem, else None.  Checked: shapes, dtypes and values (finite, within :data:`_MAX_ABS`,
    and the demonstrations as :func:`~tpee_ompl.library.demos.demo_problem` checks them: inside the robot's joint
    limits, starting and ending at the pair's Table-1 presets).  Reading and writing a library use this one check."""
    a = {name: np.asarray(x) for name, x in a.items()}
    first = a["starts"].shape
    if len(first) != 2:
        return "starts", f"has shape {first}, expected (m, 4) for m demonstrations"
    for name, shape in _pair_shapes(first[0], n_basis).items():
        if a[name].shape != shape:
            return name, f"has shape {a[name].shape}, expected {shape}"
    for name in _PAIR_ARRAYS:
        x = a[name]
        if name.endswith("_scaled"):
            if x.dtype != bool:
                return name, f"must be booleans, got {x.dtype}"
            continue
        if x.dtype.kind != "f":
            return name, f"must be floats, got {x.dtype}"
        if name != "margins" and not np.all(np.isfinite(x)):
            return name, "holds NaN or inf"
        too_big = _beyond_limit(name, x)
        if too_big:
            return name, too_big
    return demo_problem(robot, i, j, a["starts"], a["goals"], a["waypoints"])


def _pair_arrays(archive: _Archive, i: int, j: int, n_basis: int, robot: WearerArm) -> dict[str, np.ndarray]:
    """Pair (i, j)'s arrays: declared shapes checked before unpacking, then :func:`_pair_problem`'s checks;
    LibraryFileError naming the array."""
    p, path = f"p{i}{j}_", archive.path
    missing = [p + n for n in _PAIR_ARRAYS if p + n not in archive.keys]
    if missing:
        raise LibraryFileError(f"path library {path}: array {missing[0]!r} is missing")
    first = archive.shape(p + "starts")
    if len(first) != 2:
        raise LibraryFileError(f"path library {path}: array {p + 'starts'!r} has shape {first}, expected (m, 4) for "
                               "m demonstrations")
    shapes = _pair_shapes(first[0], n_basis)
    for name, shape in shapes.items():
        declared = archive.shape(p + name)
        if declared != shape:
            raise LibraryFileError(f"path library {path}: array {p + name!r} has shape {declared}, expected {shape}")
    a = {name: archive.read(p + name) for name in shapes}
    problem = _pair_problem(i, j, a, n_basis, robot)
    if problem is not None:
        raise LibraryFileError(f"path library {path}: array {p + problem[0]!r} {problem[1]}")
    return a


_READ_ERRORS = (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, KeyError)
"""What reading a damaged ``.npz`` raises (a corrupt deflate stream: ``zlib.error``)."""


def _unreadable(path: Path, why: object) -> LibraryFileError:
    return LibraryFileError(f"path library {path} is unreadable (truncated or not a library file): {why}")


class _Archive:
    """The arrays of an open ``.npz`` file, read one at a time: each one's header is read (and its declared size
    counted against :data:`MAX_LIBRARY_BYTES`) before it is unpacked, so a file cannot make the reader unpack more
    than that, and members the reader does not ask for are never unpacked."""

    def __init__(self, z: np.lib.npyio.NpzFile, path: Path) -> None:
        self.z, self.path, self.keys = z, path, frozenset(z.files)
        self._headers: dict[str, tuple[tuple[int, ...], np.dtype]] = {}
        self._declared = 0

    def header(self, key: str) -> tuple[tuple[int, ...], np.dtype]:
        """The declared shape and dtype of array ``key`` (nothing unpacked; its size counted)."""
        if key not in self._headers:
            try:
                with self.z.zip.open(key + ".npy") as f:
                    version = np.lib.format.read_magic(f)
                    read = {(1, 0): np.lib.format.read_array_header_1_0,
                            (2, 0): np.lib.format.read_array_header_2_0}.get(version)
                    if read is None:
                        raise ValueError(f"array {key!r} has .npy format version {version}")
                    shape, _, dtype = read(f)
            except _READ_ERRORS as exc:
                raise _unreadable(self.path, exc) from exc
            self._declared += int(np.prod(shape, dtype=object)) * dtype.itemsize
            if self._declared > MAX_LIBRARY_BYTES:
                raise LibraryFileError(f"path library {self.path}: array {key!r} of shape {shape} would unpack the "
                                       f"file's arrays to more than {MAX_LIBRARY_BYTES / 2**30:g} GiB")
            self._headers[key] = (tuple(int(v) for v in shape), dtype)
        return self._headers[key]

    def shape(self, key: str) -> tuple[int, ...]:
        """The declared shape of array ``key`` (nothing unpacked)."""
        return self.header(key)[0]

    def read(self, key: str) -> np.ndarray:
        """Array ``key``, unpacked after its header was checked."""
        self.header(key)
        try:
            return self.z[key]
        except _READ_ERRORS as exc:
            raise _unreadable(self.path, exc) from exc


def _beyond_limit(name: str, x: np.ndarray) -> str | None:
    """What is wrong when the library array ``name`` (``waypoints``, ``fwd_weights``, ...) holds a value beyond
    :data:`_MAX_ABS`, else None."""
    if name not in _MAX_ABS or not x.size:
        return None
    m = float(np.nanmax(np.abs(x)))
    if m <= _MAX_ABS[name]:
        return None
    return f"holds {m:g}, beyond +/-{_MAX_ABS[name]:g} ({'joint angles, rad' if name in _ANGLES else 'DMP weights'})"


@contextlib.contextmanager
def _open_archive(path: Path) -> Iterator[_Archive]:
    """The library file at ``path`` open for reading: FileNotFoundError, PermissionError naming the file (one it may
    not read), or LibraryFileError for what is not a regular file (a folder, a pipe: np.load would wait on it
    forever) or not an ``.npz`` archive."""
    if path.exists() and not path.is_file():
        raise LibraryFileError(f"path library {path} is not a regular file")
    try:
        fh = open(path, "rb")  # opened first: zipfile.is_zipfile says False for a file it may not read
    except PermissionError as exc:
        raise PermissionError(f"path library {path} cannot be read ({exc.strerror})") from None
    with fh:
        if not zipfile.is_zipfile(fh):  # numpy's own message would advise loading it with pickle
            raise _unreadable(path, "not an .npz archive")
        try:
            fh.seek(0)
            z = np.load(fh, allow_pickle=False)
        except _READ_ERRORS as exc:
            raise _unreadable(path, exc) from exc
        with z:
            yield _Archive(z, path)


def _read_meta(archive: _Archive) -> Any:
    """The file's ``meta`` record, parsed (one JSON text of at most ``_MAX_META_BYTES``); LibraryFileError if not."""
    path = archive.path
    if "meta" not in archive.keys:
        raise LibraryFileError(f"path library {path} has no valid metadata: no 'meta' record")
    shape, dtype = archive.header("meta")
    if shape != () or dtype.kind != "U" or dtype.itemsize > _MAX_META_BYTES:
        raise LibraryFileError(f"path library {path} has no valid metadata: 'meta' must be one JSON text of at "
                               f"most {_MAX_META_BYTES} bytes, got {dtype} of shape {shape}")
    try:
        return json.loads(str(archive.read("meta")))
    except (json.JSONDecodeError, RecursionError) as exc:
        raise LibraryFileError(f"path library {path} has no valid metadata: {exc}") from exc


def library_model_hash(path: str | Path) -> str:
    """The model hash a library file was built for, read from its metadata alone.

    Raises FileNotFoundError (no such file), PermissionError (a file it may not read) or LibraryFileError (not a
    regular file, unreadable, no model hash):
    a damaged library is said as such, never taken for one of another model."""
    return _meta_with_model(_file_path(path))["model_hash"]


def _meta_with_model(path: Path) -> dict[str, Any]:
    """The metadata record of a library file, which names a model (LibraryFileError otherwise)."""
    with _open_archive(path) as archive:
        meta = _read_meta(archive)
    if not isinstance(meta, dict) or not isinstance(meta.get("model_hash"), str):
        raise LibraryFileError(f"path library {path} has no valid metadata: no model hash")
    return meta


def library_settings(path: str | Path) -> dict[str, Any]:
    """What a library file says of itself without a model: its model hash and its checked settings (pairs, per_step,
    n_candidates, query_stride, DMP options, build parameters and counters); the demonstrations are not read.
    Raises as :func:`library_model_hash`, or LibraryFileError naming a bad field."""
    path = _file_path(path)
    meta = _meta_with_model(path)
    return {"model_hash": meta["model_hash"], **_check_meta(meta, path)}


def packaged_library_for(robot: WearerArm) -> Path | None:
    """The packaged path library when it was built for ``robot``'s model (it was for the packaged one), else None;
    a damaged packaged library raises (:func:`library_model_hash`)."""
    from ..resources import default_library_path

    path = default_library_path()
    return path if library_model_hash(path) == robot.model_hash else None


def read_library(path: str | Path, robot: WearerArm) -> tuple[dict[tuple[int, int], PairDemos], dict[str, Any]]:
    """The demos per pair and the library's settings (``PathLibrary`` keyword arguments) of a file written by :func:`write_library`.

    Every field of the metadata and every array is checked (type, shape, finite values) before use.

    Raises
    ------
    FileNotFoundError
        If there is no such file.
    PermissionError
        If the file may not be read (the message names it).
    LibraryFileError
        If the file is damaged, has another format version, was built for another model, or a field
        or array is malformed (the message names it).
    """
    with _open_archive(_file_path(path)) as archive:
        return _read_archive(archive, robot)


def _read_archive(archive: _Archive, robot: WearerArm) -> tuple[dict[tuple[int, int], PairDemos], dict[str, Any]]:
    """:func:`read_library` on the open file."""
    path = archive.path
    meta = _read_meta(archive)
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
        a = _pair_arrays(archive, i, j, n_basis, robot)
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
