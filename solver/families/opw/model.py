"""A pinocchio model of an OPW arm built from its parameters (robots.md section 3).

The chain follows the paper's frames, with each joint's zero and direction set to the maker's
(the joint axis times its sign correction, the joint placement turned by minus its offset), so
pinocchio's forward kinematics of the maker's q is the paper's forward formula (tests check it
against :func:`solver.families.opw.ik.forward_kinematics` and py-opw-kinematics to 1e-12).
Frames: ``base_link`` {B} at the root, ``tool0`` the flange: c4 along joint 6's axis from the
wrist centre, with the axes of the paper's end frame (R = Rz(t1) Ry(t2 + t3) Rz(t4) Ry(t5)
Rz(t6), so at the paper's zero, arm straight up, tool0's axes are {B}'s), which is what
opw_kinematics' ``forward`` returns and what the makers' URDFs call tool0.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from solver.families.opw.parameters import OpwParameters

_X, _Y, _Z = np.eye(3)


def _turn(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` about a unit coordinate ``axis``."""
    return np.asarray(pin.exp3(axis * angle))


def opw_model(
    parameters: OpwParameters,
    *,
    joint_names: tuple[str, ...],
    q_lower: np.ndarray,
    q_upper: np.ndarray,
    qdot_max: np.ndarray,
) -> pin.Model:
    """The pinocchio model of the chain base_link -> tool0.

    Args:
        parameters: the geometry.
        joint_names: the six joint names.
        q_lower: shape (6,), rad, lower position limits (maker's convention).
        q_upper: shape (6,), rad, upper position limits.
        qdot_max: shape (6,), rad/s, speed limits.
    """
    p = parameters
    # (translation from the previous joint, paper axis) of each joint, paper frames.
    joints = (
        (np.zeros(3), _Z),
        (np.array([p.a1, p.b, p.c1]), _Y),
        (np.array([0.0, 0.0, p.c2]), _Y),
        (np.array([p.a2, 0.0, p.c3]), _Z),
        (np.zeros(3), _Y),
        (np.zeros(3), _Z),
    )
    model = pin.Model()
    model.name = "opw"
    model.addFrame(pin.Frame("base_link", 0, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    parent = 0
    for i, (translation, axis) in enumerate(joints):
        placement = pin.SE3(_turn(axis, -p.offsets[i]), translation)
        joint = pin.JointModelRevoluteUnaligned(axis * p.sign_corrections[i])
        parent = model.addJoint(
            parent,
            joint,
            placement,
            joint_names[i],
            np.array([1e3]),
            np.array([qdot_max[i]]),
            np.array([q_lower[i]]),
            np.array([q_upper[i]]),
        )
        model.appendBodyToJoint(parent, pin.Inertia.Identity(), pin.SE3.Identity())
    flange = pin.SE3(np.eye(3), np.array([0.0, 0.0, p.c4]))
    model.addFrame(pin.Frame("tool0", parent, 0, flange, pin.FrameType.OP_FRAME))
    return model
