"""Shortcuts between fake-time waypoints: what dimension-RRT does after each improvement it accepts.

The paper's rule improves a waypoint only when a random sample happens to shorten the path there.
After such a sample, each intermediate waypoint ``W[t]`` can also move its values of the sample's
group straight towards the point that makes the path through its neighbours shortest: with the
waypoint's other DOFs fixed, ``|A - X| + |X - B|`` is least at the point of the segment ``A -> B``
(the group's DOFs) a fraction ``a / (a + b)`` along it, where ``a`` and ``b`` are the fixed DOFs'
distances to the neighbours (exact for the Euclidean metric; with no fixed DOF, the projection of
``W[t]`` onto the segment).  The length through the neighbours is convex along the way there, so each
fraction of the move shortens the path; the largest of :data:`SHORTCUT_FRACTIONS` whose waypoint and
both motions pass is taken, by the same checks as a sample's candidate.  One sweep can leave the
path short of what the next gives (a moved waypoint moves its neighbours' shortest points), so with a
prescribed group kept to the end the sweeps repeat (:func:`sweep_until_settled`) while each still
shortens the path by :data:`SWEEP_MIN_GAIN` of its length, at most :data:`MAX_SWEEPS` times.  A waypoint that lands on its
neighbours' segment in every DOF can never move again by the paper's rule (nothing is shorter there),
which is why :class:`~tpee_ompl.planning.dimension_rrt.DimensionRRT` uses them by default only with a
prescribed group.  Measured in ``docs/dimension_rrt.md`` ("Shortcuts between fake-time waypoints").

Without a prescribed group (the released search) two waypoints can also collapse onto each other, and
the step between them is then wasted: :func:`respread_candidate` drops the inner one and puts its step
on the longest segment (:func:`~tpee_ompl.planning.layered_trees.spread_waypoints`), a path no longer
than before that the search keeps once it passes.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from .layered_trees import spread_waypoints

if TYPE_CHECKING:  # pragma: no cover
    from .space_layout import RealVectorLayout
    from .search_checker import Checker

__all__ = ["COLLAPSED_FRACTION", "MAX_SWEEPS", "SHORTCUT_FRACTIONS", "SWEEP_MIN_GAIN", "respread_candidate",
           "shortcut_targets", "shortcut_waypoints", "sweep_until_settled"]

SHORTCUT_FRACTIONS = (1.0, 0.5, 0.25)
"""Fractions of the way to the shortest point tried, largest first (the first that passes is kept)."""
MAX_SWEEPS = 8
"""Most sweeps in a row after one improvement when the rows are kept to the end (a search whose rows are or
will be released sweeps once)."""
SWEEP_MIN_GAIN = 0.003
"""Another sweep follows only while the last one shortened the path by at least this fraction of it."""
COLLAPSED_FRACTION = 0.1
"""A segment shorter than this fraction of the path's mean segment has collapsed (its step is wasted)."""


def shortcut_targets(A: np.ndarray, X: np.ndarray, B: np.ndarray, dims: np.ndarray, layout: RealVectorLayout) -> np.ndarray:
    """For each row of X (m, n): X with its DOFs ``dims`` moved to where the path A -> X -> B is shortest
    while X's other DOFs stay (exact for the Euclidean metric; differences the short way round for SO2)."""
    dAX, dXB, dAB = layout.delta(A, X), layout.delta(X, B), layout.delta(A, B)
    fixed = np.ones(X.shape[1], dtype=bool)
    fixed[dims] = False
    a = np.linalg.norm(dAX[:, fixed], axis=1)
    b = np.linalg.norm(dXB[:, fixed], axis=1)
    seg = dAB[:, dims]
    proj = np.clip((dAX[:, dims] * seg).sum(axis=1) / np.maximum((seg * seg).sum(axis=1), 1e-300), 0.0, 1.0)
    f = np.where(a + b > 1e-12, a / np.maximum(a + b, 1e-300), proj)
    T = X.copy()
    T[:, dims] = A[:, dims] + f[:, None] * seg
    return layout.wrap(T)


def shortcut_waypoints(W: np.ndarray, L: np.ndarray, dims: np.ndarray, layout: RealVectorLayout, checker: Checker,
                       dirty: np.ndarray | None = None, screen_only: bool = False,
                       stop: Callable[[], bool] | None = None) -> int:
    """Move the intermediate waypoints of the valid path W (h, n) towards their shortest points, in place.

    The odd steps go first, then the even ones, so no two neighbours move at once (the motion between
    them would be unchecked).  ``L`` (h - 1,) holds the segment lengths and is kept up to date; a
    waypoint moves only when the path gets shorter and the candidate and both its motions are valid,
    so W stays a valid path (``screen_only``: its moves pass their candidate screens only, see
    :meth:`~tpee_ompl.planning.search_checker.Checker.candidates`).  ``dirty`` (h,) bool, updated in
    place: only the waypoints marked are tried (the others, with themselves and their neighbours where
    they were when last tried, get the same candidates; with full checks also the same verdicts, while
    a screen's verdict can depend on whether the candidate was screened alone or with others); a tried
    waypoint is unmarked, and a moved one marks itself and its neighbours.  ``stop()`` (the planner's termination
    condition) is asked before each batch of candidates is checked: once it holds, the sweep ends where it is (W
    stays a valid path).  Returns the number of waypoints moved."""
    moved = 0
    for first in (1, 2):
        ts = np.arange(first, len(W) - 1, 2)
        if dirty is not None:
            ts = ts[dirty[ts]]
            dirty[ts] = False
        if not len(ts):
            continue
        A, X, B = W[ts - 1], W[ts].copy(), W[ts + 1]
        T = shortcut_targets(A, X, B, dims, layout)
        todo = np.ones(len(ts), dtype=bool)
        for fraction in SHORTCUT_FRACTIONS:
            C = layout.interpolate(X, T, np.full(len(ts), fraction))
            dl, dr = layout.distance(A, C), layout.distance(C, B)
            sel = np.flatnonzero(todo & (dl + dr < L[ts - 1] + L[ts] - 1e-12))
            if not len(sel):
                break
            if stop is not None and stop():
                return moved
            yes = np.ones(len(sel), dtype=bool)
            vc, left, right = checker.candidates(C[sel], A[sel], B[sel], yes, yes, yes, screen_only=screen_only)
            for k in sel[vc & left & right]:
                t = ts[k]
                W[t] = C[k]
                L[t - 1], L[t] = dl[k], dr[k]
                todo[k] = False
                moved += 1
                if dirty is not None:
                    dirty[t - 1 : t + 2] = True
    return moved


def sweep_until_settled(W: np.ndarray, L: np.ndarray, dims: np.ndarray, layout: RealVectorLayout, checker: Checker,
                        max_sweeps: int | None = None, stop: Callable[[], bool] | None = None) -> int:
    """:func:`shortcut_waypoints` again while the last sweep moved a waypoint and shortened the path by at
    least :data:`SWEEP_MIN_GAIN` of its length, at most ``max_sweeps`` (default :data:`MAX_SWEEPS`) sweeps.

    Each sweep after the first tries only the waypoints that moved or whose neighbours moved since they
    were last tried.  With a batched checker and more than one sweep, a move is taken on its screen
    (the candidate and every 4th or 8th state of its motions) and the motions that changed are checked in
    full once, at the end: a waypoint often moves several times, and its passing motions need no full
    check.  If one of them fails, W goes back to where it was and the sweeps run again with every move
    checked in full.  ``stop()`` (the planner's termination condition) is asked before each batch of candidates
    and after each sweep: once it holds, no further candidates are tried (a failed final check then leaves W where
    it was).  Returns the number
    of waypoint moves; W stays a valid path."""
    n = MAX_SWEEPS if max_sweeps is None else max_sweeps
    lazy = n > 1 and checker.batched
    W0, L0 = (W.copy(), L.copy()) if lazy else (W, L)
    moved = _sweeps(W, L, dims, layout, checker, n, lazy, stop)
    if lazy and moved:
        k = np.flatnonzero((W[:-1] != W0[:-1]).any(axis=1) | (W[1:] != W0[1:]).any(axis=1))
        if not checker.check_motions(W[:-1][k], W[1:][k]).all():
            W[:], L[:] = W0, L0
            moved = 0 if stop is not None and stop() else _sweeps(W, L, dims, layout, checker, n, False, stop)
    return moved


def _sweeps(W: np.ndarray, L: np.ndarray, dims: np.ndarray, layout: RealVectorLayout, checker: Checker, n: int,
            screen_only: bool, stop: Callable[[], bool] | None) -> int:
    """Up to n sweeps of :func:`shortcut_waypoints` for :func:`sweep_until_settled`, moves taken on their
    screens when ``screen_only``."""
    moved = 0
    dirty = np.ones(len(W), dtype=bool)
    for _ in range(n):
        before = float(L.sum())
        m = shortcut_waypoints(W, L, dims, layout, checker, dirty, screen_only, stop)
        moved += m
        if not m or before - float(L.sum()) < SWEEP_MIN_GAIN * before or (stop is not None and stop()):
            break
    return moved


def respread_candidate(W: np.ndarray, L: np.ndarray, layout: RealVectorLayout) -> np.ndarray | None:
    """The path W (h, n) (segment lengths L) with a collapsed waypoint's step moved to its longest segment,
    or None when no segment is shorter than :data:`COLLAPSED_FRACTION` of the mean.

    Of the shortest segment's inner ends, the one whose neighbours are closest is dropped (the path
    only gets shorter, by the triangle inequality), and the step goes onto the segment whose pieces
    are longest (the geometry does not change there).  The caller checks the new waypoint and motions."""
    if len(W) < 3 or not L.min() < COLLAPSED_FRACTION * L.mean():
        return None
    k = int(np.argmin(L))
    i = min((i for i in (k, k + 1) if 0 < i < len(W) - 1), key=lambda i: float(layout.distance(W[i - 1], W[i + 1])))
    S = W.copy()
    S[i] = S[i - 1]  # held: spread_waypoints hands the step to the longest segment
    out = spread_waypoints(S, layout.interpolate, layout.distance)
    return None if out is S else out
