"""URDF ``<mimic>`` joints: a joint that follows another (``follower = multiplier x master + offset``).

Pinocchio's parser (without its mimic option, which gives a joint no coordinate of its own) loads a mimic joint as
an independent joint, so a planner would give the two values the robot cannot take.  A moving mimic joint and the
joint it mimics are therefore locked together, at values that keep the relation; a ``<mimic>`` on a fixed joint
(example-robot-data's Talos arm: the gripper's fingers) moves nothing, so it is ignored and the joint stays fixed,
as Pinocchio's own mimic support does.
"""

from __future__ import annotations

import logging
import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Mimic", "check_mimics", "mimics"]

log = logging.getLogger(__name__)

_MOVING = ("revolute", "continuous", "prismatic")
"""The 1-DOF joint types, whose ``<mimic>`` Pinocchio would load as an independent joint."""
_TOLERANCE = 1e-9
"""Radians or metres: how far a locked mimic may be from ``multiplier x master + offset`` (the rounding of the
numbers typed)."""


@dataclass(frozen=True)
class Mimic:
    """One URDF ``<mimic>``: ``name = multiplier x master + offset``."""

    name: str
    master: str
    multiplier: float
    offset: float

    def value(self, master_value: float) -> float:
        """The mimic joint's position for the master's (radians or metres)."""
        return self.multiplier * master_value + self.offset

    def relation(self, master: str = "") -> str:
        """The relation as text, the master written ``master`` (default: its name, quoted)."""
        return f"{self.name!r} = {self.multiplier:g} x {master or repr(self.master)} + {self.offset:g}"


def mimics(root: ET.Element, urdf: Path) -> list[Mimic]:
    """The file's moving mimic joints; a ``<mimic>`` on a fixed (or floating, planar) joint is passed over."""
    out = []
    for joint in root.findall("joint"):
        el = joint.find("mimic")
        if el is None:
            continue
        if joint.get("type") not in _MOVING:
            log.debug("URDF %s: joint %r is %s: its <mimic> is ignored (it moves nothing)", urdf, joint.get("name"),
                      joint.get("type"))
            continue
        out.append(Mimic(str(joint.get("name")), str(el.get("joint")), float(el.get("multiplier", 1.0)),
                         float(el.get("offset", 0.0))))
    return out


def check_mimics(root: ET.Element, planned: set[str], locked: Mapping[str, float], urdf: Path) -> None:
    """Refuse a planned mimic joint, a planned joint whose mimic is locked, and locked values that break a relation.

    ``planned``: the joints left to plan; ``locked``: the locked joints' values (checked numbers; a continuous
    joint's angle is compared modulo 2 pi).  ValueError naming the joints.
    """
    moving = {j.get("name") for j in root.findall("joint") if j.get("type") in _MOVING}
    continuous = {j.get("name") for j in root.findall("joint") if j.get("type") == "continuous"}
    found = mimics(root, urdf)
    for m in found:
        if m.master not in moving:
            if m.name in planned:
                raise ValueError(f"URDF {urdf}: joint {m.name!r} mimics {m.master!r}, which is not a moving joint of "
                                 f"the URDF: lock {m.name!r} (locked={{{m.name!r}: value}}) or remove its <mimic>")
            continue
        followers = [f for f in found if f.master == m.master]
        locks = ", ".join([f"{m.master!r}: v",
                           *(f"{f.name!r}: {f.multiplier:g} * v + {f.offset:g}" for f in followers)])
        advice = f"lock {m.master!r} and the joints that mimic it (locked={{{locks}}})"
        if m.name in planned:
            raise ValueError(f"URDF {urdf}: joint {m.name!r} mimics {m.master!r}, which would be planned as an "
                             f"independent joint: {advice}")
        if m.master in planned:  # its mimic locked, it free: the two would part (a gripper's two fingers)
            raise ValueError(f"URDF {urdf}: joint {m.master!r} is planned while {m.name!r}, which mimics it, is "
                             f"locked: {advice}")
        want, have = m.value(float(locked[m.master])), float(locked[m.name])
        gap = have - want
        if m.name in continuous:
            gap = math.remainder(gap, 2 * math.pi)
        if abs(gap) > _TOLERANCE * max(1.0, abs(want)):
            raise ValueError(f"URDF {urdf}: locked[{m.name!r}] = {have:g}, but {m.name!r} mimics {m.master!r}: "
                             f"{m.relation()} = {want:g} at locked[{m.master!r}] = {locked[m.master]:g}")
