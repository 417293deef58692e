"""A URDF document read into the pinocchio chain from its root to the tool frame.

pinocchio's parser (urdfdom) is run with its stderr captured (:mod:`solver.core.native_stderr`)
so that a refusal carries its reason; what pinocchio leaves unsaid (two root links, mimic joints
between base and tool) is read from the document itself (:mod:`solver.core.urdf_structure`).
A link no joint names (a ROS 2 generated UR5e's ``world``) is taken out of the document before
it is read (:func:`without_stray_links`), continuous joints are read as revolute ones with no
position limit where the file gives none (:func:`readable_urdf`, :func:`unlimit`), and answers
say both (:class:`UrdfReading`).
A request's speed limits, one per coordinate, cannot name a mimic joint: they are checked
against the mimic joints' own (:func:`check_mimic_speed_limits`). Names in messages are cut (a
request may send a name of megabytes).
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from solver.core.exceptions import (
    InvalidInputError,
    RobotModelError,
    cut,
    quoted,
    quoted_names,
)
from solver.core.native_stderr import first_error, native_stderr
from solver.core.urdf_structure import (
    ContinuousJoint,
    Mimic,
    continuous_as_revolute,
    inverted_limits,
    joint_axes,
    joint_problem,
    mimic_joints,
    nesting_depth,
    not_well_formed,
    parsed,
    root_links,
    stray_links,
    tree_problem,
    uses_xacro,
    without_links,
)


def frame_names(model: pin.Model) -> str:
    """The model's frame names for a message, each cut and at most 20 (:func:`quoted_names`)."""
    return quoted_names([f.name for f in model.frames if f.name != "universe"])


@dataclass(frozen=True)
class UrdfReading:
    """What was changed in a URDF document before it was read, as answers say it.

    Attributes:
        left_out_links: links no joint names, taken out (:func:`without_stray_links`).
        continuous_joints: the chain's ``continuous`` joints, read as revolute joints
            (:func:`solver.core.urdf_structure.continuous_as_revolute`).
        unlimited_joints: those of them whose ``<limit>`` gives no lower or upper: that side
            has no position limit (a continuous joint has none in URDF's own terms).
        locked_joints: the document's joints that move but not the tool frame (a gripper's
            fingers), held at 0 (:func:`chain_from_urdf`).
    """

    left_out_links: tuple[str, ...] = ()
    continuous_joints: tuple[str, ...] = ()
    unlimited_joints: tuple[str, ...] = ()
    locked_joints: tuple[str, ...] = ()


MAX_URDF_DEPTH = 100
"""The deepest nesting of elements a request's URDF may have (a URDF's is 4 or 5: robot,
joint, limit; a link's collision, geometry, mesh). pinocchio's parser refuses far less deep
documents than this module's ElementTree writes back by recursion (1,000: RecursionError)."""


AXIS_LENGTHS = (1e-6, 1e6)
"""The lengths of a joint's ``<axis xyz>`` taken (and normalised, as the parser does). A zero
axis has no direction, and pinocchio's normalisation of one of length 1e-300 or 1e308 gave
NaN: a chain of NaN, refused deep in the kernels (LinAlgError, a 500)."""


def readable_urdf(
    urdf: str, *, frames: tuple[str, ...]
) -> tuple[str, list[ContinuousJoint], tuple[str, ...]]:
    """The document pinocchio reads for a request's URDF: stray links out, continuous revolute.

    Returns the document, its continuous joints (for :func:`chain_from_urdf`) and the links
    left out (:func:`without_stray_links`, ``frames`` as there).

    Raises:
        RobotModelError: on ``robot.urdf``, a document that is not well-formed XML or whose
            root is not ``<robot>``, elements nested deeper than MAX_URDF_DEPTH, a
            joint whose axis has a length outside AXIS_LENGTHS, joints that are no tree, a
            joint with two mimics, a mimic multiplier, a negative velocity or an origin out of
            bounds, or a limit whose lower is above its upper (naming the joint or link).
    """
    root = parsed(urdf)
    if root is None:
        # pinocchio's parser reads documents this one refuses (junk after </robot>, a second
        # root, an undefined entity), and every check here and of the collision meshes
        # (solver.path.cell.robot_geometry) reads the document with this one: such a document
        # skipped them all (a mesh read from anywhere on the server; the hostile-input audit)
        reason = cut(not_well_formed(urdf) or "")
        raise RobotModelError("robot.urdf", f"cannot parse the URDF: not well-formed XML: {reason}")
    if root.tag != "robot":  # a namespace (xmlns="...") the checks' parser reads, pinocchio's not
        raise RobotModelError(
            "robot.urdf",
            f"cannot parse the URDF: its root element is {quoted(root.tag)}, not 'robot' (a URDF's "
            "elements are in no XML namespace)",
        )
    _refuse_unreadable(root)
    urdf, left_out = without_stray_links(urdf, frames=frames)
    urdf, continuous = continuous_as_revolute(urdf)
    return urdf, continuous, left_out


def _refuse_unreadable(root: ElementTree.Element) -> None:
    """:func:`readable_urdf`'s refusals of a parsed request URDF, naming the joint.

    Elements nested too deep, a joint axis of no direction, joints that do not form a tree
    (:func:`~solver.core.urdf_structure.tree_problem`), a joint's mimic, velocity or origin the
    parser reads wrongly or unsaid (:func:`~solver.core.urdf_structure.joint_problem`), a limit
    whose lower is above its upper.
    """
    depth = nesting_depth(root)
    if depth > MAX_URDF_DEPTH:
        raise RobotModelError(
            "robot.urdf",
            f"cannot parse the URDF: its elements nest {depth} deep, more than "
            f"{MAX_URDF_DEPTH} (a URDF's nest a few levels)",
        )
    for axis in joint_axes(root):
        if not AXIS_LENGTHS[0] <= axis.length <= AXIS_LENGTHS[1]:
            x, y, z = axis.xyz
            raise RobotModelError(
                "robot.urdf",
                f"joint {quoted(axis.joint)}: its axis ({x:.6g} {y:.6g} {z:.6g}) has length "
                f"{axis.length:.3g}; an axis is a direction, a unit vector (lengths from "
                "1e-6 to 1e6 are normalised)",  # AXIS_LENGTHS
            )
    problem = tree_problem(root) or joint_problem(root)
    if problem is not None:
        raise RobotModelError("robot.urdf", f"cannot read the URDF: {problem}")
    inverted = inverted_limits(root)
    if inverted:  # it was read, and the joint then fitted nowhere (joint_limits at waypoint 0)
        name, lower, upper = inverted[0]
        raise RobotModelError(
            "robot.urdf",
            f"joint {quoted(name)}: its limit's lower {lower:.6g} is above its upper {upper:.6g}",
        )


def unlimited(model: pin.Model, continuous: Sequence[ContinuousJoint]) -> tuple[str, ...]:
    """The joints of ``model`` among ``continuous`` whose URDF gives no lower or no upper."""
    return tuple(
        joint.name
        for joint in continuous
        if model.existJointName(joint.name) and (joint.lower is None or joint.upper is None)
    )


def unlimit(model: pin.Model, continuous: Sequence[ContinuousJoint]) -> None:
    """Give the model's continuous joints no position limit where their URDF gives none.

    pinocchio read 0 for a missing ``lower`` or ``upper`` of a continuous joint made revolute;
    that side becomes -inf or +inf (:func:`chain_from_urdf` calls this).
    """
    by_name = {joint.name: joint for joint in continuous}
    for name in unlimited(model, continuous):
        index = model.joints[model.getJointId(name)].idx_q
        if by_name[name].lower is None:
            model.lowerPositionLimit[index] = -np.inf
        if by_name[name].upper is None:
            model.upperPositionLimit[index] = np.inf


def without_stray_links(urdf: str, *, frames: tuple[str, ...]) -> tuple[str, tuple[str, ...]]:
    """The document without the links no joint names, where that leaves it one root; their names.

    A link that no joint names has no pose: it is not part of the robot, and pinocchio refuses
    the document for it (two root links). It is taken out, and the caller says so, unless it
    carries collision geometry (a cell would check what has no place) or is one of ``frames``
    (the request's base or tool frame): then, as where two joined trees have a root each, the
    document is returned as it is, and :func:`chain_from_urdf` refuses it naming the roots.

    Args:
        urdf: the URDF document.
        frames: the frames the request names (its base and tool frames).

    Returns:
        The document to read (``urdf`` itself where nothing is taken out) and the names of the
        links taken out, in the document's order.
    """
    roots = root_links(urdf)
    if len(roots) < 2:
        return urdf, ()
    stray = [s.name for s in stray_links(urdf) if not s.collision and s.name not in frames]
    if len([root for root in roots if root not in stray]) != 1:
        return urdf, ()
    return without_links(urdf, set(stray)), tuple(stray)


def chain_from_urdf(
    urdf: str, *, tool_frame: str, continuous: Sequence[ContinuousJoint] = ()
) -> pin.Model:
    """Read the serial chain from the root to ``tool_frame`` out of URDF text.

    Joints that do not move the tool frame (grippers, fingers) are locked at their neutral
    position (0: pinocchio's for a revolute or prismatic joint), so the model is the chain from
    the root to ``tool_frame``.

    Args:
        urdf: the URDF document.
        tool_frame: link or frame of the tool flange.
        continuous: the document's continuous joints made revolute (:func:`readable_urdf`):
            those without limits get none (:func:`unlimit`) before a mimic joint's own limits
            narrow its leader's.

    Raises:
        RobotModelError: the URDF cannot be parsed, the frame is missing or no joint moves it.
    """
    error: Exception | None = None
    with native_stderr() as said:
        try:
            full = pin.buildModelFromXML(urdf)
        except (RuntimeError, ValueError) as exc:
            error = exc
    if error is not None:
        roots = root_links(urdf)
        if len(roots) > 1:  # pinocchio says why on stderr only
            named_roots = quoted_names(roots)
            raise RobotModelError(
                "robot.urdf",
                f"cannot parse the URDF: {len(roots)} root links ({named_roots})"
                ": every link but one must be a joint's child; remove the stray link or attach "
                "it with a fixed joint",
            ) from error
        reason = first_error(said[0]) or quoted(str(error))
        if uses_xacro(urdf):  # the parser's reason (no links, an unknown element) hides why
            reason += (
                "; the document is xacro (it has xacro: elements), not a URDF: expand it first "
                "(ROS: xacro file.urdf.xacro > file.urdf)"
            )
        raise RobotModelError("robot.urdf", f"cannot parse the URDF: {reason}") from error
    _links_keep_their_names(full)
    if not full.existFrame(tool_frame):
        names = frame_names(full)
        raise RobotModelError(
            "robot.tool_frame", f"no frame {quoted(tool_frame)} in the model; frames: {names}"
        )
    tool_joint = full.frames[full.getFrameId(tool_frame)].parentJoint
    chain = {full.names[j] for j in full.supports[tool_joint]}
    mimics = mimic_joints(urdf)
    coupled = [mimics[name] for name in sorted(chain) if name in mimics]
    for mimic in coupled:
        if mimic.leader not in chain or mimic.leader in mimics or mimic.multiplier == 0.0:
            raise RobotModelError(
                "robot.urdf",
                f"joint {quoted(mimic.joint)} mimics {quoted(mimic.leader)} (q = "
                f"{mimic.multiplier:g} q_leader + {mimic.offset:g}) between the base and the "
                "tool, but its leader is not a joint of its own between them (or the "
                "multiplier is 0): that coupling is not modelled",
            )
    if coupled:  # pinocchio couples them: one coordinate per leader
        full = pin.buildModelFromXML(urdf, mimic=True)
        _links_keep_their_names(full)
    locked = [j for j in range(1, full.njoints) if full.names[j] not in chain]
    model = pin.buildReducedModel(full, locked, pin.neutral(full)) if locked else full
    if model.nv == 0:
        raise RobotModelError("robot.tool_frame", f"no joint moves frame {quoted(tool_frame)}")
    unlimit(model, continuous)
    for mimic in coupled:
        _limit_leader(model, mimic)
    return model


JOINT_FRAME_SUFFIX = " (joint)"
"""Appended to the name of a joint's frame that a link's frame also has."""


def _links_keep_their_names(model: pin.Model) -> None:
    """Rename each joint's frame that has a link's name to ``name (joint)``, in place.

    A URDF may name a joint as a link (its child, or another): pinocchio then has two frames of
    that name, and looking it up raised "Several frames match the filter" (a 500). A frame a
    request names (``base_frame``, ``tool_frame``) is the link's, as REP 199 names them; the
    joint's frame stays reachable by its new name, which the frames listed in messages show.
    """
    links = {frame.name for frame in model.frames if frame.type == pin.FrameType.BODY}
    for index, frame in enumerate(model.frames):
        if frame.type != pin.FrameType.BODY and frame.name in links:
            frame.name += JOINT_FRAME_SUFFIX
            model.frames[index] = frame


def _limit_leader(model: pin.Model, mimic: Mimic) -> None:
    """Narrow the leader's limits in ``model`` by the mimic joint's own, through the coupling.

    q_mimic = m q + o within [lower, upper] holds q within [(lower - o) / m, (upper - o) / m]
    (ends swapped for m < 0), and |qdot_mimic| = |m| |qdot| <= velocity holds |qdot| <=
    velocity / |m|: the leader's limits are the tighter of its own and these, so every limit
    (the DTF's, the position checks) counts the mimic joint.
    """
    index = model.joints[model.getJointId(mimic.leader)].idx_q
    m, o = mimic.multiplier, mimic.offset
    if mimic.lower is not None and mimic.upper is not None:
        ends = sorted(((mimic.lower - o) / m, (mimic.upper - o) / m))
        model.lowerPositionLimit[index] = max(model.lowerPositionLimit[index], ends[0])
        model.upperPositionLimit[index] = min(model.upperPositionLimit[index], ends[1])
    if mimic.velocity is not None and mimic.velocity > 0.0:
        speed = min(model.velocityLimit[index], mimic.velocity / abs(m))
        model.velocityLimit[index] = speed


def chain_mimics(urdf: str, model: pin.Model) -> tuple[Mimic, ...]:
    """The mimic joints of ``model`` (read by :func:`chain_from_urdf` from ``urdf``), in order."""
    mimics = mimic_joints(urdf)
    return tuple(
        mimics[model.names[j]]
        for j in range(1, model.njoints)
        if model.joints[j].shortname() == "JointModelMimic" and model.names[j] in mimics
    )


def check_mimic_speed_limits(
    qdot_max: np.ndarray, joint_names: Sequence[str], mimics: Sequence[Mimic]
) -> None:
    """Refuse speed limits that would let a mimic joint pass its own (a request's limits).

    A request gives one speed limit per coordinate: a mimic joint has no entry, its speed is
    |m| times its leader's. A leader's limit above velocity / |m| would drive the mimic joint
    past its own URDF limit; neither clipping it silently nor dropping the mimic's limit is
    right, so it is refused, naming both joints and the largest value accepted (exact: that
    value itself passes).

    Args:
        qdot_max: shape (n,), rad/s (m/s), the checked limits, one per coordinate.
        joint_names: the n coordinates' joint names (the leaders among them).
        mimics: the chain's mimic joints, each with its own limits (:func:`chain_mimics`).

    Raises:
        InvalidInputError: on ``robot.joint_velocity_limits``, naming the leader, the mimic
            joint, the coupling and the bound.
    """
    for mimic in mimics:
        if mimic.velocity is None or mimic.velocity <= 0.0 or mimic.leader not in joint_names:
            continue  # no usable limit of its own: the leader's bounds it
        k = list(joint_names).index(mimic.leader)
        bound = mimic.velocity / abs(mimic.multiplier)
        if qdot_max[k] > bound:
            raise InvalidInputError(
                "robot.joint_velocity_limits",
                f"joint {k} ({quoted(mimic.leader)}) limit {float(qdot_max[k]):.6g} would let "
                f"joint {quoted(mimic.joint)}, which mimics it (q = {mimic.multiplier:g} "
                f"q_leader + {mimic.offset:g}), move at {abs(mimic.multiplier) * qdot_max[k]:.6g}"
                f", past its own URDF velocity limit {mimic.velocity:g}; the limits are one per "
                f"coordinate and a mimic joint has none: give {quoted(mimic.leader)} at most "
                f"{bound!r} (its limit over |multiplier|), or raise the mimic joint's limit in "
                "the URDF",
            )
