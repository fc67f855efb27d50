"""Reading the wearer's URDF and SRDF into Pinocchio and Coal models, refusing what would load wrongly.

urdfdom drops ``<capsule>`` silently and Coal gives wrong answers for zero or non-finite sizes, so
every ``<collision>`` element must become a geometry, every URDF cylinder becomes a Coal capsule
(``urdf/README.md``), and the SRDF's disabled pairs must name real links.
"""

from __future__ import annotations

import hashlib
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

__all__ = ["ARM_JOINTS", "MUZZLE_FRAME", "LoadedModel", "ModelFiles", "bounding_radius", "load_wearer_model"]

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


def _read_text(path: Path, kind: str) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"malformed {kind} {path}: not UTF-8 text ({exc})") from exc


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
    geom.computeLocalAABB()
    return float(geom.aabb_radius)


@dataclass(frozen=True)
class _LoadedFiles:
    urdf: Path
    srdf: Path | None


def load_wearer_model(urdf: Path, srdf: Path | None) -> LoadedModel:
    """Load and check the wearer + arm URDF (and SRDF): the arm joints, the muzzle frame, sizes, limits.

    Raises
    ------
    FileNotFoundError
        A missing URDF or SRDF.
    ValueError
        A malformed file, ``<capsule>``, missing joints or frame, unsupported shapes, bad sizes or limits.
    """
    if not urdf.is_file():
        raise FileNotFoundError(f"URDF file not found: {urdf}")
    text = _read_text(urdf, "URDF")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ValueError(f"malformed URDF {urdf}: {exc}") from exc
    if root.tag != "robot":
        raise ValueError(f"malformed URDF {urdf}: root element is <{root.tag}>, expected <robot>")
    if any(c.tag == "capsule" for c in root.iter()):
        raise ValueError(f"URDF {urdf} uses <capsule>, which urdfdom drops silently; use <cylinder> (loaded as capsules)")
    joints = {j.get("name"): j.get("type") for j in root.iter("joint")}
    for name in ARM_JOINTS:
        if joints.get(name) != "revolute":
            raise ValueError(f"URDF {urdf} lacks revolute joint {name!r} (found: {sorted(k for k in joints if k)})")
    if MUZZLE_FRAME not in {link.get("name") for link in root.iter("link")}:
        raise ValueError(f"URDF {urdf} lacks the {MUZZLE_FRAME!r} link")
    n_collision_elements = sum(1 for _ in root.iter("collision"))
    digest = hashlib.sha256(text.encode())
    if srdf is not None and srdf.is_file():
        digest.update(srdf.read_bytes())

    try:
        model = pin.buildModelFromXML(text)
        gmodel = pin.buildGeomFromUrdfString(model, text, pin.GeometryType.COLLISION)
    except Exception as exc:  # the bindings raise RuntimeError/ValueError with C++ text
        raise ValueError(f"Pinocchio could not load URDF {urdf}: {exc}") from exc
    if tuple(model.names[1:]) != ARM_JOINTS:
        raise ValueError(f"URDF {urdf}: moving joints must be exactly {ARM_JOINTS}, got {tuple(model.names[1:])}")
    if gmodel.ngeoms != n_collision_elements:
        raise ValueError(
            f"URDF {urdf}: {n_collision_elements} <collision> elements but only "
            f"{gmodel.ngeoms} geometries were loaded (unsupported shape?)"
        )
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    for k, name in enumerate(ARM_JOINTS):
        if not (np.isfinite(lo[k]) and np.isfinite(hi[k]) and lo[k] < hi[k]):
            raise ValueError(f"URDF {urdf}: joint {name!r} has limits [{lo[k]}, {hi[k]}] (need finite lower < upper)")
    for go in gmodel.geometryObjects:  # every URDF cylinder is a capsule (urdf/README.md)
        _check_shape_sizes(go.geometry, go.name, urdf)
        if isinstance(go.geometry, coal.Cylinder):
            go.geometry = coal.Capsule(go.geometry.radius, 2.0 * go.geometry.halfLength)

    gmodel.addAllCollisionPairs()
    if srdf is not None:
        _apply_srdf(model, gmodel, srdf)
    return LoadedModel(model, gmodel, digest.hexdigest()[:16])


def _apply_srdf(model: pin.Model, gmodel: pin.GeometryModel, srdf: Path) -> None:
    """Remove the SRDF's disabled pairs, after checking that it names only links of the model."""
    if not srdf.is_file():
        raise FileNotFoundError(f"SRDF file not found: {srdf}")
    try:
        root = ET.fromstring(_read_text(srdf, "SRDF"))
    except ET.ParseError as exc:
        raise ValueError(f"malformed SRDF {srdf}: {exc}") from exc
    if root.tag != "robot":
        raise ValueError(f"malformed SRDF {srdf}: root element is <{root.tag}>, expected <robot>")
    links = {f.name for f in model.frames}
    for dc in root.iter("disable_collisions"):
        for key in ("link1", "link2"):
            if dc.get(key) not in links:
                raise ValueError(f"SRDF {srdf} names unknown link {dc.get(key)!r}")
    pin.removeCollisionPairs(model, gmodel, str(srdf))
