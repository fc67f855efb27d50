"""The wearer + 4-DOF arm model: the muzzle, the line of sight, and the packaged model files.

One :class:`WearerArm` loads the URDF and SRDF once (the packaged default or user files); its
collision checking is that of any robot (:class:`~tpee_ompl.model.robot_checker.RobotChecker`:
URDF cylinders become Coal capsules, batched checks, lever arms).  It adds where the muzzle
points and whether the line of sight from the muzzle to a target is clear of the wearer.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Literal

import coal
import numpy as np
import pinocchio as pin

from ..resources import model_file
from ..validation import as_float_array
from .robot_checker import DEFAULT_SECURITY_MARGIN, MAX_SECURITY_MARGIN, RobotChecker
from .urdf_loading import ARM_JOINTS, MUZZLE_FRAME, LoadedModel, ModelFiles, load_wearer_model

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


MAX_TARGET_DISTANCE = 1.0e6
"""Metres. Targets with a coordinate beyond +-this are refused (no physical target is that far; beyond
it the line-of-sight and aiming arithmetic would lose its precision or overflow)."""


DEFAULT_URDF = "wearer_arm.urdf"
DEFAULT_SRDF = "wearer_arm.srdf"


def check_target_point(target: object) -> np.ndarray:
    """Return target as a (3,) float array (metres, world frame) within MAX_TARGET_DISTANCE, or raise
    ValueError naming it (the one check of a target point; aiming adds its own, geometric ones)."""
    t = as_float_array(target, "target")
    if t.shape != (3,) or not np.all(np.isfinite(t)):
        raise ValueError(f"target must be 3 finite numbers (x, y, z in metres), got {target!r}")
    if np.max(np.abs(t)) > MAX_TARGET_DISTANCE:
        raise ValueError(f"target {t} is farther than MAX_TARGET_DISTANCE = {MAX_TARGET_DISTANCE:g} m")
    return t


class WearerArm(RobotChecker):
    """A standing wearer made of collision primitives, with the paper's 4-DOF arm on the back.

    A :class:`~tpee_ompl.model.robot_checker.RobotChecker` (all the collision checking) of the
    wearer's URDF, plus the muzzle and the line of sight.  The wearer is the static world: it is
    on the universe joint, so ``link_margins`` widen arm-wearer pairs.

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
        srdf_path: str | os.PathLike | None | Literal[False] = None,
        security_margin: float = DEFAULT_SECURITY_MARGIN,
        n_threads: int | None = None,
        link_margins: Mapping[str, float] | None = None,
    ) -> None:
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
        self._setup(ModelFiles(urdf, srdf), security_margin, n_threads, link_margins, (MUZZLE_FRAME,))
        self.muzzle_frame_id = self.model.getFrameId(MUZZLE_FRAME)
        self._build_line_of_sight_shapes()

    def _load_model(self) -> LoadedModel:
        return load_wearer_model(self.files.urdf, self.files.srdf)

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

    # ------------------------------------------------------------------ pointing
    def muzzle(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Muzzle point (m) and unit pointing direction (+x of the barrel) in the world frame."""
        M = self.frame_placement(q, MUZZLE_FRAME)
        return M.translation.copy(), M.rotation[:, 0].copy()

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
