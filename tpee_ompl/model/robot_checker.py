"""Batched collision checking of any URDF robot among fixed obstacles, with Pinocchio and Coal.

One :class:`RobotChecker` loads a URDF (+ SRDF) once, adds the obstacles, prunes the pairs that
can never come close, and answers what every planner asks: is this configuration valid (one at a
time or a batch in one ``pin.computeCollisionsInParallel`` call, both through Pinocchio's tree broadphase:
:mod:`~tpee_ompl.model.collision_pools`), how far is it from collision,
and how large a joint step keeps every point of the robot within a given displacement
(:meth:`RobotChecker.max_joint_step`, the motion-check guarantee of :mod:`tpee_ompl.planning.setup`).
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..validation import as_config_batch, as_float_array, check_bool, check_int, check_number
from .clearance_balls import BallScreen, separated_pairs
from .collision_pools import CollisionPool, new_pool, single_check
from .lever_arms import joint_lever_arms, pair_lever_arms
from .obstacles import Obstacle
from .pair_diagnostics import warn_always_colliding
from .stall_guard import StallGuard
from .urdf_loading import LoadedModel, ModelFiles, bounding_radius, is_prismatic, load_urdf_model

__all__ = ["DEFAULT_SECURITY_MARGIN", "MAX_SECURITY_MARGIN", "RobotChecker"]

log = logging.getLogger(__name__)

DEFAULT_SECURITY_MARGIN = 0.02
"""Metres. A configuration is valid only if every checked pair is at least this far apart."""
MAX_SECURITY_MARGIN = 1.0
"""Metres. Largest accepted security margin."""
FIRST_INVALID_PAIRS = True
"""``first_invalid`` checks its rows two at a time, one per thread, when the checker has two threads (the same
answer and an exact count; False: one row at a time on one thread, before 2026-11-26; a switch for
``experiments/speed_switches.py pair-checks``)."""
class RobotChecker:
    """Collision checking of a URDF robot (every 1-DOF joint not locked is planned) among obstacles.

    A continuous joint's coordinate is its angle (:attr:`circular`): planners keep it in [-pi, pi] (:attr:`lower`,
    :attr:`upper`), and the validity checks take any finite angle as the same joint position wrapped (ROS's
    ``joint_states`` report continuous joints unwrapped, e.g. 7.0 rad).

    Parameters
    ----------
    urdf_path : path
    srdf_path : path or None
        Its ``disable_collisions`` link pairs are not checked.
    security_margin : float, metres
        Pairs closer than this count as colliding (Coal security margin).
    n_threads : int or None
        Threads for batched checks (default: all cores, at most 2).
    link_margins : mapping {link name: metres}, optional
        Larger margins between these links and the static world (the fixed base and the
        obstacles: every geometry on the universe joint).  Moving-moving pairs keep
        ``security_margin``.  Never smaller than ``security_margin``.
    obstacles : sequence of :class:`~tpee_ompl.model.obstacles.Obstacle`
    locked : mapping {joint name: value}, optional
        Joints removed from planning, fixed at these values (radians or metres).
    package_dirs : sequence of paths
        Where ``package://`` mesh files are found.
    cylinders_as_capsules : bool
        Load every URDF ``<cylinder>`` as a Coal capsule of the same radius and length (default,
        the wearer's rule: its 1.0 URDF writes capsules as cylinders; a ``<capsule>``, which urdfdom reads from
        version 1.1 on, is one already).
        False keeps true cylinders.  Obstacles are never converted.
    extra_points : sequence of frame names
        Frames whose origins count as robot points in :meth:`lever_arms` (e.g. a tool tip).
    srdf_unknown_links : {"error", "skip"}
        An SRDF pair naming a link the URDF lacks is an error (default: a typo would leave the pair checked), or
        is passed over (``"skip"``: the SRDF of a larger robot, e.g. a humanoid's for one of its arms).
    convex_meshes : bool
        Check every robot mesh as its convex hull (never a collision missed; cheap near contact, where a
        detailed mesh at a positive margin can cost milliseconds per pair).  Off by default.
    """

    def __init__(
        self,
        urdf_path: str | os.PathLike,
        srdf_path: str | os.PathLike | None = None,
        *,
        security_margin: float = DEFAULT_SECURITY_MARGIN,
        n_threads: int | None = None,
        link_margins: Mapping[str, float] | None = None,
        obstacles: Sequence[Obstacle] = (),
        locked: Mapping[str, float] | None = None,
        package_dirs: Sequence[str | os.PathLike] = (),
        cylinders_as_capsules: bool = True,
        extra_points: Sequence[str] = (),
        convex_meshes: bool = False,
        srdf_unknown_links: str = "error",
    ) -> None:
        for what, value in (("urdf_path", urdf_path), ("srdf_path", srdf_path)):
            if value is not None and not isinstance(value, (str, os.PathLike)) or isinstance(value, bool):
                raise ValueError(f"{what} must be a path{' or None' if what == 'srdf_path' else ''}, got {value!r}")
        if urdf_path is None:
            raise ValueError("urdf_path must be a path, got None")
        if locked is not None and not isinstance(locked, Mapping):
            raise ValueError(f"locked must be a mapping {{joint name: value}}, got {locked!r}")
        if isinstance(obstacles, (str, Obstacle)) or not isinstance(obstacles, Sequence):
            raise ValueError(f"obstacles must be a sequence of Obstacle, got {obstacles!r}")
        if isinstance(package_dirs, (str, os.PathLike)):
            package_dirs = (package_dirs,)
        if not isinstance(package_dirs, (list, tuple)) or not all(isinstance(d, (str, os.PathLike)) for d in package_dirs):
            raise ValueError(f"package_dirs must be a path or a list of paths, got {package_dirs!r}")
        self._options = {"package_dirs": tuple(package_dirs), "locked": dict(locked or {}), "obstacles": tuple(obstacles),
                         "cylinders_as_capsules": check_bool("cylinders_as_capsules", cylinders_as_capsules),
                         "convex_meshes": check_bool("convex_meshes", convex_meshes),
                         "srdf_unknown_links": srdf_unknown_links}
        self._setup(ModelFiles(Path(urdf_path), Path(srdf_path) if srdf_path is not None else None),
                    security_margin, n_threads, link_margins, extra_points)

    def _setup(self, files: ModelFiles, security_margin: float, n_threads: int | None,
               link_margins: Mapping[str, float] | None, extra_points: Sequence[str]) -> None:
        """Check the settings, load the files (:meth:`_load_model`), prune pairs, build the pool."""
        self.security_margin = check_number("security_margin (metres)", security_margin, low=0.0, high=MAX_SECURITY_MARGIN)
        n_threads = check_int("n_threads", n_threads, minimum=1, maximum=1024, optional=True)
        self.files = files
        self.link_margins = self._check_link_margins(link_margins, self.security_margin)
        self.n_threads = int(n_threads) if n_threads is not None else min(2, os.cpu_count() or 1)
        if self.n_threads > (os.cpu_count() or 1):  # each thread has its own copy of the collision data (meshes)
            log.warning("n_threads=%d on a machine with %d core(s): each thread holds a copy of the collision data, and "
                        "threads beyond the cores only wait", self.n_threads, os.cpu_count() or 1)
        self._lever_arms: np.ndarray | None = None
        self._pair_lever_arms: np.ndarray | None = None
        self.collision_checks = 0
        """Configurations checked for collision so far (single and batched)."""
        self.stall_guard = StallGuard()
        """When threaded calls stall on a busy machine, the next ones run on one thread for a while."""
        loaded = self._load_model()
        self.model, self.gmodel = loaded.model, loaded.gmodel
        self.model_hash = loaded.model_hash
        """Short SHA-256 of the URDF (+ SRDF, mesh files, locked joints, obstacles): kept with query sets, libraries."""
        self.circular = np.array([n in loaded.continuous for n in self.model.names[1:]], dtype=bool)
        """Per planned joint, True for a URDF continuous joint: its coordinate is an angle in [-pi, pi] that wraps
        around (an SO2 subspace in :func:`~tpee_ompl.planning.setup.make_space`)."""
        self.circular.setflags(write=False)
        self.data = self.model.createData()
        if isinstance(extra_points, str) or not all(isinstance(f, str) for f in extra_points):
            raise ValueError(f"extra_points must be a sequence of frame names, got {extra_points!r}")
        unknown = [f for f in extra_points if not self.model.existFrame(f)]
        if unknown:
            raise ValueError(f"extra_points names unknown frame(s) {unknown}")
        self._extra_frames = tuple(self.model.getFrameId(f) for f in extra_points)
        self._prune_unreachable_pairs()
        self.lower = self.model.lowerPositionLimit.copy()
        self.upper = self.model.upperPositionLimit.copy()
        self._rebuild_geometry_data()
        big = np.finfo(float).max  # a continuous joint takes any finite angle (inf and NaN fail)
        self.check_lower = np.where(self.circular, -big, self.lower)
        self.check_upper = np.where(self.circular, big, self.upper)
        """:attr:`lower` and :attr:`upper` as the validity checks use them: +/- max float for a continuous joint."""
        self._lower_list = self.check_lower.tolist()
        self._upper_list = self.check_upper.tolist()
        self.always_colliding = warn_always_colliding(self)
        """Link pairs within their margin in every configuration sampled at load (then no state is valid; warned)."""
        log.debug("loaded %s: %d geometries, %d pairs", files.urdf, self.gmodel.ngeoms, len(self.gmodel.collisionPairs))

    def _load_model(self) -> LoadedModel:
        return load_urdf_model(self.files.urdf, self.files.srdf, **self._options)

    def _prune_unreachable_pairs(self) -> None:
        """Drop static-static pairs, and static-moving pairs whose static geometry lies beyond the reach
        of the moving geometry's subtree (the lever arm of its revolute root joint, plus the margin).

        Removing a pair that can never come within the margin changes no answer; it only saves time.
        """
        pin.forwardKinematics(self.model, self.data, pin.neutral(self.model))
        arms = self.lever_arms()
        margin = max([self.security_margin, *self.link_margins.values()])
        parents = self.model.parents
        removed = []
        # copies: items are views into the C++ vector, shifted by each removal (the wrong pairs went, collisions missed)
        for cp in [pin.CollisionPair(c.first, c.second) for c in self.gmodel.collisionPairs]:
            a, b = self.gmodel.geometryObjects[cp.first], self.gmodel.geometryObjects[cp.second]
            if a.parentJoint == 0 and b.parentJoint == 0:
                removed.append(cp)
                continue
            static, moving = (a, b) if a.parentJoint == 0 else (b, a) if b.parentJoint == 0 else (None, None)
            if static is None:
                continue
            root = moving.parentJoint
            while parents[root] != 0:
                root = parents[root]
            if is_prismatic(self.model.joints[root]):
                continue  # its origin moves: no fixed pivot to measure from
            pivot = self.data.oMi[root].translation
            gap = np.linalg.norm(static.placement.translation - pivot) - bounding_radius(static.geometry)
            if gap > arms[root - 1] + margin:
                removed.append(cp)
        for cp in removed:
            self.gmodel.removeCollisionPair(cp)
        self.pruned_pairs = len(removed)
        """Collision pairs dropped as never within the margin."""

    @staticmethod
    def _check_link_margins(link_margins: Mapping[str, float] | None, base: float) -> dict[str, float]:
        if link_margins is None:
            return {}
        if not isinstance(link_margins, Mapping):
            raise ValueError(f"link_margins must be a mapping {{link name: metres}}, got {link_margins!r}")
        out = {}
        for name, m in link_margins.items():
            if not isinstance(name, str):
                raise ValueError(f"link_margins keys must be link names, got {name!r}")
            out[name] = check_number(f"link_margins[{name!r}] (metres, >= security_margin = {base})", m,
                                     low=base, high=MAX_SECURITY_MARGIN)
        return out

    def _margin_matrix(self) -> np.ndarray:
        """(ng, ng) security margins: the base margin, raised for the static pairs of ``link_margins``' links."""
        static = np.array([g.parentJoint == 0 for g in self.gmodel.geometryObjects])
        with_geometry = {self.model.frames[g.parentFrame].name for g in self.gmodel.geometryObjects}
        unknown = sorted(set(self.link_margins) - with_geometry)
        if unknown:
            raise ValueError(f"link_margins names unknown link(s) or links without collision geometry {unknown}; "
                             f"links with geometry: {sorted(with_geometry)}")
        link_margin = np.array([self.link_margins.get(self.model.frames[g.parentFrame].name, self.security_margin)
                                for g in self.gmodel.geometryObjects])
        moving_static = static[:, None] != static[None, :]
        wide = np.maximum(link_margin[:, None], link_margin[None, :])
        return np.where(moving_static, wide, self.security_margin)

    def new_check_data(self) -> pin.GeometryData:
        """A fresh ``GeometryData`` set up as the checks use it: per-pair margins, contacts enabled, and
        the pairs proven separated (:attr:`separated_pairs`) not checked."""
        gdata = pin.GeometryData(self.gmodel)
        gdata.setSecurityMargins(self.gmodel, self._margin_matrix())
        for req in gdata.collisionRequests:
            req.enable_contact = True  # Coal misses edge/corner contacts otherwise
        for p in self.separated_pairs:
            gdata.deactivateCollisionPair(p)
        return gdata

    def ball_screen(self) -> BallScreen:
        """The robot's :class:`~tpee_ompl.model.clearance_balls.BallScreen` (built on first use)."""
        if self._ball_screen is None:
            self._ball_screen = BallScreen(self)
        return self._ball_screen

    def _rebuild_geometry_data(self) -> None:
        self._ball_screen: BallScreen | None = None
        M = self._margin_matrix()  # (the model is fixed after loading: computed once)
        self._pair_margins = np.array([M[cp.first, cp.second] for cp in self.gmodel.collisionPairs])
        self.separated_pairs = tuple(separated_pairs(self))
        """Pairs (``gmodel.collisionPairs`` indices) proven never within their margin, so not checked
        (:func:`~tpee_ompl.model.clearance_balls.separated_pairs`); :meth:`clearance` still measures them."""
        self.gdata = self.new_check_data()
        self._distance_data = pin.GeometryData(self.gmodel)
        self.pool = new_pool(self.model, self.gmodel, self.gdata, self.n_threads)
        self._collides = single_check(self.model, self.data, self.gmodel, self.gdata)

    # ------------------------------------------------------------------ facts
    @property
    def nq(self) -> int:
        """Number of planned joints."""
        return self.model.nq

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint names in configuration order."""
        return tuple(self.model.names[1:])

    def geometry_names(self, joint: str | int = 0) -> list[str]:
        """Names of the geometries attached to a joint (0 = the static world: fixed base and obstacles)."""
        jid = self._joint_id(joint) if not isinstance(joint, int) or isinstance(joint, bool) else joint
        if not 0 <= jid < self.model.njoints:
            raise ValueError(f"joint index {joint} is out of range 0..{self.model.njoints - 1}")
        return [go.name for go in self.gmodel.geometryObjects if go.parentJoint == jid]

    def _joint_id(self, joint: str) -> int:
        """The model's index of the joint named ``joint``; ValueError naming it when there is none."""
        if not isinstance(joint, str) or not self.model.existJointName(joint):
            raise ValueError(f"unknown joint {joint!r} (joints: {list(self.model.names)[1:]})")
        return int(self.model.getJointId(joint))

    def lever_arms(self) -> np.ndarray:
        """Per joint, how far a unit step of it can move any robot point: metres per radian for a
        revolute joint (an upper bound on the distance from its axis to any point it moves), 1 for a
        prismatic joint.  Points: every geometry (its bounding sphere) and the ``extra_points`` frames.

        Used to bound how far the robot can move for a given joint step (see :meth:`max_joint_step`); computed once."""
        if self._lever_arms is None:
            self._lever_arms = joint_lever_arms(self.model, self.gmodel, self._extra_frames)
        return self._lever_arms.copy()

    def pair_lever_arms(self) -> np.ndarray:
        """Per checked pair, how fast each joint can change the pair's distance: shape (P, nq), P =
        ``len(gmodel.collisionPairs)`` in that order; metres per radian (revolute) or per metre (prismatic).

        Seen from the two bodies' lowest common ancestor, only the joints on the kinematic path between
        them move one body relative to the other; joint i of that path moves a point of geometry g by at
        most ``|dq_i|`` times the lever of i to g (as in :meth:`lever_arms`, but for g alone).  So
        ``|d_p(q') - d_p(q)| <= sum_i |q'_i - q_i| R[p, i]`` along any straight joint motion.  A row of
        zeros is a pair whose distance cannot change.  Computed once (the model is fixed after loading).
        """
        if self._pair_lever_arms is None:
            self._pair_lever_arms = pair_lever_arms(self.model, self.gmodel)
        return self._pair_lever_arms.copy()

    def pair_margins(self) -> np.ndarray:
        """Per checked pair (``gmodel.collisionPairs`` order), its security margin in metres (shape (P,)):
        a configuration is valid only if every pair's distance is at least its margin."""
        return self._pair_margins.copy()

    def max_joint_step(self, displacement: float | None = None) -> float:
        """Largest Euclidean joint step that moves no point of the robot more than ``displacement`` (m).

        A step dq moves any point at most sum_i |dq_i| r_i <= ||dq||_2 ||r||_2 (Cauchy-Schwarz), with r the lever
        arms.  Default displacement: the security margin."""
        if displacement is None:
            if not self.security_margin > 0:
                raise ValueError("security_margin is 0: a zero margin gives no motion-check guarantee (no step moves "
                                 "nothing); give a margin > 0 or a joint_step")
            d = self.security_margin
        else:
            d = check_number("displacement (metres)", displacement, low=0.0, low_open=True)
        return d / float(np.linalg.norm(self.lever_arms()))

    # ------------------------------------------------------------------ kinematics
    def check_config(self, q: np.ndarray) -> np.ndarray:
        """Return q as a float array of shape (nq,), or raise ValueError naming the problem."""
        q = as_float_array(q, "configuration")
        if q.shape != (self.nq,):
            raise ValueError(f"configuration must have shape ({self.nq},); got {q.shape}")
        if not np.all(np.isfinite(q)):
            raise ValueError(f"configuration contains NaN or inf: {q}")
        return q

    def within_limits(self, q: np.ndarray) -> bool:
        """True if q is inside the URDF joint limits (a continuous joint has none: any finite angle)."""
        return bool(self.inside_limits(self.check_config(q)[None])[0])

    def inside_limits(self, Q: np.ndarray) -> np.ndarray:
        """Per row of Q (N, nq), True when inside the joint limits (:meth:`within_limits`); no input checks."""
        return ((Q >= self.check_lower) & (Q <= self.check_upper)).all(axis=-1)

    def check_free(self, q: np.ndarray, name: str = "configuration") -> np.ndarray:
        """Return q (nq,) when it is finite, inside the joint limits and collision-free, else raise ValueError
        naming ``name`` and, for a collision, the closest pair (a planning or tracking endpoint's check)."""
        try:
            q = self.check_config(q)
        except ValueError as exc:
            raise ValueError(f"{name}: {exc}") from None
        shown = f"[{', '.join(f'{v:.4g}' for v in q)}]"
        if not self.within_limits(q):
            k = int(np.flatnonzero((q < self.check_lower) | (q > self.check_upper))[0])
            raise ValueError(f"{name} {shown} is outside the joint limits: {self.joint_names[k]} = {q[k]:.6g} is "
                             f"outside [{self.lower[k]:.6g}, {self.upper[k]:.6g}]")
        if not self.is_valid(q):
            a, b, d = self.closest_pair(q)
            hint = ("; neighbouring links: if they always touch, disable the pair in the SRDF"
                    if self._neighbours(a, b) else "")
            raise ValueError(f"{name} {shown} is in collision ({a} vs {b}, distance {d:.3f} m{hint})")
        return q

    def _neighbours(self, geometry_a: str, geometry_b: str) -> bool:
        """True when the geometries' bodies are one or joined by one joint; an obstacle (universe frame) never is."""
        a, b = (self.gmodel.geometryObjects[self.gmodel.getGeometryId(g)] for g in (geometry_a, geometry_b))
        ja, jb, up = a.parentJoint, b.parentJoint, self.model.parents
        return (ja == jb or up[ja] == jb or up[jb] == ja) and 0 not in (a.parentFrame, b.parentFrame)

    def frame_placement(self, q: np.ndarray, frame: str) -> pin.SE3:
        """World placement of a named frame at configuration q."""
        q = self.check_config(q)
        if not isinstance(frame, str) or not self.model.existFrame(frame):
            raise ValueError(f"unknown frame {frame!r}")
        fid = self.model.getFrameId(frame)
        pin.forwardKinematics(self.model, self.data, q)
        return pin.updateFramePlacement(self.model, self.data, fid)

    def joint_placement(self, q: np.ndarray, joint: str) -> pin.SE3:
        """World placement of a joint frame at configuration q."""
        q = self.check_config(q)
        jid = self._joint_id(joint)
        pin.forwardKinematics(self.model, self.data, q)
        return self.data.oMi[jid].copy()

    # ------------------------------------------------------------------ collision
    def is_valid(self, q: np.ndarray) -> bool:
        """True if q is within limits and no checked pair is closer than its margin
        (``security_margin``, or for a pair with the static world the link's ``link_margins`` entry)."""
        q = self.check_config(q)
        if not self.inside_limits(q[None])[0]:
            return False
        self.collision_checks += 1
        return not self._collides(q, True)

    def is_valid_values(self, values: Sequence[float]) -> bool:
        """:meth:`is_valid` for nq plain floats (an OMPL state's values), without the input checks.

        The per-state OMPL checker calls this ~10^5 times per plan.  NaN fails the limit test, so a
        non-finite value is still reported invalid rather than passed to Pinocchio.  Another number of
        values than ``nq`` raises ValueError naming it (one ``len``: the only check added to the hot path).
        """
        if len(values) != self.nq:
            raise ValueError(f"is_valid_values needs {self.nq} values (one per joint), got {len(values)}")
        for v, lo, hi in zip(values, self._lower_list, self._upper_list):
            if not lo <= v <= hi:
                return False
        self.collision_checks += 1
        return not self._collides(np.array(values), True)

    def are_valid(self, Q: np.ndarray) -> np.ndarray:
        """Batched :meth:`is_valid` for Q of shape (N, nq): one Pinocchio call; returns bool (N,)."""
        Q = as_config_batch(Q, self.nq)
        ok = self.inside_limits(Q)
        if ok.any():
            ok[ok] = self.collision_free(Q[ok])
        return ok

    def first_invalid(self, Q: np.ndarray) -> int:
        """Index of the first invalid row of Q (N, nq), or -1: :meth:`are_valid` in row order, stopping there.

        The rows are checked in order, two at a time (one per thread) when the checker has two threads,
        and the checks stop after the pair that holds the first invalid row: a caller that puts the states
        most likely to fail first (a motion's midpoint before its quarter points) finds a failure without
        checking the rest.  The count is exact (both rows of the last pair, only rows checked for collision).
        Pairs rather than one call for all rows: Pinocchio's stop-at-first-collision splits a batch between
        its threads in halves, so the second thread would start with the rows least likely to fail and the
        rows checked could not be counted."""
        Q = as_config_batch(Q, self.nq)
        if len(Q) == 0:
            return -1
        outside = (~self.inside_limits(Q)).nonzero()[0]
        end = int(outside[0]) if len(outside) else len(Q)
        if end == 0:
            return 0
        Qt = np.asfortranarray(Q[:end].T)  # (nq, end), each configuration a contiguous column
        first, a = end, 0
        if self.stall_guard.threads(self.n_threads) > 1 and end > 1 and FIRST_INVALID_PAIRS:
            for a in range(0, end, 2):
                t = time.perf_counter()
                pair = pin.computeCollisionsInParallel(2, self.pool, Qt[:, a : a + 2], True, False)
                self.collision_checks += len(pair)
                if any(pair):
                    first = a if pair[0] else a + 1
                    break
                if self.stall_guard.stalled(t, 2):  # the rest on one thread
                    a += 2
                    break
            else:
                a = end
        if first == end and a < end:
            collides = np.asarray(pin.computeCollisionsInParallel(1, self.pool, Qt[:, a:], True, True), dtype=bool)
            first = a + int(np.argmax(collides)) if collides.any() else end
            self.collision_checks += min(first + 1, end) - a
        return first if first < len(Q) else -1

    @property
    def stalls(self) -> int:
        """Times the checker went on one thread after stalled calls (:class:`~tpee_ompl.model.stall_guard.StallGuard`)."""
        return self.stall_guard.stalls

    def collision_free(self, Q: np.ndarray, pool: CollisionPool | None = None) -> np.ndarray:
        """:meth:`are_valid` for a float array Q (N >= 1, nq) already known finite and inside the joint
        limits (a motion's states between two checked ends): the collision check alone, no input checks.
        ``pool``: another pool of this model with other margins (default: the checks' own)."""
        self.collision_checks += len(Q)
        threads = self.stall_guard.threads(self.n_threads)
        t = time.perf_counter()
        collides = pin.computeCollisionsInParallel(threads, self.pool if pool is None else pool,
                                                   np.ascontiguousarray(Q.T), True, False)
        if threads > 1:
            self.stall_guard.stalled(t, len(Q))
        return ~np.asarray(collides, dtype=bool)

    def _closest(self, q: np.ndarray) -> int:
        """Distances of every checked pair at q computed; the closest pair's index, -1 when none is checked."""
        k = pin.computeDistances(self.model, self.data, self.gmodel, self._distance_data, self.check_config(q))
        return k if len(self._pair_margins) else -1

    def clearance(self, q: np.ndarray, from_margins: bool = False) -> float:
        """Smallest distance (m, negative when penetrating) over all checked pairs at q; ``from_margins``: of each pair's
        distance less its margin, the distance to the nearest invalid configuration (OMPL's clearance; < 0 inside one)."""
        k = self._closest(q)
        if from_margins:
            d = np.fromiter((r.min_distance for r in self._distance_data.distanceResults), float)
            return float((d - self._pair_margins).min()) if len(d) else np.inf
        return float(self._distance_data.distanceResults[k].min_distance) if k >= 0 else np.inf

    def closest_pair(self, q: np.ndarray) -> tuple[str, str, float]:
        """The two geometry names of the closest checked pair at q, and their distance (m); ValueError without pairs."""
        k = self._closest(q)
        if k < 0:
            raise ValueError("closest_pair: no collision pair is checked (each was disabled or proven never close)")
        cp = self.gmodel.collisionPairs[k]
        names = self.gmodel.geometryObjects
        return names[cp.first].name, names[cp.second].name, float(self._distance_data.distanceResults[k].min_distance)
