"""A URDF or SRDF file read as XML the way urdfdom reads it, and a URDF checked as urdfdom reads it, before Pinocchio
sees it.

urdfdom (Pinocchio's URDF parser) prints a C++ error on stderr for each element it cannot read and then says only
"not a valid URDF model"; what it would refuse is refused here first, with one line naming the file and element.
What it reads is read: its XML parser, tinyxml2, knows no namespaces, so neither does this reader (a default
``xmlns`` on ``<robot>``, as Drake's URDFs have, or an undeclared prefix such as ``<sensor:camera>`` in a
``<gazebo>`` block are names like any other), keeps an attribute's tabs and line breaks, and reads bytes as they
are, so a file that is not UTF-8 is decoded as its XML declaration says (Latin-1 without one).  Versions, numbers
and shapes are read as urdfdom 6 reads them: ``version="1.01"`` is 1.1, ``<capsule>`` is read from version 1.1 on,
a number is read whole (``effort="1 2"`` and ``"1 "`` are not numbers), and only where urdfdom looks (the first
``<origin>`` of a joint, not a ``<transmission>``'s joints).
"""

from __future__ import annotations

import codecs
import logging
import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path
from xml.parsers import expat

__all__ = ["finite_numbers", "parse_urdf", "read_robot_xml", "read_text", "urdf_version"]

log = logging.getLogger(__name__)

_DECLARED_ENCODING = re.compile(
    rb"""(?:\xef\xbb\xbf)?<\?xml\s[^>]*?\bencoding\s*=\s*["']([A-Za-z][A-Za-z0-9._-]*)["']""")
"""The encoding an XML declaration names (``<?xml version="1.0" encoding="ISO-8859-1"?>``)."""
_VERSION_PART = re.compile(r"[ \t\n\v\f\r]*[+-]?[0-9]+")
"""One part of a URDF version as urdfdom reads it (``strtol``, base 10, nothing after the digits)."""
_NUMBER = re.compile(r"[ \t\n\v\f\r]*[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
"""One number as urdfdom's ``strToDouble`` reads it: a C++ stream in the classic locale, blanks before the number and
nothing after it."""
_WARNED_LATIN1: set[Path] = set()
"""The files already said to be read as Latin-1 (each is read more than once per load)."""


def read_text(path: Path, kind: str) -> str:
    """The file's text: UTF-8, else in the encoding its XML declaration names, else Latin-1 (with a warning, once per
    file).  urdfdom reads the bytes as they are, so a Latin-1 comment (``<!-- Jürgen -->``) loads there; UTF-16, which
    it cannot read, is refused (ValueError naming the file)."""
    try:
        return path.read_text(encoding="utf-8")  # (the text a UTF-8 file's model hash has always covered)
    except UnicodeDecodeError:
        pass
    data = path.read_bytes()
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)) or b"\0" in data:
        raise ValueError(f"malformed {kind} {path}: UTF-16 (or binary) text, which urdfdom cannot read: save it as "
                         "UTF-8")
    declared = _DECLARED_ENCODING.match(data)
    name = declared.group(1).decode("ascii").lower().replace("-", "").replace("_", "") if declared else ""
    if declared and not name.startswith(("utf16", "utf32", "ucs")):  # (no NUL byte: not what it declares)
        try:
            return path.read_text(encoding=declared.group(1).decode("ascii"))
        except (LookupError, UnicodeError):  # an unknown name; bytes that are not in it (UTF-16 without a BOM)
            pass
    if path not in _WARNED_LATIN1:
        _WARNED_LATIN1.add(path)
        said = (f"declares encoding {declared.group(1).decode('ascii')!r} but is not" if declared
                else "declares no encoding")
        log.warning("%s %s is not UTF-8 and %s: read as Latin-1 (urdfdom reads its bytes as they are); save it as "
                    "UTF-8 to be sure of its names", kind, path, said)
    return path.read_text(encoding="latin-1")


def read_robot_xml(path: Path, kind: str) -> tuple[ET.Element, str]:
    """The ``<robot>`` root of a URDF or SRDF file and the file's text (:func:`read_text`), or FileNotFoundError /
    ValueError naming the file."""
    if path.is_dir():
        raise ValueError(f"{kind} path {path} is a folder: {'an' if kind == 'SRDF' else 'a'} {kind} file is expected")
    if not path.is_file():
        raise FileNotFoundError(f"{kind} file not found: {path}")
    text = read_text(path, kind)
    try:
        root = _parse_xml(text)
    except expat.ExpatError as exc:
        raise ValueError(f"malformed {kind} {path}: {exc}") from exc
    if root.tag != "robot":
        raise ValueError(f"malformed {kind} {path}: root element is <{root.tag}>, expected <robot>")
    return root, text


def _parse_xml(text: str) -> ET.Element:
    """The element tree of an XML text as tinyxml2 (urdfdom's parser) reads it; ExpatError when it is not XML.

    Namespaces are ignored: a prefix stays part of its element's or attribute's name, ``xmlns`` and ``xmlns:x`` are
    attributes, and an undeclared prefix is no error (expat without a namespace separator, feeding ElementTree's
    builder).  Attribute values are tinyxml2's too: a tab or line break in one stays (XML parsers make it a space),
    and a DOCTYPE's entity stays unexpanded (``radius="&r;"``), as urdfdom gets them."""
    data = text.encode("utf-8")
    builder = ET.TreeBuilder()
    parser = expat.ParserCreate("utf-8")  # (over an XML declaration's encoding: the text is decoded already)
    parser.buffer_text = True

    def start(tag: str, attrs: dict[str, str]) -> None:
        raw = _START_TAG.match(data, parser.CurrentByteIndex) if attrs else None
        if raw is not None and any(c in raw.group(1) for c in (b"\t", b"\n", b"&")):  # (read_text made CRs LFs)
            for name, quoted in _ATTRIBUTE.findall(raw.group(1)):
                name = name.decode("utf-8")
                if name in attrs:  # (not one a DTD adds)
                    attrs[name] = _ENTITY.sub(_entity, quoted[1:-1].decode("utf-8"))
        builder.start(tag, attrs)

    parser.StartElementHandler = start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    parser.Parse(data, True)
    return builder.close()


_START_TAG = re.compile(rb"""<[^\s/>]+((?:\s+[^\s=/>]+\s*=\s*(?:"[^"]*"|'[^']*'))*)\s*/?>""")
"""A start tag as written; group 1: its attributes."""
_ATTRIBUTE = re.compile(rb"""([^\s=/>]+)\s*=\s*("[^"]*"|'[^']*')""")
_ENTITY = re.compile(r"&(#x[0-9A-Fa-f]+|#[0-9]+|lt|gt|amp|quot|apos);")
"""The references tinyxml2 replaces in an attribute: characters and XML's five entities (none a DOCTYPE declares)."""


def _entity(ref: re.Match[str]) -> str:
    name = ref.group(1)
    if name.startswith("#"):
        return chr(int(name[2:], 16) if name[1] == "x" else int(name[1:]))
    return {"lt": "<", "gt": ">", "amp": "&", "quot": '"', "apos": "'"}[name]


_NUMBERS = {"sphere": ("radius",), "cylinder": ("radius", "length"), "capsule": ("radius", "length"),
            "box": ("size",), "origin": ("xyz", "rpy"),
            "axis": ("xyz",), "limit": ("lower", "upper", "effort", "velocity"), "mass": ("value",),
            "inertia": ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), "mesh": ("scale",),
            "mimic": ("multiplier", "offset"),
            "safety_controller": ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"),
            "calibration": ("rising", "falling"), "dynamics": ("damping", "friction")}
"""Numeric attributes of URDF elements, checked before urdfdom reads them (it prints a C++ error per bad one)."""
_VECTORS = {("origin", "xyz"): 3, ("origin", "rpy"): 3, ("origin", "quat_xyzw"): 4, ("axis", "xyz"): 3,
            ("box", "size"): 3, ("mesh", "scale"): 3}
"""The attributes among them that urdfdom reads as a vector, and its length (the others are one number)."""
_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
_SHAPES = {"sphere": ("radius",), "box": ("size",), "cylinder": ("radius", "length"), "mesh": ("filename",),
           "capsule": ("radius", "length")}
"""urdfdom's shapes (``<capsule>`` from ``<robot version="1.1">`` on) and their required attributes."""


def parse_urdf(urdf: Path) -> ET.Element:
    """The URDF's ``<robot>`` root, after refusing what urdfdom would refuse or drop (each with a C++ error on
    stderr and no name in Pinocchio's exception) and what it would read wrongly; ValueError naming the element."""
    root, _ = read_robot_xml(urdf, "URDF")
    version = _check_robot(root, urdf)
    quaternion = ("quat_xyzw",) if version >= (1, 1) else ()  # (urdfdom ignores it in 1.0)
    for owner, el in _read_by_urdfdom(root):
        where = f"URDF {urdf}: {owner.tag} {owner.get('name')!r}"
        for attr in _NUMBERS.get(el.tag, ()) + (quaternion if el.tag == "origin" else ()):
            text = el.get(attr)
            problem = None if text is None else _number_problem(text, _VECTORS.get((el.tag, attr), 1))
            if problem:
                shown = text.translate({9: "\\t", 10: "\\n", 13: "\\r"})  # (one line)
                raise ValueError(f"{where}: <{el.tag} {attr}=\"{shown}\"> {problem}")
        if el.tag == "origin" and quaternion and el.get("quat_xyzw") is not None:
            if el.get("rpy") is not None:
                raise ValueError(f"{where}: an <origin> has both rpy and quat_xyzw, which urdfdom refuses")
            if not any(float(v) for v in el.get("quat_xyzw").split()):
                raise ValueError(f"{where}: <origin quat_xyzw=\"{el.get('quat_xyzw')}\"> is no rotation (Pinocchio "
                                 "would read it as none)")
    links = [_check_link(link, urdf, version) for link in root.findall("link")]
    joints = [_check_joint(joint, urdf, version) for joint in root.findall("joint")]
    for kind, names in (("link", links), ("joint", joints)):
        twice = next((n for k, n in enumerate(names) if n in names[:k]), None)
        if twice is not None:
            raise ValueError(f"URDF {urdf}: {kind} {twice!r} appears twice")
    _check_tree(root, set(links), urdf)
    return root


def _read_by_urdfdom(root: ET.Element) -> Iterator[tuple[ET.Element, ET.Element]]:
    """(link or joint, element) for each element whose numbers urdfdom reads: only the ``<robot>``'s own links and
    joints (not the ``<joint>`` of a ``<transmission>``, ``<gazebo>`` or ``<ros2_control>`` block), and of each
    element the first where urdfdom takes the first (its ``FirstChildElement``): one ``<origin>``, one ``<axis>``
    (not of a fixed or floating joint), one ``<limit>``, one ``<inertial>``, one shape per ``<geometry>``..."""
    for link in root.findall("link"):
        inertial = link.find("inertial")
        found = [] if inertial is None else [inertial.find(tag) for tag in ("origin", "mass", "inertia")]
        for part in (*link.findall("visual"), *link.findall("collision")):
            found += [part.find("origin"), _shape(part)]
        yield from ((link, el) for el in found if el is not None)
    for joint in root.findall("joint"):
        tags = ["origin", "limit", "safety_controller", "calibration", "mimic", "dynamics"]
        tags += ["axis"] if joint.get("type") not in ("fixed", "floating") else []
        yield from ((joint, el) for el in map(joint.find, tags) if el is not None)


def _shape(part: ET.Element) -> ET.Element | None:
    """The shape urdfdom reads in a ``<visual>`` or ``<collision>``: the first element in its first ``<geometry>``."""
    geometry = part.find("geometry")
    return None if geometry is None or len(geometry) == 0 else geometry[0]


def _number_problem(text: str, count: int) -> str | None:
    """What is wrong with an attribute urdfdom reads as ``count`` numbers (for a message), or None.

    One number is read whole by ``strToDouble`` (blanks before it, nothing after: "1 2" and "1 " are refused); a
    vector is split at spaces, and each piece read so (a tab or line break between two numbers is not a space)."""
    if not finite_numbers(text):
        return "is not a list of finite numbers"
    if count == 1 and len(text.split()) > 1:
        return "needs 1 number"
    if count == 1 and text != text.rstrip():
        return "has a blank after its number, which urdfdom does not read as a number"
    pieces = [p for p in text.split(" ") if p]
    if count > 1 and not all(_NUMBER.fullmatch(p) for p in pieces):
        return "has a tab or line break between or after its numbers: urdfdom splits a vector at spaces only"
    if count > 1 and len(pieces) != count:
        return f"needs {count} numbers"
    return None


def urdf_version(root: ET.Element, urdf: Path) -> tuple[int, int]:
    """The ``<robot version>`` as urdfdom reads it, (major, minor) in [(1, 0), (1, 2)]; (1, 0) when there is none.

    urdfdom splits it at dots into exactly two parts and reads each as C's ``strtol`` does, whole: blanks before the
    digits and a sign are read, anything after them is not (" 1.0", "01.0" and "1.00" are 1.0, "1.01" is 1.1; "1.0 ",
    "1" and "1.0.0" are refused).  ValueError naming the file otherwise."""
    text = root.get("version")
    if text is None:
        return (1, 0)
    parts = text.split(".")
    if len(parts) == 2 and all(_VERSION_PART.fullmatch(p) for p in parts):
        version = (int(parts[0]), int(parts[1]))
        if (1, 0) <= version <= (1, 2):
            return version
    raise ValueError(f"URDF {urdf}: <robot version=\"{text}\">: urdfdom reads versions 1.0, 1.1 and 1.2 (major.minor)")


def _check_robot(root: ET.Element, urdf: Path) -> tuple[int, int]:
    """The ``<robot>`` element's name, version, materials and links, as urdfdom requires them; returns the version."""
    if root.get("name") is None:
        raise ValueError(f"URDF {urdf}: <robot> has no name attribute")
    version = urdf_version(root, urdf)
    materials = [m.get("name") for m in root.findall("material") if m.get("name") is not None]
    twice = next((n for k, n in enumerate(materials) if n in materials[:k]), None)
    if twice is not None:
        raise ValueError(f"URDF {urdf}: material {twice!r} is defined twice")
    if root.find("link") is None:
        raise ValueError(f"URDF {urdf} has no <link>")
    return version


def _check_link(link: ET.Element, urdf: Path, version: tuple[int, int]) -> str:
    """A ``<link>``'s name, inertial, visual and collision shapes as urdfdom reads them (a ``<visual>`` or
    ``<collision>`` it cannot read loses the link all its collision geometry, printing errors); returns the name."""
    name = link.get("name")
    if name is None:
        raise ValueError(f"URDF {urdf}: a <link> has no name attribute")
    where = f"URDF {urdf}: link {name!r}"
    inertial = link.find("inertial")
    if inertial is not None:
        mass, inertia = inertial.find("mass"), inertial.find("inertia")
        if mass is None or mass.get("value") is None:
            raise ValueError(f"{where}: <inertial> needs <mass value=...>")
        missing = [a for a in _NUMBERS["inertia"] if inertia is None or inertia.get(a) is None]
        if missing:
            raise ValueError(f"{where}: <inertial> needs <inertia> with {', '.join(missing)}")
    for part in (*link.findall("visual"), *link.findall("collision")):
        lost = f" (urdfdom fails to parse the <{part.tag}>, and link {name!r} loses all its collision geometry)"
        shape = _shape(part)
        if shape is None:
            raise ValueError(f"{where}: a <{part.tag}> has no <geometry> shape{lost}")
        if shape.tag == "capsule" and version < (1, 1):
            raise ValueError(f"{where}: <capsule> needs <robot version=\"1.1\"> (or 1.2): urdfdom reads it from "
                             f"version 1.1 on, and in 1.0 it fails to parse the <{part.tag}> and link {name!r} loses "
                             "all its collision geometry (printing errors); declare version=\"1.1\", or use "
                             "<cylinder> (loaded as a capsule)")
        if shape.tag not in _SHAPES:
            raise ValueError(f"{where}: <{part.tag}> shape <{shape.tag}> is none of urdfdom's {', '.join(_SHAPES)}"
                             f"{lost}")
        missing = [a for a in _SHAPES[shape.tag] if shape.get(a) is None]
        if missing:
            raise ValueError(f"{where}: <{shape.tag}> needs the attribute(s) {', '.join(missing)}{lost}")
        material = part.find("material")
        if part.tag == "visual" and material is not None and material.get("name") is None:
            raise ValueError(f"{where}: a <visual>'s <material> has no name{lost}")
        if part.tag == "collision":
            _check_sizes(shape, where)
    return name


def _check_sizes(shape: ET.Element, where: str) -> None:
    """A collision shape's sizes: > 0 (a capsule's length >= 0: a sphere), a mesh's scale not 0 (Coal would give
    wrong answers, or nothing would collide with a flat mesh)."""
    for attr in _SHAPES[shape.tag]:
        point = (shape.tag, attr) == ("capsule", "length")
        small = [v for v in shape.get(attr).split() if shape.tag != "mesh" and (float(v) < 0 or float(v) == 0
                                                                                 and not point)]
        if small:
            raise ValueError(f"{where}: <{shape.tag} {attr}=\"{shape.get(attr)}\"> has a size of {small[0]} "
                             f"(must be {'>=' if point else '>'} 0)")
    if shape.tag == "mesh" and any(float(v) == 0 for v in shape.get("scale", "1 1 1").split()):
        raise ValueError(f"{where}: <mesh filename=\"{shape.get('filename')}\" scale=\"{shape.get('scale')}\"> "
                         "has a zero scale: the mesh would be flat, with no volume for anything to collide with")


def _check_joint(joint: ET.Element, urdf: Path, version: tuple[int, int]) -> str:
    """A ``<joint>``'s name, type and the elements urdfdom requires of it; returns the name."""
    name = joint.get("name")
    if name is None:
        raise ValueError(f"URDF {urdf}: a <joint> has no name attribute")
    where = f"URDF {urdf}: joint {name!r}"
    kind = joint.get("type")
    if kind not in _JOINT_TYPES:
        raise ValueError(f"{where} has type {kind!r}, none of {', '.join(_JOINT_TYPES)}")
    limit = joint.find("limit")
    if limit is None and kind in ("revolute", "prismatic"):
        raise ValueError(f"{where} is {kind} without a <limit>")
    if limit is not None:
        needed = ["effort", "velocity"] if version < (1, 2) else []
        needed += ["lower", "upper"] if version >= (1, 2) and kind in ("revolute", "prismatic") else []
        missing = [a for a in needed if limit.get(a) is None]
        if missing:
            raise ValueError(f"{where}: <limit> needs the attribute(s) {', '.join(missing)}")
        negative = [a for a in ("effort", "velocity") if limit.get(a) is not None and float(limit.get(a)) < 0]
        if negative:
            raise ValueError(f"{where}: <limit {negative[0]}=\"{limit.get(negative[0])}\"> is negative")
    axis = joint.find("axis")
    if kind in ("revolute", "prismatic", "continuous") and axis is not None \
            and not any(float(v) for v in axis.get("xyz", "0").split()):  # urdfdom: (1, 0, 0) without <axis> only
        shown = f"<axis xyz=\"{axis.get('xyz')}\">" if "xyz" in axis.attrib else "<axis> without xyz (a zero axis)"
        raise ValueError(f"{where} has {shown}: a zero axis moves nothing (a revolute joint would scale its child "
                         "instead of turning it)")
    for tag, attrs, what in (("safety_controller", ("k_velocity",), "k_velocity"), ("mimic", ("joint",), "joint"),
                             ("dynamics", ("damping", "friction"), "damping or friction")):
        el = joint.find(tag)
        if el is not None and all(el.get(a) is None for a in attrs):
            raise ValueError(f"{where}: <{tag}> needs {what}")
    return name


def _check_tree(root: ET.Element, links: set[str], urdf: Path) -> None:
    """Every joint joins two links of the file, no link has two parents, and all links hang from one root."""
    parent: dict[str, tuple[str, str]] = {}
    for joint in root.findall("joint"):  # (not a <transmission>'s) urdfdom prints "Failed to build tree" and says only
        # "not a valid URDF model"
        ends = []
        for end in ("parent", "child"):
            el = joint.find(end)
            name = None if el is None else el.get("link")
            if name not in links:
                raise ValueError(f"URDF {urdf}: joint {joint.get('name')!r} has {end} link {name!r}, which is not a "
                                 "<link> of the file")
            ends.append(name)
        if ends[1] in parent:
            raise ValueError(f"URDF {urdf}: link {ends[1]!r} is the child of two joints, {parent[ends[1]][1]!r} and "
                             f"{joint.get('name')!r}")
        parent[ends[1]] = (ends[0], joint.get("name"))
    roots = sorted(links - set(parent))
    if len(roots) != 1:
        raise ValueError(f"URDF {urdf}: " + ("no root link: the joints form a loop" if not roots else
                         f"{len(roots)} root links {roots[:4]}: every link but one must be a joint's child"))
    for link in links:
        seen = {link}
        while link in parent:
            link = parent[link][0]
            if link in seen:
                raise ValueError(f"URDF {urdf}: the joints form a loop through link {link!r}")
            seen.add(link)


def finite_numbers(text: str) -> bool:
    """Whether ``text`` is one or more whitespace-separated finite numbers, each as urdfdom reads one (C++'s
    ``operator>>``: "1e5", ".5", "+1." are numbers; "inf", "nan", "1_0", "0x10" and "1,5" are not)."""
    words = text.split()
    return bool(words) and all(_NUMBER.fullmatch(w) and math.isfinite(float(w)) for w in words)
