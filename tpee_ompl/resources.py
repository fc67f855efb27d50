"""Packaged data: the wearer model, the named query sets and the default path library.

The one place that knows where the data files live.  Everything is read through
:mod:`importlib.resources`, so an installed wheel and a source checkout find the same files.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

__all__ = ["DEFAULT_LIBRARY", "data_path", "default_library_path", "model_file", "query_set_path"]

DEFAULT_LIBRARY = "default.npz"


def data_path(*parts: str) -> Path:
    """Filesystem path of a packaged data file under ``tpee_ompl/data/`` (whether or not it exists)."""
    return Path(str(resources.files("tpee_ompl").joinpath("data", *parts)))


def model_file(name: str) -> Path:
    """Path of a packaged model file (``wearer_arm.urdf``, ``wearer_arm.srdf``).

    Raises
    ------
    FileNotFoundError
        If the package carries no such file (a broken install).
    """
    p = data_path("model", name)
    if not p.is_file():
        raise FileNotFoundError(f"packaged model file {name!r} not found at {p}")
    return p


def query_set_path(name: str) -> Path:
    """Path of a named query set (``data/queries/<name>.json``)."""
    return data_path("queries", f"{name}.json")


def default_library_path() -> Path:
    """Path of the default cross-sector path library (``data/library/default.npz``)."""
    return data_path("library", DEFAULT_LIBRARY)
