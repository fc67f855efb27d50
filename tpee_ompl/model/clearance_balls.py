"""Clearance balls with boolean checks: prove pairs apart for good, and certify joint-space balls with
one batched collision call at inflated margins.

A pair's distance changes at most ``sum_i |dq_i| R[p, i] <= ||dq|| ||R[p]||`` along a joint step dq
(:meth:`RobotChecker.pair_lever_arms`).  Two uses of that bound, both exact (no answer of the checker
changes, only its cost):

* :func:`separated_pairs`: a pair whose two bodies have at most one joint between them has a distance
  that is a function of that joint alone; sampled over the joint's whole range densely enough, its
  lower bound above the margin proves the pair never collides, so it need not be checked (the
  wearer's first link spinning about its own axis, its boom and barrel under the tilt joint).
* :class:`BallScreen`: a state that passes the collision check with every pair's margin raised by
  ``radius * ||R[p]||`` keeps every pair at least its own margin apart at *every* state within
  ``radius`` of it (Euclidean, joint space).  A motion's dense states near such a state need no check
  of their own (:func:`screened_all_valid`).
"""

from __future__ import annotations

import bisect
import math
import time
from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from .collision_pools import CollisionPool, new_pool

if TYPE_CHECKING:
    from .robot_checker import RobotChecker

__all__ = ["BallScreen", "CHAINS", "SCREEN_COST_LIMIT", "SCREEN_LEVELS", "separated_pairs", "screened_all_valid",
           "screened_lines_valid"]

SEPARATION_TOLERANCE = 1e-5
"""Metres taken off every Coal distance (and added to every inflated margin) before it proves anything."""
SEPARATION_SAMPLE_GAP = 0.001
"""Metres: the grid over a joint's range is fine enough that the lever bound between samples is this."""
MAX_SEPARATION_SAMPLES = 20000
SCREEN_LEVELS = (4.0, 1.0)
"""Ball radii tried in turn, in motion-check steps: states 4 steps (then 1 step) either side are
certified by one state checked at the inflated margins; what no ball covers is checked densely.
Measured on RRT* motions of the wearer and the Panda (``experiments/screened_motions.py --levels 2,1
4,1 ...``): against (2, 1), the radii until 2026-11-25, 10-11 % less time on the wearer's motions and
7 % on the Panda's; (3, 1), (4, 2, 1) and (8, 1) were slower, (6, 1) slower on the wearer."""
MIDDLES_FIRST = True
"""What no ball covers is checked plainly in two calls, each remaining block's middle state first, then the other
states of the lines whose middles passed (False: all of them in one call, before 2026-11-27; a switch for
``experiments/colliding_motions.py --switch middles``).  The same verdicts either way."""
CHAINS = True
"""A path's motions (each starting where the last ended, ``chained`` in :func:`screened_lines_valid`) are covered as one
polyline, a ball reaching across a waypoint (False: each motion a line of its own, before 2026-11-27; a switch for
``experiments/chained_paths.py``).  The same verdicts either way."""
SCREEN_COST_LIMIT = 4.0
"""The screen is used where its inflated check of a state costs at most this many plain checks
(:meth:`BallScreen.pays`).  A ball of 4 steps covers up to 9 states; near contact, Coal's mesh-mesh checks at
inflated margins can cost far more than that saves (a helper's probe, 2026-11-26: per valid state, 0.7x a
plain check on the wearer and 0.8x on the Panda shelf, 9x on a UR5 with gripper, 11x on the Talos arm, 51x on a
Kinova arm whose link meshes have 17,000-45,000 triangles: there one 28-state screen call took 3 s)."""
_CALIBRATION_DRAWS = 512
_CALIBRATION_STATES = 32
_CALIBRATION_BLOCK = 16
PLAIN_CHECK_LIMIT = 1e-3
"""Seconds per state: a robot whose plain check costs more (detailed meshes near contact: the SO101 arm's
18 ms) is not screened, and its screen is not even timed (one of its inflated checks took 0.3-25 s)."""


def separated_pairs(robot: RobotChecker) -> list[int]:
    """Indices (``gmodel.collisionPairs`` order) of pairs proven never closer than their margin.

    Only pairs with no joint between their bodies (one distance decides) or one bounded joint (the
    distance over a grid of its range, minus the lever bound between grid points) are tried.
    """
    R, margins = robot.pair_lever_arms(), robot.pair_margins()
    model, gmodel = robot.model, robot.gmodel
    data, gd = model.createData(), pin.GeometryData(gmodel)
    gd.deactivateAllCollisionPairs()
    q0 = pin.neutral(model)
    out = []
    for p in range(len(R)):
        joints = np.flatnonzero(R[p])
        if len(joints) > 1:
            continue
        if len(joints) == 0:
            grid, gap = q0[None, :], 0.0
        else:
            j = int(joints[0])
            lo, hi = float(robot.lower[j]), float(robot.upper[j])
            if not (math.isfinite(lo) and math.isfinite(hi)) or hi <= lo:
                continue
            n = int(math.ceil(R[p, j] * (hi - lo) / (2 * SEPARATION_SAMPLE_GAP))) + 1
            if n > MAX_SEPARATION_SAMPLES:
                continue
            values = np.linspace(lo, hi, max(n, 2))
            grid = np.repeat(q0[None, :], len(values), axis=0)
            grid[:, j] = values
            gap = R[p, j] * (values[1] - values[0]) / 2
        gd.activateCollisionPair(p)
        apart = True
        for q in grid:
            pin.computeDistances(model, data, gmodel, gd, q)
            if gd.distanceResults[p].min_distance - gap - SEPARATION_TOLERANCE < margins[p]:
                apart = False  # one grid point close enough decides: the rest cannot prove it apart
                break
        gd.deactivateCollisionPair(p)
        if apart:
            out.append(p)
    return out


class BallScreen:
    """Batched checks at margins inflated for a joint-space radius (module docstring).

    ``clear(Q, radius)[k]`` True proves every state within ``radius`` (rad, Euclidean) of Q[k] valid
    (every checked pair at least its margin apart); False proves nothing.  One Pinocchio pool per
    radius, built on first use; pairs the robot does not check stay unchecked.
    """

    def __init__(self, robot: RobotChecker) -> None:
        self.robot = robot
        self._lever_norms = np.linalg.norm(robot.pair_lever_arms(), axis=1)
        self._pools: dict[float, CollisionPool] = {}
        self._pays: dict[float, bool] = {}

    def pays(self, radius: float) -> bool:
        """Whether screening at ``radius`` pays on this robot: its check of a state costs at most
        :data:`SCREEN_COST_LIMIT` plain checks (:meth:`cost_ratio`, measured once per radius; True when it
        cannot be measured).  Only the cost depends on it: a screened and a dense check give the same verdicts."""
        radius = float(radius)
        if radius not in self._pays:
            ratio = self.cost_ratio(radius)
            self._pays[radius] = ratio is None or ratio <= SCREEN_COST_LIMIT
        return self._pays[radius]

    def cost_ratio(self, radius: float) -> float | None:
        """Time of the inflated check at ``radius`` over the plain check, on up to 32 collision-free states drawn
        (seeded) in the joint box, the best of three calls each (a call the scheduler interrupted does not
        decide); None when fewer than 4 of 512 draws are free, inf when a plain check costs more than
        :data:`PLAIN_CHECK_LIMIT`.  Bounded: the draws stop at 32 free states, and the inflated check is timed on
        one state before the others.  Leaves the checker as it was (``collision_checks``, its stall guard)."""
        robot = self.robot
        kept = robot.collision_checks, robot.stall_guard.state()
        try:
            rng = np.random.default_rng(0)
            free, fastest, drawn = [], math.inf, 0  # fastest: per state, the quickest block (not an interrupted one)
            while len(free) < _CALIBRATION_STATES and drawn < _CALIBRATION_DRAWS:
                Q = rng.uniform(robot.lower, robot.upper, (_CALIBRATION_BLOCK, robot.nq))
                t0 = time.perf_counter()
                free.extend(Q[robot.collision_free(Q)])
                fastest, drawn = min(fastest, (time.perf_counter() - t0) / len(Q)), drawn + len(Q)
                if drawn >= 2 * _CALIBRATION_BLOCK and fastest > PLAIN_CHECK_LIMIT:
                    return math.inf
            if len(free) < 4:
                return None
            V = np.array(free[:_CALIBRATION_STATES])
            for states in (V[:1], V):  # one state first (best of two): far beyond the limit, the rest is not needed
                plain, screened = math.inf, math.inf
                for _ in range(2 if len(states) == 1 else 3):
                    t0 = time.perf_counter()
                    robot.collision_free(states)
                    t1 = time.perf_counter()
                    self.clear(states, radius)
                    t2 = time.perf_counter()
                    plain, screened = min(plain, t1 - t0), min(screened, t2 - t1)
                if screened > 10 * SCREEN_COST_LIMIT * plain:
                    break
            return screened / max(plain, 1e-9)
        finally:
            robot.collision_checks = kept[0]
            robot.stall_guard.restore(kept[1])

    def _pool(self, radius: float) -> CollisionPool:
        pool = self._pools.get(radius)
        if pool is None:
            robot = self.robot
            gd = robot.new_check_data()
            for k, req in enumerate(gd.collisionRequests):
                req.security_margin += radius * self._lever_norms[k] + SEPARATION_TOLERANCE
            pool = new_pool(robot.model, robot.gmodel, gd, robot.n_threads)
            self._pools[radius] = pool
        return pool

    def prepare(self, radii: Iterable[float]) -> None:
        """Build the pools for these radii now (a few ms each), so that the first check does not pay for them."""
        for radius in radii:
            self._pool(float(radius))

    def clear(self, Q: np.ndarray, radius: float) -> np.ndarray:
        """bool (N,): True where every state within ``radius`` of Q[k] is collision-free with the margins
        (joint limits are the caller's to check)."""
        Q = np.asarray(Q, dtype=float)
        if len(Q) == 0:
            return np.zeros(0, dtype=bool)
        return self.robot.collision_free(Q, self._pool(float(radius)))


def screened_all_valid(robot: RobotChecker, screen: BallScreen, chunks: list[np.ndarray], step: float,
                       levels: tuple[float, ...] = SCREEN_LEVELS, probes: int = 0) -> np.ndarray:
    """Per chunk (the dense states of one straight motion, evenly spaced along it), True iff every
    state of it is valid: the same answer as ``robot.are_valid(chunk).all()``, with fewer checks
    (:func:`screened_lines_valid` on the chunks one after the other; ``probes``: as there)."""
    K = len(chunks)
    if K == 0:
        return np.zeros(0, dtype=bool)
    if K == 1:
        return np.array([_one_motion_valid(robot, screen, np.asarray(chunks[0], dtype=float), step, levels,
                                           probes=probes)])
    sizes = np.array([len(c) for c in chunks], dtype=np.int64)
    spacing = np.array([float(np.linalg.norm(c[1] - c[0])) if len(c) > 1 else 0.0 for c in chunks])
    return screened_lines_valid(robot, screen, np.concatenate(chunks), sizes, spacing, step, levels)


def screened_lines_valid(robot: RobotChecker, screen: BallScreen, S: np.ndarray, sizes: np.ndarray,
                         spacing: np.ndarray, step: float, levels: tuple[float, ...] = SCREEN_LEVELS,
                         probes: int = 0, chained: np.ndarray | None = None) -> np.ndarray:
    """:func:`screened_all_valid` for K lines given as one array: S (sum of ``sizes``, nq) holds line k's
    ``sizes[k]`` states, evenly ``spacing[k]`` apart along a straight segment, after line k - 1's.

    ``chained`` (K - 1,) bool: line k + 1 goes on from line k's last state (a path's motions, each starting
    where the last ended); chained lines are covered as one polyline, so a ball reaches across a waypoint.
    Each line (or chain) starts as one block of states to cover.  At each level h, every block is cut into
    blocks of consecutive states that a ball of radius h*``step`` round one of them covers (along the lines
    at most that far from it: no farther in joint space; on one line 2H+1 states, H the states it reaches
    either side); the centre state of each block of 3 or more is checked by :meth:`BallScreen.clear`,
    and a block whose centre passes is covered.  One batched call per level over all lines; the states
    left are checked plainly (:meth:`RobotChecker.collision_free`), each block's middle state first, then, in a
    second call, the others of the lines whose middles all passed: a colliding line is mostly found by the first
    call, and its other uncovered states go unchecked (2026-11-27: RRTConnect's first paths at home 639 -> 515
    checks, mean).  A line with an end outside the joint
    limits is invalid at once (as in ``are_valid``); the joint box is convex, so the states of the
    others lie inside it, and so do the states a ball covers.  ``probes``: for one line, that many of its states
    checked plainly first, as OMPL's validator starts (:data:`PROBES`, what ``si.checkMotion`` asks for).
    """
    K = len(sizes)
    if K == 1:  # one motion (a compound space's si.checkMotion among others)
        return np.array([_one_motion_valid(robot, screen, S[: int(sizes[0])], step, levels, float(spacing[0]),
                                           probes)])
    offsets = np.cumsum(sizes) - sizes
    if K and sizes.all():  # a motion check's lines (never empty): the common case without masks
        within = robot.inside_limits(S[np.concatenate((offsets, offsets + sizes - 1))])
        if (within[:K] & within[K:]).all():
            return np.array(_blocks_valid(robot, screen, S, offsets.tolist(), sizes.tolist(), spacing.tolist(), step,
                                          levels, None if chained is None else np.asarray(chained, dtype=bool).tolist()))
    live = np.flatnonzero(sizes > 0)
    E = S[np.concatenate((offsets[live], offsets[live] + sizes[live] - 1))]  # first and last states
    within = robot.inside_limits(E)
    out = np.ones(len(sizes), dtype=bool)  # an empty line has no invalid state
    out[live] = within[: len(live)] & within[len(live) :]
    live = live[out[live]]
    links = None  # a line left out breaks its chain
    if chained is not None and len(live):
        links = (np.asarray(chained, dtype=bool)[live[1:] - 1] & (np.diff(live) == 1)).tolist()
    out[live] = _blocks_valid(robot, screen, S, offsets[live].tolist(), sizes[live].tolist(), spacing[live].tolist(),
                              step, levels, links)
    return out


def _blocks_valid(robot: RobotChecker, screen: BallScreen, S: np.ndarray, starts: list[int], sizes: list[int],
                  spacing: list[float], step: float, levels: tuple[float, ...],
                  chained: list[bool] | None = None) -> list[bool]:
    """The ball screening of :func:`screened_lines_valid` for lines already inside the joint limits, in plain
    Python over the blocks (a few dozen per call: cheaper than array bookkeeping); one verdict per line.

    A line of its own is cut by index (:func:`_cut_line`).  Lines chained to each other (``chained[k]``: line k + 1
    goes on from line k; its states are rows of S right after line k's) are cut by each state's position along the
    chain, which bounds its joint-space distance to any other state of the chain (:func:`_cut`)."""
    blocks: list[tuple[int, int, int]] = []  # (first row, end row, line; -1: a chain of lines) still to cover
    joined = [False] * len(starts)
    for k, (a, m) in enumerate(zip(starts, sizes)):
        joined[k] = bool(k and CHAINS and chained is not None and chained[k - 1] and blocks[-1][1] == a)
        blocks.append((blocks.pop()[0], a + m, -1) if joined[k] else (a, a + m, k))
    pos: list[float] = []
    if any(joined):  # positions along the chains (rows of lines of their own stay 0, never read)
        pos = [0.0] * len(S)
        for k, (a, m, sp) in enumerate(zip(starts, sizes, spacing)):
            base = pos[a - 1] if joined[k] else 0.0
            pos[a : a + m] = [base + sp * i for i in range(1, m + 1)]
    for h in levels:
        if not blocks:
            break
        radius = h * step
        screened: list[tuple[int, int, int]] = []
        centres: list[int] = []
        left: list[tuple[int, int, int]] = []  # pieces with no state to screen at this level
        for a, b, k in blocks:
            if k < 0:
                _cut(pos, a, b, radius * (1 + 1e-12), screened, centres, left)
            else:
                H = int(math.floor(radius / spacing[k] * (1 + 1e-12))) if spacing[k] > 0 else 0  # states reached
                _cut_line(a, b, k, H, screened, centres, left)
        if centres:
            left += [p for p, ok in zip(screened, screen.clear(S[centres], radius).tolist()) if not ok]
        blocks = left
    ok = [True] * len(starts)
    if not blocks:
        return ok

    def line(i: int, k: int) -> int:  # the line of row i in a block of line k (-1: of a chain)
        return k if k >= 0 else bisect.bisect_right(starts, i) - 1

    # what no ball covers, in two calls: each block's middle state (beside a ball that failed: the likeliest to
    # collide), then the other states of the lines still valid, so a colliding line stops there
    if MIDDLES_FIRST:
        mids = [(a + b - 1) // 2 for a, b, _ in blocks]
        for (_, _, k), i, free in zip(blocks, mids, robot.collision_free(S[mids]).tolist()):
            if not free:
                ok[line(i, k)] = False
    else:
        mids = [-1] * len(blocks)  # (no middle checked first)
    rows: list[int] = []
    owner: list[int] = []  # the line of each row
    for (a, b, k), c in zip(blocks, mids):
        if k >= 0:  # a line of its own
            if ok[k]:
                rows.extend(i for i in range(a, b) if i != c)
                owner.extend([k] * (b - a - (c >= 0)))
            continue
        for i in range(a, b):
            if i != c and ok[j := line(i, k)]:
                rows.append(i)
                owner.append(j)
    if rows:
        for i in np.flatnonzero(~robot.collision_free(S[rows])).tolist():
            ok[owner[i]] = False
    return ok


def _cut_line(a: int, b: int, k: int, H: int, screened: list[tuple[int, int, int]], centres: list[int],
              left: list[tuple[int, int, int]]) -> None:
    """Cut rows a..b-1 of line k, evenly spaced, into blocks of 2H+1 (a ball reaching H states either side of the
    middle one), the rest into one centred block: blocks of 3 or more rows go to ``screened`` with their centre in
    ``centres``, the others to ``left``."""
    if H < 1:
        left.append((a, b, k))
        return
    width = 2 * H + 1
    full, rest = divmod(b - a, width)
    end = a + full * width
    for s in range(a, end, width):
        screened.append((s, s + width, k))
        centres.append(s + H)
    if rest >= 3:
        screened.append((end, b, k))
        centres.append(end + (rest - 1) // 2)
    elif rest:
        left.append((end, b, k))


def _cut(pos: list[float], a: int, b: int, reach: float, screened: list[tuple[int, int, int]], centres: list[int],
         left: list[tuple[int, int, int]]) -> None:
    """Cut rows a..b-1 of a chain (positions ``pos``, ascending) into blocks that a ball of radius ``reach`` round one
    of their rows covers: each block as far as it reaches from its first row, the last one centred on what remains.
    Blocks of 3 or more rows go to ``screened`` with their centre in ``centres``; the others to ``left``
    (neighbouring ones of this cut joined: rows of two chains never, their positions start again)."""
    i, first_left = a, len(left)
    while i < b:
        c = bisect.bisect_right(pos, pos[i] + reach, i, b) - 1  # the farthest centre that reaches row i
        if pos[b - 1] - pos[c] <= reach:  # one ball reaches the last row: centred on the rest
            c = bisect.bisect_right(pos, (pos[i] + pos[b - 1]) / 2, i, c + 1) - 1
            while pos[b - 1] - pos[c] > reach:
                c += 1
            e = b
        else:
            e = bisect.bisect_right(pos, pos[c] + reach, c, b)
        if e - i >= 3:
            screened.append((i, e, -1))
            centres.append(c)
        elif len(left) > first_left and left[-1][1] == i:
            left[-1] = (left[-1][0], e, -1)
        else:
            left.append((i, e, -1))
        i = e


PROBES = 2
"""States of a motion that ``si.checkMotion`` asks about (the native planners' single calls) checked plainly before
its screen, as OMPL's ``DiscreteMotionValidator`` starts: its end, then the middle, ... (bisection), up to the first
invalid one.  A colliding motion is mostly found there; a free one pays these checks on top of its screen.  The
batched calls (dimension-RRT's, which screens its motions first, stopping at a collision) take none."""


def _probe_rows(n: int, k: int) -> list[int]:
    """The first ``k`` of a motion's n states in the order OMPL checks them: the last (the end state), then the
    middles of the rest, breadth first."""
    rows, spans = [n - 1], [(0, n - 2)]
    while len(rows) < min(k, n) and spans:
        lo, hi = spans.pop(0)
        if lo <= hi:
            mid = (lo + hi) // 2
            rows.append(mid)
            spans += [(lo, mid - 1), (mid + 1, hi)]
    return rows


def _one_motion_valid(robot: RobotChecker, screen: BallScreen, S: np.ndarray, step: float,
                      levels: tuple[float, ...], spacing: float | None = None, probes: int = 0) -> bool:
    """:func:`screened_all_valid` for one chunk (``si.checkMotion``'s case, once per motion): the limit test
    on its two ends without building arrays, ``probes`` states plainly (:data:`PROBES`), then :func:`_blocks_valid`.
    ``spacing``: of the states along the (unwrapped) line, when S[1] - S[0] is not it (wrapped SO2 values)."""
    n = len(S)
    if n == 0:
        return True
    # the states lie on a segment, and the joint box is convex: its two ends decide the limits
    lower, upper = robot.check_lower, robot.check_upper
    if not ((S[0] >= lower).all() and (S[0] <= upper).all() and (S[-1] >= lower).all() and (S[-1] <= upper).all()):
        return False
    if probes and robot.first_invalid(S[_probe_rows(n, probes)]) >= 0:
        return False
    if spacing is None:
        spacing = math.sqrt(float((S[1] - S[0]) @ (S[1] - S[0]))) if n > 1 else 0.0
    return _blocks_valid(robot, screen, S, [0], [n], [spacing], step, levels)[0]
