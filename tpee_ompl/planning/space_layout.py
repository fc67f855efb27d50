"""Reading and measuring the states of an OMPL space in numpy: a RealVector or SO2 space, or a compound of them.

:class:`RealVectorLayout` flattens a state into one vector (subspaces in order, an SO2 leaf one angle) and
reproduces the space's own ``distance``, ``interpolate`` and bounds, so that the planners here work on
arrays and agree with what OMPL measures and checks.
"""

from __future__ import annotations

import math

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from .paths import array_to_path, path_to_array

__all__ = ["RealVectorLayout", "MAX_BOUND"]

MAX_BOUND = 1e100
"""Largest bound magnitude of a RealVector DOF accepted: beyond it squared distances overflow to inf."""


class RealVectorLayout:
    """Reads and writes states of a RealVector or SO2 space, or of a (nested) compound of them.

    The flat vector of a state concatenates its subspaces' values in subspace order; an SO2 leaf is
    one value in [-pi, pi) (a continuous joint).  Differences, distances and interpolation go
    through the space's own rules: an SO2 value moves the short way round (wrap-around), as
    ``SO2StateSpace.distance``/``interpolate`` do.

    Parameters
    ----------
    space : ob.StateSpace
        ``ob.RealVectorStateSpace`` (with bounds), ``ob.SO2StateSpace`` or an ``ob.CompoundStateSpace``
        whose leaves are those.

    Raises
    ------
    ValueError
        For any other space type (SE3, SO3, ...; the message names it), or a RealVector space
        without finite bounds (``low < high`` for every dimension).
    """

    def __init__(self, space: ob.StateSpace) -> None:
        self.space = space
        # leaves: (access path of subspace indices, dimension, weight, is SO2)
        self._leaves: list[tuple[tuple[int, ...], int, float, bool]] = []
        lows: list[float] = []
        highs: list[float] = []
        self._collect(space, (), 1.0, lows, highs)
        self.n = sum(d for _, d, _, _ in self._leaves)
        self.lower = np.array(lows, dtype=float)
        self.upper = np.array(highs, dtype=float)
        self.lower.setflags(write=False)
        self.upper.setflags(write=False)
        bounds = np.cumsum([0] + [d for _, d, _, _ in self._leaves])
        self._slices = [slice(int(bounds[i]), int(bounds[i + 1])) for i in range(len(self._leaves))]
        self._weights = np.array([w for _, _, w, _ in self._leaves])
        self._leaf_starts = np.array([sl.start for sl in self._slices], dtype=np.intp)
        self.circular = np.zeros(self.n, dtype=bool)
        """True for the SO2 (wrap-around) entries of the flat vector."""
        for (_, _, _, so2), sl in zip(self._leaves, self._slices):
            self.circular[sl] = so2
        self.circular.setflags(write=False)
        self.has_circular = bool(self.circular.any())
        self.is_plain = (len(self._leaves) == 1 and self._leaves[0][0] == () and self._weights[0] == 1.0
                         and not self.has_circular)
        """A single RealVector space: the metric is the plain Euclidean norm."""

    def layout_changed(self, space: ob.StateSpace) -> bool:
        """Whether ``space``'s bounds, subspace weights or subspaces differ from those this layout was built with
        (OMPL's planners read them at each solve).  For a single RealVector space a read of its bounds; otherwise
        a new layout compared."""
        if self.is_plain and isinstance(space, ob.RealVectorStateSpace):
            b = space.getBounds()
            return list(b.low) != self.lower.tolist() or list(b.high) != self.upper.tolist()
        layout = RealVectorLayout(space)
        return not (layout._leaves == self._leaves and np.array_equal(layout.lower, self.lower)
                    and np.array_equal(layout.upper, self.upper))

    def _collect(self, space: ob.StateSpace, path: tuple[int, ...], weight: float, lows: list, highs: list) -> None:
        if isinstance(space, ob.RealVectorStateSpace):
            if space.getDimension() == 0:
                return  # holds no value (and would give an empty leaf to the metric's reduceat)
            b = space.getBounds()
            lo, hi = [float(v) for v in b.low], [float(v) for v in b.high]
            # a dimension of width 0 is a joint locked this way: it keeps its value, as OMPL's samplers keep it
            bad = [i for i in range(len(lo)) if not (math.isfinite(lo[i]) and math.isfinite(hi[i]) and lo[i] <= hi[i])]
            where = f" (subspace {list(path)})" if path else ""
            if not any(lo + hi):  # OMPL's RealVectorBounds start at 0 and 0: none were set
                raise ValueError(f"RealVectorStateSpace{where} has no bounds (every low and high is 0): call "
                                 "space.setBounds(low, high) first")
            if bad:
                raise ValueError(f"RealVectorStateSpace{where} has no valid bounds for dimension(s) {bad} (low must be "
                                 "<= high, both finite): call space.setBounds(low, high) first")
            if all(a == b for a, b in zip(lo, hi)):
                raise ValueError(f"RealVectorStateSpace{where} has bounds of width 0 for every dimension: nothing in "
                                 "it can move (and OMPL's motion checks divide by its extent); leave it out of the "
                                 "space")
            huge = [i for i in range(len(lo)) if max(abs(lo[i]), abs(hi[i])) > MAX_BOUND]
            if huge:
                raise ValueError(f"RealVectorStateSpace{where} has bounds beyond +/-{MAX_BOUND:g} for dimension(s) {huge}: "
                                 "distances would overflow (rescale the coordinates)")
            self._leaves.append((path, int(space.getDimension()), weight, False))
            lows.extend(lo)
            highs.extend(hi)
        elif isinstance(space, ob.SO2StateSpace):
            self._leaves.append((path, 1, weight, True))
            lows.append(-math.pi)
            highs.append(math.pi)
        elif isinstance(space, ob.CompoundStateSpace) and type(space) is ob.CompoundStateSpace:
            for k in range(space.getSubspaceCount()):
                self._collect(space.getSubspace(k), path + (k,), weight * space.getSubspaceWeight(k), lows, highs)
        else:
            where = f" (subspace {list(path)})" if path else ""
            raise ValueError(
                f"dimension-RRT supports RealVectorStateSpace, SO2StateSpace and compounds of them; "
                f"got {type(space).__name__}{where}"
            )

    def _leaf(self, state: ob.State, path: tuple[int, ...]) -> ob.State:
        for k in path:
            state = state[k]
        return state

    def read(self, state: ob.State) -> np.ndarray:
        """The state's values as a flat array (n,)."""
        out = np.empty(self.n)
        for (path, d, _, so2), sl in zip(self._leaves, self._slices):
            leaf = self._leaf(state, path)
            out[sl] = [leaf.value] if so2 else [leaf[i] for i in range(d)]
        return out

    def write(self, state: ob.State, values: np.ndarray | list[float]) -> ob.State:
        """Write a flat array (n,) or list of floats into the state; return the state."""
        if self.is_plain:  # the state is the RealVector state itself: one slice assignment
            state[0 : self.n] = values if type(values) is list else np.asarray(values, dtype=float).tolist()
            return state
        values = np.asarray(values, dtype=float)
        for (path, d, _, so2), sl in zip(self._leaves, self._slices):
            if so2:
                self._leaf(state, path).value = float(values[sl][0])
            else:
                self._leaf(state, path)[0:d] = [float(v) for v in values[sl]]
        return state

    def wrap(self, X: np.ndarray, dims: np.ndarray | None = None) -> np.ndarray:
        """X (..., n) with its SO2 entries brought into [-pi, pi) (unchanged without SO2 leaves).  ``dims``: X holds
        only these entries of the flat vector, in this order (default: all of them)."""
        if not self.has_circular:
            return X
        circular = self.circular if dims is None else self.circular[dims]
        X = np.array(X, dtype=float, copy=True)
        C = np.mod(X[..., circular] + math.pi, 2.0 * math.pi) - math.pi
        C[C >= math.pi] -= 2.0 * math.pi  # rounding can give +pi, outside SO2's bounds
        X[..., circular] = C
        return X

    def delta(self, A: np.ndarray, B: np.ndarray, dims: np.ndarray | None = None) -> np.ndarray:
        """B - A, with SO2 entries taken the short way round (in [-pi, pi]; exactly half a turn keeps its sign, as
        ``SO2StateSpace`` interpolates).  ``dims``: A and B hold only
        these entries of the flat vector, in this order (default: all of them)."""
        D = np.asarray(B, dtype=float) - np.asarray(A, dtype=float)
        if self.has_circular:
            circular = self.circular if dims is None else self.circular[dims]
            raw = D[..., circular]
            short = np.mod(raw + math.pi, 2.0 * math.pi) - math.pi
            short[(short == -math.pi) & (raw > 0)] = math.pi  # half a turn: the + way, as SO2StateSpace.interpolate
            D[..., circular] = short
        return D

    def interpolate(self, A: np.ndarray, B: np.ndarray, t: np.ndarray | float) -> np.ndarray:
        """The state a fraction t of the way from A to B along the space's geodesic (wrap-around for SO2)."""
        t = np.asarray(t, dtype=float)
        return self.wrap(np.asarray(A, dtype=float) + t[..., None] * self.delta(A, B) if t.ndim else
                         np.asarray(A, dtype=float) + float(t) * self.delta(A, B))

    def distance(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """The space's metric between rows of A and B (..., n), as ``si.distance`` computes it."""
        D = self.delta(A, B)
        if self.is_plain:
            return np.sqrt(np.einsum("...i,...i->...", D, D))
        return self._leaf_norms(D) @ self._weights

    def _leaf_norms(self, D: np.ndarray) -> np.ndarray:
        """Per leaf, the Euclidean norm of its entries of D (..., n): shape (..., leaves)."""
        return np.sqrt(np.add.reduceat(D * D, self._leaf_starts, axis=-1))

    def leaf_extents(self) -> np.ndarray:
        """Per subspace (leaf), its ``getMaximumExtent()``: the diagonal of a RealVector leaf's bounds, pi for SO2."""
        return np.array([math.pi if so2 else float(np.linalg.norm(self.upper[sl] - self.lower[sl]))
                         for (_, _, _, so2), sl in zip(self._leaves, self._slices)])

    def leaf_distances(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Per subspace (leaf), its own distance between rows of A and B: shape (..., leaves), unweighted."""
        return self._leaf_norms(self.delta(A, B))

    def path_length(self, W: np.ndarray) -> float:
        """Length of the polyline through waypoints W (K, n) in the space's metric."""
        return float(self.distance(W[:-1], W[1:]).sum()) if len(W) > 1 else 0.0

    def to_path(self, si: ob.SpaceInformation, W: np.ndarray) -> og.PathGeometric:
        """An ``og.PathGeometric`` through the waypoints W (K, n)."""
        return array_to_path(si, W) if self.is_plain else array_to_path(si, W, write=self.write)

    def from_path(self, path: og.PathGeometric) -> np.ndarray:
        """Waypoints of a geometric path, shape (K, n)."""
        return path_to_array(path, self.n, read=self.read)
