"""A URDF's collision mesh files: relative paths found in the URDF's folder, a hint where a mesh was looked for, and
the files' bytes for the model hash.

Pinocchio looks a relative ``<mesh filename="meshes/x.stl"/>`` up in ``package_dirs`` only (then in
``ROS_PACKAGE_PATH``), never beside the URDF; a relative path names a file relative to the URDF's folder, so it
is resolved there first.
"""

from __future__ import annotations

import hashlib
import re
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import coal
import pinocchio as pin

__all__ = ["mesh_digests", "missing_mesh_hint", "resolve_relative_meshes"]

_URI = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")
"""``package://``, ``file://``, ...: a mesh filename that is not a plain path."""


def resolve_relative_meshes(root: ET.Element, urdf: Path) -> bool:
    """Rewrite (in ``root``) every collision mesh filename that is a relative path to a file in the URDF's folder
    as that file's absolute path; True when one was.  Others stay as written (Pinocchio looks them up in
    ``package_dirs``)."""
    changed = False
    for mesh in root.findall("link/collision/geometry/mesh"):
        name = mesh.get("filename", "")
        if not name or _URI.match(name) or Path(name).is_absolute():
            continue
        beside = urdf.parent / name
        if beside.is_file():
            mesh.set("filename", str(beside.resolve()))
            changed = True
    return changed


def missing_mesh_hint(message: str, dirs: Sequence[str], urdf: Path) -> str:
    """A hint to add to Pinocchio's ``Mesh ... could not be found`` (else ""): where such a mesh is looked up."""
    found = re.search(r"Mesh (\S+) could not be found", message)
    if found is None:
        return ""
    name, given = found.group(1), f"given: {list(dirs) if dirs else 'none'}"
    if name.startswith("package://"):
        package = name[len("package://"):].split("/")[0]
        return (f" (a package:// mesh is looked up in package_dirs: give the folder that holds the package's folder "
                f"{package!r}; {given})")
    if _URI.match(name):
        return ""
    return f" (a relative mesh path is looked up in the URDF's folder {urdf.parent}, then in package_dirs; {given})"


def mesh_digests(gmodel: pin.GeometryModel) -> list[str]:
    """Per mesh geometry, ``"mesh=<geometry name>:<SHA-256 of its file's bytes>"``, for the model hash.

    The bytes decide the shape (with the URDF's scale, which the URDF's text holds); where the file is does not:
    the same package found in another folder, or the robot's files moved, keep the hash of the query sets and
    path libraries made for it."""
    out, seen = [], {}
    for go in gmodel.geometryObjects:
        if isinstance(go.geometry, coal.BVHModelBase) and Path(go.meshPath).is_file():
            if go.meshPath not in seen:
                seen[go.meshPath] = hashlib.sha256(Path(go.meshPath).read_bytes()).hexdigest()
            out.append(f"mesh={go.name}:{seen[go.meshPath]}")
    return out
