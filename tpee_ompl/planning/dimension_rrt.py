"""Dimension-RRT (Zou et al. 2022, sec. 4.1.2) as an OMPL planner.

The path is ``h`` fake-time waypoints (see :mod:`tpee_ompl.planning.grouped_space`).  Groups of DOFs are
handled in order; a prescribed group (Table 3 for DOF1/DOF2) is taken as given.  For a planned group
each iteration draws ONE ``k_i``-dimensional sample ``c`` and tries it at every intermediate step
``t``: the candidate waypoint is ``W[t]`` with the group's values replaced by ``c``.

Improvement (the paper's rule, on a valid path): ``W[t]`` is replaced by the candidate iff the
path gets shorter, the candidate is valid and both motions to ``W[t-1]`` and ``W[t+1]`` are valid.
The cost test (``|W[t-1]-c| + |c-W[t+1]| < |W[t-1]-W[t]| + |W[t]-W[t+1]|`` in the space's metric)
runs first and costs no collision check.  Steps are tried in turn ``t = 1 .. h-2``; two neighbouring
steps are never both replaced by one sample (the motion between them was not checked).

Feasibility phase (before the first valid path; the paper leaves it open): a forward tree from the
start and a backward tree from the goal whose depth-t nodes are waypoints of step t (only the
current group varies).  They are seeded with the valid prefix and suffix of the initial path
(prescribed groups as given, the others linear).  The sample is tried at every step t: connected to
the nearest forward node of step t-1 it joins the forward tree, to the nearest backward node of
step t+1 the backward tree, to both and the path is complete.  Every node is valid and reached by
a valid motion, so two neighbouring waypoints that both start in collision cannot deadlock it (the
literal rule needs both motions valid, impossible when both neighbours collide).  Half of its
samples are Gaussian around a random tree node (sigma log-uniform in 1-10 % of the bound widths) so
the trees grow out of narrow pockets; the other half are uniform.

Narrowing: once a valid path exists and the group has drawn ``narrow_after`` samples, 90 % of the
samples come from the bounding box of the current path's group values (all ``h`` steps), padded
by ``max(range_, span * narrowing ** (m / 100))`` (``span``: the group's bound widths; ``m``:
samples since narrowing started) and clipped to the bounds; 10 % stay uniform over the bounds.

Batching: the candidate waypoints of one sample and their motions go through the validity
checker's batched ``are_valid(Q)`` when it has one (two calls per sample at most: candidates plus
every 8th interior motion state, then the remaining interior states of the survivors); otherwise
per-state ``si.isValid`` and per-motion ``si.checkMotion``.  Motion states are those OMPL's
discrete motion validator checks.  An exact solution is reported only after every segment of the
final path passed ``si.checkMotion``.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from ompl import base as ob

from ..validation import check_bool, check_int, check_name, check_number
from .grouped_space import GroupedSpace, RealVectorLayout

__all__ = ["DimensionRRT", "DimensionRRTOptions"]

log = logging.getLogger(__name__)

_COARSE_STRIDE = 8
"""First pass over a motion checks every 8th interior state (collisions span many states)."""
_UNIFORM_FRACTION = 0.1
"""Share of samples drawn uniformly over the bounds once the sampling region has narrowed."""
_NARROWING_UNIT = 100
"""The narrowing factor applies per this many samples."""
_GROUP_BLOCK = 100
"""With several planned groups, each gets this many consecutive samples in turn."""
_REPAIR_FRACTION = 0.5
"""Share of repair samples while no valid path exists."""
_REPAIR_SIGMA = (0.01, 0.1)
"""Repair samples: Gaussian around a waypoint, sigma log-uniform in this range times the bound widths."""
_PROGRESS_PERIOD = 0.01
"""Seconds between progress-trace entries (OMPL's benchmark records progress about as often)."""


def _status(code: Any) -> ob.PlannerStatus:
    return ob.PlannerStatus(code)


class _Checker:
    """Validity of states and motions for one SpaceInformation, batched when the setup allows it."""

    def __init__(self, si: ob.SpaceInformation, layout: RealVectorLayout, batch: bool) -> None:
        self.si = si
        self.layout = layout
        svc = si.getStateValidityChecker()
        mv = si.getMotionValidator()
        are_valid = getattr(svc, "are_valid", None)
        self.step: float | None = None
        self.euclid = True
        if batch and callable(are_valid):
            factor = max(1, int(si.getStateSpace().getValidSegmentCountFactor()))
            if isinstance(getattr(mv, "step", None), float) and callable(getattr(mv, "check_motions", None)):
                # BatchedMotionValidator: Euclidean, ceil(|b-a| / step) segments (step / factor)
                self.step = float(mv.effective_step()) if callable(getattr(mv, "effective_step", None)) else mv.step
            elif type(mv) is ob.MotionValidator:  # the C++ default, DiscreteMotionValidator
                self.step = float(si.getStateSpace().getLongestValidSegmentLength()) / factor
                self.euclid = layout.is_plain
        self.batched = self.step is not None
        self._are_valid = are_valid if self.batched else None
        counter_owner = getattr(svc, "robot", svc)
        self._counter_owner = counter_owner if isinstance(getattr(counter_owner, "collision_checks", None), int) else None
        self.own_checks = 0
        self._longest = float(si.getStateSpace().getLongestValidSegmentLength())
        self._s1, self._s2 = si.allocState(), si.allocState()

    def counter(self) -> int:
        """Configurations checked so far (the robot's counter when available, else our own count)."""
        return self._counter_owner.collision_checks if self._counter_owner is not None else self.own_checks

    def states(self, Q: np.ndarray) -> np.ndarray:
        """Validity of configurations Q (m, n)."""
        if len(Q) == 0:
            return np.zeros(0, dtype=bool)
        self.own_checks += len(Q)
        if self._are_valid is not None:
            return np.asarray(self._are_valid(Q), dtype=bool)
        s = self._s1
        out = np.empty(len(Q), dtype=bool)
        for k, q in enumerate(Q):
            self.layout.write(s, q)
            out[k] = self.si.isValid(s)
        return out

    def interior(self, A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Interior states of motions A[k] -> B[k]: (states (M, n), motion index (M,), step index j >= 1)."""
        d = np.sqrt(((B - A) ** 2).sum(-1)) if self.euclid else self.layout.distance(A, B)
        nd = np.maximum(1, np.ceil(d / self.step)).astype(int)
        cnt = nd - 1
        total = int(cnt.sum())
        idx = np.repeat(np.arange(len(A)), cnt)
        j = np.arange(total) - np.repeat(np.cumsum(cnt) - cnt, cnt) + 1
        frac = j / nd[idx]
        return A[idx] + frac[:, None] * (B[idx] - A[idx]), idx, j

    def motions(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Validity of the interiors of motions A[k] -> B[k] (ends not checked), one call when batched."""
        K = len(A)
        if K == 0:
            return np.zeros(0, dtype=bool)
        if self.batched:
            S, idx, _ = self.interior(A, B)
            ok = self.states(S)
            return np.bincount(idx[~ok], minlength=K) == 0
        out = np.empty(K, dtype=bool)
        for k in range(K):
            out[k] = self._check_motion(A[k], B[k])
        return out

    def _check_motion(self, a: np.ndarray, b: np.ndarray) -> bool:
        self.layout.write(self._s1, a)
        self.layout.write(self._s2, b)
        self.own_checks += max(1, math.ceil(float(self.layout.distance(a, b)) / self._longest))
        return bool(self.si.checkMotion(self._s1, self._s2))

    def candidates(
        self, C: np.ndarray, A: np.ndarray, B: np.ndarray, left_known: np.ndarray, right_known: np.ndarray, strict: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Evaluate candidate waypoints C (m, n) between neighbours A and B (m, n).

        ``left_known[k]`` / ``right_known[k]`` false means that neighbour is invalid, so that motion is
        invalid without a check.  For ``strict[k]`` candidates only all-valid matters, so the second
        motion is not finished once one fails.  Returns validity of C, of A->C and of C->B (ends incl.).
        """
        m = len(C)
        vc = self.states(C) if not self.batched else None
        if self.batched:
            # pass 1: candidate states + every 8th interior state of motions whose other end is valid
            SL, iL, jL = self.interior(A, C)
            SR, iR, jR = self.interior(C, B)
            cL, cR = (jL % _COARSE_STRIDE == 0) & left_known[iL], (jR % _COARSE_STRIDE == 0) & right_known[iR]
            ok = self.states(np.concatenate([C, SL[cL], SR[cR]]))
            vc = ok[:m]
            nl = int(cL.sum())
            badL = np.bincount(iL[cL][~ok[m : m + nl]], minlength=m) > 0
            badR = np.bincount(iR[cR][~ok[m + nl :]], minlength=m) > 0
            goL = vc & left_known & ~badL
            goR = vc & right_known & ~badR
            both = goL & goR
            goL &= both | ~strict
            goR &= both | ~strict
            # pass 2: the remaining interior states of motions still in question
            fL, fR = ~cL & goL[iL], ~cR & goR[iR]
            ok2 = self.states(np.concatenate([SL[fL], SR[fR]]))
            nl2 = int(fL.sum())
            left = goL & (np.bincount(iL[fL][~ok2[:nl2]], minlength=m) == 0)
            right = goR & (np.bincount(iR[fR][~ok2[nl2:]], minlength=m) == 0)
            return vc, left, right
        left = np.zeros(m, dtype=bool)
        right = np.zeros(m, dtype=bool)
        for k in range(m):
            if not vc[k]:
                continue
            if left_known[k]:
                left[k] = self._check_motion(A[k], C[k])
            if right_known[k] and (left[k] or not strict[k]):
                right[k] = self._check_motion(C[k], B[k])
        return vc, left, right


class _Search:
    """The dimension-RRT iteration on a waypoint array; OMPL-free apart from the checker."""

    def __init__(
        self,
        grouped: GroupedSpace,
        checker: _Checker,
        rng: np.random.Generator,
        start: np.ndarray,
        goal: np.ndarray,
        narrow_after: int,
        narrowing: float,
        range_: np.ndarray,
        initial: np.ndarray | None = None,
    ) -> None:
        self.g = grouped
        self.checker = checker
        self.rng = rng
        self.narrow_after = narrow_after
        self.narrowing = narrowing
        self.range_ = range_
        self.dist = grouped.layout.distance
        W = grouped.initial_waypoints(start, goal)
        if initial is not None:
            for gi in grouped.planned:
                d = grouped.group_dims(gi)
                W[1:-1, d] = initial[1:-1, d]
        self.W = W
        V = np.ones(len(W), dtype=bool)
        V[1:-1] = checker.states(W[1:-1])
        self.V = V
        self.E = V[:-1] & V[1:]
        self.E[self.E] = checker.motions(W[:-1][self.E], W[1:][self.E])
        self.L = self.dist(W[:-1], W[1:])
        self.samples = 0
        self.group_samples = {gi: 0 for gi in grouped.planned}
        self.narrow_start: dict[int, int | None] = {gi: None for gi in grouped.planned}
        self._dims = {gi: grouped.group_dims(gi) for gi in grouped.planned}
        self._bounds = {gi: grouped.group_bounds(gi) for gi in grouped.planned}
        self._tree: _LayeredTrees | None = None
        self._uniform = np.empty((0, 0))
        self._normal = np.empty((0, 0))
        self._ui = 0

    @property
    def valid(self) -> bool:
        return bool(self.V.all() and self.E.all())

    @property
    def cost(self) -> float:
        return float(self.L.sum())

    def _next_random(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Buffered randomness for one sample: 3 + k uniforms and k standard normals."""
        if self._ui >= len(self._uniform) or self._uniform.shape[1] != k + 3:
            self._uniform = self.rng.random((1024, k + 3))
            self._normal = self.rng.standard_normal((1024, k))
            self._ui = 0
        i = self._ui
        self._ui += 1
        return self._uniform[i], self._normal[i]

    def current_group(self) -> int:
        planned = self.g.planned
        return planned[(self.samples // _GROUP_BLOCK) % len(planned)]

    def draw(self, gi: int) -> np.ndarray:
        """One k_i-dimensional sample for group gi: repair, narrowed or uniform (module docstring)."""
        d = self._dims[gi]
        lo, hi = self._bounds[gi]
        u, z = self._next_random(len(d))
        span = hi - lo
        valid = self.valid
        if not valid and u[0] < _REPAIR_FRACTION and self._tree is not None:
            anchor = self._tree.anchor(u[1])
            sigma = span * _REPAIR_SIGMA[0] * (_REPAIR_SIGMA[1] / _REPAIR_SIGMA[0]) ** u[2]
            return np.clip(anchor + sigma * z, lo, hi)
        n0 = self.narrow_start[gi]
        if n0 is None and valid and self.group_samples[gi] >= self.narrow_after:
            n0 = self.narrow_start[gi] = self.group_samples[gi]
        if n0 is not None and u[0] >= _UNIFORM_FRACTION:
            m = self.group_samples[gi] - n0
            pad = np.maximum(self.range_[gi], span * self.narrowing ** (m / _NARROWING_UNIT))
            vals = self.W[:, d]
            lo = np.maximum(lo, vals.min(axis=0) - pad)
            hi = np.minimum(hi, vals.max(axis=0) + pad)
        return lo + u[3:] * (hi - lo)

    def iterate(self) -> int:
        """Draw one sample for the current group and try it at every intermediate step.

        Returns the number of waypoints changed (feasibility phase: 1 when the layered trees
        connected, 0 otherwise).
        """
        gi = self.current_group()
        valid = self.valid
        if not valid and (self._tree is None or self._tree.group != gi):
            self._tree = _LayeredTrees(self, gi)
        c = self.draw(gi)
        self.samples += 1
        self.group_samples[gi] += 1
        return self._improve(gi, c) if valid else self._grow(c)

    def _grow(self, c: np.ndarray) -> int:
        """Feasibility phase: extend the forward/backward layered trees with the sample c."""
        tree = self._tree
        d = tree.dims
        h = self.g.h
        ts, fi, bi = [], [], []
        for t in range(1, h - 1):
            f = tree.fwd[t - 1].nearest(c)
            b = tree.bwd[t + 1].nearest(c)
            if f >= 0 or b >= 0:
                ts.append(t)
                fi.append(f)
                bi.append(b)
        if not ts:
            return 0
        ts_a = np.array(ts)
        C = self.W[ts_a].copy()
        C[:, d] = c
        A = self.W[ts_a - 1].copy()
        B = self.W[ts_a + 1].copy()
        for k, t in enumerate(ts):
            if fi[k] >= 0:
                A[k, d] = tree.fwd[t - 1].values[fi[k]]
            if bi[k] >= 0:
                B[k, d] = tree.bwd[t + 1].values[bi[k]]
        has_f, has_b = np.array(fi) >= 0, np.array(bi) >= 0
        vc, left, right = self.checker.candidates(C, A, B, has_f, has_b, np.zeros(len(ts), dtype=bool))
        for k, t in enumerate(ts):
            if not vc[k]:
                continue
            if left[k] and right[k]:
                self._adopt(tree.path(t, c, fi[k], bi[k]))
                self._tree = None
                return 1
            if left[k]:
                tree.fwd[t].add(c, fi[k])
            if right[k]:
                tree.bwd[t].add(c, bi[k])
        return 0

    def _adopt(self, W: np.ndarray) -> None:
        """Take W (h, n), checked by the trees, as the current (valid) path."""
        self.W[:] = W
        self.V[:] = True
        self.E[:] = True
        self.L[:] = self.dist(W[:-1], W[1:])

    def _improve(self, gi: int, c: np.ndarray) -> int:
        """Paper's rule on a valid path: replace W[t] when valid, connected and shorter."""
        d = self._dims[gi]
        W, V, E, L = self.W, self.V, self.E, self.L
        C = W[1:-1].copy()
        C[:, d] = c
        A, B = W[:-2], W[2:]
        dl, dr = self.dist(A, C), self.dist(C, B)
        shorter = dl + dr < L[:-1] + L[1:] - 1e-12
        if not shorter.any():
            return 0
        ts = np.flatnonzero(shorter)
        yes = np.ones(len(ts), dtype=bool)
        vc, left, right = self.checker.candidates(C[ts], A[ts], B[ts], yes, yes, yes)
        ok = vc & left & right
        accepted = 0
        last = -2
        for k in np.flatnonzero(ok):
            t = int(ts[k]) + 1
            if t == last + 1:
                continue
            W[t] = C[t - 1]
            L[t - 1], L[t] = dl[t - 1], dr[t - 1]
            accepted += 1
            last = t
        return accepted


class _Layer:
    """Nodes of one fake-time layer of a layered tree: group values and parent indices."""

    def __init__(self, k: int) -> None:
        self.values = np.empty((16, k))
        self.parents: list[int] = []

    def __len__(self) -> int:
        return len(self.parents)

    def add(self, x: np.ndarray, parent: int) -> None:
        n = len(self.parents)
        if n == len(self.values):
            self.values = np.concatenate([self.values, np.empty_like(self.values)])
        self.values[n] = x
        self.parents.append(parent)

    def nearest(self, x: np.ndarray) -> int:
        """Index of the node closest to x (group values, Euclidean), -1 if empty."""
        n = len(self.parents)
        if n == 0:
            return -1
        D = self.values[:n] - x
        return int(np.argmin(np.einsum("ij,ij->i", D, D)))


class _LayeredTrees:
    """Feasibility phase: a forward tree from the start and a backward tree from the goal whose
    depth-t nodes are waypoints of fake-time step t (only the current group varies; the other DOFs
    are those of the current path at that step).  Every node is valid and connected to its parent
    by a valid motion, so there is no deadlock between neighbouring invalid waypoints.  Seeded with
    the valid prefix and suffix of the current path."""

    def __init__(self, search: _Search, gi: int) -> None:
        self.group = gi
        self.dims = d = search._dims[gi]
        self.base = search.W.copy()
        h = len(self.base)
        self.fwd = [_Layer(len(d)) for _ in range(h)]
        self.bwd = [_Layer(len(d)) for _ in range(h)]
        V, E, W = search.V, search.E, search.W
        self.fwd[0].add(W[0, d], -1)
        t = 1
        while t < h - 1 and V[t] and E[t - 1]:
            self.fwd[t].add(W[t, d], 0)
            t += 1
        self.bwd[h - 1].add(W[h - 1, d], -1)
        t = h - 2
        while t > 0 and V[t] and E[t]:
            self.bwd[t].add(W[t, d], 0)
            t -= 1

    def anchor(self, u: float) -> np.ndarray:
        """Group values of a tree node picked by u in [0, 1): a uniform layer, then a uniform node."""
        layers = [layer for layer in (*self.fwd, *self.bwd) if len(layer)]
        x = u * len(layers)
        layer = layers[int(x)]
        return layer.values[int((x - int(x)) * len(layer))]

    def path(self, t: int, c: np.ndarray, f: int, b: int) -> np.ndarray:
        """The waypoints (h, n) through forward node f at t-1, c at t, backward node b at t+1."""
        W = self.base.copy()
        d = self.dims
        W[t, d] = c
        for s in range(t - 1, -1, -1):
            W[s, d] = self.fwd[s].values[f]
            f = self.fwd[s].parents[f]
        for s in range(t + 1, len(W)):
            W[s, d] = self.bwd[s].values[b]
            b = self.bwd[s].parents[b]
        return W


@dataclass(frozen=True)
class DimensionRRTOptions:
    """Settings of :class:`DimensionRRT`, checked once here.

    Attributes
    ----------
    groups : sequence of sequences of int, optional
        DOF indices per group in planning order (default ``[[0, 1], [2, 3]]`` for 4-D, else pairs).
    h : int
        Fake-time steps including start and goal (default 7, the length of the Table 3 rows).
    max_samples : int, optional
        Stop after this many samples even if the termination condition still allows time.
    seed : int, optional
        Seed of the planner's own ``np.random.Generator`` (OMPL's seed does not cover it).
    narrow_after : int
        Samples of a group (and a valid path) before its sampling region narrows (default 200).
    narrowing : float in (0, 1]
        Factor by which the padding of the narrowed region shrinks every 100 samples (default 0.5).
    range_ : float or sequence of float, optional
        Smallest padding of the narrowed region, in the DOFs' units (default 2 % of each bound width).
    name : str
        Planner name (``geometric_<name>`` in a Benchmark database).
    batch : bool
        Use the checker's batched ``are_valid`` when it has one (default True).
    """

    groups: Sequence[Sequence[int]] | None = None
    h: int = 7
    max_samples: int | None = None
    seed: int | None = None
    narrow_after: int = 200
    narrowing: float = 0.5
    range_: float | Sequence[float] | None = None
    name: str = "DimensionRRT"
    batch: bool = True

    def __post_init__(self) -> None:
        check_name("name", self.name)
        set_ = lambda field_, value: object.__setattr__(self, field_, value)  # noqa: E731 (frozen dataclass)
        set_("max_samples", check_int("max_samples", self.max_samples, minimum=1, optional=True))
        set_("seed", check_int("seed", self.seed, minimum=0, optional=True))
        set_("narrow_after", check_int("narrow_after", self.narrow_after, minimum=0))
        set_("narrowing", check_number("narrowing", self.narrowing, low=0.0, high=1.0, low_open=True))
        set_("batch", check_bool("batch", self.batch))
        if self.range_ is not None:
            try:
                arr = np.asarray(self.range_, dtype=float)
            except (TypeError, ValueError):
                arr = None
            if arr is None or arr.ndim > 1 or arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
                raise ValueError(f"range_ must be a positive number or array, got {self.range_!r}")


def _resolve_options(options: DimensionRRTOptions | None, overrides: Mapping[str, Any]) -> DimensionRRTOptions:
    """``options`` (default settings if None) with the keyword overrides applied, validated."""
    if options is None:
        options = DimensionRRTOptions()
    elif not isinstance(options, DimensionRRTOptions):
        raise ValueError(f"options must be a DimensionRRTOptions, got {type(options).__name__}")
    return dataclasses.replace(options, **overrides) if overrides else options


class DimensionRRT(ob.Planner):
    """Dimension-RRT (paper sec. 4.1.2): anytime, fake-time, DOF-grouped path optimisation.

    Parameters
    ----------
    si : ob.SpaceInformation
        A RealVector space, or a compound of RealVector spaces.
    options : DimensionRRTOptions, optional
        The planner's settings (defaults if omitted).
    prescribed : dict {group index: array (h, k_i)}, optional
        Group trajectories taken as given, start and goal rows included (``{0: Table 3 row}``).
    initial_waypoints : array (h, n), optional
        A first guess of the path (e.g. a DMP path from :mod:`tpee_ompl.library.path_library`): the
        planned groups' intermediate waypoints start there instead of on the straight line
        (see :meth:`set_initial_waypoints`).
    **overrides
        Fields of :class:`DimensionRRTOptions` replacing those of ``options``
        (``DimensionRRT(si, max_samples=500, seed=1)``); an unknown name raises ``TypeError``.

    Raises
    ------
    ValueError
        Overlapping, missing or out-of-range DOF indices, ``h < 3``, ``max_samples < 1``, bad
        ``narrowing``/``narrow_after``/``range_``, or a space that is not RealVector-based.
    TypeError
        An override that is not a field of :class:`DimensionRRTOptions`.
    """

    def __init__(
        self,
        si: ob.SpaceInformation,
        options: DimensionRRTOptions | None = None,
        *,
        prescribed: Mapping[int, np.ndarray] | None = None,
        initial_waypoints: np.ndarray | None = None,
        **overrides: Any,
    ) -> None:
        # Validate everything BEFORE super().__init__: an exception raised after it leaves a
        # half-constructed nanobind trampoline whose collection crashed the interpreter.
        opts = _resolve_options(options, overrides)
        if not isinstance(si, ob.SpaceInformation):
            raise ValueError(f"si must be an ompl.base.SpaceInformation, got {type(si).__name__}")
        grouped = GroupedSpace(si, opts.groups, opts.h, prescribed)
        layout = grouped.layout
        span = layout.upper - layout.lower
        if opts.range_ is None:
            rng_full = 0.02 * span
        else:
            arr = np.asarray(opts.range_, dtype=float)
            if arr.ndim > 1 or (arr.ndim == 1 and len(arr) != layout.n):
                raise ValueError(f"range_ must be a positive number or array of {layout.n}, got {opts.range_!r}")
            rng_full = np.broadcast_to(arr, (layout.n,)).copy()
        initial = self._check_initial(grouped, initial_waypoints)
        super().__init__(si, opts.name)
        self.options = opts
        self.grouped = grouped
        self.h = self.grouped.h
        self.groups = self.grouped.groups
        self.prescribed = self.grouped.prescribed
        self.max_samples = opts.max_samples
        self.seed = opts.seed
        self.narrow_after = opts.narrow_after
        self.narrowing = opts.narrowing
        self.range_ = rng_full
        self.batch = opts.batch
        self._rng = np.random.default_rng(opts.seed)
        self._stats: dict[str, Any] = self._empty_stats()
        self._ranges = {gi: rng_full[self.grouped.group_dims(gi)] for gi in self.grouped.planned}
        self._initial = initial

    @staticmethod
    def _check_initial(grouped: GroupedSpace, W: np.ndarray | None) -> np.ndarray | None:
        if W is None:
            return None
        layout = grouped.layout
        try:
            arr = np.array(W, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"initial_waypoints must be a numeric array of shape ({grouped.h}, {layout.n})") from None
        if arr.shape != (grouped.h, layout.n):
            raise ValueError(f"initial_waypoints must have shape ({grouped.h}, {layout.n}), got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError("initial_waypoints contains NaN or inf")
        if np.any(arr < layout.lower - 1e-12) or np.any(arr > layout.upper + 1e-12):
            raise ValueError("initial_waypoints lie outside the state space bounds")
        return arr

    def set_initial_waypoints(self, W: np.ndarray | None) -> None:
        """Start the next solves from the waypoints W (h, n) instead of the straight line; None to unset.

        Only the planned groups' intermediate waypoints are taken from W: start, goal and the
        prescribed groups always come from the problem.  Nothing in W is trusted: its waypoints and
        motions are checked like any other, and an invalid W only gives the feasibility phase a head
        start (its valid prefix and suffix seed the layered trees).  Kept across :meth:`clear`.
        """
        self._initial = self._check_initial(self.grouped, W)

    # ------------------------------------------------------------------ reporting
    def settings(self) -> dict[str, str]:
        """Parameter name -> value as text (for the benchmark's ``plannerConfigs``)."""
        return {
            "groups": str(self.groups),
            "prescribed_groups": str(sorted(self.prescribed)),
            "h": str(self.h),
            "max_samples": str(self.max_samples),
            "seed": str(self.seed),
            "narrow_after": str(self.narrow_after),
            "narrowing": str(self.narrowing),
            "range": str([round(float(v), 6) for v in self.range_]),
            "batch": str(self.batch),
            "initial_waypoints": "none" if self._initial is None else "set",
        }

    @staticmethod
    def _empty_stats() -> dict[str, Any]:
        return {
            "samples": 0,
            "collision_checks": 0,
            "first_solution_time": None,
            "best_cost": math.inf,
            "iterations": 0,
            "progress": [],
        }

    def last_run_stats(self) -> dict[str, Any]:
        """Statistics of the last solve: samples, collision_checks, first_solution_time (s or None),
        best_cost (inf if none), iterations, progress [(time_s, best_cost, samples), ...]."""
        out = dict(self._stats)
        out["progress"] = list(self._stats["progress"])
        return out

    # ------------------------------------------------------------------ OMPL overrides
    def clear(self) -> None:
        """Forget the last run (the random generator keeps its state, so runs differ)."""
        super().clear()
        self._stats = self._empty_stats()

    def solve(self, ptc: ob.PlannerTerminationCondition | float) -> ob.PlannerStatus:
        """Plan until ``ptc`` or the sample cap; see the module docstring."""
        if isinstance(ptc, (int, float)):  # p.solve(1.0) from Python reaches here with a float
            ptc = ob.timedPlannerTerminationCondition(float(ptc))
        self._stats = self._empty_stats()
        try:
            return self._solve(ptc)
        except Exception:  # an exception escaping into ot.Benchmark would abort the whole benchmark
            log.exception("DimensionRRT.solve failed")
            return _status(ob.PlannerStatus.CRASH)

    def _endpoints(self) -> tuple[ob.State | None, ob.State | None, ob.PlannerStatus | None]:
        si, pdef = self.getSpaceInformation(), self.getProblemDefinition()
        # never pdef.getStartState(i): its Python wrapper frees a state pdef owns (crash at exit)
        pis = self.getPlannerInputStates()
        start = pis.nextStart()
        if start is None and pis.getSeenStartStatesCount() > 0:  # solve() again without clear()
            pis.restart()
            start = pis.nextStart()
        if start is None or not (si.satisfiesBounds(start) and si.isValid(start)):
            return None, None, _status(ob.PlannerStatus.INVALID_START)
        goal = pdef.getGoal()
        if isinstance(goal, ob.GoalState):
            gstate = goal.getState()
        else:
            log.error("DimensionRRT needs a goal that is a single state, got %s", type(goal).__name__)
            return None, None, _status(ob.PlannerStatus.UNRECOGNIZED_GOAL_TYPE)
        if not (si.satisfiesBounds(gstate) and si.isValid(gstate)):
            return None, None, _status(ob.PlannerStatus.INVALID_GOAL)
        return start, gstate, None

    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        t0 = time.perf_counter()
        si, pdef = self.getSpaceInformation(), self.getProblemDefinition()
        start, gstate, bad = self._endpoints()
        if bad is not None:
            return bad
        layout = self.grouped.layout
        q0, q1 = layout.read(start), layout.read(gstate)
        mismatch = self.grouped.endpoint_mismatch(q0, q1)
        if mismatch is not None:
            log.error("the %s state is not on the prescribed trajectory", mismatch)
            return _status(ob.PlannerStatus.INVALID_START if mismatch == "start" else ob.PlannerStatus.INVALID_GOAL)
        checker = _Checker(si, layout, self.batch)
        checks0 = checker.counter()
        search = _Search(self.grouped, checker, self._rng, q0, q1, self.narrow_after, self.narrowing, self._ranges,
                         self._initial)
        stats = self._stats
        progress = stats["progress"]
        best_W, best_cost, first_time = None, math.inf, None
        cap = self.max_samples if self.grouped.planned else 0
        last_log = -math.inf

        def record(now: float) -> None:
            progress.append((now - t0, best_cost, search.samples))

        if search.valid:
            best_W, best_cost, first_time = search.W.copy(), search.cost, time.perf_counter() - t0
        record(time.perf_counter())
        while not ptc() and (cap is None or search.samples < cap):
            accepted = search.iterate()
            now = time.perf_counter()
            if accepted and search.valid:
                if first_time is None:
                    first_time = now - t0
                if search.cost < best_cost:
                    best_W, best_cost = search.W.copy(), search.cost
                    record(now)
                    last_log = now
                    continue
            if now - last_log >= _PROGRESS_PERIOD:
                record(now)
                last_log = now
        record(time.perf_counter())

        status = _status(ob.PlannerStatus.TIMEOUT)
        if best_W is not None:
            path = self.grouped.to_path(si, best_W)
            states = path.getStates()
            if all(si.checkMotion(states[i], states[i + 1]) for i in range(len(states) - 1)):
                pdef.addSolutionPath(path, False, 0.0, self.getName())
                status = _status(ob.PlannerStatus.EXACT_SOLUTION)
            else:
                log.warning("DimensionRRT: final si.checkMotion rejected the path; no solution reported")
                best_cost, first_time = math.inf, None
        stats.update(
            samples=search.samples,
            iterations=search.samples,
            collision_checks=checker.counter() - checks0,
            first_solution_time=first_time,
            best_cost=best_cost,
        )
        return status
