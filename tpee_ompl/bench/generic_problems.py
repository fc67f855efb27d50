"""Benchmark problems set up with plain OMPL + numpy only: no project code in their set-up.

Planar arms among circles (4-8 joints; one with continuous joints, a ``CompoundStateSpace`` of
``SO2StateSpace``), a 4-D point through a hole in a wall and a 3-D narrow passage, taken from
``experiments/foreign_problems.py``.  Validity checkers are plain Python functions (one call per
state, counted by :class:`CountingChecker`); motions are checked by OMPL's default
``DiscreteMotionValidator``, so these problems have no batched motion validator (checker
``discrete`` only).  OMPL is imported only when a set-up is built, so listing the problems needs none.
:func:`planar_arm_setup` and :func:`box_point_setup` build such a set-up for any start and goal
(``experiments/foreign_problems.py`` and the planning tests' arms use them).

Each problem has a deterministic query set: ``n_queries`` start/goal pairs drawn from a seeded
generator, both valid, whose straight motion collides (checked here in numpy at the set-up's
resolution, the states OMPL's discrete motion validator checks).
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ompl import base as ob
    from ompl import geometric as og

__all__ = ["ARM_OBS", "ARM_OBS2", "ARM_REACH", "GENERIC_PROBLEMS", "CountingChecker", "GenericProblem", "arm_free",
           "arm_points", "box_point_setup", "generic_queries", "make_generic_setup", "planar_arm_setup"]

ARM_OBS = ((0.0, 1.0, 0.25), (-0.9, 0.8, 0.2), (0.9, 0.75, 0.2))
ARM_OBS2 = ((0.0, 1.0, 0.25), (-0.9, 0.8, 0.2), (0.9, 0.75, 0.2), (-0.3, -0.9, 0.25), (0.6, -0.6, 0.15))
ARM_REACH = 1.5
"""Total length of every planar arm (m); link length = ``ARM_REACH / n``."""


@dataclass(frozen=True)
class GenericProblem:
    """One generic problem: its space, validity rule, grouping and how its queries are drawn."""

    name: str
    description: str
    kind: str
    """``arm`` (planar arm, joint angles), ``arm-so2`` (the same with continuous joints) or ``box`` (point in
    [0, 1]^n)."""
    n: int
    groups: tuple[tuple[int, ...], ...]
    """Grouping of dimension-RRT (contiguous index groups)."""
    obstacles: tuple[tuple[float, float, float], ...] = ()
    """Circles (x, y, radius) for the arms."""
    blocked: str = ""
    """Name of the box problems' obstacle rule (:data:`_BLOCKED`)."""
    start_box: tuple[tuple[float, float], ...] = ()
    """Per-dimension (low, high) ranges start states are drawn from."""
    goal_box: tuple[tuple[float, float], ...] = ()
    resolution: float = 0.01
    """``si.setStateValidityCheckingResolution`` (fraction of the space's extent)."""
    n_queries: int = 10
    seed: int = 0


# ----------------------------------------------------------------- validity rules (numpy)
def arm_points(q: np.ndarray, link: float, per_link: int = 4) -> np.ndarray:
    """Points along the links of a planar arm at joint angles q (n,), base at the origin -> (n * per_link, 2)."""
    ang = np.cumsum(q)
    d = link * np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    joints = np.vstack([np.zeros((1, 2)), np.cumsum(d, axis=0)])
    s = np.linspace(0.0, 1.0, per_link)
    return (joints[:-1, None, :] + s[None, :, None] * d[:, None, :]).reshape(-1, 2)


def arm_free(q: np.ndarray, obstacles: np.ndarray, link: float) -> bool:
    """True if no point of :func:`arm_points` (4 points a link) lies in or on a circle of ``obstacles`` (m, 3)."""
    p = arm_points(q, link)
    diff = p[:, None, :] - obstacles[None, :, :2]
    return bool(np.all(np.einsum("poc,poc->po", diff, diff) > obstacles[:, 2] ** 2))


def _wall_with_hole(x: Sequence[float]) -> bool:
    """4-D: wall 0.45 < x0 < 0.55 with a hole |x_i - 0.5| < 0.12 for i = 1..3."""
    return 0.45 < x[0] < 0.55 and not all(abs(v - 0.5) < 0.12 for v in x[1:])


def _narrow_passage(x: Sequence[float]) -> bool:
    """3-D: wall 0.4 < x0 < 0.6 with a slot 0.48 < x1 < 0.52 (any x2)."""
    return 0.4 < x[0] < 0.6 and not 0.48 < x[1] < 0.52


_BLOCKED: dict[str, Callable[[Sequence[float]], bool]] = {"wall_with_hole": _wall_with_hole,
                                                          "narrow_passage": _narrow_passage}


def _validity_rule(p: GenericProblem) -> Callable[[np.ndarray], bool]:
    """The problem's validity test of one configuration (numpy array (n,))."""
    if p.kind in ("arm", "arm-so2"):
        return _arm_rule(p.obstacles, ARM_REACH / p.n)
    return _box_rule(p.blocked)


def _arm_rule(obstacles: Sequence[Sequence[float]] | np.ndarray, link: float) -> Callable[[np.ndarray], bool]:
    obs = np.asarray(obstacles, dtype=float).reshape(-1, 3)
    return lambda q: arm_free(q, obs, link)


def _box_rule(blocked: str) -> Callable[[np.ndarray], bool]:
    rule = _BLOCKED[blocked]
    return lambda x: not rule(x)


# ----------------------------------------------------------------- OMPL set-up
def _space(kind: str, n: int) -> ob.StateSpace:
    from ompl import base as ob

    if kind == "arm-so2":
        space = ob.CompoundStateSpace()
        for _ in range(n):
            space.addSubspace(ob.SO2StateSpace(), 1.0)
        return space
    space = ob.RealVectorStateSpace(n)
    if kind == "arm":
        space.setBounds(-math.pi, math.pi)
    else:
        space.setBounds(0.0, 1.0)
    return space


def _reader(kind: str, n: int) -> Callable[[ob.State], Sequence[float]]:
    """A state's values: an array for the arms' numpy rule, plain floats for the boxes' comparisons (3x faster)."""
    if kind == "arm-so2":
        return lambda s: np.array([s[i].value for i in range(n)])
    if kind == "box":
        return lambda s: [s[i] for i in range(n)]
    return lambda s: np.array([s[i] for i in range(n)])


def _write(kind: str, n: int, s: ob.State, q: Sequence[float]) -> None:
    for i in range(n):
        if kind == "arm-so2":
            s[i].value = float(q[i])
        else:
            s[i] = float(q[i])


def _hash(kind: str, n: int, obstacles: tuple, blocked: str, reach: float, resolution: float) -> str:
    text = repr((kind, n, obstacles, blocked, reach, resolution))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def model_hash(p: GenericProblem) -> str:
    """A short hash of everything that decides validity: kind, dimension, obstacles or rule, resolution."""
    return _hash(p.kind, p.n, p.obstacles, p.blocked, ARM_REACH, p.resolution)


class CountingChecker:
    """A Python validity checker that counts its calls (``collision_checks``), one per state checked."""

    def __init__(self, valid: Callable[[np.ndarray], bool], read: Callable[[ob.State], np.ndarray], hash_: str,
                 nq: int) -> None:
        self.valid, self.read, self.model_hash, self.nq = valid, read, hash_, nq
        self.collision_checks = 0

    def __call__(self, state: ob.State) -> bool:
        self.collision_checks += 1
        return bool(self.valid(self.read(state)))


def _setup(kind: str, n: int, checker: CountingChecker, start: Sequence[float], goal: Sequence[float],
           resolution: float) -> og.SimpleSetup:
    from ompl import base as ob
    from ompl import geometric as og

    ss = og.SimpleSetup(_space(kind, n))
    si = ss.getSpaceInformation()
    ss.setStateValidityChecker(checker)
    si.setStateValidityCheckingResolution(resolution)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    s0, s1 = si.allocState(), si.allocState()
    _write(kind, n, s0, start)
    _write(kind, n, s1, goal)
    ss.setStartAndGoalStates(s0, s1, 1e-9)
    ss._generic_refs = (checker, s0, s1)  # Python objects referenced only from C++ would be collected
    ss.endpoint_states = (s0, s1)  # Python's copies: pdef.getStartState from Python is unsafe
    si.setup()
    return ss


def planar_arm_setup(n: int, start: Sequence[float], goal: Sequence[float],
                     obstacles: Sequence[Sequence[float]] | np.ndarray, continuous: bool = False,
                     resolution: float = 0.01, reach: float = ARM_REACH) -> tuple[og.SimpleSetup, CountingChecker]:
    """A planar arm of n equal links (total ``reach``) among circles (x, y, r), from ``start`` to ``goal``.

    Joints in [-pi, pi] (``RealVectorStateSpace``), or continuous (a ``CompoundStateSpace`` of ``SO2StateSpace``);
    path-length objective.  Returns the ``SimpleSetup`` (its ``endpoint_states`` are the start and goal states)
    and its :class:`CountingChecker`.
    """
    kind = "arm-so2" if continuous else "arm"
    obs = tuple(tuple(float(v) for v in o) for o in np.asarray(obstacles, dtype=float).reshape(-1, 3))
    checker = CountingChecker(_arm_rule(obs, reach / n), _reader(kind, n),
                              _hash(kind, n, obs, "", reach, resolution), n)
    return _setup(kind, n, checker, start, goal, resolution), checker


def box_point_setup(n: int, blocked: str, start: Sequence[float], goal: Sequence[float],
                    resolution: float = 0.005) -> tuple[og.SimpleSetup, CountingChecker]:
    """A point in [0, 1]^n, invalid where the rule ``blocked`` (``wall_with_hole`` or ``narrow_passage``) says.

    Path-length objective; returns the ``SimpleSetup`` (with ``endpoint_states``) and its :class:`CountingChecker`.
    """
    # ARM_REACH is in the hash of every generic problem, boxes included (hashes already stored stay valid)
    hash_ = _hash("box", n, (), blocked, ARM_REACH, resolution)
    checker = CountingChecker(_box_rule(blocked), _reader("box", n), hash_, n)
    return _setup("box", n, checker, start, goal, resolution), checker


def make_generic_setup(p: GenericProblem, start: Sequence[float], goal: Sequence[float],
                       batched: bool = False) -> tuple[og.SimpleSetup, CountingChecker]:
    """The problem's ``SimpleSetup`` (path-length objective) from ``start`` to ``goal``, and its counting checker.

    Raises ValueError for ``batched=True``: these problems use OMPL's ``DiscreteMotionValidator``.
    """
    if batched:
        raise ValueError(f"problem {p.name}: no batched motion validator (Python validity checker, "
                         "OMPL's discrete motion validator): use checker 'discrete'")
    if p.kind == "box":
        return box_point_setup(p.n, p.blocked, start, goal, p.resolution)
    return planar_arm_setup(p.n, start, goal, p.obstacles, p.kind == "arm-so2", p.resolution)


# ----------------------------------------------------------------- queries (numpy)
def _straight_states(p: GenericProblem, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The states OMPL's discrete motion validator checks along a -> b (SO2 values the short way round)."""
    d = b - a
    if p.kind == "arm-so2":
        d = np.mod(d + math.pi, 2 * math.pi) - math.pi
        dist = float(np.abs(d).sum())  # compound of SO2 with weight 1: sum of the angle distances
        extent = p.n * math.pi
    else:
        dist = float(np.linalg.norm(d))
        extent = math.sqrt(p.n) * (2 * math.pi if p.kind == "arm" else 1.0)
    steps = max(1, math.ceil(dist / (p.resolution * extent)))
    t = np.arange(1, steps + 1) / steps
    X = a + t[:, None] * d
    if p.kind == "arm-so2":
        X = np.mod(X + math.pi, 2 * math.pi) - math.pi
    return X


def generic_queries(p: GenericProblem) -> list[dict]:
    """The problem's queries: ``id``, ``start``, ``goal`` (lists), drawn with seed ``p.seed``.

    Start and goal are valid; the straight motion between them is not.
    """
    rng = np.random.default_rng(p.seed)
    valid = _validity_rule(p)
    lo0, hi0 = np.array(p.start_box).T
    lo1, hi1 = np.array(p.goal_box).T
    out: list[dict] = []
    for _ in range(100_000):
        if len(out) == p.n_queries:
            break
        a, b = rng.uniform(lo0, hi0), rng.uniform(lo1, hi1)
        if valid(a) and valid(b) and not all(valid(x) for x in _straight_states(p, a, b)):
            out.append({"id": len(out), "start": [float(v) for v in a], "goal": [float(v) for v in b]})
    if len(out) < p.n_queries:
        raise RuntimeError(f"problem {p.name}: drew only {len(out)} of {p.n_queries} queries")
    return out


def _arm(name: str, n: int, obstacles, groups, seed: int, continuous: bool = False) -> GenericProblem:
    """A planar arm swinging from the right (first joint 0.1..0.6 rad) to the left (2.5..3.0), the rest bent a little.

    The continuous-joint arm swings from 2.6..3.0 to -2.8..-2.4 rad, the short way across pi.
    """
    rest = ((-0.4, 0.4),) * (n - 1)
    if continuous:
        start, goal = ((2.6, 3.0),) + rest, ((-2.8, -2.4),) + rest
        kind, what = "arm-so2", f"planar arm, {n} continuous joints (SO2 compound) among {len(obstacles)} circles"
    else:
        start, goal = ((0.1, 0.6),) + rest, ((2.5, 3.0),) + rest
        kind, what = "arm", f"planar arm, {n} joints in [-pi, pi] among {len(obstacles)} circles"
    return GenericProblem(name=name, description=f"{what}; groups {[list(g) for g in groups]}", kind=kind, n=n,
                          groups=groups, obstacles=obstacles, start_box=start, goal_box=goal, seed=seed)


GENERIC_PROBLEMS: dict[str, GenericProblem] = {p.name: p for p in (
    _arm("arm4", 4, ARM_OBS, ((0, 1), (2, 3)), seed=4),
    _arm("arm6", 6, ARM_OBS, ((0, 1), (2, 3), (4, 5)), seed=6),
    _arm("arm7", 7, ARM_OBS2, ((0, 1), (2, 3), (4, 5, 6)), seed=7),
    _arm("arm8", 8, ARM_OBS2, ((0, 1), (2, 3), (4, 5), (6, 7)), seed=8),
    _arm("arm5-so2", 5, ARM_OBS2, ((0, 1), (2, 3, 4)), seed=5, continuous=True),
    GenericProblem(name="point4-hole",
                   description="4-D point in the unit box, a wall with a hole (0.24 wide); groups [[0, 1], [2, 3]]",
                   kind="box", n=4, groups=((0, 1), (2, 3)), blocked="wall_with_hole",
                   start_box=((0.05, 0.35),) + ((0.05, 0.95),) * 3, goal_box=((0.65, 0.95),) + ((0.05, 0.95),) * 3,
                   resolution=0.005, seed=41),
    GenericProblem(name="narrow3",
                   description="3-D point in the unit box, a wall with a 0.04-wide slot; groups [[0, 1], [2]]",
                   kind="box", n=3, groups=((0, 1), (2,)), blocked="narrow_passage",
                   start_box=((0.05, 0.35),) + ((0.05, 0.95),) * 2, goal_box=((0.65, 0.95),) + ((0.05, 0.95),) * 2,
                   resolution=0.005, seed=31),
)}
"""The generic problems by name."""
