"""A path library on disk: one compressed ``.npz`` file, format :data:`FORMAT_VERSION`, model hash included.

Layout: ``meta`` (JSON: format version, model hash, per_step, n_candidates, DMP options, pairs,
build counters and parameters, query stride) and, per pair ``p<i><j>_``, the demos' ``starts``,
``goals``, ``waypoints``, ``margins`` and the forward/reverse DMPs' ``*_weights`` and ``*_scaled``.
The DMPs' response profiles are recomputed on reading (:meth:`tpee_ompl.library.dmp.DMP.from_weights`).
:meth:`PathLibrary.save` and :meth:`PathLibrary.load` use :func:`write_library` and :func:`read_library`.
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.wearer_arm import WearerArm
from .demos import N_FAKE_TIME_STEPS, PairDemos
from .dmp import DMP, DMPOptions

if TYPE_CHECKING:
    from .path_library import PathLibrary

__all__ = ["FORMAT_VERSION", "LibraryFileError", "read_library", "write_library"]

FORMAT_VERSION = 2
"""Version of the ``.npz`` layout written by :func:`write_library` (2: per-demo planning margins)."""


class LibraryFileError(ValueError):
    """A library file that cannot be used: truncated, wrong format version, or another model."""


def write_library(library: PathLibrary, path: str | Path) -> Path:
    """Write ``library`` to one ``.npz`` file (format :data:`FORMAT_VERSION`, model hash included); returns the path."""
    path = Path(path)
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
    with open(path, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    return path


def read_library(path: str | Path, robot: WearerArm) -> tuple[dict[tuple[int, int], PairDemos], dict[str, Any]]:
    """The demos per pair and the library's settings (``PathLibrary`` keyword arguments) of a file written by :func:`write_library`.

    Raises
    ------
    FileNotFoundError
        If there is no such file.
    LibraryFileError
        If the file is damaged, has another format version, or was built for another model.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise
    except (zipfile.BadZipFile, EOFError, OSError, ValueError, KeyError) as exc:
        raise LibraryFileError(f"path library {path} is unreadable (truncated or not a library file): {exc}") from exc
    try:
        meta = json.loads(str(arrays["meta"]))
    except (KeyError, json.JSONDecodeError) as exc:
        raise LibraryFileError(f"path library {path} has no valid metadata: {exc}") from exc
    if meta.get("format_version") != FORMAT_VERSION:
        raise LibraryFileError(
            f"path library {path} has format version {meta.get('format_version')!r}; "
            f"this code reads version {FORMAT_VERSION}: rebuild the library"
        )
    if meta.get("model_hash") != robot.model_hash:
        raise LibraryFileError(
            f"path library {path} was built for model {meta.get('model_hash')!r}, but the robot is "
            f"model {robot.model_hash!r}: rebuild the library for this URDF/SRDF"
        )
    options = DMPOptions(**meta["options"])
    per_step = int(meta["per_step"])
    n_steps = (N_FAKE_TIME_STEPS - 1) * per_step + 1
    data: dict[tuple[int, int], PairDemos] = {}
    try:
        for i, j in meta["pairs"]:
            p = f"p{i}{j}_"
            pd = PairDemos(arrays[p + "starts"], arrays[p + "goals"], arrays[p + "waypoints"], arrays[p + "margins"])
            if not (len(pd.starts) == len(pd.goals) == len(pd.waypoints) == len(pd.margins)):
                raise ValueError(f"pair {i}->{j}: starts, goals, waypoints and margins differ in length")
            for W, fw, fs, rw, rs in zip(pd.waypoints, arrays[p + "fwd_weights"], arrays[p + "fwd_scaled"],
                                         arrays[p + "rev_weights"], arrays[p + "rev_scaled"], strict=True):
                pd.forward.append(DMP.from_weights(fw, W[0, 2:], W[-1, 2:], fs, n_steps, options))
                pd.reverse.append(DMP.from_weights(rw, W[-1, 2:], W[0, 2:], rs, n_steps, options))
            data[(int(i), int(j))] = pd
    except (KeyError, ValueError) as exc:
        raise LibraryFileError(f"path library {path} is inconsistent: {exc}") from exc
    settings = {"per_step": per_step, "options": options, "n_candidates": int(meta["n_candidates"]),
                "build_stats": meta.get("build_stats"), "query_stride": int(meta.get("query_stride", 10)),
                "build_params": meta.get("build_params")}
    return data, settings
