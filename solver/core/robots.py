"""Robot models: a pinocchio chain with its base frame, tool point, limits and IK family.

A :class:`Robot` wraps a pinocchio model with the two frames the method needs: the base frame
{B} in which poses and twists are expressed, and the tool point {TCP} (the tool frame {F} times
an optional offset T_F_TCP), plus the kinematics family that solves its IK (robots.md section 1).
The catalogue, and the numeric family a URDF arm gets by default, are the families' registry's
(:mod:`solver.families`, a layer above); this module builds robots (their limits checked by
:mod:`solver.core.joint_limits`), and re-exports :func:`solver.core.urdf_chain.chain_from_urdf`,
which reads URDFs.
"""

from __future__ import annotations

import dataclasses
import importlib.metadata
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from solver.core.exceptions import InvalidInputError, RobotModelError, quoted
from solver.core.family import KinematicsFamily
from solver.core.joint_limits import check_acceleration_limits, check_speed_limits
from solver.core.urdf_chain import (
    UrdfReading,
    chain_from_urdf,
    check_mimic_speed_limits,
    frame_names,
)
from solver.core.urdf_structure import Mimic

_URDF_NAME = re.compile(r"<robot\b[^>]*?\bname\s*=\s*([\"'])(.*?)\1", re.S)
SHOWN_NAME_CHARACTERS = 60
"""A URDF's own name is cut to this length where it is shown (:attr:`Robot.shown_name`)."""

__all__ = [
    "Robot",
    "chain_from_urdf",
    "example_robot_data_dir",
    "frame_names",
    "robot_from_model",
]


@dataclass(frozen=True, eq=False)
class Robot:
    """A serial arm with its base frame, tool point and joint limits.

    Attributes:
        name: catalogue name, or ``"urdf"`` for a robot read from a request.
        model: pinocchio model; its frame ``tool_point_frame`` is the tool point {TCP}.
        base_frame: name of the frame {B} poses and twists are expressed in.
        tool_frame: name of the tool frame {F} (the flange for UR arms).
        joint_names: names of the n joints, in configuration order.
        q_lower: shape (n,), rad, lower joint position limits.
        q_upper: shape (n,), rad, upper joint position limits.
        qdot_max: shape (n,), rad/s, joint speed limits (all > 0).
        transform_tool_to_tcp: shape (4, 4), the tool point in the tool frame, T_F_TCP.
        transform_world_to_base: shape (4, 4), {B} in the model's root frame (fixed).
        family: the kinematics family that solves its IK and J^-1 t (robots.md section 1):
            an analytic one, or the numeric one for any other serial chain of six joints or
            more; ``None`` for a shorter chain (``/v1/dtf`` only).
        qddot_max: shape (n,), rad/s^2, joint acceleration limits (all > 0), or ``None``: no
            acceleration limits, the path index is mu_path alone (motion.md section 1).
        urdf: the URDF text the model was read from (its ``<collision>`` elements are the
            robot's geometry in a cell, cell.md section 2); ``None`` for a model built from
            kinematic parameters.
        mimics: the chain's mimic joints (URDF ``<mimic>``), whose own speed limits bound
            any speed limits given for their leaders (:func:`check_mimic_speed_limits`).
        reading: what was changed in the URDF document before it was read (links no joint
            names left out, continuous joints read as revolute ones;
            :func:`solver.core.urdf_chain.readable_urdf`); answers say so.
    """

    name: str
    model: pin.Model
    base_frame: str
    tool_frame: str
    joint_names: tuple[str, ...]
    q_lower: np.ndarray
    q_upper: np.ndarray
    qdot_max: np.ndarray
    transform_tool_to_tcp: np.ndarray
    transform_world_to_base: np.ndarray
    family: KinematicsFamily | None = None
    qddot_max: np.ndarray | None = None
    urdf: str | None = None
    mimics: tuple[Mimic, ...] = ()
    reading: UrdfReading = UrdfReading()

    @property
    def dof(self) -> int:
        """Number of joints n."""
        return len(self.joint_names)

    @property
    def shown_name(self) -> str:
        """The robot's name as answers and pictures show it: a request's URDF by its own name.

        A robot read from a request's URDF is named ``urdf`` (a name that keys nothing of the
        catalogue's, as the published capsule radii); shown, it says which arm it is:
        ``abb_irb2400 (URDF)`` from ``<robot name="abb_irb2400">`` (cut to
        SHOWN_NAME_CHARACTERS), ``URDF`` where the document names none. Any other robot
        keeps its name.
        """
        if self.name != "urdf" or self.urdf is None:
            return self.name
        match = _URDF_NAME.search(self.urdf)
        own = match.group(2).strip()[:SHOWN_NAME_CHARACTERS] if match else ""
        return f"{own} (URDF)" if own else "URDF"

    @property
    def tool_point_frame(self) -> int:
        """Pinocchio frame id of the tool point {TCP}."""
        return int(self.model.getFrameId("tool_point"))

    def with_options(
        self,
        *,
        qdot_max: np.ndarray | list[float] | None = None,
        transform_tool_to_tcp: np.ndarray | None = None,
        qddot_max: np.ndarray | list[float] | None = None,
    ) -> Robot:
        """Return a copy with other joint speed or acceleration limits and/or another tool point.

        Args:
            qdot_max: shape (n,), rad/s, each finite and > 0; ``None`` keeps the model's.
            transform_tool_to_tcp: shape (4, 4), T_F_TCP; ``None`` keeps the current one.
            qddot_max: shape (n,), rad/s^2, each finite and > 0; ``None`` keeps the current
                ones (none for a model that has none).

        Raises:
            InvalidInputError: a limit has the wrong shape, is not finite or is <= 0, or a
                speed limit would let a mimic joint pass its own.
        """
        robot = self
        if qdot_max is not None:
            limits = check_speed_limits(qdot_max, self.joint_names)
            check_mimic_speed_limits(limits, self.joint_names, self.mimics)
            robot = dataclasses.replace(robot, qdot_max=limits)
        if qddot_max is not None:
            accelerations = check_acceleration_limits(qddot_max, self.joint_names)
            robot = dataclasses.replace(robot, qddot_max=accelerations)
        if transform_tool_to_tcp is not None:
            tcp = np.asarray(transform_tool_to_tcp, dtype=float)
            model = pin.Model(robot.model)
            _set_tool_point(model, robot.tool_frame, tcp)
            robot = dataclasses.replace(robot, model=model, transform_tool_to_tcp=tcp.copy())
        return robot


def _set_tool_point(model: pin.Model, tool_frame: str, transform_tool_to_tcp: np.ndarray) -> None:
    """Add (or move) the frame ``tool_point`` = tool frame * T_F_TCP in ``model``."""
    tool = model.frames[model.getFrameId(tool_frame)]
    placement = tool.placement * pin.SE3(transform_tool_to_tcp)
    if model.existFrame("tool_point"):
        model.frames[model.getFrameId("tool_point")].placement = placement
    else:
        model.addFrame(pin.Frame("tool_point", tool.parentJoint, placement, pin.FrameType.OP_FRAME))


def robot_from_model(
    name: str,
    model: pin.Model,
    *,
    base_frame: str,
    tool_frame: str,
    qdot_max: np.ndarray | list[float] | None = None,
    family: KinematicsFamily | None,
    mimics: tuple[Mimic, ...] = (),
) -> Robot:
    """Check the frames of ``model`` and wrap it as a :class:`Robot`.

    Args:
        name: name reported for the robot.
        model: pinocchio model of the chain (1-DOF joints only).
        base_frame: frame {B}, fixed to the root.
        tool_frame: the flange frame {F}.
        qdot_max: shape (n,), rad/s; ``None`` takes the model's velocity limits.
        family: the kinematics family; ``None`` for none (``/v1/dtf`` only). The registry's
            :func:`solver.families.default_family` gives the numeric one to a serial chain of
            six joints or more.
        mimics: the model's mimic joints with their own limits (its leaders' limits in the
            model are already narrowed by them); ``qdot_max`` is checked against them.

    Raises:
        RobotModelError: a frame is missing or moves, a joint is not 1-DOF, or the model's
            speed limits are unusable and none are given.
        InvalidInputError: ``qdot_max`` is unusable or would let a mimic joint pass its own.
    """
    for field, frame in (("robot.base_frame", base_frame), ("robot.tool_frame", tool_frame)):
        if not model.existFrame(frame):
            names = frame_names(model)
            raise RobotModelError(field, f"no frame {quoted(frame)} in the model; frames: {names}")
    base = model.frames[model.getFrameId(base_frame)]
    if base.parentJoint != 0:
        raise RobotModelError(
            "robot.base_frame",
            f"frame {quoted(base_frame)} moves with joint {quoted(model.names[base.parentJoint])}; "
            "the base frame must be fixed to the root",
        )
    coordinates = [
        j
        for j in range(1, model.njoints)
        if model.joints[j].shortname() != "JointModelMimic"  # a mimic joint follows another
    ]
    several = [j for j in coordinates if model.joints[j].nq != 1 or model.joints[j].nv != 1]
    if several:
        raise RobotModelError(
            "robot.urdf",
            f"joint {quoted(model.names[several[0]])} moves in {model.joints[several[0]].nv} "
            "degrees of freedom (a planar or floating joint); only revolute and prismatic "
            "joints are supported between base and tool",
        )
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    transform_world_to_base = data.oMf[model.getFrameId(base_frame)].homogeneous.copy()
    joint_names = tuple(model.names[j] for j in coordinates)
    if qdot_max is not None:
        limits = check_speed_limits(qdot_max, joint_names)
        check_mimic_speed_limits(limits, joint_names, mimics)
    else:
        try:
            limits = check_speed_limits(model.velocityLimit, joint_names)
        except InvalidInputError as exc:
            raise RobotModelError(
                "robot.urdf", f"{exc.message}; give robot.joint_velocity_limits (rad/s)"
            ) from exc
    _set_tool_point(model, tool_frame, np.eye(4))
    robot = Robot(
        name=name,
        model=model,
        base_frame=base_frame,
        tool_frame=tool_frame,
        joint_names=joint_names,
        q_lower=model.lowerPositionLimit.copy(),
        q_upper=model.upperPositionLimit.copy(),
        qdot_max=limits,
        transform_tool_to_tcp=np.eye(4),
        transform_world_to_base=transform_world_to_base,
        family=family,
        mimics=mimics,
    )
    return robot


def example_robot_data_dir() -> Path:
    """Folder of the robot descriptions the ``example-robot-data`` wheel installs.

    The wheel ships URDFs only (its Python loader is another package, which we do not use), so
    files are found through the distribution's metadata.
    """
    dist = importlib.metadata.distribution("example-robot-data")
    return Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))
