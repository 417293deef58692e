"""What pinocchio's URDF parser leaves unsaid: a document's root links and its mimic joints.

pinocchio refuses a URDF with two root links with "The XML stream does not contain a valid URDF
model", the cause going to the server's stderr only; and it reads a ``<mimic>`` joint as a free
joint of its own, so an arm whose joints are coupled (ABB IRB 5400's joint5b follows joint5)
would be answered with joint paths that break the coupling. This module reads the document's
structure itself, so that both are said in the answer (robots.md section 4), and finds the
links joined to nothing (:func:`stray_links`: a ROS 2 generated UR5e's ``<link name="world"/>``,
whose joint the generator left out), which :func:`without_links` takes out of the document, and
the ``continuous`` joints, which :func:`continuous_as_revolute` makes revolute (pinocchio gives
such a joint two coordinates, the solver takes one angle a joint).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass

from solver.core.exceptions import quoted, quoted_names


@dataclass(frozen=True)
class Mimic:
    """A joint that follows another: q = multiplier * q_leader + offset (URDF ``<mimic>``).

    ``lower``, ``upper`` (rad or m) and ``velocity`` (rad/s or m/s) are the mimic joint's own
    limits (its ``<limit>``), None where not given.
    """

    joint: str
    leader: str
    multiplier: float
    offset: float
    lower: float | None = None
    upper: float | None = None
    velocity: float | None = None


def _tree(urdf: str) -> ElementTree.Element | None:
    """The document's root element, or None where it is no XML at all."""
    try:
        return ElementTree.fromstring(urdf)
    except ElementTree.ParseError:
        return None


def parsed(urdf: str) -> ElementTree.Element | None:
    """The document's root element, or None where it is no XML.

    For the readers below that take a parsed document: one parse for all of them.
    """
    return _tree(urdf)


def not_well_formed(urdf: str) -> str | None:
    """Why the document is not well-formed XML (the XML parser's words), or None where it is."""
    try:
        ElementTree.fromstring(urdf)
    except ElementTree.ParseError as error:
        return str(error)
    return None


def nesting_depth(root: ElementTree.Element) -> int:
    """How deep a parsed document's elements nest (the root alone: 1).

    Counted without recursion: ElementTree writes a document back by recursion, which a
    document nested a thousand deep ended with RecursionError (a 500).
    """
    deepest, stack = 0, [(root, 1)]
    while stack:
        element, depth = stack.pop()
        deepest = max(deepest, depth)
        stack.extend((child, depth + 1) for child in element)
    return deepest


def root_links(urdf: str) -> list[str]:
    """The links no joint has as its child, in the document's order (one for a valid arm)."""
    root = _tree(urdf)
    if root is None:
        return []
    links = [link.get("name", "") for link in root.iter("link")]
    children = {
        child.get("link", "") for joint in root.iter("joint") for child in joint.iter("child")
    }
    return [name for name in links if name not in children]


@dataclass(frozen=True)
class StrayLink:
    """A link no joint names, as parent or child: joined to nothing, so it has no pose.

    ``collision``: it carries ``<collision>`` elements (geometry a cell would check, which a
    link without a pose cannot give).
    """

    name: str
    collision: bool


def stray_links(urdf: str) -> list[StrayLink]:
    """The links of the document that no joint names, in its order, where it has joints.

    A document of one link and no joint has none (that link is the whole robot).
    """
    root = _tree(urdf)
    if root is None:
        return []
    joints = root.findall("joint")
    named = {
        end.get("link", "")
        for joint in joints
        for end in (*joint.findall("parent"), *joint.findall("child"))
    }
    if not joints:
        return []
    return [
        StrayLink(link.get("name", ""), link.find("collision") is not None)
        for link in root.findall("link")
        if link.get("name", "") not in named
    ]


def without_links(urdf: str, names: set[str]) -> str:
    """The document with its top-level links named in ``names`` taken out (as XML text).

    Comments and the XML declaration are not kept; every element and attribute is.
    """
    root = _tree(urdf)
    if root is None:
        return urdf
    for link in root.findall("link"):
        if link.get("name", "") in names:
            root.remove(link)
    return ElementTree.tostring(root, encoding="unicode")


@dataclass(frozen=True)
class ContinuousJoint:
    """A ``continuous`` joint: a hinge with no position limits in URDF's own terms.

    ``lower`` and ``upper`` (rad) are what its ``<limit>`` gives anyway (Kinova's files give
    +-2 pi), None where it gives none.
    """

    name: str
    lower: float | None
    upper: float | None


def continuous_as_revolute(urdf: str) -> tuple[str, list[ContinuousJoint]]:
    """The document with its ``continuous`` joints made ``revolute``, and those joints.

    pinocchio models a continuous joint by (cos, sin), two coordinates for one angle; the
    solver takes one angle a joint. A revolute joint needs a ``<limit>``: one is added where the
    joint has none (no speed limit: the request must give one); where ``lower`` or ``upper`` is
    missing, pinocchio reads 0, which the caller replaces (:class:`ContinuousJoint`). The
    document is returned as it is where it has no continuous joint.
    """
    root = _tree(urdf)
    if root is None:
        return urdf, []
    found = []
    for joint in root.findall("joint"):
        if joint.get("type") != "continuous":
            continue
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = ElementTree.SubElement(joint, "limit", {"effort": "0", "velocity": "0"})
        found.append(
            ContinuousJoint(
                joint.get("name", ""), _number(limit.get("lower")), _number(limit.get("upper"))
            )
        )
    if not found:
        return urdf, []
    return ElementTree.tostring(root, encoding="unicode"), found


def fixed_to_root(urdf: str, link: str) -> bool:
    """Whether ``link`` is in the document and joined to its root by fixed joints only.

    REP 199's ``base``, the frame a controller's Cartesian poses are in, is such a link.
    """
    root = _tree(urdf)
    if root is None or link not in {element.get("name") for element in root.iter("link")}:
        return False
    parents = {}  # child link: (parent link, joint type)
    for joint in root.iter("joint"):
        child, parent = joint.find("child"), joint.find("parent")
        if child is not None and parent is not None:
            parents[child.get("link", "")] = (parent.get("link", ""), joint.get("type"))
    seen = set()
    while link in parents and link not in seen:
        seen.add(link)
        link, kind = parents[link]
        if kind != "fixed":
            return False
    return link not in seen


XACRO_NAMESPACE = "http://www.ros.org/wiki/xacro"


def uses_xacro(urdf: str) -> bool:
    """Whether the document has xacro elements (a macro file ROS expands into a URDF)."""
    root = _tree(urdf)
    if root is None:
        return False
    prefix = "{" + XACRO_NAMESPACE + "}"
    return any(element.tag.startswith(prefix) for element in root.iter())


def movable_joints(urdf: str) -> list[str]:
    """The names of the document's joints that are not ``fixed``, in its order."""
    root = _tree(urdf)
    if root is None:
        return []
    return [j.get("name", "") for j in root.findall("joint") if j.get("type") != "fixed"]


@dataclass(frozen=True)
class JointAxis:
    """A joint's ``<axis xyz>``, as three numbers, and their length (``math.hypot``)."""

    joint: str
    xyz: tuple[float, float, float]
    length: float


def _movable_with(root: ElementTree.Element, tag: str) -> Iterator[tuple[str, ElementTree.Element]]:
    """Each joint that is not ``fixed`` and has a ``tag`` element: its name and that element."""
    for joint in root.findall("joint"):
        element = joint.find(tag)
        if joint.get("type") != "fixed" and element is not None:
            yield joint.get("name", ""), element


def joint_axes(root: ElementTree.Element) -> list[JointAxis]:
    """The axes of a parsed document's joints that are not ``fixed`` and give three finite numbers.

    A joint without ``<axis>`` (URDF's default, 1 0 0) or whose ``xyz`` is not three finite
    numbers is left out: the parser names the latter.
    """
    axes = []
    for name, element in _movable_with(root, "axis"):
        try:
            xyz = tuple(float(v) for v in element.get("xyz", "1 0 0").split())
        except ValueError:
            continue
        if len(xyz) == 3 and all(math.isfinite(v) for v in xyz):
            axes.append(JointAxis(name, xyz, math.hypot(*xyz)))
    return axes


def inverted_limits(root: ElementTree.Element) -> list[tuple[str, float, float]]:
    """(name, lower, upper) of each movable joint whose ``<limit>`` has lower above upper."""
    inverted = []
    for name, limit in _movable_with(root, "limit"):
        lower, upper = _number(limit.get("lower")), _number(limit.get("upper"))
        if lower is not None and upper is not None and lower > upper:
            inverted.append((name, lower, upper))
    return inverted


def tree_problem(root: ElementTree.Element) -> str | None:
    """What keeps a parsed document's joints from forming a tree, or None where they do.

    A link or joint named twice (the parser then named two root links, both the same).
    A link that is the child of two joints, or joints that lead back to where they started,
    close a loop: pinocchio's parser crashed the process on such a document (a segmentation
    fault) or read one of the two joints twice and dropped the other.
    """
    for kind in ("link", "joint"):
        counts = Counter(element.get("name", "") for element in root.findall(kind))
        twice = next((name for name, count in counts.items() if count > 1), None)
        if twice is not None:  # pinocchio's parser then named two root links, both this one
            return (
                f"{kind} {quoted(twice)} is defined {counts[twice]} times: each {kind} is one "
                f"<{kind}> element"
            )
    parents: dict[str, list[str]] = {}  # child link: the joints that have it as their child
    parent_link: dict[str, str] = {}
    for joint in root.findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            continue  # the parser names the joint
        name, child_link = joint.get("name", ""), child.get("link", "")
        parents.setdefault(child_link, []).append(name)
        parent_link[child_link] = parent.get("link", "")
    for link, joints in parents.items():
        if len(joints) > 1:
            return (
                f"link {quoted(link)} is the child of {len(joints)} joints "
                f"({quoted_names(joints)}): a URDF is a tree, each link the child of one joint "
                "(a closed chain cannot be read)"
            )
    rooted: set[str] = set()  # links whose joints lead up to a root: each walked once
    for start in parent_link:
        link, seen = start, {start}
        while link in parent_link and link not in rooted:
            link = parent_link[link]
            if link in seen:
                return (
                    f"the joints above link {quoted(start)} lead back to link {quoted(link)}: "
                    "a URDF is a tree, with no loop of joints"
                )
            seen.add(link)
        rooted |= seen
    return None


def joint_problem(root: ElementTree.Element) -> str | None:
    """What a parsed document's joint elements say that the parser reads wrongly or unsaid.

    A joint with two ``<mimic>`` elements (the parser couples it to the first; a reading of the
    last would narrow the wrong joint's limits), a mimic multiplier outside MULTIPLIERS, a
    negative velocity limit (the parser's refusal names no joint), a joint origin farther than
    MAX_ORIGIN (an LP of such a chain misses its twist: no arm is that big).
    """
    for joint in root.findall("joint"):
        name = quoted(joint.get("name", ""))
        mimics = joint.findall("mimic")
        if len(mimics) > 1:
            return f"joint {name} has {len(mimics)} <mimic> elements; a joint mimics one joint"
        multiplier = _number(mimics[0].get("multiplier")) if mimics else None
        if (
            multiplier is not None
            and 0.0 < abs(multiplier)
            and not (MULTIPLIERS[0] <= abs(multiplier) <= MULTIPLIERS[1])
        ):
            return (
                f"joint {name}: its mimic multiplier {multiplier:.6g} is outside +-1e-6 to "
                "+-1e6 (a gear ratio)"  # MULTIPLIERS
            )
        limit = joint.find("limit")
        velocity = _number(limit.get("velocity")) if limit is not None else None
        if velocity is not None and velocity < 0.0:
            return f"joint {name}: its velocity limit {velocity:.6g} is negative"
        origin = joint.find("origin")
        xyz = _numbers(origin.get("xyz", "")) if origin is not None else None
        if xyz is not None and not max(abs(v) for v in xyz) <= MAX_ORIGIN:
            return (
                f"joint {name}: its origin xyz has a value beyond +-{MAX_ORIGIN:g} m (no arm is "
                "that big; a URDF's lengths are in metres)"
            )
    return None


MULTIPLIERS = (1e-6, 1e6)
"""The magnitudes a ``<mimic multiplier>`` may have (0 is refused where the coupling is read)."""
MAX_ORIGIN = 100.0
"""m, the largest coordinate of a joint's ``<origin xyz>``: an OPW arm's lengths have the same
bound (solver.families.opw.parameters.MAX_LENGTH). At 1e8 m the DTF's LP answered a twist 11 %
off the one asked, at 1e10 m HiGHS failed (a 500)."""


def _numbers(text: str) -> list[float] | None:
    """Finite numbers separated by spaces, None where any is not one (the parser names it)."""
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        return None
    return values if values and all(math.isfinite(v) for v in values) else None


def joint_count(urdf: str) -> int:
    """How many ``<joint>`` elements the document's robot has (0 where it is no XML)."""
    root = _tree(urdf)
    return 0 if root is None else sum(1 for _ in root.iter("joint"))


def collision_count(urdf: str) -> int:
    """How many ``<collision>`` elements the document has (0 where it is no XML)."""
    root = _tree(urdf)
    return 0 if root is None else sum(1 for _ in root.iter("collision"))


def mimic_joints(urdf: str) -> dict[str, Mimic]:
    """The document's mimic joints by name."""
    root = _tree(urdf)
    mimics: dict[str, Mimic] = {}
    if root is None:
        return mimics
    for joint in root.iter("joint"):
        for mimic in joint.iter("mimic"):
            name = joint.get("name", "")
            limit = joint.find("limit")
            bounds = {
                key: _number(limit.get(key)) if limit is not None else None
                for key in ("lower", "upper", "velocity")
            }
            if joint.get("type") == "continuous":
                bounds["lower"] = bounds["upper"] = None
            mimics[name] = Mimic(
                joint=name,
                leader=mimic.get("joint", ""),
                multiplier=float(mimic.get("multiplier", "1") or 1.0),
                offset=float(mimic.get("offset", "0") or 0.0),
                **bounds,
            )
    return mimics


def _number(text: str | None) -> float | None:
    """A limit's value, None where absent or not a number."""
    try:
        return None if text is None else float(text)
    except ValueError:
        return None
