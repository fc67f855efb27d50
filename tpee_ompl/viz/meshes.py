"""Faces of the wearer and the arm: collision primitives as quads, shading, the per-robot scene mesh.

The wearer's collision primitives (boxes, spheres, capsules, cylinders) and the arm are turned
into one triangle/quad soup, so the figures can draw them as a single ``Poly3DCollection`` and
matplotlib depth-sorts every face against every other face (separate artists would only be
sorted as wholes).  The wearer's faces do not move: :func:`scene_mesh` computes them once per
robot and caches them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin

from .style import ARM_COLOR, BARREL_COLOR, INVALID_COLOR, LIGHT, wearer_color

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

__all__ = ["SceneMesh", "arm_polygons", "primitive_polygons", "scene_mesh", "shade"]


def _revolve(profile_r: np.ndarray, profile_z: np.ndarray, n_theta: int) -> np.ndarray:
    """Quads (M, 4, 3) of the surface of revolution of a (r, z) profile about the local z axis."""
    th = np.linspace(0.0, 2.0 * np.pi, n_theta + 1)
    c, s = np.cos(th), np.sin(th)
    grid = np.stack(
        [
            profile_r[:, None] * c[None, :],
            profile_r[:, None] * s[None, :],
            np.broadcast_to(profile_z[:, None], (len(profile_z), n_theta + 1)),
        ],
        axis=-1,
    )  # (rings, n_theta+1, 3)
    quads = np.stack([grid[:-1, :-1], grid[:-1, 1:], grid[1:, 1:], grid[1:, :-1]], axis=2)
    return quads.reshape(-1, 4, 3)


def _sphere_quads(radius: float, n_theta: int, n_phi: int) -> np.ndarray:
    phi = np.linspace(-np.pi / 2, np.pi / 2, n_phi + 1)
    return _revolve(radius * np.cos(phi), radius * np.sin(phi), n_theta)


def _capsule_quads(radius: float, half_length: float, n_theta: int, n_cap: int) -> np.ndarray:
    phi = np.linspace(-np.pi / 2, 0.0, n_cap + 1)
    r = np.concatenate([radius * np.cos(phi), radius * np.cos(phi[::-1])])
    z = np.concatenate([radius * np.sin(phi) - half_length, half_length - radius * np.sin(phi[::-1])])
    return _revolve(r, z, n_theta)


_BOX_FACES = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])


def _box_quads(half: np.ndarray) -> np.ndarray:
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float) * half
    return corners[_BOX_FACES]


def primitive_polygons(geom: coal.CollisionGeometry, placement: pin.SE3, resolution: int = 14) -> np.ndarray:
    """Faces of one collision primitive in the world frame.

    Parameters
    ----------
    geom : coal.Box, coal.Sphere, coal.Capsule or coal.Cylinder
        Capsules and cylinders are along their local z (Coal convention).
    placement : pin.SE3
        World placement of the geometry.
    resolution : int
        Facets around a circle.

    Returns
    -------
    ndarray, shape (M, 4, 3), metres
    """
    n_cap = max(2, resolution // 4)
    if isinstance(geom, coal.Box):
        local = _box_quads(np.asarray(geom.halfSide, dtype=float))
    elif isinstance(geom, coal.Sphere):
        local = _sphere_quads(float(geom.radius), resolution, max(4, resolution // 2))
    elif isinstance(geom, coal.Capsule):
        local = _capsule_quads(float(geom.radius), float(geom.halfLength), resolution, n_cap)
    elif isinstance(geom, coal.Cylinder):
        r, h = float(geom.radius), float(geom.halfLength)
        local = _revolve(np.array([0.0, r, r, 0.0]), np.array([-h, -h, h, h]), resolution)
    else:
        raise ValueError(f"cannot draw geometry of type {type(geom).__name__}")
    R, t = np.asarray(placement.rotation), np.asarray(placement.translation)
    return local @ R.T + t


def shade(polys: np.ndarray, rgb: np.ndarray, alpha: float = 1.0) -> np.ndarray:
    """Per-face RGBA (M, 4): a Lambert-like shade of rgb, two-sided so face winding does not matter."""
    n = np.cross(polys[:, 2] - polys[:, 0], polys[:, 3] - polys[:, 1])
    norm = np.linalg.norm(n, axis=1)
    norm[norm < 1e-12] = 1.0
    k = 0.40 + 0.60 * np.abs(n @ LIGHT) / norm
    rgba = np.empty((len(polys), 4))
    rgba[:, :3] = np.clip(np.asarray(rgb)[None, :] * k[:, None], 0.0, 1.0)
    rgba[:, 3] = alpha
    return rgba


@dataclass
class SceneMesh:
    """Static wearer faces (computed once per robot) plus the arm's geometry ids.

    Attributes
    ----------
    wearer_polys : ndarray, shape (M, 4, 3), metres
    wearer_colors : ndarray, shape (M, 4), RGBA
    arm_ids : list of int
        Geometry ids attached to the arm's joints.
    barrel_ids : set of int
        Those attached to the last joint (drawn darker; left out of boom ghosts).
    lo, hi : ndarray, shape (3,), metres
        Box around the wearer and a sphere of the arm's reach around joint 1 (floor at z = 0).
    """

    wearer_polys: np.ndarray
    wearer_colors: np.ndarray
    arm_ids: list[int]
    barrel_ids: set[int]
    lo: np.ndarray
    hi: np.ndarray

    def view_box(self, extra: Sequence[np.ndarray], max_extent: float) -> tuple[np.ndarray, np.ndarray]:
        """Box around the wearer and arm, grown to include extra points within ``max_extent`` of its centre."""
        lo, hi = self.lo.copy(), self.hi.copy()
        centre = (lo + hi) / 2
        for p in extra:
            if p is not None and np.linalg.norm(np.asarray(p) - centre) <= max_extent:
                lo, hi = np.minimum(lo, p), np.maximum(hi, p)
        pad = 0.05 * (hi - lo)
        lo, hi = lo - pad, hi + pad
        lo[2] = max(lo[2], 0.0)
        return lo, hi


_MESH_CACHE: dict[str, SceneMesh] = {}
"""Scene meshes by model hash (the model's files and settings): a robot freed and another built at its address got
its drawing when they were keyed by ``id(robot)``."""


def scene_mesh(robot: WearerArm) -> SceneMesh:
    """The robot's :class:`SceneMesh`, computed on the first call for its model and then returned from a cache."""
    key = robot.model_hash
    if key in _MESH_CACHE:
        return _MESH_CACHE[key]
    polys, colors, arm_ids, barrel_ids = [], [], [], set()
    barrel_joint = robot.model.getJointId(robot.joint_names[-1])
    for i, go in enumerate(robot.gmodel.geometryObjects):
        if go.parentJoint == 0:
            p = primitive_polygons(go.geometry, go.placement)
            polys.append(p)
            colors.append(shade(p, np.array(wearer_color(go.name))))
        else:
            arm_ids.append(i)
            if go.parentJoint == barrel_joint:
                barrel_ids.add(i)
    wp = np.concatenate(polys)
    # view box: the wearer plus a sphere of the arm's reach around joint 1
    pin.forwardKinematics(robot.model, robot.data, pin.neutral(robot.model))
    pivot = robot.data.oMi[1].translation.copy()
    reach = float(robot.lever_arms()[0])
    pts = wp.reshape(-1, 3)
    lo = np.minimum(pts.min(axis=0), pivot - reach)
    hi = np.maximum(pts.max(axis=0), pivot + reach)
    lo[2] = max(lo[2], 0.0)
    mesh = SceneMesh(wp, np.concatenate(colors), arm_ids, barrel_ids, lo, hi)
    _MESH_CACHE[key] = mesh
    return mesh


def arm_polygons(
    robot: WearerArm, q: np.ndarray, mesh: SceneMesh, valid: bool, boom_only: bool = False, rgba: Any = None
) -> tuple[np.ndarray, np.ndarray]:
    """Arm faces (M, 4, 3) and colours (M, 4) at q: red when invalid, ``rgba`` (a ghost) if given."""
    pin.forwardKinematics(robot.model, robot.data, q)
    pin.updateGeometryPlacements(robot.model, robot.data, robot.gmodel, robot.gdata)
    polys, colors = [], []
    for i in mesh.arm_ids:
        if boom_only and i in mesh.barrel_ids:
            continue
        go = robot.gmodel.geometryObjects[i]
        p = primitive_polygons(go.geometry, robot.gdata.oMg[i].copy())
        if rgba is not None:
            c = shade(p, np.asarray(rgba[:3]), alpha=rgba[3])
        else:
            c = shade(p, INVALID_COLOR if not valid else (BARREL_COLOR if i in mesh.barrel_ids else ARM_COLOR))
        polys.append(p)
        colors.append(c)
    return np.concatenate(polys), np.concatenate(colors)
