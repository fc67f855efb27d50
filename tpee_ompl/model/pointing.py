"""Aiming inverse kinematics of the target pointing end effector (paper section 2.3, eqs. 1-11).

Given a target point in the world frame and the posture sector's DOF1/DOF2, the pan (DOF3) and
tilt (DOF4) angles that put the target on the barrel's extension line have a closed form: move the
target into the pan joint's frame (eq. 6), turn the pan so that the target lies in the barrel's
plane, which is offset by l_OB = L3 from the pan axis (eqs. 7-9), then tilt the barrel up to the
target (eqs. 10-11).  Every constant is read from the loaded model (:class:`PointingGeometry`).

Deviations from the printed equations (all checked against Pinocchio FK of the URDF)
-------------------------------------------------------------------------------------
1. Eq. 6, ``S = W * M - T``: the world origin of the paper sits at the DOF1/DOF2 pivot; here the
   pivot is at ``pivot`` (the j1 origin), so ``S = M^T (W - pivot) - T`` (row vector times M is
   ``M^T W``, the world-to-j2-frame rotation, which the paper's form already does).
2. Eq. 5, ``T = [154.5, 0, -468]`` mm: the pan joint sits at ``T = (0.1545, 0, +0.468)`` m in the
   j2 frame of this model (the boom rises along +z of the j2 frame); T is read from the URDF.
3. Eq. 3 mixes ``cos(-DOF2)``/``sin(-DOF2)`` with ``sin(DOF2)``/``cos(DOF2)``; evaluated, it is
   Ry(-DOF2), which is the URDF's j2 axis (0, -1, 0).  We do not use the printed matrix: the
   rotations are built from the joint axes read from the model (Rodrigues' formula).
4. Eq. 7, ``arctan(y_s / x_s)`` with a manual quadrant fix: we use ``atan2(y_s, x_s)``.
5. Eqs. 8-9, ``J = J_AOD - pi +/- arccos(l_OB / l_AO)``: with this model's zero pan (barrel along
   +x of the pan frame, offset L3 along +y) the constant is ``-pi/2``, i.e.
   ``J = J_AOD - pi/2 +/- arccos(L3 / l_AO)``.  The '+' branch aims forward (|DOF4| <= pi/2), the
   '-' branch aims over the top (|DOF4| >= pi/2, feasible only within the tilt limits, i.e. for
   nearly vertical targets).  Both are shifted by multiples of 2*pi (pan limits exceed +-pi) and
   the candidate inside the joint limits closest to a reference pan is chosen ("smaller rotation").
6. Eq. 11, ``l_AB = sqrt(s_x^2 + s_y^2 + l_OB)`` adds a length to squared lengths: the tangent
   length is ``l_AB = sqrt(s_x^2 + s_y^2 - l_OB^2)`` (right triangle O-B-A, Fig. 6).
7. Eq. 10, ``arctan(s_z / l_AB)``: ``atan2(s_z, +-l_AB)`` so the over-the-top branch gets the
   right quadrant; positive DOF4 raises the barrel because the j4 axis is (0, -1, 0).
8. l_OB = l_OC = L3 here (the barrel plane is offset by L3 on one side only).

Targets with ``s_x^2 + s_y^2 <= L3^2`` lie in the cylinder blind area (Fig. 2a) and raise
:class:`BlindAreaError`; targets that would sit between the tilt joint and the muzzle, or that
need a tilt outside the limits, raise :class:`UnreachableTargetError`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from ..validation import as_float_array, check_bool, check_type
from .urdf_loading import ARM_JOINTS
from .robot_checker import RobotChecker
from .wearer_arm import MAX_TARGET_DISTANCE, MUZZLE_FRAME, WearerArm, check_target_point, default_robot
from .sectors import posture_preset

__all__ = [
    "AimingError",
    "BlindAreaError",
    "PointingGeometry",
    "UnreachableTargetError",
    "aim",
    "aim_batch",
    "aim_checked",
    "aim_errors",
    "check_target",
    "default_geometry",
    "pointing_frame",
]

BLIND_TOLERANCE = 1e-9
"""Metres. Targets closer than L3 + this to the pan axis are in the blind area, and those less than this beyond
the muzzle are not beyond it (at the muzzle the direction to the target is rounding noise)."""


class AimingError(ValueError):
    """The target cannot be aimed at from the given posture."""


class BlindAreaError(AimingError):
    """The target is in the pointing blind area: the cylinder of radius L3 around the pan axis (Fig. 2a)."""


class UnreachableTargetError(AimingError):
    """The target is not a valid aim point: non-finite, inside the wearer, behind the muzzle, beyond the tilt limits."""


def _rodrigues(axis: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Rotations about a unit axis by angles theta (N,): array (N, 3, 3)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(theta)[:, None, None], np.cos(theta)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


@dataclass(frozen=True)
class PointingGeometry:
    """Constants of the arm that the aiming IK needs, read from the model (metres, unit vectors).

    Attributes
    ----------
    pivot : ndarray (3,)
        World position of the j1 origin (the DOF1/DOF2 pivot).
    base_rotation : ndarray (3, 3)
        World rotation of the j1 frame at DOF1 = 0.
    axis1, axis2 : ndarray (3,)
        DOF1 and DOF2 axes in their joint frames.
    offset12 : ndarray (3,)
        j2 origin in the j1 frame (zero here).
    rotation12 : ndarray (3, 3)
        j2 frame rotation in the j1 frame at DOF2 = 0.
    boom : ndarray (3,)
        T: pan joint origin in the j2 frame (eq. 5, sign corrected).
    rotation23 : ndarray (3, 3)
        Pan joint frame rotation in the j2 frame.
    offset : float
        l_OB = l_OC = L3: distance of the barrel plane from the pan axis.
    barrel : float
        L4: distance from the tilt axis to the muzzle along the barrel.
    pan_limits, tilt_limits : tuple of float, radians
    dof12_lower, dof12_upper : ndarray (2,), radians
    """

    pivot: np.ndarray
    base_rotation: np.ndarray
    axis1: np.ndarray
    axis2: np.ndarray
    offset12: np.ndarray
    rotation12: np.ndarray
    boom: np.ndarray
    rotation23: np.ndarray
    offset: float
    barrel: float
    pan_limits: tuple[float, float]
    tilt_limits: tuple[float, float]
    dof12_lower: np.ndarray
    dof12_upper: np.ndarray

    @classmethod
    def from_robot(cls, robot: WearerArm) -> PointingGeometry:
        """Read the constants from a loaded model; raise ValueError if its pointing system is not pan-offset-tilt."""
        if not isinstance(robot, RobotChecker):  # (another RobotChecker is refused below: not pan-offset-tilt)
            raise ValueError(f"robot must be a WearerArm, got {type(robot).__name__}")
        m = robot.model
        names = tuple(m.names[1:])
        if names != ARM_JOINTS or not m.existFrame(MUZZLE_FRAME):  # another robot (an IndexError further down)
            raise ValueError(f"aiming needs the wearer arm (joints {list(ARM_JOINTS)} and the {MUZZLE_FRAME!r} link); "
                             f"this robot has the joints {list(names)}")
        jp = m.jointPlacements
        data = m.createData()

        def axis_of(i: int) -> np.ndarray:
            q = np.zeros(m.nq)
            pin.forwardKinematics(m, data, q)
            before = data.oMi[i].rotation.copy()
            q[i - 1] = 1.0
            pin.forwardKinematics(m, data, q)
            w = pin.log3(before.T @ data.oMi[i].rotation)
            return w / np.linalg.norm(w)

        axes = [axis_of(i) for i in range(1, 5)]
        muzzle = m.frames[m.getFrameId(MUZZLE_FRAME)]
        offset_vec = jp[4].translation
        problems = []
        if m.parents[1] != 0:
            problems.append("j1 must hang from the world")
        if not np.allclose(axes[2], [0, 0, 1], atol=1e-9):
            problems.append(f"pan axis {axes[2]} is not +z of the j3 frame")
        if not (np.allclose(jp[4].rotation, np.eye(3)) and np.allclose(offset_vec[[0, 2]], 0) and offset_vec[1] > 0):
            problems.append(f"j4 must be offset along +y of the pan frame, got {offset_vec}")
        if not np.allclose(axes[3], [0, -1, 0], atol=1e-9):
            problems.append(f"tilt axis {axes[3]} is not (0, -1, 0)")
        if muzzle.parentJoint != 4 or not (
            np.allclose(muzzle.placement.rotation, np.eye(3)) and np.allclose(muzzle.placement.translation[1:], 0)
        ):
            problems.append("muzzle must sit on +x of the j4 frame")
        if problems:
            raise ValueError("unsupported pointing system: " + "; ".join(problems))
        lo, hi = robot.lower, robot.upper
        return cls(
            pivot=jp[1].translation.copy(),
            base_rotation=jp[1].rotation.copy(),
            axis1=axes[0],
            axis2=axes[1],
            offset12=jp[2].translation.copy(),
            rotation12=jp[2].rotation.copy(),
            boom=jp[3].translation.copy(),
            rotation23=jp[3].rotation.copy(),
            offset=float(offset_vec[1]),
            barrel=float(muzzle.placement.translation[0]),
            pan_limits=(float(lo[2]), float(hi[2])),
            tilt_limits=(float(lo[3]), float(hi[3])),
            dof12_lower=lo[:2].copy(),
            dof12_upper=hi[:2].copy(),
        )

    def pan_frame(self, dof12: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World origin (N, 3) and rotation (N, 3, 3) of the pan joint frame at pan 0 for DOF1/DOF2 (N, 2)."""
        dof12 = np.atleast_2d(dof12)
        r1 = self.base_rotation @ _rodrigues(self.axis1, dof12[:, 0])
        r2 = r1 @ self.rotation12 @ _rodrigues(self.axis2, dof12[:, 1])
        origin = self.pivot + r1 @ self.offset12 + r2 @ self.boom
        return origin, r2 @ self.rotation23


@functools.lru_cache(maxsize=1)
def _default_geometry() -> PointingGeometry:
    return PointingGeometry.from_robot(default_robot())


def default_geometry() -> PointingGeometry:
    """Pointing geometry of the packaged model (cached)."""
    return _default_geometry()


def _as_dof12(posture: int | np.ndarray, n: int) -> np.ndarray:
    if isinstance(posture, (int, np.integer)) and not isinstance(posture, bool):
        return np.broadcast_to(posture_preset(int(posture)), (n, 2))
    if isinstance(posture, bool):
        raise ValueError(f"unknown sector {posture!r}: sectors are 1, 2, 3, 4")  # noqa: TRY004 (bad input value)
    d = as_float_array(posture, "posture")
    if d.shape == (2,):
        d = np.broadcast_to(d, (n, 2))
    if d.shape != (n, 2) or not np.all(np.isfinite(d)):
        raise ValueError(f"posture must be a sector number, a finite (2,) DOF1/DOF2 pair or ({n}, 2); got {posture!r}")
    return d


def _as_targets(targets: np.ndarray) -> np.ndarray:
    t = as_float_array(targets, "targets")
    if t.ndim == 1:
        t = t[None, :]
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"targets must have shape (N, 3); got {np.shape(targets)}")
    return t


def pointing_frame(
    targets: np.ndarray, posture: int | np.ndarray, geometry: PointingGeometry | None = None
) -> np.ndarray:
    """Targets (N, 3) in the pan joint frame at pan 0 (eq. 6, corrected): S = R^T (W - origin), shape (N, 3)."""
    g = geometry or default_geometry()
    t = _as_targets(targets)
    origin, rot = g.pan_frame(_as_dof12(posture, len(t)))
    return np.einsum("nji,nj->ni", rot, t - origin)


def aim_batch(
    targets: np.ndarray,
    posture: int | np.ndarray,
    *,
    geometry: PointingGeometry | None = None,
    pan_reference: float | np.ndarray = 0.0,
    strict: bool = True,
) -> np.ndarray:
    """Configurations (N, 4) that put each target (N, 3), metres, world frame, on the barrel's +x ray.

    Parameters
    ----------
    targets : ndarray (N, 3), metres
    posture : int sector 1-4, or DOF1/DOF2 radians, shape (2,) or (N, 2)
    geometry : PointingGeometry, optional (default: the packaged model)
    pan_reference : float or ndarray (N,), radians
        Among the pan solutions (two branches, eqs. 8-9, each shifted by 2*pi) inside the limits,
        the one closest to this is returned (the "smaller rotation").
    strict : bool
        Raise on the first target that cannot be aimed at (default); if False, its row is NaN.

    Raises
    ------
    BlindAreaError, UnreachableTargetError (both ValueError)
    """
    g = geometry or default_geometry()
    if not isinstance(g, PointingGeometry):
        raise ValueError(f"geometry must be a PointingGeometry, got {type(g).__name__}")
    strict = check_bool("strict", strict)
    t = _as_targets(targets)
    n = len(t)
    dof12 = _as_dof12(posture, n)
    try:
        ref = np.broadcast_to(as_float_array(pan_reference, "pan_reference"), (n,))
    except ValueError as exc:
        raise ValueError(f"pan_reference must be a number or an array of {n}, got {pan_reference!r}") from exc
    out = np.full((n, 4), np.nan)
    out[:, :2] = dof12
    finite = np.all(np.isfinite(t), axis=1) & np.isfinite(ref)
    if strict and not finite.all():
        k = int(np.flatnonzero(~finite)[0])
        raise UnreachableTargetError(f"target {k} {t[k]} or its pan reference {ref[k]} is not finite")
    far = finite & (np.max(np.abs(np.where(np.isfinite(t), t, 0.0)), axis=1) > MAX_TARGET_DISTANCE)
    if strict and far.any():
        k = int(np.flatnonzero(far)[0])
        raise UnreachableTargetError(f"target {k} {t[k]} is farther than MAX_TARGET_DISTANCE = {MAX_TARGET_DISTANCE:g} m")
    finite &= ~far
    outside = np.any((dof12 < g.dof12_lower) | (dof12 > g.dof12_upper), axis=1)
    if strict and outside.any():
        k = int(np.flatnonzero(outside)[0])
        raise ValueError(
            f"posture DOF1/DOF2 {dof12[k]} (row {k}) is outside the joint limits "
            f"[{g.dof12_lower}, {g.dof12_upper}]"
        )
    finite &= ~outside
    # the pan closest to any reference beyond a limit is the one closest to that limit
    ref = np.clip(np.where(np.isfinite(ref), ref, 0.0), *g.pan_limits)
    s = np.zeros_like(t)
    s[finite] = pointing_frame(t[finite], dof12[finite], g)
    sx, sy, sz = s.T
    r = np.hypot(sx, sy)  # distance from the pan axis
    blind = finite & (r <= g.offset + BLIND_TOLERANCE)
    if strict and blind.any():
        k = int(np.flatnonzero(blind)[0])
        raise BlindAreaError(
            f"target {k} {t[k]} is {r[k]:.4f} m from the pan axis, inside the blind cylinder "
            f"of radius L3 = {g.offset:.4f} m (Fig. 2a): change posture"
        )
    ok = finite & ~blind
    # eq. 11 (corrected): l_AB = sqrt(r^2 - l_OB^2), factored so it cannot overflow
    l_ab = np.where(ok, np.sqrt(np.abs(r - g.offset)) * np.sqrt(r + g.offset), 1.0)
    reach = np.hypot(l_ab, sz)  # distance from the tilt axis to the target along the barrel line
    behind = ok & (reach <= g.barrel + BLIND_TOLERANCE)
    if strict and behind.any():
        k = int(np.flatnonzero(behind)[0])
        raise UnreachableTargetError(
            f"target {k} {t[k]} is {reach[k]:.4f} m from the tilt axis, not beyond the muzzle (L4 = {g.barrel:.4f} m)"
        )
    ok &= ~behind
    phi = np.arctan2(sy, sx)  # eq. 7
    lo3, hi3 = g.pan_limits
    lo4, hi4 = g.tilt_limits
    best_cost = np.full(n, np.inf)
    two_pi = 2.0 * np.pi
    for sign in (1.0, -1.0):  # forward branch, then over-the-top branch (eqs. 8-9)
        pan0 = phi - np.arctan2(g.offset, sign * l_ab)
        tilt = np.arctan2(sz, sign * l_ab)  # eq. 10
        tilt_ok = (tilt >= lo4) & (tilt <= hi4)
        k0 = np.round((ref - pan0) / two_pi)
        for dk in (-1.0, 0.0, 1.0):
            pan = pan0 + two_pi * (k0 + dk)
            cost = np.abs(pan - ref)
            better = ok & tilt_ok & (pan >= lo3) & (pan <= hi3) & (cost < best_cost - 1e-12)
            out[better, 2] = pan[better]
            out[better, 3] = tilt[better]
            best_cost[better] = cost[better]
    none = ok & ~np.isfinite(best_cost)
    if strict and none.any():
        k = int(np.flatnonzero(none)[0])
        raise UnreachableTargetError(f"target {k} {t[k]} needs a pan or tilt outside the joint limits")
    out[~(ok & np.isfinite(best_cost))] = np.nan
    return out


def aim(
    target: np.ndarray,
    posture: int | np.ndarray,
    *,
    geometry: PointingGeometry | None = None,
    pan_reference: float = 0.0,
) -> np.ndarray:
    """Configuration (4,), radians, that aims the barrel at one world target (3,), metres; see :func:`aim_batch`."""
    t = as_float_array(target, "target")
    if t.shape != (3,):
        raise ValueError(f"target must have shape (3,); got {t.shape}")
    return aim_batch(t[None], posture, geometry=geometry, pan_reference=pan_reference)[0]


def aim_errors(robot: WearerArm, q: np.ndarray, target: np.ndarray) -> tuple[float, float, float]:
    """How well q aims at target, by Pinocchio FK.

    Returns
    -------
    perpendicular : float, metres
        Distance of the target from the barrel's axis line.
    along : float, metres
        Signed distance of the target's foot point ahead of the muzzle (> 0: in front).
    angle : float, radians
        Angle between the barrel's +x axis and the muzzle-to-target direction.
    """
    p, u = check_type("robot", robot, WearerArm).muzzle(q)
    d = np.asarray(target, dtype=float) - p
    along = float(d @ u)
    perp = float(np.linalg.norm(d - along * u))
    return perp, along, float(np.arctan2(perp, along))


def check_target(target: np.ndarray, robot: WearerArm | None = None) -> np.ndarray:
    """Return target as a finite (3,) array within MAX_TARGET_DISTANCE, or raise UnreachableTargetError.

    With a robot, also refuse targets inside (or touching) the wearer or the arm's base link, where no
    line of sight can reach them.
    """
    try:
        t = check_target_point(target)
    except ValueError as exc:
        raise UnreachableTargetError(str(exc)) from None
    if robot is not None:
        check_type("robot", robot, WearerArm)
        point = coal.Sphere(1e-6)
        tf = coal.Transform3s(np.eye(3), t)
        req, res = coal.DistanceRequest(), coal.DistanceResult()
        base_joint = robot.model.getJointId("j1")
        for go in robot.gmodel.geometryObjects:
            if go.parentJoint == 0 or (go.parentJoint == base_joint and isinstance(go.geometry, coal.Sphere)):
                placement = go.placement if go.parentJoint == 0 else robot.model.jointPlacements[base_joint] * go.placement
                res.clear()
                if coal.distance(point, tf, go.geometry, coal.Transform3s(placement), req, res) <= 0.0:
                    raise UnreachableTargetError(f"target {t} is inside {go.name}")
    return t


def aim_checked(
    robot: WearerArm,
    targets: np.ndarray,
    posture: int | np.ndarray,
    *,
    pan_reference: float | np.ndarray = 0.0,
    geometry: PointingGeometry | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Aim at many targets (N, 3) and check the result: configurations (N, 4) and ok (N,) bool.

    ok means the IK has a solution inside the limits, the configuration is collision-free (batched
    check) and the muzzle-to-target segment is clear of the wearer and the boom.  Rows that fail
    the IK are NaN.
    """
    robot = check_type("robot", robot, WearerArm)
    g = geometry or PointingGeometry.from_robot(robot)
    Q = aim_batch(targets, posture, geometry=g, pan_reference=pan_reference, strict=False)
    ok = np.all(np.isfinite(Q), axis=1)
    if ok.any():
        ok[ok] = robot.are_valid(Q[ok])
    t = _as_targets(targets)
    for i in np.flatnonzero(ok):
        ok[i] = robot.line_of_sight_clear(Q[i], t[i])
    return Q, ok
