"""The fake-time, DOF-grouped view of an OMPL problem used by dimension-RRT (paper sec. 4.1.2).

A path is a stack of ``h`` full configurations ("fake-time" waypoints, rows 0 and ``h-1`` being the
start and goal).  The DOFs are split into ordered groups; group ``i`` with ``k_i`` DOFs has a
*path-space point* made of its values at the ``h-2`` intermediate steps, an array of
``(h-2) * k_i`` numbers.  A group can be *prescribed*: its ``(h, k_i)`` values are given (Table 3
for DOF1/DOF2 in the TPEE case) and never planned.

The grouped view lives alongside an ordinary OMPL state space, a ``RealVectorStateSpace`` or a
compound of them: :class:`GroupedSpace` only reads and writes states of that space, so native
planners (RRT*, ...) run on exactly the same ``SpaceInformation`` with the same validity checker,
bounds, metric and motion-check resolution.

Metric
------
Path length is measured with the state space's own ``distance``, which
:meth:`~tpee_ompl.planning.space_layout.RealVectorLayout.distance` reproduces in numpy: the Euclidean norm
of the joint differences for a ``RealVectorStateSpace`` (radians for the wearer arm), and the weighted sum of the subspaces' Euclidean norms for a compound
space.  It is the metric of ``ob.PathLengthOptimizationObjective`` and of ``PathGeometric.length``,
so every planner is scored with it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..validation import check_int
from .space_layout import RealVectorLayout

__all__ = [
    "GroupedSpace",
    "default_groups",
    "group_lists",
    "validate_groups",
    "validate_prescribed",
    "interpolate_waypoints",
    "refine_waypoints",
    "MAX_H",
]

MAX_H = 10_000
"""Largest number of fake-time steps accepted (the paper uses 7); bounds memory per path."""
_BOUND_TOL = 1e-12
"""How far a given waypoint value may lie outside the bounds (rounding)."""


def default_groups(n: int) -> list[list[int]]:
    """Default DOF groups: consecutive pairs ``[[0, 1], [2, 3], ...]``, a last singleton for odd n."""
    if n < 1:
        raise ValueError(f"the space must have at least one dimension, got {n}")
    return [list(range(i, min(i + 2, n))) for i in range(0, n, 2)]


def group_lists(groups: Sequence[Sequence[int]]) -> list[list[int]]:
    """Check the form of ``groups`` (non-empty lists of distinct non-negative DOF indices, no index in two
    groups) without knowing the space; return them as lists of int (numpy arrays accepted).

    Raises
    ------
    ValueError
        On an empty group, an index that is not a non-negative integer, or an index in two groups.
    """
    if isinstance(groups, np.ndarray):
        groups = groups.tolist()
    if isinstance(groups, (str, bytes)) or not isinstance(groups, Sequence) or len(groups) == 0:
        raise ValueError(f"groups must be a non-empty list of lists of DOF indices, got {groups!r}")
    out: list[list[int]] = []
    seen: dict[int, int] = {}
    for gi, group in enumerate(groups):
        if isinstance(group, np.ndarray) and group.ndim == 1:
            group = group.tolist()
        if isinstance(group, (str, bytes)) or not isinstance(group, Sequence) or len(group) == 0:
            raise ValueError(f"group {gi} must be a non-empty list of DOF indices, got {group!r}")
        g: list[int] = []
        for d in group:
            if isinstance(d, bool) or not isinstance(d, (int, np.integer)):
                raise ValueError(f"group {gi}: DOF index {d!r} is not an integer")
            d = int(d)
            if d < 0:
                raise ValueError(f"group {gi}: DOF index {d} is negative")
            if d in seen:
                raise ValueError(f"DOF index {d} appears twice in group {gi}" if seen[d] == gi else
                                 f"DOF index {d} appears in more than one group ({seen[d]} and {gi}): groups overlap")
            seen[d] = gi
            g.append(d)
        out.append(g)
    return out


def validate_groups(groups: Sequence[Sequence[int]], n: int) -> list[list[int]]:
    """Check that groups partition ``range(n)``; return them as lists of int.

    Raises
    ------
    ValueError
        On an empty group, an index out of range, an index in two groups or an index in none.
    """
    out = group_lists(groups)
    seen = {d for g in out for d in g}
    for gi, g in enumerate(out):
        for d in g:
            if d >= n:
                raise ValueError(f"group {gi}: DOF index {d} is out of range for a {n}-D space")
    missing = sorted(set(range(n)) - seen)
    if missing:
        raise ValueError(f"DOF indices {missing} are in no group: groups must cover all {n} DOFs")
    return out


def validate_prescribed(
    prescribed: Mapping[int, np.ndarray] | None, groups: Sequence[Sequence[int]], h: int,
    layout: RealVectorLayout | None = None,
) -> dict[int, np.ndarray]:
    """Check prescribed group trajectories: keys are group indices, values arrays (h, k_i), finite, and with
    ``layout`` within the space's bounds (a path along them must stay in the space; SO2 values are wrapped
    into [-pi, pi) first, as the space itself would)."""
    if prescribed is None:
        return {}
    if not isinstance(prescribed, Mapping):
        raise ValueError(f"prescribed must be a dict {{group index: array (h, k)}}, got {type(prescribed).__name__}")
    out: dict[int, np.ndarray] = {}
    for key, value in prescribed.items():
        if isinstance(key, bool) or not isinstance(key, (int, np.integer)) or not 0 <= int(key) < len(groups):
            raise ValueError(f"prescribed key {key!r} is not a group index (0..{len(groups) - 1})")
        k = len(groups[int(key)])
        try:
            arr = np.array(value, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"prescribed trajectory of group {int(key)} is not an array of numbers: {exc}") from exc
        if arr.ndim == 1 and k == 1:
            arr = arr[:, None]
        if arr.shape != (h, k):
            raise ValueError(f"prescribed trajectory of group {int(key)} must have shape ({h}, {k}), got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            bad = arr[~np.isfinite(arr)][0]
            raise ValueError(f"prescribed trajectory of group {int(key)} contains {bad} (NaN or inf)")
        if layout is not None:
            dims = list(groups[int(key)])
            full = np.zeros((h, layout.n))
            full[:, dims] = arr
            arr = layout.wrap(full)[:, dims]
            lower, upper = layout.lower, layout.upper
            out_of = (arr < lower[dims] - _BOUND_TOL) | (arr > upper[dims] + _BOUND_TOL)
            if out_of.any():
                t, j = (int(v) for v in np.argwhere(out_of)[0])
                raise ValueError(f"prescribed trajectory of group {int(key)} leaves the space's bounds: step {t}, "
                                 f"DOF {dims[j]} = {float(arr[t, j])!r} is outside [{lower[dims[j]]:g}, "
                                 f"{upper[dims[j]]:g}]")
            arr = np.clip(arr, lower[dims], upper[dims])  # within _BOUND_TOL: on the bound, where OMPL accepts it
        arr.setflags(write=False)
        out[int(key)] = arr
    return out


def interpolate_waypoints(start: np.ndarray, goal: np.ndarray, h: int) -> np.ndarray:
    """``h`` evenly spaced waypoints on the straight line start -> goal, shape (h, n), ends included."""
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    s = np.linspace(0.0, 1.0, h)[:, None]
    return start + s * (goal - start)


def refine_waypoints(W: np.ndarray, layout: RealVectorLayout) -> np.ndarray:
    """W (h, n) with the midpoint of every segment inserted (in the space's geodesic): (2h - 1, n)."""
    out = np.empty((2 * len(W) - 1, W.shape[1]))
    out[0::2] = W
    out[1::2] = layout.interpolate(W[:-1], W[1:], np.full(len(W) - 1, 0.5))
    return out


class GroupedSpace:
    """A fake-time, DOF-grouped description of a problem over an OMPL RealVector(-compound) space.

    Parameters
    ----------
    space : ob.StateSpace or ob.SpaceInformation
        The ordinary OMPL space the problem is defined on.
    groups : list of lists of int, optional
        DOF indices per group, in planning order (default :func:`default_groups`).
    h : int
        Number of fake-time steps including start and goal (default 7: start, 5 intermediate, goal).
    prescribed : dict {group index: array (h, k_i)}, optional
        Group trajectories taken as given, start and goal rows included (e.g. Table 3).

    Raises
    ------
    ValueError
        Bad groups (overlap, missing or out-of-range DOF), ``h < 3``, badly shaped prescribed rows.
    """

    def __init__(
        self,
        space: ob.StateSpace | ob.SpaceInformation,
        groups: Sequence[Sequence[int]] | None = None,
        h: int = 7,
        prescribed: Mapping[int, np.ndarray] | None = None,
    ) -> None:
        if isinstance(space, ob.SpaceInformation):
            space = space.getStateSpace()
        self.layout = RealVectorLayout(space)
        n = self.layout.n
        self.h = check_int("h (fake-time steps incl. start and goal)", h, minimum=3, maximum=MAX_H)
        self.groups = validate_groups(default_groups(n) if groups is None else groups, n)
        self.prescribed = validate_prescribed(prescribed, self.groups, self.h, self.layout)
        self.planned = [g for g in range(len(self.groups)) if g not in self.prescribed]
        """Indices of the groups to plan, in planning order."""
        self._dims = [np.array(g, dtype=int) for g in self.groups]
        self._bounds = [(self.layout.lower[d], self.layout.upper[d]) for d in self._dims]
        for d in self._dims:
            d.setflags(write=False)
        for lo, hi in self._bounds:
            lo.setflags(write=False)
            hi.setflags(write=False)
        planned = [self._dims[g] for g in self.planned]
        self.planned_dims = np.sort(np.concatenate(planned)) if planned else np.zeros(0, int)
        """The planned groups' DOF indices together, in index order (read-only)."""
        self.planned_dims.setflags(write=False)
        self._steps = np.linspace(0.0, 1.0, self.h)  # the fake-time steps' fractions of the straight start -> goal
        self._steps.setflags(write=False)

    @property
    def n(self) -> int:
        """Dimension of the full configuration."""
        return self.layout.n

    def group_dims(self, g: int) -> np.ndarray:
        """DOF indices of group g, int array (k_g,), read-only."""
        return self._dims[g]

    def group_bounds(self, g: int) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds (k_g,) of group g, read-only."""
        return self._bounds[g]

    def check_initial(self, W: np.ndarray | None) -> np.ndarray | None:
        """A first guess of the path, W (h, n), as a float array: finite and within the bounds (None passes)."""
        if W is None:
            return None
        layout = self.layout
        try:
            arr = np.array(W, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"initial_waypoints must be a numeric array of shape ({self.h}, {layout.n})") from None
        if arr.shape != (self.h, layout.n):
            raise ValueError(f"initial_waypoints must have shape ({self.h}, {layout.n}), got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError("initial_waypoints contains NaN or inf")
        arr = layout.wrap(arr)  # SO2 values into [-pi, pi), as the space keeps them (atan2 gives +pi)
        if np.any(arr < layout.lower - _BOUND_TOL) or np.any(arr > layout.upper + _BOUND_TOL):
            raise ValueError("initial_waypoints lie outside the state space bounds")
        return np.clip(arr, layout.lower, layout.upper)  # within _BOUND_TOL: on the bound, where OMPL accepts it

    def endpoint_mismatch(self, start: np.ndarray, goal: np.ndarray, tol: float = 1e-6) -> str | None:
        """None if start/goal lie on every prescribed trajectory, else "start" or "goal"."""
        start, goal = np.asarray(start), np.asarray(goal)
        for g, traj in self.prescribed.items():
            d = self._dims[g]
            if abs(traj[0] - start[d]).max() > tol:
                return "start"
            if abs(traj[-1] - goal[d]).max() > tol:
                return "goal"
        return None

    def initial_waypoints(self, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """Initial path (h, n): prescribed groups as given, the others linear from start to goal."""
        W = self.layout.interpolate(start, goal, self._steps)
        for g, traj in self.prescribed.items():
            W[:, self.group_dims(g)] = traj
        W[0], W[-1] = start, goal
        return W

    def refined(self, start: np.ndarray, goal: np.ndarray) -> GroupedSpace:
        """The same problem with ``2h - 1`` fake-time steps: a step is inserted halfway between every
        two.  Prescribed trajectories keep their rows at the even steps and get the midpoints (their
        polyline is unchanged, so a Table 3 row still prescribes the same motion)."""
        W = refine_waypoints(self.initial_waypoints(start, goal), self.layout)
        prescribed = {g: W[:, self.group_dims(g)] for g in self.prescribed}
        return GroupedSpace(self.layout.space, self.groups, 2 * self.h - 1, prescribed)

    def released(self) -> GroupedSpace:
        """The same steps with every DOF in one planned group (no prescribed rows): what the search
        continues in once ``release_after`` lets a converged path leave its prescribed rows (each sample
        then moves a waypoint in all DOFs at once, as a path pressed against an obstacle needs)."""
        return GroupedSpace(self.layout.space, [list(range(self.layout.n))], self.h)

    def group_point(self, W: np.ndarray, g: int) -> np.ndarray:
        """Path-space point of group g: its values at the h-2 intermediate steps, flat ((h-2) k_g,)."""
        return np.asarray(W)[1:-1][:, self.group_dims(g)].reshape(-1).copy()

    def with_group_point(self, W: np.ndarray, g: int, x: np.ndarray) -> np.ndarray:
        """Copy of W (h, n) whose intermediate group-g values are the path-space point x."""
        d = self.group_dims(g)
        x = np.asarray(x, dtype=float)
        if x.shape != ((self.h - 2) * len(d),):
            raise ValueError(f"path-space point of group {g} must have shape ({(self.h - 2) * len(d)},), got {x.shape}")
        out = np.array(W, dtype=float, copy=True)
        out[1:-1, d] = x.reshape(self.h - 2, len(d))
        return out

    def to_path(self, si: ob.SpaceInformation, W: np.ndarray) -> og.PathGeometric:
        """``og.PathGeometric`` through the waypoints W (h, n)."""
        return self.layout.to_path(si, W)

    def from_path(self, path: og.PathGeometric) -> np.ndarray:
        """Waypoints (K, n) of an ``og.PathGeometric``."""
        return self.layout.from_path(path)

    def path_length(self, W: np.ndarray) -> float:
        """Length of the waypoint polyline in the space's metric (see module docstring)."""
        return self.layout.path_length(W)
