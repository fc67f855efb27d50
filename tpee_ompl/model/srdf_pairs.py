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


_LINK_ATTRIBUTES = {"disable_collisions": ("link1", "link2"), "enable_collisions": ("link1", "link2"),
                    "disable_default_collisions": ("link",)}
"""The SRDF's collision entries (MoveIt's srdfdom reads all three; Pinocchio only the first) and their link names."""


def _entry(el: ET.Element) -> str:
    """An SRDF element as it is written, for messages: ``<disable_collisions link1="a" link2="b">``."""
    return "<" + " ".join([el.tag, *(f'{k}="{v}"' for k, v in el.attrib.items() if k != "reason")]) + ">"


def apply_srdf(model: pin.Model, gmodel: pin.GeometryModel, srdf: Path, unknown_links: str = "error") -> None:
    """Remove the SRDF's disabled pairs, after checking that it names only links of the model (``unknown_links``
    "error"), or passing over the entries that name other links ("skip"; the rest apply).

    As in MoveIt's allowed collision matrix: ``<disable_collisions link1 link2>`` disables a pair of links;
    ``<disable_default_collisions link>`` disables every pair of that link, with the obstacles too, except the pairs
    that an ``<enable_collisions link1 link2>`` enables again; ``<disable_collisions>`` wins over
    ``<enable_collisions>``.
    """
    root, text = read_robot_xml(srdf, "SRDF")
    for vj in root.iter("virtual_joint"):  # a mobile or legged robot's base: the URDF's root stays fixed here
        if vj.get("type") in ("floating", "planar"):
            log.warning("SRDF %s declares the %s virtual joint %r: its base is fixed to the world here (only the "
                        "URDF's joints are planned)", srdf, vj.get("type"), vj.get("name"))
    links = {f.name for f in model.frames if f.type == pin.FrameType.BODY}
    entries = [(el, [el.get(a) for a in attrs]) for tag, attrs in _LINK_ATTRIBUTES.items() for el in root.iter(tag)]
    joint_entries = []
    for el, names in entries:
        for attr, name in zip(_LINK_ATTRIBUTES[el.tag], names):
            if name is None:
                raise ValueError(f"SRDF {srdf}: {_entry(el)} has no {attr}")
        message = _joint_named(model, links, el, names, srdf)
        if message and unknown_links == "error":
            raise ValueError(message)
        joint_entries += [message] if message else []
    if joint_entries:  # an SRDF of a larger robot (or a mistake in it): said once
        log.warning("%s%s: passed over, as MoveIt does (the pairs stay checked)", joint_entries[0],
                    f" (and {len(joint_entries) - 1} more entries naming joints)" if len(joint_entries) > 1 else "")
    foreign = [(el, names) for el, names in entries if any(n not in links for n in names)]
    if foreign and unknown_links == "skip":
        log.info("SRDF %s: %d of its %d collision entries name links the URDF lacks; passed over", srdf, len(foreign),
                 len(entries))
    elif foreign:
        name = next(n for n in foreign[0][1] if n not in links)
        raise ValueError(f"SRDF {srdf} names unknown link {name!r} ({len(foreign)} of its {len(entries)} collision "
                         "entries name links the URDF lacks: an SRDF of another or a larger robot? keep only the "
                         "entries of this URDF's links, or pass srdf_unknown_links='skip')")
    # from the text, not the path: Pinocchio's path reader refuses a file not named *.srdf (an SRDF saved as .xml),
    # and the text is decoded as the reader decoded it (a Latin-1 comment)
    pin.removeCollisionPairsFromXML(model, gmodel, text)
    known = [(el.tag, names) for el, names in entries if all(n in links for n in names)]
    no_default = {names[0] for tag, names in known if tag == "disable_default_collisions"}
    if no_default:
        enabled = {frozenset(names) for tag, names in known if tag == "enable_collisions"}
        frame = [model.frames[go.parentFrame].name for go in gmodel.geometryObjects]
        # copies: items are views into the C++ vector, shifted by each removal
        for cp in [pin.CollisionPair(c.first, c.second) for c in gmodel.collisionPairs]:
            pair = (frame[cp.first], frame[cp.second])
            if no_default.intersection(pair) and frozenset(pair) not in enabled:
                gmodel.removeCollisionPair(cp)


def _joint_named(model: pin.Model, links: set[str], el: ET.Element, names: list[str], srdf: Path) -> str | None:
    """The message for an entry naming a joint of the model instead of a link, or None."""
    joint = next((n for n in names if n not in links and n != "universe" and model.existFrame(n)), None)
    if joint is None:
        return None
    jid = model.getFrameId(joint)
    child = next((f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentFrame == jid), None)
    return f"SRDF {srdf}: {_entry(el)} names joint {joint!r}, not a link (its child link is {child!r})"
