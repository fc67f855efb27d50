"""The wearer + 4-DOF arm model: loading, forward kinematics and collision checking.

One :class:`WearerArm` loads the URDF and SRDF once (the packaged default or user files),
turns the URDF cylinders into Coal capsules, and answers the questions every planner asks:
is this configuration valid, how far is it from collision, where does the muzzle point,
and is the line of sight from the muzzle to a target clear of the wearer.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from ..resources import model_file
from ..validation import as_float_array, check_int, check_number
from .urdf_loading import ARM_JOINTS, MUZZLE_FRAME, ModelFiles, bounding_radius, load_wearer_model

__all__ = [
    "ARM_JOINTS",
    "DEFAULT_SECURITY_MARGIN",
    "MAX_SECURITY_MARGIN",
    "MAX_TARGET_DISTANCE",
    "DEFAULT_SRDF",
    "DEFAULT_URDF",
    "WearerArm",
    "check_target_point",
    "default_robot",
]

log = logging.getLogger(__name__)

ARM_LINKS = ("link1", "link2", "link3", "link4")
BOOM_LINKS = ("link1", "link2")
DEFAULT_SECURITY_MARGIN = 0.02
"""Metres. A configuration is valid only if every checked pair is at least this far apart."""
MAX_SECURITY_MARGIN = 1.0
"""Metres. Largest accepted security margin (with more, every configuration touches the wearer)."""
MAX_TARGET_DISTANCE = 1.0e6
"""Metres. Targets with a coordinate beyond +-this are refused (no physical target is that far; beyond
it the line-of-sight and aiming arithmetic would lose its precision or overflow)."""


DEFAULT_URDF = "wearer_arm.urdf"
DEFAULT_SRDF = "wearer_arm.srdf"


def _as_config_batch(Q: np.ndarray, nq: int) -> np.ndarray:
    Q = as_float_array(Q, "configurations")
    if Q.ndim == 1:
        Q = Q[None, :]
    if Q.ndim != 2 or Q.shape[1] != nq:
        raise ValueError(f"configurations must have shape (N, {nq}); got {Q.shape}")
    bad = ~np.all(np.isfinite(Q), axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"configurations contain NaN or inf: row {k} is {Q[k]}")
    return Q


def check_target_point(target: object) -> np.ndarray:
    """Return target as a (3,) float array (metres, world frame) within MAX_TARGET_DISTANCE, or raise
    ValueError naming it (the one check of a target point; aiming adds its own, geometric ones)."""
    t = as_float_array(target, "target")
    if t.shape != (3,) or not np.all(np.isfinite(t)):
        raise ValueError(f"target must be 3 finite numbers (x, y, z in metres), got {target!r}")
    if np.max(np.abs(t)) > MAX_TARGET_DISTANCE:
        raise ValueError(f"target {t} is farther than MAX_TARGET_DISTANCE = {MAX_TARGET_DISTANCE:g} m")
    return t


class WearerArm:
    """A standing wearer made of collision primitives, with the paper's 4-DOF arm on the back.

    Parameters
    ----------
    urdf_path, srdf_path : path or None
        Model files; ``None`` loads the packaged default.  ``srdf_path=False`` uses no SRDF.
    security_margin : float, metres
        Pairs closer than this count as colliding (Coal security margin).
    n_threads : int or None
        Threads for batched checks (default: all cores, at most 2).
    link_margins : mapping {link name: metres}, optional
        Larger margins between these arm links and the wearer, e.g. ``{"link3": 0.03, "link4":
        0.03}`` to plan demonstrations that keep more room around the pointing system only.
        Arm-arm pairs keep ``security_margin`` (some sit at a fixed distance, e.g. the barrel and
        the boom 3.5 cm apart).  Never smaller than ``security_margin``.
    """

    def __init__(
        self,
        urdf_path: str | os.PathLike | None = None,
        srdf_path: str | os.PathLike | None | bool = None,
        security_margin: float = DEFAULT_SECURITY_MARGIN,
        n_threads: int | None = None,
        link_margins: Mapping[str, float] | None = None,
    ) -> None:
        security_margin = check_number("security_margin (metres)", security_margin, low=0.0, high=MAX_SECURITY_MARGIN)
        n_threads = check_int("n_threads", n_threads, minimum=1, maximum=1024, optional=True)
        for what, value in (("urdf_path", urdf_path), ("srdf_path", srdf_path)):
            if value is not None and value is not False and not isinstance(value, (str, os.PathLike)):
                raise ValueError(f"{what} must be a path, None or (srdf_path only) False, got {value!r}")
        if urdf_path is False:
            raise ValueError("urdf_path must be a path or None, got False")
        urdf = Path(urdf_path) if urdf_path is not None else model_file(DEFAULT_URDF)
        if srdf_path is None:
            srdf = model_file(DEFAULT_SRDF) if urdf_path is None else None
        elif srdf_path is False:
            srdf = None
        else:
            srdf = Path(srdf_path)
        self.files = ModelFiles(urdf, srdf)
        self.security_margin = float(security_margin)
        self.link_margins = self._check_link_margins(link_margins, self.security_margin)
        self.n_threads = int(n_threads) if n_threads is not None else min(2, os.cpu_count() or 1)
        self._lever_arms: np.ndarray | None = None
        self.collision_checks = 0
        """Configurations checked for collision so far (single and batched)."""
        self._load()

    # ------------------------------------------------------------------ loading
    def _load(self) -> None:
        urdf, srdf = self.files.urdf, self.files.srdf
        loaded = load_wearer_model(urdf, srdf)
        self.model, self.gmodel = loaded.model, loaded.gmodel
        self.model_hash = loaded.model_hash
        """Short SHA-256 of the URDF (+ SRDF) text: stored with query sets and path libraries."""
        self.data = self.model.createData()
        self._prune_unreachable_pairs()
        self._rebuild_geometry_data()
        self.muzzle_frame_id = self.model.getFrameId(MUZZLE_FRAME)
        self.lower = self.model.lowerPositionLimit.copy()
        self.upper = self.model.upperPositionLimit.copy()
        self._lower_list = self.lower.tolist()
        self._upper_list = self.upper.tolist()
        self._build_line_of_sight_shapes()
        log.debug("loaded %s: %d geometries, %d pairs", urdf, self.gmodel.ngeoms, len(self.gmodel.collisionPairs))

    def _prune_unreachable_pairs(self) -> None:
        """Drop arm-wearer pairs whose wearer part lies beyond the arm's reach from joint 1 (plus margin).

        Removing a pair that can never come within the margin changes no answer; it only saves time.
        """
        pin.forwardKinematics(self.model, self.data, pin.neutral(self.model))
        pivot = self.data.oMi[1].translation.copy()
        reach = self.lever_arms()[0] + max([self.security_margin, *self.link_margins.values()])
        removed = []
        for cp in list(self.gmodel.collisionPairs):
            a, b = self.gmodel.geometryObjects[cp.first], self.gmodel.geometryObjects[cp.second]
            wearer = a if a.parentJoint == 0 else b if b.parentJoint == 0 else None
            if wearer is None:
                continue
            gap = np.linalg.norm(wearer.placement.translation - pivot) - bounding_radius(wearer.geometry)
            if gap > reach:
                removed.append(cp)
        for cp in removed:
            self.gmodel.removeCollisionPair(cp)
        self.pruned_pairs = len(removed)

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
        """(ng, ng) security margins: the base margin, raised for the wearer pairs of ``link_margins``' links."""
        on_wearer = np.array([g.parentJoint == 0 for g in self.gmodel.geometryObjects])
        with_geometry = {self.model.frames[g.parentFrame].name for g in self.gmodel.geometryObjects}
        unknown = sorted(set(self.link_margins) - with_geometry)
        if unknown:
            raise ValueError(f"link_margins names unknown link(s) or links without collision geometry {unknown}; "
                             f"links with geometry: {sorted(with_geometry)}")
        link_margin = np.array([self.link_margins.get(self.model.frames[g.parentFrame].name, self.security_margin)
                                for g in self.gmodel.geometryObjects])
        arm_wearer = on_wearer[:, None] != on_wearer[None, :]
        wide = np.maximum(link_margin[:, None], link_margin[None, :])
        return np.where(arm_wearer, wide, self.security_margin)

    def _rebuild_geometry_data(self) -> None:
        self.gdata = pin.GeometryData(self.gmodel)
        self.gdata.setSecurityMargins(self.gmodel, self._margin_matrix())
        for req in self.gdata.collisionRequests:
            req.enable_contact = True  # Coal misses edge/corner contacts otherwise
        self.pool = pin.GeometryPool(self.model, self.gmodel, self.n_threads)
        self.pool.update(self.gdata)

    def _build_line_of_sight_shapes(self) -> None:
        """Wearer geometries (static) and boom geometries (moving) that may block the line of sight."""
        boom_joints = {self.model.getJointId(j) for j in ("j1", "j2")}
        self._los_static = []
        self._los_boom = []
        for i, go in enumerate(self.gmodel.geometryObjects):
            if go.parentJoint == 0:
                self._los_static.append(coal.CollisionObject(go.geometry, coal.Transform3s(go.placement)))
            elif go.parentJoint in boom_joints:
                self._los_boom.append(i)
        self._los_manager = coal.DynamicAABBTreeCollisionManager()
        for obj in self._los_static:
            self._los_manager.registerObject(obj)
        self._los_manager.setup()

    # ------------------------------------------------------------------ facts
    @property
    def nq(self) -> int:
        """Number of joints (4)."""
        return self.model.nq

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint names in configuration order."""
        return tuple(self.model.names[1:])

    def geometry_names(self, joint: str | int = 0) -> list[str]:
        """Names of the geometries attached to a joint (0 = the wearer)."""
        jid = joint if isinstance(joint, int) else self.model.getJointId(joint)
        return [go.name for go in self.gmodel.geometryObjects if go.parentJoint == jid]

    def lever_arms(self) -> np.ndarray:
        """Upper bound, per joint, on the distance from that joint's axis to any arm point it moves (metres).

        Used to bound how far the arm can move for a given joint step (see :meth:`max_joint_step`).
        The model is fixed after loading, so this is computed once.
        """
        if self._lever_arms is None:
            self._lever_arms = self._compute_lever_arms()
        return self._lever_arms.copy()

    def _compute_lever_arms(self) -> np.ndarray:
        n = self.nq
        reach = np.zeros(n)
        for j in range(1, n + 1):
            best = 0.0
            for go in self.gmodel.geometryObjects:
                k = go.parentJoint
                if k < j:
                    continue
                # chain of joint offsets from joint j down to the geometry's joint, then the shape itself
                dist = sum(np.linalg.norm(self.model.jointPlacements[m].translation) for m in range(j + 1, k + 1))
                dist += np.linalg.norm(go.placement.translation) + bounding_radius(go.geometry)
                best = max(best, dist)
            for f in self.model.frames:  # the muzzle tip too
                if f.parentJoint >= j and f.name == MUZZLE_FRAME:
                    dist = sum(np.linalg.norm(self.model.jointPlacements[m].translation) for m in range(j + 1, f.parentJoint + 1))
                    best = max(best, dist + np.linalg.norm(f.placement.translation))
            reach[j - 1] = best
        return reach

    def max_joint_step(self, displacement: float | None = None) -> float:
        """Largest Euclidean joint step (radians) that moves no point of the arm more than ``displacement``.

        A step dq moves any arm point at most sum_i |dq_i| r_i <= ||dq||_2 ||r||_2 (Cauchy-Schwarz),
        with r the lever arms.  Default displacement: the security margin.
        """
        d = self.security_margin if displacement is None else float(displacement)
        if not d > 0:
            raise ValueError("displacement must be > 0 (a zero security margin gives no motion-check guarantee)")
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
        """True if q is inside the URDF joint limits."""
        q = self.check_config(q)
        return bool(np.all(q >= self.lower) and np.all(q <= self.upper))

    def frame_placement(self, q: np.ndarray, frame: str) -> pin.SE3:
        """World placement of a named frame at configuration q."""
        q = self.check_config(q)
        fid = self.model.getFrameId(frame)
        if fid >= self.model.nframes:
            raise ValueError(f"unknown frame {frame!r}")
        pin.forwardKinematics(self.model, self.data, q)
        return pin.updateFramePlacement(self.model, self.data, fid)

    def joint_placement(self, q: np.ndarray, joint: str) -> pin.SE3:
        """World placement of a joint frame at configuration q."""
        q = self.check_config(q)
        pin.forwardKinematics(self.model, self.data, q)
        return self.data.oMi[self.model.getJointId(joint)].copy()

    def muzzle(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Muzzle point (m) and unit pointing direction (+x of the barrel) in the world frame."""
        M = self.frame_placement(q, MUZZLE_FRAME)
        return M.translation.copy(), M.rotation[:, 0].copy()

    # ------------------------------------------------------------------ collision
    def is_valid(self, q: np.ndarray) -> bool:
        """True if q is within limits and no checked pair (arm-wearer, arm-arm) is closer than its margin
        (``security_margin``, or for an arm-wearer pair the arm link's ``link_margins`` entry)."""
        q = self.check_config(q)
        if not (np.all(q >= self.lower) and np.all(q <= self.upper)):
            return False
        self.collision_checks += 1
        return not pin.computeCollisions(self.model, self.data, self.gmodel, self.gdata, q, True)

    def is_valid_values(self, values: Sequence[float]) -> bool:
        """:meth:`is_valid` for nq plain floats (an OMPL state's values), without the input checks.

        The per-state OMPL checker calls this ~10^5 times per plan.  NaN fails the limit test, so a
        non-finite value is still reported invalid rather than passed to Pinocchio.  Another number of
        values than ``nq`` raises ValueError naming it (one ``len``: the only check added to the hot path).
        """
        if len(values) != self.nq:
            raise ValueError(f"is_valid_values needs {self.nq} values (DOF1..DOF{self.nq}), got {len(values)}")
        for v, lo, hi in zip(values, self._lower_list, self._upper_list):
            if not lo <= v <= hi:
                return False
        self.collision_checks += 1
        return not pin.computeCollisions(self.model, self.data, self.gmodel, self.gdata, np.array(values), True)

    def are_valid(self, Q: np.ndarray) -> np.ndarray:
        """Batched :meth:`is_valid` for Q of shape (N, nq): one Pinocchio call; returns bool (N,)."""
        Q = _as_config_batch(Q, self.nq)
        ok = np.all((Q >= self.lower) & (Q <= self.upper), axis=1)
        if ok.any():
            Qin = np.ascontiguousarray(Q[ok].T)  # Pinocchio wants (nq, N)
            self.collision_checks += Qin.shape[1]
            collides = pin.computeCollisionsInParallel(self.n_threads, self.pool, Qin, True, False)
            ok[ok] = ~np.asarray(collides, dtype=bool)
        return ok

    def clearance(self, q: np.ndarray) -> float:
        """Smallest distance (m, negative when penetrating) over all checked pairs at q."""
        q = self.check_config(q)
        k = pin.computeDistances(self.model, self.data, self.gmodel, self.gdata, q)
        return float(self.gdata.distanceResults[k].min_distance)

    def closest_pair(self, q: np.ndarray) -> tuple[str, str, float]:
        """The two geometry names of the closest checked pair at q, and their distance (m)."""
        q = self.check_config(q)
        k = pin.computeDistances(self.model, self.data, self.gmodel, self.gdata, q)
        cp = self.gmodel.collisionPairs[k]
        names = self.gmodel.geometryObjects
        return names[cp.first].name, names[cp.second].name, float(self.gdata.distanceResults[k].min_distance)

    def line_of_sight_clear(self, q: np.ndarray, target: np.ndarray) -> bool:
        """True if the segment muzzle -> target touches neither the wearer nor the arm's boom."""
        target = check_target_point(target)
        p, _ = self.muzzle(q)
        d = target - p
        length = float(np.linalg.norm(d))
        if length < 1e-9:
            return True
        R = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), d / length).matrix()
        seg = coal.CollisionObject(coal.Capsule(0.0, length), coal.Transform3s(R, p + d / 2))
        cb = coal.CollisionCallBackDefault()
        self._los_manager.collide(seg, cb)
        if cb.data.result.isCollision():
            return False
        pin.updateGeometryPlacements(self.model, self.data, self.gmodel, self.gdata)  # boom moved with q
        req, res = coal.CollisionRequest(), coal.CollisionResult()
        for i in self._los_boom:
            res.clear()
            if coal.collide(seg.collisionGeometry(), seg.getTransform(), self.gmodel.geometryObjects[i].geometry,
                            coal.Transform3s(self.gdata.oMg[i]), req, res):
                return False
        return True


_DEFAULT: WearerArm | None = None


def default_robot() -> WearerArm:
    """The packaged model, loaded once per process (read-only use; build your own to change settings)."""
    global _DEFAULT
    if _DEFAULT is None:
        _DEFAULT = WearerArm()
    return _DEFAULT
