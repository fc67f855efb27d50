"""Paths as OMPL sees them, in numpy: states <-> arrays, the states a motion check visits, lengths, resampling.

The one home of these conversions and of OMPL's subdivision rule (what ``DiscreteMotionValidator``
checks along a motion), so every planner, checker and experiment agrees on them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from ompl import base as ob
from ompl import geometric as og

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

__all__ = [
    "MIN_JOINT_STEP",
    "array_to_path",
    "motion_is_valid",
    "motion_states",
    "path_length",
    "path_to_array",
    "polyline_motion_states",
    "resample_waypoints",
    "set_state",
    "state_to_array",
]


def state_to_array(state: ob.State, n: int) -> np.ndarray:
    """Copy the first n values of a RealVector state into a numpy array."""
    return np.array([state[i] for i in range(n)], dtype=float)


def set_state(state: ob.State, values: Sequence[float]) -> ob.State:
    """Write values into a RealVector state and return it."""
    state[0 : len(values)] = [float(v) for v in values]
    return state


def path_to_array(path: og.PathGeometric, n: int) -> np.ndarray:
    """Waypoints of a geometric path as an array (K, n)."""
    return np.array([[s[i] for i in range(n)] for s in path.getStates()], dtype=float)


def array_to_path(si: ob.SpaceInformation, waypoints: np.ndarray) -> og.PathGeometric:
    """An ``og.PathGeometric`` through the given (K, n) waypoints."""
    path = og.PathGeometric(si)
    for w in np.asarray(waypoints, dtype=float):
        s = si.allocState()
        set_state(s, w)
        path.append(s)
    return path


MIN_JOINT_STEP = 1e-4
"""Radians. Smallest accepted motion-check step: finer steps make one motion check take millions of states."""


def motion_states(a: np.ndarray, b: np.ndarray, step: float, include_start: bool = False) -> np.ndarray:
    """States checked along the straight motion a -> b, as OMPL's DiscreteMotionValidator picks them.

    ``ceil(|b - a| / step)`` segments; the end state is included, the start only on request.

    Raises
    ------
    ValueError
        If a or b is not finite, their shapes differ, or step is not a finite number > 0.
    """
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape or a.ndim != 1:
        raise ValueError(f"motion ends must be two vectors of the same length, got shapes {a.shape} and {b.shape}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError(f"motion ends must be finite, got {a} -> {b}")
    if not (isinstance(step, (int, float, np.integer, np.floating)) and math.isfinite(step) and step > 0):
        raise ValueError(f"step must be a finite number > 0, got {step!r}")
    n = max(1, math.ceil(float(np.linalg.norm(b - a)) / step))
    t = np.arange(0 if include_start else 1, n + 1) / n
    return a + t[:, None] * (b - a)


def polyline_motion_states(path: np.ndarray, step: float) -> np.ndarray:
    """All states ``si.checkMotion`` checks along the polyline ``path`` (K, n), plus its first state.

    For each segment a -> b: ``n = max(1, ceil(|b - a| / step))`` states ``a + (k / n)(b - a)``,
    k = 1..n, exactly those of :func:`motion_states` (OMPL's discrete motion validator), built
    for all segments at once; shape (1 + sum n, n).
    """
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or len(path) < 1:
        raise ValueError(f"path must have shape (K >= 1, n); got {path.shape}")
    if not step > 0:
        raise ValueError(f"step must be > 0, got {step!r}")
    delta = np.diff(path, axis=0)
    if len(delta) == 0:
        return path[:1].copy()
    counts = np.maximum(1, np.ceil(np.linalg.norm(delta, axis=1) / step)).astype(np.int64)
    seg = np.repeat(np.arange(len(delta)), counts)
    k = np.arange(1, counts.sum() + 1) - np.repeat(np.cumsum(counts) - counts, counts)
    states = path[seg] + (k / counts[seg])[:, None] * delta[seg]
    return np.vstack([path[:1], states])


def resample_waypoints(waypoints: np.ndarray, per_step: int = 100) -> np.ndarray:
    """Put ``per_step`` samples on each straight segment, quintic in fake time; shape ((S-1) per_step + 1, n).

    Every sample lies on the segment between its two waypoints (same geometry as the input path).
    """
    W = np.asarray(waypoints, dtype=float)
    if W.ndim != 2 or W.shape[0] < 2:
        raise ValueError(f"waypoints must have shape (S >= 2, n); got {W.shape}")
    if per_step < 1:
        raise ValueError(f"per_step must be >= 1, got {per_step}")
    u = np.arange(per_step) / per_step
    s = u**3 * (10.0 - 15.0 * u + 6.0 * u**2)
    seg = W[:-1, None, :] + s[None, :, None] * (W[1:] - W[:-1])[:, None, :]
    return np.vstack([seg.reshape(-1, W.shape[1]), W[-1:]])


def motion_is_valid(robot: WearerArm, path: np.ndarray, step: float | None = None) -> bool:
    """True if the first state and every straight segment of ``path`` (K, 4) pass the motion check.

    Checks the states of :func:`~tpee_ompl.planning.paths.polyline_motion_states` (those ``si.checkMotion`` checks in a
    :func:`~tpee_ompl.planning.setup.make_simple_setup` setup at resolution ``step``, default
    ``robot.max_joint_step()``) in ONE batched ``robot.are_valid`` call.
    """
    step = robot.max_joint_step() if step is None else float(step)
    return bool(robot.are_valid(polyline_motion_states(path, step)).all())


def path_length(path: np.ndarray) -> float:
    """Euclidean joint-space length of a polyline (K, n), radians (the setups' path-length objective)."""
    return float(np.linalg.norm(np.diff(np.asarray(path, dtype=float), axis=0), axis=1).sum())
