"""Paths as OMPL sees them, in numpy: states <-> arrays, the states a motion check visits, the
whole-path check, lengths, resampling.

The one home of these conversions, of OMPL's subdivision rule (what ``DiscreteMotionValidator``
checks along a motion) and of the whole-path check (:func:`path_passes_motion_checks`, what
``og.PathGeometric.check`` does), so every planner, checker and experiment agrees on them.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from ompl import base as ob
from ompl import geometric as og

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

__all__ = [
    "MIN_JOINT_STEP",
    "array_to_path",
    "batched_motion_states",
    "bisection_levels",
    "bisection_order",
    "counted_motion_states",
    "motion_interior_states",
    "motion_is_valid",
    "motion_states",
    "motion_step",
    "path_length",
    "path_passes_motion_checks",
    "path_to_array",
    "planned_waypoints",
    "polyline_motion_states",
    "resample_waypoints",
    "set_state",
    "state_to_array",
    "states_to_array",
    "unchecked_motion_states",
]


def state_to_array(state: ob.State, n: int) -> np.ndarray:
    """Copy the first n values of a RealVector state into a numpy array."""
    return np.array([state[i] for i in range(n)], dtype=float)


def set_state(state: ob.State, values: Sequence[float]) -> ob.State:
    """Write values into a RealVector state and return it."""
    state[0 : len(values)] = [float(v) for v in values]
    return state


def path_to_array(
    path: og.PathGeometric, n: int, *, read: Callable[[ob.State], np.ndarray] | None = None
) -> np.ndarray:
    """Waypoints of a geometric path as an array (K, n).

    ``read(state) -> (n,)`` reads other state types (e.g. :meth:`RealVectorLayout.read` for a compound
    space); the default reads the first n values of a RealVector state.  Anything but a path first is a ValueError
    naming the order (``array_to_path`` takes the SpaceInformation first).
    """
    if not isinstance(path, og.PathGeometric):
        raise ValueError(f"path_to_array(path, n) takes an og.PathGeometric first, got {type(path).__name__} "
                         "(array_to_path is the one that takes the SpaceInformation first)")
    return states_to_array(path.getStates(), n, read=read)


def states_to_array(states: Sequence[ob.State], n: int, *,
                    read: Callable[[ob.State], np.ndarray] | None = None) -> np.ndarray:
    """OMPL states as an array (K, n): :func:`path_to_array` for states not in a path (a planner's data)."""
    if read is None:
        if len(states) and isinstance(states[0], ob.CompoundState):  # s[i] would read past its subspaces
            raise ValueError("path_to_array reads RealVector states; a CompoundStateSpace's need "
                             "read=RealVectorLayout(space).read")
        return np.array([[s[i] for i in range(n)] for s in states], dtype=float).reshape(-1, n)
    return np.array([read(s) for s in states], dtype=float).reshape(-1, n)


def array_to_path(
    si: ob.SpaceInformation, waypoints: np.ndarray, *, write: Callable[[ob.State, np.ndarray], object] | None = None
) -> og.PathGeometric:
    """An ``og.PathGeometric`` through the given (K, n) waypoints.

    ``write(state, values)`` writes other state types (e.g. :meth:`RealVectorLayout.write`); the
    default is :func:`set_state` (RealVector states).  It is given one state for every waypoint in turn
    (the path keeps a copy of each), and the waypoint as an array (n,).  Anything but a SpaceInformation first is a
    ValueError naming the order (``path_to_array`` takes the path first).
    """
    if not isinstance(si, ob.SpaceInformation):
        raise ValueError(f"array_to_path(si, waypoints) takes an ob.SpaceInformation first, got {type(si).__name__} "
                         "(path_to_array is the one that takes the path first)")
    W = np.asarray(waypoints, dtype=float)
    path = og.PathGeometric(si)
    s = si.allocState()  # one state written for each waypoint: PathGeometric.append keeps a copy
    if write is None:  # RealVector states: each row as plain floats in one slice assignment
        for w in W.tolist():
            s[0 : len(w)] = w
            path.append(s)
        return path
    for w in W:
        write(s, w)
        path.append(s)
    return path


def path_passes_motion_checks(
    si: ob.SpaceInformation,
    waypoints: og.PathGeometric | Sequence[ob.State] | np.ndarray,
    *,
    check_first: bool = True,
    segments: Sequence[int] | None = None,
    in_bounds: bool = False,
) -> bool:
    """OMPL's whole-path check: the first state is valid and every segment passes ``si.checkMotion``.

    Makes the calls ``og.PathGeometric.check()`` makes, in the same order: ``si.isValid`` of the
    first state, then ``si.checkMotion(w[k], w[k + 1])`` for k = 0 .. K-2, stopping at the first
    failure (so it agrees with ``check()`` and costs the same).  When the space's motion validator
    is the project's :class:`~tpee_ompl.planning.setup.BatchedMotionValidator` (``make_simple_setup``),
    the motions go through its ``check_motions`` instead: the same states ``checkMotion`` checks, in
    one batched call (a 61-waypoint path: one call instead of 60), without the early stop.  An empty path passes; the
    SpaceInformation is set up first if it is not (as ``check()`` does).  Neither checks the
    bounds (``si.satisfiesBounds``; ``in_bounds`` adds that) nor where the path starts or ends.

    Parameters
    ----------
    si : ob.SpaceInformation
    waypoints : og.PathGeometric, sequence of ob.State, or array (K, n)
        An array is written into states of a ``RealVectorStateSpace`` of dimension n (for other
        spaces pass states or a path).
    check_first : bool
        False skips ``si.isValid`` of the first state, for a caller that has just checked it
        (the motion checks never check a motion's first state).
    segments : sequence of int, optional
        Check only these segments (k: ``w[k] -> w[k + 1]``), for a caller that knows the others
        passed ``si.checkMotion`` already (dimension-RRT re-checks only the segments an improvement changed).
    in_bounds : bool
        Also require every state within the space's bounds (``si.satisfiesBounds``; a validity checker need
        not test them, and a path OMPL's planners return never leaves them): what the package's planners
        ask of a path before they post it.

    Raises
    ------
    ValueError
        An array that is not (K, n) with n the space's dimension, not finite, or given for a space
        that is not a ``RealVectorStateSpace``.
    """
    if isinstance(waypoints, og.PathGeometric):
        states = list(waypoints.getStates())
    elif not isinstance(waypoints, np.ndarray) and all(isinstance(w, ob.State) for w in waypoints):
        states = list(waypoints)
    else:
        space = si.getStateSpace()
        if not isinstance(space, ob.RealVectorStateSpace):
            raise ValueError(f"waypoints as an array need a RealVectorStateSpace, got {type(space).__name__}")
        try:
            W = np.asarray(waypoints, dtype=float)
        except (TypeError, ValueError):
            raise ValueError("waypoints must be a PathGeometric, a sequence of states or an array (K, n)") from None
        n = int(space.getDimension())
        if W.ndim != 2 or W.shape[1] != n:
            raise ValueError(f"waypoints must have shape (K, {n}), got {W.shape}")
        if not np.all(np.isfinite(W)):
            raise ValueError("waypoints contain NaN or inf")
        mv = si.getMotionValidator() if si.isSetup() else None
        if segments is None and len(W) > 1 and callable(getattr(mv, "check_motions", None)) \
                and callable(getattr(mv, "read_state", None)):
            # the project's validator takes the array as it is: no OMPL state per waypoint, written and read back
            if in_bounds:
                bounds, eps = space.getBounds(), np.finfo(float).eps  # satisfiesBounds' own tolerance
                if not (np.all(W - eps <= np.array(bounds.high)) and np.all(W + eps >= np.array(bounds.low))):
                    return False
            if check_first and not si.isValid(set_state(si.allocState(), W[0])):
                return False
            return bool(mv.check_motions(W[:-1], W[1:]).all())
        states = [set_state(si.allocState(), w) for w in W]
    if not si.isSetup():
        si.setup()
    if not states:
        return True
    if in_bounds and not all(si.satisfiesBounds(s) for s in states):
        return False
    if check_first and not si.isValid(states[0]):
        return False
    ks = range(len(states) - 1) if segments is None else list(segments)
    if not ks:
        return True
    mv = si.getMotionValidator()
    batched, read = getattr(mv, "check_motions", None), getattr(mv, "read_state", None)
    if callable(batched) and callable(read):
        # the project's BatchedMotionValidator: the same states checkMotion checks, in one batched call; only the
        # waypoints of the segments asked for are read (k and k + 1 stay neighbours in ``need``, which is sorted)
        need = sorted(set(ks).union(k + 1 for k in ks))
        row = {k: i for i, k in enumerate(need)}
        W = np.array([read(states[k]) for k in need], dtype=float)
        idx = np.array([row[k] for k in ks], dtype=np.intp)
        return bool(batched(W[idx], W[idx + 1]).all())
    return all(si.checkMotion(states[k], states[k + 1]) for k in ks)


MIN_JOINT_STEP = 1e-4
"""Radians. Smallest accepted motion-check step: finer steps make one motion check take millions of states."""


def _check_step(step: float) -> None:
    """Raise ValueError unless step is a finite number > 0 (a motion check's joint-space step)."""
    if not (isinstance(step, (int, float, np.integer, np.floating)) and math.isfinite(step) and step > 0):
        raise ValueError(f"step must be a finite number > 0, got {step!r}")


def motion_states(a: np.ndarray, b: np.ndarray, step: float, include_start: bool = False) -> np.ndarray:
    """States checked along the straight motion a -> b, as OMPL's DiscreteMotionValidator picks them.

    ``max(1, ceil(|b - a| / step))`` segments (one when a == b); the end state is included, the start only
    on request.

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
    _check_step(step)
    return unchecked_motion_states(a, b, step, include_start)


def unchecked_motion_states(a: np.ndarray, b: np.ndarray, step: float, include_start: bool = False,
                            factor: int = 1) -> np.ndarray:
    """:func:`motion_states` without its input checks, for inner loops whose ends are known finite
    float vectors of one length (a motion validator's OMPL states).  ``factor``: the space's
    ``validSegmentCountFactor`` f, so ``f * ceil(|b - a| / step)`` segments, as OMPL counts them."""
    d = b - a
    n = factor * max(1, math.ceil(math.sqrt(float(d @ d)) / step))
    S = a + (np.arange(0 if include_start else 1, n + 1) / n)[:, None] * d
    S[-1] = b  # b itself, as OMPL checks s2 (a + 1.0 * (b - a) can be an ulp past a joint limit b sits on)
    return S


def batched_motion_states(A: np.ndarray, B: np.ndarray, step: float, factor: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """:func:`motion_states` of the motions A[k] -> B[k] (K, n) at once: ``(states, counts)``, motion k's
    ``counts[k]`` states after motion k - 1's, each the same float as :func:`motion_states` gives
    (``factor`` as in :func:`unchecked_motion_states`).

    Raises
    ------
    ValueError
        If A or B is not finite, their shapes differ or are not (K, n), or step is not a finite number > 0.
    """
    A, B = np.asarray(A, dtype=float), np.asarray(B, dtype=float)
    if A.shape != B.shape or A.ndim != 2:
        raise ValueError(f"motion ends must be two (K, n) arrays of one shape, got shapes {A.shape} and {B.shape}")
    if not (np.isfinite(A).all() and np.isfinite(B).all()):
        raise ValueError("motion ends must be finite")
    _check_step(step)
    D = B - A
    n = straight_segment_counts(D, step, factor)
    S = counted_motion_states(A, D, n)
    S[np.cumsum(n) - 1] = B  # each motion's end is B[k] itself (see unchecked_motion_states)
    return S, n


_vecdot = getattr(np, "vecdot", None)  # numpy >= 2: each row's dot product as ``d @ d`` rounds it, in one call
_EXACT = 2.0**52  # float counts below this convert to int64 exactly


def straight_segment_counts(D: np.ndarray, step: float, factor: int = 1) -> np.ndarray:
    """Segments of each straight motion of displacement D[k] (K, n) at ``step``, as :func:`motion_states` counts
    them (one dot product per motion: the same rounding), times ``factor``.  Not validated (inner loops); a
    non-finite or astronomically long motion raises as ``math.ceil`` does (ValueError, OverflowError)."""
    if _vecdot is not None and len(D):
        q = np.maximum(1.0, np.ceil(np.sqrt(_vecdot(D, D)) / step))
        if (q * factor < _EXACT).all():
            return factor * q.astype(np.int64)
    return np.array([factor * max(1, math.ceil(math.sqrt(float(d @ d)) / step)) for d in D], dtype=np.int64)


def counted_motion_states(A: np.ndarray, D: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """The states ``A[k] + (j / counts[k]) D[k]``, j = 1 .. counts[k], of every motion k in motion order (its
    start excluded, its end ``A[k] + D[k]`` included; callers that have the end B[k] put it in that row, as OMPL
    checks the end state itself): :func:`batched_motion_states` once the counts are known.  Not validated (inner
    loops)."""
    if len(counts) == 0:
        return np.zeros((0, A.shape[-1]))
    ends = np.cumsum(counts)
    j = np.arange(1, int(ends[-1]) + 1) - np.repeat(ends - counts, counts)  # 1 .. counts[k] within motion k
    return np.repeat(A, counts, axis=0) + (j / np.repeat(counts, counts))[:, None] * np.repeat(D, counts, axis=0)


def motion_interior_states(
    A: np.ndarray, B: np.ndarray, step: float, lengths: np.ndarray | None = None, stride: int = 1,
    counts: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Interior states of the motions A[k] -> B[k] (K, n), as OMPL's discrete motion validator picks them.

    Motion k has ``n_k = max(1, ceil(d_k / step))`` segments, ``d_k`` being ``lengths[k]`` (the
    space's metric; default Euclidean ``|B[k] - A[k]|``), or ``counts[k]`` when given (OMPL's own
    ``validSegmentCount``).  Returns its interior states
    ``A[k] + (j / n_k)(B[k] - A[k])``, j = 1 .. n_k - 1 (only the multiples of ``stride``), for all
    motions at once, in motion order: ``(states (M, n), motion index k (M,), step index j (M,))``.
    Neither end is included (unlike :func:`motion_states`).  Not validated: it runs in planners' inner
    loops.
    """
    D = B - A
    if counts is not None:
        nd = np.asarray(counts).tolist()
    else:
        d = np.sqrt((D * D).sum(-1)) if lengths is None else lengths
        nd = np.maximum(1, np.ceil(d / step)).astype(int).tolist()
    js = [np.arange(stride, n, stride) for n in nd]  # a few motions per call: one small arange each
    idx = np.repeat(np.arange(len(A)), [len(x) for x in js])
    j = np.concatenate(js) if js else np.zeros(0, dtype=int)
    return A[idx] + (j / np.array(nd)[idx])[:, None] * D[idx], idx, j


def polyline_motion_states(path: np.ndarray, step: float) -> np.ndarray:
    """All states ``si.checkMotion`` checks along the polyline ``path`` (K, n), plus its first state:
    its first row, then :func:`batched_motion_states` of its segments (the states of :func:`motion_states`,
    OMPL's discrete motion validator, for every segment at once); shape (1 + sum n, n).
    """
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or len(path) < 1:
        raise ValueError(f"path must have shape (K >= 1, n); got {path.shape}")
    if len(path) == 1:
        if not np.isfinite(path).all():
            raise ValueError("motion ends must be finite")
        _check_step(step)
        return path.copy()
    states, _ = batched_motion_states(path[:-1], path[1:], step)
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


def motion_step(robot: WearerArm, step: float | None = None) -> float:
    """The joint-space step a motion of ``robot`` is checked at: ``step``, at most ``robot.max_joint_step()`` (the
    step the collision guarantee holds for; the default; no cap at a zero margin) and at least :data:`MIN_JOINT_STEP`.
    ValueError otherwise."""
    from ..validation import check_number

    own = robot.max_joint_step() if robot.security_margin > 0 else math.inf  # margin 0: no step is guaranteed
    if step is None and not math.isfinite(own):
        raise ValueError("security_margin is 0: the robot has no motion step of its own; give a step")
    step = own if step is None else min(check_number("step (radians)", step, low=MIN_JOINT_STEP), own)
    if step < MIN_JOINT_STEP:
        raise ValueError(f"the robot's motion step {step:.3g} rad (security margin {robot.security_margin:g} m) is "
                         f"below MIN_JOINT_STEP = {MIN_JOINT_STEP:g} rad: give a larger security_margin")
    return step


def motion_is_valid(robot: WearerArm, path: np.ndarray, step: float | None = None) -> bool:
    """True if the first state and every straight segment of ``path`` (K, nq) pass the motion check.

    Checks the states of :func:`~tpee_ompl.planning.paths.polyline_motion_states` (those ``si.checkMotion`` checks in a
    :func:`~tpee_ompl.planning.setup.make_simple_setup` setup at resolution :func:`motion_step` ``(robot, step)``)
    in ONE batched ``robot.are_valid`` call, after the waypoints alone: a path with a waypoint that is not finite
    or outside the joint limits is invalid at once (densifying a segment 1e6 rad long would fill the memory).
    """
    step = motion_step(robot, step)
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or len(path) < 1 or path.shape[1] != robot.nq:
        raise ValueError(f"path must have shape (K >= 1, {robot.nq}); got {path.shape}")
    if not np.isfinite(path).all() or not ((path >= robot.lower) & (path <= robot.upper)).all():
        return False  # (the waypoints' collision checks come with the motion's states)
    return bool(robot.are_valid(polyline_motion_states(path, step)).all())


def planned_waypoints(W: object, nq: int, who: str = "the planner") -> np.ndarray:
    """A planner callable's answer as a (K >= 2, nq) float array of finite numbers (a copy), else ValueError
    saying what ``who`` returned (the tracker's and the library's fallback planners are user code)."""
    try:
        path = np.array(W, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{who} returned {type(W).__name__}, not an array of waypoints") from None
    if path.ndim != 2 or path.shape[1] != nq or len(path) < 2:
        raise ValueError(f"{who} returned waypoints of shape {path.shape}, expected (K >= 2, {nq})")
    if not np.isfinite(path).all():
        raise ValueError(f"{who} returned waypoints that are not finite")
    return path


def path_length(path: np.ndarray) -> float:
    """Euclidean joint-space length of a polyline (K, n), radians (the setups' path-length objective).

    For a compound space's weighted metric see :meth:`~tpee_ompl.planning.space_layout.RealVectorLayout.path_length`.
    """
    return float(np.linalg.norm(np.diff(np.asarray(path, dtype=float), axis=0), axis=1).sum())


@functools.lru_cache(maxsize=256)
def bisection_levels(m: int) -> np.ndarray:
    """Level of each of m evenly spaced points in bisection order: the middle one 0, the middles of
    the two halves 1, and so on (OMPL's discrete motion validator visits a motion's states this way)."""
    levels = np.zeros(m, dtype=int)
    todo = [(0, m - 1, 0)]
    while todo:
        lo, hi, level = todo.pop()
        if lo <= hi:
            mid = (lo + hi) // 2
            levels[mid] = level
            todo += [(lo, mid - 1, level + 1), (mid + 1, hi, level + 1)]
    levels.setflags(write=False)  # cached: shared by every caller
    return levels


@functools.lru_cache(maxsize=256)
def bisection_order(m: int) -> np.ndarray:
    """Indices of m evenly spaced points in bisection order, level by level (the order OMPL's discrete motion
    validator checks a motion's states in, so that a collision is found after few of them)."""
    order = np.argsort(bisection_levels(m), kind="stable")
    order.setflags(write=False)  # cached: shared by every caller
    return order
