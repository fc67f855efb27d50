"""Reading a URDF and SRDF (the wearer's or any robot's) into Pinocchio and Coal models, refusing what would load wrongly.

urdfdom reads ``<capsule>`` only in a URDF of version 1.1 or later (in 1.0 the link loses its collision geometry)
and Coal gives wrong answers for zero or non-finite sizes, so every ``<collision>`` element must become a geometry,
every URDF cylinder becomes a Coal capsule (``urdf/README.md``), and the SRDF's disabled pairs must name real links.
"""

from __future__ import annotations

import copy
import hashlib
import math
import numbers
import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from ..validation import MAX_JOINT_VALUE
from .mesh_files import mesh_digests, missing_mesh_hint, resolve_relative_meshes
from .mimic_joints import check_mimics
from .obstacles import Obstacle
from .srdf_pairs import apply_srdf
from .urdf_xml import parse_urdf, read_text

__all__ = [
    "ARM_JOINTS",
    "MUZZLE_FRAME",
    "LoadedModel",
    "ModelFiles",
    "bounding_radius",
    "is_prismatic",
    "load_urdf_model",
    "load_wearer_model",
]

ARM_JOINTS = ("j1", "j2", "j3", "j4")
"""Joint names in configuration order: DOF1 (about x), DOF2 (about -y), pan, tilt."""
MUZZLE_FRAME = "muzzle"
"""The barrel's tip frame; its +x axis is the pointing direction."""


@dataclass(frozen=True)
class ModelFiles:
    """The URDF and (optional) SRDF a model was loaded from."""

    urdf: Path
    srdf: Path | None


@dataclass(frozen=True)
class LoadedModel:
    """Pinocchio kinematic and collision models (SRDF pairs removed) and the files' short hash."""

    model: pin.Model
    gmodel: pin.GeometryModel
    model_hash: str
    continuous: tuple[str, ...] = ()
    """The planned joints that are continuous in the URDF (loaded as revolute joints limited to [-pi, pi])."""


def _check_shape_sizes(geom: coal.CollisionGeometry, name: str, urdf: Path) -> None:
    """Refuse zero, negative or non-finite primitive sizes (Coal would silently give wrong answers)."""
    sizes: list[float] = []
    if isinstance(geom, coal.Capsule) or isinstance(geom, coal.Cylinder):
        sizes = [geom.radius]
        if not (np.isfinite(geom.halfLength) and geom.halfLength >= 0):
            raise ValueError(f"URDF {urdf}: geometry {name!r} has length {2 * geom.halfLength}")
    elif isinstance(geom, coal.Sphere):
        sizes = [geom.radius]
    elif isinstance(geom, coal.Box):
        sizes = list(2 * np.asarray(geom.halfSide))
    for v in sizes:
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"URDF {urdf}: geometry {name!r} has a size of {v} (must be finite and > 0)")


def bounding_radius(geom: coal.CollisionGeometry) -> float:
    """Radius of a sphere about the geometry's origin that contains it, metres."""
    if isinstance(geom, coal.Capsule):
        return geom.radius + geom.halfLength
    if isinstance(geom, coal.Sphere):
        return geom.radius
    if isinstance(geom, coal.Box):
        return float(np.linalg.norm(geom.halfSide))
    if isinstance(geom, coal.Cylinder):
        return float(np.hypot(geom.radius, geom.halfLength))
    geom.computeLocalAABB()  # meshes and other shapes: the AABB's sphere, which need not be centred
    return float(np.linalg.norm(geom.aabb_center) + geom.aabb_radius)


def load_wearer_model(urdf: Path, srdf: Path | None) -> LoadedModel:
    """Load and check the wearer + arm URDF (and SRDF): the arm joints, the muzzle frame, sizes, limits.

    Raises
    ------
    FileNotFoundError
        A missing URDF or SRDF.
    ValueError
        A malformed file, ``<capsule>`` in a version 1.0 URDF, missing joints or frame, unsupported shapes, bad sizes
        or limits.
    """
    root = parse_urdf(urdf)
    joints = {j.get("name"): j.get("type") for j in root.findall("joint")}  # (not a <transmission>'s)
    for name in ARM_JOINTS:
        if joints.get(name) != "revolute":
            raise ValueError(f"URDF {urdf} lacks revolute joint {name!r} (found: {sorted(k for k in joints if k)}): a "
                             f"wearer arm has the revolute joints {list(ARM_JOINTS)} and the link {MUZZLE_FRAME!r}; "
                             "another robot is planned with RobotChecker(urdf, srdf) and make_simple_setup, or "
                             "benchmarked as a problem (tpee-ompl bench --list-problems)")
    if MUZZLE_FRAME not in {link.get("name") for link in root.findall("link")}:
        raise ValueError(f"URDF {urdf} lacks the {MUZZLE_FRAME!r} link")
    loaded = load_urdf_model(urdf, srdf)
    if tuple(loaded.model.names[1:]) != ARM_JOINTS:
        raise ValueError(f"URDF {urdf}: moving joints must be exactly {ARM_JOINTS}, got {tuple(loaded.model.names[1:])}")
    return loaded


def load_urdf_model(
    urdf: Path,
    srdf: Path | None = None,
    *,
    package_dirs: Sequence[str | os.PathLike] = (),
    cylinders_as_capsules: bool = True,
    locked: Mapping[str, float] | None = None,
    obstacles: Sequence[Obstacle] = (),
    convex_meshes: bool = False,
    srdf_unknown_links: str = "error",
) -> LoadedModel:
    """Load any URDF (+ SRDF) for collision checking: every ``<collision>`` becomes a geometry.

    ``locked`` joints are removed (``pin.buildReducedModel``, fixed at the given values); the
    remaining joints must be 1-DOF (revolute, prismatic or continuous) with finite limits.  A continuous
    joint is loaded as a revolute joint limited to [-pi, pi] (the same kinematics, one coordinate: its angle)
    and named in :attr:`LoadedModel.continuous`; planners treat that coordinate as an SO2 angle that wraps
    around (:func:`~tpee_ompl.planning.setup.make_space`).  With
    ``cylinders_as_capsules`` (default, the wearer's rule in ``urdf/README.md``) every URDF cylinder
    becomes a Coal capsule of the same radius and length (a ``<capsule>``, which urdfdom reads from
    ``<robot version="1.1">`` on, is one already).  With ``convex_meshes`` every collision mesh of the
    robot becomes its convex hull (Coal's ``buildConvexHull``): a superset of the mesh, so never a collision
    missed, and much cheaper to check near contact at a positive margin (MoveIt users' convex collision
    meshes).  Obstacles go on the universe joint.
    Collision pairs: every pair of geometries on different joints (so never obstacle-obstacle or
    obstacle-base), minus the SRDF's disabled link pairs.  The model hash covers the URDF and SRDF
    texts, the collision mesh files' bytes (not where they are found) and, when given, the locked values,
    obstacles, a ``cylinders_as_capsules=False`` and the meshes made convex hulls (``convex_meshes``; a flat
    mesh, which has none, stays a mesh).  An SRDF pair naming a link the
    URDF lacks is refused (a typo would leave that pair checked), or with ``srdf_unknown_links="skip"`` passed
    over (the SRDF of a larger robot, e.g. a whole humanoid's for one arm: its other pairs apply).

    Raises FileNotFoundError (a missing file) or ValueError (anything that would load wrongly).
    """
    if srdf_unknown_links not in ("error", "skip"):
        raise ValueError(f"srdf_unknown_links must be 'error' or 'skip', got {srdf_unknown_links!r}")
    root = parse_urdf(urdf)
    text = read_text(urdf, "URDF")
    n_collision_elements = len(root.findall("link/collision"))
    digest = hashlib.sha256(text.encode())
    if srdf is not None and srdf.is_file():
        digest.update(srdf.read_bytes())
    dirs = [str(d) for d in package_dirs]
    continuous = tuple(j.get("name") for j in root.findall("joint")
                       if j.get("type") == "continuous" and j.get("name") not in (locked or {}))
    if resolve_relative_meshes(root, urdf):  # (the hash stays the file's: the same wherever it is)
        text = ET.tostring(root, encoding="unicode")
    if continuous:
        text = _continuous_as_revolute(root, continuous)
    try:
        model = pin.buildModelFromXML(text)
        gmodel = pin.buildGeomFromUrdfString(model, text, pin.GeometryType.COLLISION, package_dirs=dirs)
    except Exception as exc:  # the bindings raise RuntimeError/ValueError with C++ text
        hint = missing_mesh_hint(str(exc), dirs, urdf)
        raise ValueError(f"Pinocchio could not load URDF {urdf}: {' '.join(str(exc).split())}{hint}") from exc
    if gmodel.ngeoms != n_collision_elements:
        raise ValueError(
            f"URDF {urdf}: {n_collision_elements} <collision> elements but only "
            f"{gmodel.ngeoms} geometries were loaded (unsupported shape?)"
        )
    extra = mesh_digests(gmodel)
    if locked:
        model, gmodel = _lock_joints(model, gmodel, locked, urdf)
        extra.append("locked=" + ",".join(f"{k}={float(v)!r}" for k, v in sorted(locked.items())))
    _check_joints(model, urdf)
    check_mimics(root, set(model.names[1:]), locked or {}, urdf)
    if model.nq == 0:
        raise ValueError(f"URDF {urdf}: no joint left to plan (every joint is fixed or locked)")
    if not any(go.parentJoint != 0 for go in gmodel.geometryObjects):
        raise ValueError(f"URDF {urdf}: no <collision> geometry moves with the planned joints: nothing to check")
    hulls: list[str] = []
    for go in gmodel.geometryObjects:
        _check_shape_sizes(go.geometry, go.name, urdf)
        if cylinders_as_capsules and isinstance(go.geometry, coal.Cylinder):
            go.geometry = coal.Capsule(go.geometry.radius, 2.0 * go.geometry.halfLength)
        if convex_meshes and isinstance(go.geometry, coal.BVHModelBase) and _solid(go.geometry):
            go.geometry.buildConvexHull(True, "Qt")
            go.geometry = go.geometry.convex
            hulls.append(go.name)
    if not cylinders_as_capsules:
        extra.append("cylinders_as_capsules=False")
    if hulls:
        extra.append("convex_meshes=" + ",".join(hulls))
    dropped = _drop_contained_spheres(gmodel)
    if dropped:
        extra.append("dropped_contained_spheres=" + ",".join(dropped))
    names = {go.name for go in gmodel.geometryObjects}
    for ob in obstacles:
        if not isinstance(ob, Obstacle):
            raise ValueError(f"obstacles must be Obstacle instances, got {ob!r}")
        if ob.name in names:
            raise ValueError(f"obstacle name {ob.name!r} is already a geometry name")
        names.add(ob.name)
        gmodel.addGeometryObject(pin.GeometryObject(ob.name, 0, 0, ob.placement, ob.geometry()))
        extra.append("obstacle=" + ob.describe())
    for e in extra:
        digest.update(("\n" + e).encode())
    gmodel.addAllCollisionPairs()
    if srdf is not None:
        apply_srdf(model, gmodel, srdf, srdf_unknown_links)
    return LoadedModel(model, gmodel, digest.hexdigest()[:16], continuous)


def _continuous_as_revolute(root: ET.Element, names: Sequence[str]) -> str:
    """The URDF's text with the named continuous joints written as revolute joints limited to [-pi, pi]."""
    root = copy.deepcopy(root)
    for joint in root.findall("joint"):
        if joint.get("name") in names:
            joint.set("type", "revolute")
            limit = joint.find("limit")
            if limit is None:
                limit = ET.SubElement(joint, "limit", effort="0", velocity="0")
            limit.set("lower", repr(-math.pi))
            limit.set("upper", repr(math.pi))
    return ET.tostring(root, encoding="unicode")


def _solid(mesh: coal.BVHModelBase) -> bool:
    """True when a mesh's vertices span three dimensions, so that it has a convex hull (Coal's ``buildConvexHull``
    crashes the process on four or more coplanar points and refuses fewer than four): a flat mesh stays a mesh."""
    V = np.asarray(mesh.vertices(), dtype=float).reshape(-1, 3)
    if len(V) < 4:
        return False
    s = np.linalg.svd(V - V.mean(axis=0), compute_uv=False)
    return bool(s[2] > 1e-5 * max(s[0], 1e-12))  # 1e-9 let a float32 plate through: Coal crashed on it (~1e-8)


def _drop_contained_spheres(gmodel: pin.GeometryModel) -> list[str]:
    """Remove every sphere lying inside a capsule of the same link; return their names.

    Collision URDFs often add a sphere at each end of a cylinder (``panda_collision.urdf`` does): once
    the cylinder is a capsule those spheres are its end caps, so they change no verdict and no
    clearance (a contact or distance of the sphere is one of the capsule's too) but triple the pairs.
    """
    objs = list(gmodel.geometryObjects)
    capsules = [g for g in objs if isinstance(g.geometry, coal.Capsule)]
    dropped = []
    for g in objs:
        if not isinstance(g.geometry, coal.Sphere):
            continue
        for c in capsules:
            if c.parentFrame != g.parentFrame or c.parentJoint != g.parentJoint:
                continue
            # the sphere's centre in the capsule's frame; the capsule's axis is its local z
            p = c.placement.actInv(g.placement).translation
            h = c.geometry.halfLength
            axis_point = np.array([0.0, 0.0, min(max(p[2], -h), h)])
            if np.linalg.norm(p - axis_point) + g.geometry.radius <= c.geometry.radius + 1e-9:  # nanometre: float rounding of the URDF numbers
                dropped.append(g.name)
                break
    for name in dropped:
        gmodel.removeGeometryObject(name)
    return dropped


def _lock_joints(model: pin.Model, gmodel: pin.GeometryModel, locked: Mapping[str, float], urdf: Path):
    """The reduced models with ``locked`` joints fixed at their values (checked against the limits)."""
    q = pin.neutral(model)
    ids = []
    for name, value in locked.items():
        jid = model.getJointId(name) if isinstance(name, str) else model.njoints
        if jid >= model.njoints or jid == 0:
            raise ValueError(f"locked names unknown joint {name!r} of URDF {urdf} (joints: {list(model.names[1:])})")
        j = model.joints[jid]
        continuous = is_continuous(j)
        if j.nq != 1 and not continuous:
            raise ValueError(f"locked joint {name!r} ({j.shortname()}) has {j.nq} position values; only 1-DOF and "
                             "continuous joints can be locked (make it a fixed joint in the URDF)")
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
            raise ValueError(f"locked[{name!r}] must be a finite number, got {value!r}")
        if continuous:
            q[j.idx_q : j.idx_q + 2] = [math.cos(value), math.sin(value)]
        else:
            lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
            if not lo <= value <= hi:
                raise ValueError(f"locked[{name!r}] = {value} is outside the joint limits [{lo}, {hi}]")
            q[j.idx_q] = float(value)
        ids.append(jid)
    return pin.buildReducedModel(model, gmodel, sorted(ids), q)


def _check_joints(model: pin.Model, urdf: Path) -> None:
    """Every planned joint is 1-DOF (revolute or prismatic; continuous ones are revolute by now) with finite limits."""
    for jid in range(1, model.njoints):
        j, name = model.joints[jid], model.names[jid]
        if j.nq != 1 or j.nv != 1:
            raise ValueError(f"URDF {urdf}: joint {name!r} ({j.shortname()}) has {j.nq} position values; only 1-DOF "
                             "joints are planned: make it a fixed joint in the URDF")
        lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise ValueError(f"URDF {urdf}: joint {name!r} has limits [{lo}, {hi}] (need finite lower < upper)")
        if max(abs(lo), abs(hi)) > MAX_JOINT_VALUE:
            raise ValueError(f"URDF {urdf}: joint {name!r} has limits [{lo:g}, {hi:g}] beyond +/-{MAX_JOINT_VALUE:g} "
                             "(rad or m): no joint travels that far, and a motion across them could not be checked "
                             "state by state; give its real limits")


def is_continuous(joint: pin.JointModel) -> bool:
    """True for an unbounded revolute joint: one velocity, two position values (cos, sin of its angle)."""
    return joint.nq == 2 and joint.nv == 1


def is_prismatic(joint: pin.JointModel) -> bool:
    """True for a prismatic joint (its coordinate is in metres, not radians)."""
    return joint.shortname().startswith("JointModelP")
