"""A URDF or SRDF file read as XML, and a URDF checked as urdfdom reads it, before Pinocchio sees it.

urdfdom (Pinocchio's URDF parser) prints a C++ error on stderr for each element it cannot read and then says only
"not a valid URDF model"; what it would refuse is refused here first, with one line naming the file and element.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

__all__ = ["finite_numbers", "parse_urdf", "read_robot_xml", "read_text"]


def read_text(path: Path, kind: str) -> str:
    """The file's text, or ValueError naming it when it is not UTF-8."""
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"malformed {kind} {path}: not UTF-8 text ({exc})") from exc


def read_robot_xml(path: Path, kind: str) -> ET.Element:
    """The ``<robot>`` root of a URDF or SRDF file, or FileNotFoundError / ValueError naming the file."""
    if path.is_dir():
        raise ValueError(f"{kind} path {path} is a folder: {'an' if kind == 'SRDF' else 'a'} {kind} file is expected")
    if not path.is_file():
        raise FileNotFoundError(f"{kind} file not found: {path}")
    try:
        root = ET.fromstring(read_text(path, kind))
    except ET.ParseError as exc:
        raise ValueError(f"malformed {kind} {path}: {exc}") from exc
    if root.tag != "robot":
        raise ValueError(f"malformed {kind} {path}: root element is <{root.tag}>, expected <robot>")
    return root


_NUMBERS = {"sphere": ("radius",), "cylinder": ("radius", "length"), "box": ("size",), "origin": ("xyz", "rpy"),
            "axis": ("xyz",), "limit": ("lower", "upper", "effort", "velocity"), "mass": ("value",),
            "inertia": ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), "mesh": ("scale",)}
"""Numeric attributes of URDF elements, checked before urdfdom reads them (it prints a C++ error per bad one)."""


def parse_urdf(urdf: Path) -> ET.Element:
    root = read_robot_xml(urdf, "URDF")
    # a link's shapes only: <collision> / <capsule> elsewhere (Gazebo sensors, Pinocchio's <collision_checking>)
    # are not urdfdom's to drop
    if root.findall("link/collision/geometry/capsule") or root.findall("link/visual/geometry/capsule"):
        raise ValueError(f"URDF {urdf} uses <capsule>, which urdfdom drops silently; use <cylinder> (loaded as capsules)")
    for joint in root.iter("joint"):
        axis = joint.find("axis")
        if joint.get("type") in ("revolute", "prismatic", "continuous") and axis is not None \
                and finite_numbers(axis.get("xyz", "1 0 0")) and not any(float(v) for v in axis.get("xyz", "1 0 0").split()):
            raise ValueError(f"URDF {urdf}: joint {joint.get('name')!r} has <axis xyz=\"{axis.get('xyz')}\">: a zero axis "
                             "moves nothing (a revolute joint would scale its child instead of turning it)")
    links = {link.get("name") for link in root.findall("link")}
    for joint in root.findall("joint"):  # (not a <transmission>'s) urdfdom prints "Failed to build tree" and says only
        # "not a valid URDF model"
        for end in ("parent", "child"):
            el = joint.find(end)
            name = None if el is None else el.get("link")
            if name not in links:
                raise ValueError(f"URDF {urdf}: joint {joint.get('name')!r} has {end} link {name!r}, which is not a "
                                 "<link> of the file")
    for owner in (*root.iter("link"), *root.iter("joint")):
        for el in owner.iter():
            for attr in _NUMBERS.get(el.tag, ()):
                text = el.get(attr)
                if text is not None and not finite_numbers(text):
                    raise ValueError(f"URDF {urdf}: {owner.tag} {owner.get('name')!r}: <{el.tag} {attr}=\"{text}\"> "
                                     "is not a list of finite numbers")
    return root


def finite_numbers(text: str) -> bool:
    """Whether ``text`` is one or more whitespace-separated finite numbers."""
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        return False
    return bool(values) and all(math.isfinite(v) for v in values)
