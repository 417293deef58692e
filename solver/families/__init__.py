"""Robot kinematics families behind one seam (:mod:`solver.core.family`), and their registry.

Each family lives in its own folder with its parameters, IK, J^-1 t and catalogue entries. This
registry is the one place that names them: a new family adds its catalogue module here, and no
other solver module imports a family (the qpsolvers pattern of a backend registry).
"""

from __future__ import annotations

import dataclasses
import functools
import importlib

import numpy as np
import pinocchio as pin

from solver.core.exceptions import RobotModelError, UnknownRobotError
from solver.core.family import KinematicsFamily
from solver.core.robots import Robot, chain_from_urdf, robot_from_model
from solver.core.urdf_chain import UrdfReading, chain_mimics, readable_urdf, unlimited
from solver.core.urdf_structure import movable_joints
from solver.families.numeric.chain import SerialChain
from solver.families.numeric.family import NumericFamily
from solver.families.recognise import recognised_family

# Modules with a ``robots() -> dict[str, Robot]`` function, in catalogue order.
CATALOGUE_MODULES = (
    "solver.families.ur.catalogue",
    "solver.families.opw.catalogue",
    "solver.families.numeric.catalogue",
)
# Numeric IK solves six-dimensional poses: it needs at least six joints (robots.md section 4).
NUMERIC_MIN_DOF = 6


@functools.cache
def catalogue() -> dict[str, Robot]:
    """Every catalogue robot by name, built once (families are imported here, on first use)."""
    robots: dict[str, Robot] = {}
    for module in CATALOGUE_MODULES:
        robots.update(importlib.import_module(module).robots())
    return robots


def default_family(
    model: pin.Model, *, base_frame: str, tool_frame: str
) -> KinematicsFamily | None:
    """The family of an arm given without one: analytic where its chain is recognised, else numeric.

    A chain that is an OPW arm's gets the closed form (:mod:`solver.families.recognise`, which
    says so in the family's ``recognised``); any other serial chain numeric IK (robots.md
    section 4). ``None`` when the model has fewer than six joints or is not one serial chain
    to the tool.
    """
    if model.nv < NUMERIC_MIN_DOF:
        return None
    try:
        chain = SerialChain.from_model(model, base_frame=base_frame, tool_frame=tool_frame)
        return recognised_family(chain) or NumericFamily(
            model, base_frame=base_frame, tool_frame=tool_frame
        )
    except RobotModelError:
        return None


def closed_form_bases(urdf: str, *, tool_frame: str) -> list[str]:
    """The frames fixed to a URDF's root from which its chain to ``tool_frame`` is recognised.

    A chain read from a frame that is no turn about z of the arm's own (a frame tilted from
    it: a wall-mounted arm read from the floor's frame) is solved numerically; this names the
    base frames from which it gets the closed form (:mod:`solver.families.recognise`), to say so.

    Raises:
        RobotModelError: the URDF cannot be parsed or has no ``tool_frame``.
    """
    urdf, continuous, _ = readable_urdf(urdf, frames=(tool_frame,))
    model = chain_from_urdf(urdf, tool_frame=tool_frame, continuous=continuous)
    if model.nv != 6:  # the closed forms are six-joint arms'
        return []
    found = []
    for frame in model.frames:
        if frame.parentJoint != 0 or frame.type not in (pin.FrameType.BODY, pin.FrameType.OP_FRAME):
            continue  # a link or a frame fixed to the root, not a joint's own frame
        try:
            chain = SerialChain.from_model(model, base_frame=frame.name, tool_frame=tool_frame)
        except RobotModelError:
            continue
        if recognised_family(chain) is not None:
            found.append(frame.name)
    return found


def get_robot(name: str) -> Robot:
    """The catalogue robot ``name``.

    Raises:
        UnknownRobotError: no robot of that name.
    """
    robots = catalogue()
    if name not in robots:
        raise UnknownRobotError(name, sorted(robots))
    return robots[name]


def robot_from_urdf(
    urdf: str,
    *,
    base_frame: str,
    tool_frame: str,
    name: str = "urdf",
    qdot_max: np.ndarray | list[float] | None = None,
    family: KinematicsFamily | None = None,
) -> Robot:
    """Read a serial arm from URDF text, with its kinematics family.

    The chain is the one from the root to ``tool_frame``
    (:func:`solver.core.robots.chain_from_urdf`: other joints are locked at their neutral
    position). Links no joint names are left out of the document first, and ``continuous``
    joints read as revolute ones (no position limit where the file gives none); the robot's
    ``reading`` says so, and which joints are locked (:func:`solver.core.urdf_chain.readable_urdf`).

    Args:
        urdf: the URDF document.
        base_frame: link or frame that poses are expressed in; fixed to the root.
        tool_frame: link or frame of the tool flange.
        name: name reported for the robot.
        qdot_max: shape (n,), rad/s, joint speed limits; ``None`` takes the URDF's (which then
            must be usable).
        family: the kinematics family of the arm; ``None`` gives the numeric family to a
            chain of six joints or more (:func:`default_family`), and none to others.

    Raises:
        RobotModelError: the URDF cannot be parsed, a frame is missing, or the chain has
            joints other than 1-DOF revolute or prismatic ones.
        InvalidInputError: ``qdot_max`` is unusable, or a leader's would let its mimic joint
            pass the mimic's own limit (:func:`solver.core.urdf_chain.check_mimic_speed_limits`).
    """
    urdf, continuous, left_out = readable_urdf(urdf, frames=(base_frame, tool_frame))
    model = chain_from_urdf(urdf, tool_frame=tool_frame, continuous=continuous)
    if family is None and model.existFrame(base_frame) and model.existFrame(tool_frame):
        family = default_family(model, base_frame=base_frame, tool_frame=tool_frame)
    robot = robot_from_model(
        name,
        model,
        base_frame=base_frame,
        tool_frame=tool_frame,
        qdot_max=qdot_max,
        family=family,
        mimics=chain_mimics(urdf, model),
    )
    on_chain = [j.name for j in continuous if model.existJointName(j.name)]
    locked = [name for name in movable_joints(urdf) if not model.existJointName(name)]
    reading = UrdfReading(
        left_out, tuple(on_chain), unlimited(model, continuous), locked_joints=tuple(locked)
    )
    return dataclasses.replace(robot, urdf=urdf, reading=reading)
