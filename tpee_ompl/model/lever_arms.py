"""Lever arms of a Pinocchio model: how far a joint step can move the robot's points, and how fast each joint
can change a checked pair's distance.  :class:`~tpee_ompl.model.robot_checker.RobotChecker` computes them once
after loading (its ``lever_arms`` and ``pair_lever_arms``); the motion-check step and the clearance balls rest
on them (:mod:`tpee_ompl.model.clearance_balls`)."""

from __future__ import annotations

from collections.abc import Sequence

import coal
import numpy as np
import pinocchio as pin

from .urdf_loading import bounding_radius, is_prismatic

__all__ = ["joint_lever_arms", "pair_lever_arms"]


def joint_lever_arms(model: pin.Model, gmodel: pin.GeometryModel, extra_frames: Sequence[int] = ()) -> np.ndarray:
    """Per joint (shape (njoints - 1,)): metres per radian for a revolute joint (an upper bound on the distance
    from its axis to any point it moves: every geometry's bounding sphere and the ``extra_frames``' origins),
    1 for a prismatic joint."""
    n = model.njoints - 1
    reach = np.zeros(n)
    for j in range(1, n + 1):
        if is_prismatic(model.joints[j]):
            reach[j - 1] = 1.0
            continue
        best = 0.0
        for go in gmodel.geometryObjects:
            chain = _chain_lengths(model, j, go.parentJoint)
            if chain is None:
                continue
            dist = sum(chain)
            dist += np.linalg.norm(go.placement.translation) + bounding_radius(go.geometry)
            best = max(best, dist)
        for fid in extra_frames:
            f = model.frames[fid]
            chain = _chain_lengths(model, j, f.parentJoint)
            if chain is not None:
                best = max(best, sum(chain) + np.linalg.norm(f.placement.translation))
        reach[j - 1] = best
    return reach


def pair_lever_arms(model: pin.Model, gmodel: pin.GeometryModel) -> np.ndarray:
    """Per checked pair (``gmodel.collisionPairs`` order) and joint value, shape (P, nq): how fast that joint can
    change the pair's distance (metres per radian, or per metre for a prismatic joint).

    Seen from the two bodies' lowest common ancestor, only the joints on the kinematic path between them
    move one body relative to the other; joint i of that path moves a point of geometry g by at most
    ``|dq_i|`` times the lever of i to g.  So ``|d_p(q') - d_p(q)| <= sum_i |q'_i - q_i| R[p, i]`` along any
    straight joint motion; a row of zeros is a pair whose distance cannot change.  A revolute joint that turns
    a shape about its own axis of symmetry does not count."""
    out = np.zeros((len(gmodel.collisionPairs), model.nq))
    for p, cp in enumerate(gmodel.collisionPairs):
        ga, gb = gmodel.geometryObjects[cp.first], gmodel.geometryObjects[cp.second]
        up_a, up_b = set(_ancestors(model, ga.parentJoint)), set(_ancestors(model, gb.parentJoint))
        for go, other, path in ((ga, gb, up_a - up_b), (gb, ga, up_b - up_a)):
            for k in path:
                if not _distance_ignores_joint(model, k, go, other):
                    out[p, model.joints[k].idx_q] = _geometry_lever(model, k, go)
    return out


def _chain_lengths(model: pin.Model, j: int, k: int) -> list[float] | None:
    """Longest offsets from joint j's origin down to joint k's (root to leaf order), or None if k is not in
    j's subtree.  A prismatic joint on the way adds its largest travel."""
    chain = []
    while k > j:
        chain.append(k)
        k = model.parents[k]
    if k != j:
        return None
    out = []
    for m in reversed(chain):
        out.append(np.linalg.norm(model.jointPlacements[m].translation))
        jm = model.joints[m]
        if is_prismatic(jm):
            q = jm.idx_q
            out.append(max(abs(float(model.lowerPositionLimit[q])), abs(float(model.upperPositionLimit[q]))))
    return out


def _ancestors(model: pin.Model, j: int) -> list[int]:
    """Joints from ``j`` up to (not including) the universe."""
    out = []
    while j > 0:
        out.append(j)
        j = model.parents[j]
    return out


def _geometry_lever(model: pin.Model, k: int, go: pin.GeometryObject) -> float:
    """Bound on how far a unit step of joint k (an ancestor of go's joint) moves any point of go."""
    if is_prismatic(model.joints[k]):
        return 1.0
    chain = _chain_lengths(model, k, go.parentJoint)
    return float(sum(chain) + np.linalg.norm(go.placement.translation) + bounding_radius(go.geometry))


def _distance_ignores_joint(model: pin.Model, k: int, go: pin.GeometryObject, other: pin.GeometryObject) -> bool:
    """True if turning revolute joint k (on go's side) cannot change go's distance to ``other``: go hangs on k
    and is symmetric about k's axis, or k hangs on other's joint and other is symmetric about k's axis (a
    rotation that maps the shape onto itself)."""
    if is_prismatic(model.joints[k]):
        return False
    jdata = model.joints[k].createData()
    model.joints[k].calc(jdata, pin.neutral(model))
    motion = np.asarray(jdata.S).reshape(6, -1)[:, 0]
    if np.linalg.norm(motion[:3]) > 1e-12:
        return False  # not a pure rotation about an axis through the joint origin
    axis = motion[3:] / np.linalg.norm(motion[3:])
    if go.parentJoint == k and _symmetric_about(go, np.zeros(3), axis):
        return True
    if model.parents[k] == other.parentJoint:
        jp = model.jointPlacements[k]
        return _symmetric_about(other, jp.translation, jp.rotation @ axis)
    return False


def _symmetric_about(go: pin.GeometryObject, point: np.ndarray, axis: np.ndarray, tol: float = 1e-9) -> bool:
    """True if the geometry (placed in its joint's frame) is mapped onto itself by every rotation about
    the line through ``point`` along unit ``axis``: a sphere centred on it, a capsule or cylinder along it."""
    offset = go.placement.translation - point
    on_axis = np.linalg.norm(np.cross(offset, axis)) <= tol
    if isinstance(go.geometry, coal.Sphere):
        return bool(on_axis)
    if isinstance(go.geometry, (coal.Capsule, coal.Cylinder)):
        return bool(on_axis and np.linalg.norm(np.cross(go.placement.rotation[:, 2], axis)) <= tol)
    return False
