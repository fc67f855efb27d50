"""Joint-space planning queries for any robot: start and goal configurations with a label, JSON I/O.

A generic counterpart of :mod:`tpee_ompl.model.queries` (which is the wearer's cross-sector
format): a query is an id, a start and a goal (nq values each) and a free-text label (e.g. the
Panda's ``"shelf_low_left->table_right"``).  Named sets ship in ``tpee_ompl/data/queries/``
(``panda_shelf``), read through :func:`tpee_ompl.resources.query_set_path`.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..files import atomic_write_text
from ..validation import as_float_array
from .queries import QuerySetError, check_set_model, query_entries, read_query_document
from .robot_checker import RobotChecker

__all__ = ["JOINT_FORMAT", "JointQuery", "load_joint_query_set", "save_joint_queries"]

JOINT_FORMAT = "joint_queries/1"
"""The ``format`` key of a joint query file (the wearer's sector files have none)."""


@dataclass(frozen=True, eq=False)
class JointQuery:
    """One query: ``start`` and ``goal`` are read-only float arrays of the same length."""

    id: int
    start: np.ndarray = field(repr=False)
    goal: np.ndarray = field(repr=False)
    label: str = ""

    def __post_init__(self) -> None:
        if isinstance(self.id, bool) or not isinstance(self.id, int):
            raise ValueError(f"query id must be an integer, got {self.id!r}")
        if not isinstance(self.label, str):
            raise ValueError(f"query {self.id}: label must be a string, got {self.label!r}")
        for name in ("start", "goal"):
            try:
                a = as_float_array(getattr(self, name), name).copy()
            except ValueError as exc:
                raise ValueError(f"query {self.id}: {name} must be finite numbers, got {getattr(self, name)!r}"[:300]) from exc
            if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)):
                raise ValueError(f"query {self.id}: {name} must be a non-empty list of finite numbers, got {a!r}")
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        if self.start.shape != self.goal.shape:
            raise ValueError(f"query {self.id}: start has {self.start.size} values but goal {self.goal.size}")

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        return {"id": self.id, "label": self.label, "start": self.start.tolist(), "goal": self.goal.tolist()}

    @classmethod
    def from_dict(cls, d: object) -> JointQuery:
        """Inverse of :meth:`to_dict`, strict about JSON types (raises :class:`QuerySetError`)."""
        if not isinstance(d, dict):
            raise QuerySetError(f"a query must be a JSON object, got {type(d).__name__}")
        keys = ("id", "label", "start", "goal")
        if set(d) != set(keys):
            raise QuerySetError(f"a query has exactly the fields {', '.join(keys)}; got {sorted(d)}")
        for name in ("start", "goal"):
            v = d[name]
            if not isinstance(v, list) or not all(type(x) in (int, float) for x in v):
                raise QuerySetError(f"field {name!r} must be a list of numbers, got {v!r}"[:300])
        try:
            return cls(d["id"], d["start"], d["goal"], d["label"])
        except ValueError as exc:
            raise QuerySetError(str(exc)) from None


def save_joint_queries(path: str | os.PathLike, queries: Sequence[JointQuery], *, name: str, seed: int,
                       checker: RobotChecker, extra: dict | None = None, force: bool = True) -> Path:
    """Write a joint query set (atomically): format, name, seed, model_hash, joint_names, queries (+ extra).

    Every query must have the checker's ``nq`` values; an existing file is replaced, or with ``force=False``
    refused (:class:`~tpee_ompl.files.OutputExistsError`)."""
    for q in queries:
        if q.start.size != checker.nq:
            raise ValueError(f"query {q.id} has {q.start.size} values, the checker {checker.nq}")
    doc = {"format": JOINT_FORMAT, "name": name, "seed": seed, "model_hash": checker.model_hash,
           "joint_names": list(checker.joint_names)}
    doc.update(extra or {})
    doc["queries"] = [q.to_dict() for q in queries]
    return atomic_write_text(path, json.dumps(doc, indent=1) + "\n", force=force)


def load_joint_query_set(name_or_path: str | os.PathLike,
                         checker: RobotChecker | None = None) -> tuple[list[JointQuery], dict]:
    """Queries and the file's header (everything but ``queries``) of a named set or a JSON file.

    With ``checker``, refuse a set made for another model (``model_hash`` differs).

    Raises FileNotFoundError (no such set or file) or :class:`QuerySetError` (a ValueError: not
    JSON, another format, malformed or duplicate queries, another model)."""
    p, doc = read_query_document(name_or_path)
    if not isinstance(doc, dict) or doc.get("format") != JOINT_FORMAT:
        got = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise QuerySetError(f"{p}: not a joint query set (format {got!r}, expected {JOINT_FORMAT!r})")
    queries = query_entries(p, doc, JointQuery.from_dict)
    if len({q.start.size for q in queries}) > 1:
        raise QuerySetError(f"{p}: queries have different numbers of joints")
    header = {k: v for k, v in doc.items() if k != "queries"}
    if checker is not None:
        check_set_model(p, header, checker.model_hash, "checker")
        if queries and queries[0].start.size != checker.nq:
            raise QuerySetError(f"{p}: queries have {queries[0].start.size} joints, the checker {checker.nq}")
    return queries, header
