"""Evaluating a path library on a query set: one row per query (outcome, times, validity, lengths)."""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from ..planning.paths import motion_is_valid, path_length
from .demos import Plan
from .path_library import PathLibrary

__all__ = ["benchmark_queries"]


def benchmark_queries(
    library: PathLibrary,
    queries: Sequence,
    reference: Plan | None = None,
) -> list[dict]:
    """One row per query (objects with start, goal, from_sector, to_sector, id), ready for a DataFrame.

    Columns: ``pair``, ``id``, ``outcome``, ``query_s`` (whole :meth:`PathLibrary.query`, with
    validation, repair and fallback), ``generation_s`` (nearest demo + its DMP path, no check),
    ``raw_valid`` (that path passed the motion check), ``candidates_tried`` (demonstrations' paths the query
    generated and checked), ``length`` (rad, joint-space), and with a
    ``reference`` planner ``ref_length`` and ``length_ratio`` (NaN when either has no path).
    """
    rows = []
    step = library.robot.max_joint_step()
    for q in queries:
        i, j = int(q.from_sector), int(q.to_sector)
        start, goal = np.asarray(q.start, dtype=float), np.asarray(q.goal, dtype=float)
        t0 = time.perf_counter()
        k = int(library.demo_order(start, goal, i, j)[0])
        raw = library.generate(start, goal, i, j, k, stride=library.query_stride)
        gen_s = time.perf_counter() - t0
        raw_valid = motion_is_valid(library.robot, raw, step)
        res = library.query(start, goal, i, j)
        length = path_length(res.path) if res.path is not None else float("nan")
        row = {"pair": f"{i}->{j}", "id": int(getattr(q, "id", len(rows))), "outcome": res.outcome,
               "query_s": res.seconds, "generation_s": gen_s, "raw_valid": bool(raw_valid),
               "candidates_tried": res.candidates_tried, "length": length}
        if reference is not None:
            W = reference(start, goal, i, j)
            ref = path_length(W) if W is not None else float("nan")
            row.update(ref_length=ref, length_ratio=length / ref if ref > 0 else float("nan"))
        rows.append(row)
    return rows
