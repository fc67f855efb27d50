"""The SRDF's collision entries applied to a Pinocchio collision model, refusing what would apply wrongly.

Pinocchio removes the ``<disable_collisions>`` pairs whose two names are links of the model and passes over the
others without a word; srdfdom (MoveIt) warns about them and ignores them.  Either way the pair stays checked, so
a typo or a joint's name in place of a link's would leave a colliding pair that is meant to be disabled: such an
entry is refused, naming it (or, with ``unknown_links="skip"``, passed over: the SRDF of a larger robot).
"""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ET
from pathlib import Path

import pinocchio as pin

from .urdf_xml import read_robot_xml

__all__ = ["apply_srdf"]

log = logging.getLogger(__name__)


def _entry(el: ET.Element) -> str:
    """An SRDF element as it is written, for messages: ``<disable_collisions link1="a" link2="b">``."""
    return "<" + " ".join([el.tag, *(f'{k}="{v}"' for k, v in el.attrib.items() if k != "reason")]) + ">"


def apply_srdf(model: pin.Model, gmodel: pin.GeometryModel, srdf: Path, unknown_links: str = "error") -> None:
    """Remove the SRDF's disabled pairs, after checking that it names only links of the model (``unknown_links``
    "error"), or passing over the pairs that name other links ("skip"; Pinocchio applies the rest)."""
    root = read_robot_xml(srdf, "SRDF")
    for vj in root.iter("virtual_joint"):  # a mobile or legged robot's base: the URDF's root stays fixed here
        if vj.get("type") in ("floating", "planar"):
            log.warning("SRDF %s declares the %s virtual joint %r: its base is fixed to the world here (only the "
                        "URDF's joints are planned)", srdf, vj.get("type"), vj.get("name"))
    links = {f.name for f in model.frames if f.type == pin.FrameType.BODY}
    joints = {f.name: k for k, f in enumerate(model.frames) if f.type in (pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT)
              and f.name not in links and k > 0}
    entries = list(root.iter("disable_collisions"))
    pairs = [(dc.get("link1"), dc.get("link2")) for dc in entries]
    for dc, pair in zip(entries, pairs):
        joint = next((n for n in pair if n in joints), None)
        if joint is not None:
            child = next((f.name for f in model.frames if f.type == pin.FrameType.BODY
                          and f.parentFrame == joints[joint]), None)
            message = f"SRDF {srdf}: {_entry(dc)} names joint {joint!r}, not a link (its child link is {child!r})"
            if unknown_links == "error":
                raise ValueError(message)
            log.warning("%s: passed over, the pair stays checked (as MoveIt does)", message)
            break
    foreign = [p for p in pairs if p[0] not in links or p[1] not in links]
    if foreign and unknown_links == "skip":
        log.info("SRDF %s: %d of its %d disabled pairs name links the URDF lacks; passed over", srdf, len(foreign),
                 len(pairs))
    elif foreign:
        name = next(n for n in foreign[0] if n not in links)
        raise ValueError(f"SRDF {srdf} names unknown link {name!r} ({len(foreign)} of its {len(pairs)} disabled pairs "
                         "name links the URDF lacks: an SRDF of another or a larger robot? keep only the pairs of "
                         "this URDF's links, or pass srdf_unknown_links='skip')")
    # from the text, not the path: Pinocchio's path reader refuses a file not named *.srdf (an SRDF saved as .xml)
    pin.removeCollisionPairsFromXML(model, gmodel, srdf.read_text(encoding="utf-8"))
