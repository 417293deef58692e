"""UR arms: their standard DH parameters, datasheet joint speeds, and a pinocchio model from DH.

All UR arms share alpha = [pi/2, 0, 0, pi/2, -pi/2, 0] and a1 = a4 = a5 = a6 = d2 = d3 = 0, so
six lengths describe each (spec section 8). No URDF ships for the e-series, so their pinocchio
models are built from these; the CB-series values are the lengths of the example-robot-data
URDFs (tests check the URDF chains against them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

UR_JOINT_NAMES = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)


@dataclass(frozen=True)
class UrDh:
    """Standard DH parameters of a UR arm (metres).

    alpha = [pi/2, 0, 0, pi/2, -pi/2, 0] and a1 = a4 = a5 = a6 = d2 = d3 = 0 for every UR arm,
    so six lengths describe the whole chain.
    """

    d1: float
    a2: float
    a3: float
    d4: float
    d5: float
    d6: float

    @property
    def a(self) -> tuple[float, ...]:
        """Link lengths a_1..a_6 (m)."""
        return (0.0, self.a2, self.a3, 0.0, 0.0, 0.0)

    @property
    def d(self) -> tuple[float, ...]:
        """Link offsets d_1..d_6 (m)."""
        return (self.d1, 0.0, 0.0, self.d4, self.d5, self.d6)

    @property
    def alpha(self) -> tuple[float, ...]:
        """Link twists alpha_1..alpha_6 (rad)."""
        return (math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0)


# Spec section 8 for the e-series; the CB-series values are the lengths of the
# example-robot-data URDFs (tests check the URDF chain against these to 1e-12).
UR_DH: dict[str, UrDh] = {
    "ur3": UrDh(0.1519, -0.24365, -0.21325, 0.11235, 0.08535, 0.0819),
    "ur5": UrDh(0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823),
    "ur10": UrDh(0.1273, -0.612, -0.5723, 0.163941, 0.1157, 0.0922),
    "ur3e": UrDh(0.15185, -0.24355, -0.2132, 0.13105, 0.08535, 0.0921),
    "ur5e": UrDh(0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996),
    "ur10e": UrDh(0.1807, -0.6127, -0.57155, 0.17415, 0.11985, 0.11655),
    "ur16e": UrDh(0.1807, -0.4784, -0.36, 0.17415, 0.11985, 0.11655),
}

_PI = math.pi
# Datasheet joint speeds of the e-series (rad/s), spec section 8.
E_SERIES_SPEEDS: dict[str, tuple[float, ...]] = {
    "ur3e": (_PI, _PI, _PI, 2 * _PI, 2 * _PI, 2 * _PI),
    "ur5e": (_PI,) * 6,
    "ur10e": (2 * _PI / 3, 2 * _PI / 3, _PI, _PI, _PI, _PI),
    "ur16e": (2 * _PI / 3, 2 * _PI / 3, _PI, _PI, _PI, _PI),
}


def ur_model_from_dh(dh: UrDh) -> pin.Model:
    """Build a pinocchio model of a UR arm from standard DH parameters.

    Standard DH: T_{i-1,i} = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i) = Tz(d_i) Rz(q_i) Tx(a_i)
    Rx(alpha_i), so joint i sits at Tx(a_{i-1}) Rx(alpha_{i-1}) Tz(d_i) after joint i-1. The
    root frame is ``base``; ``tool0`` is frame 6 (the flange).
    """
    model = pin.Model()
    model.addFrame(pin.Frame("base", 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    parent = 0
    previous = pin.SE3.Identity()
    inertia = pin.Inertia(1.0, np.zeros(3), np.eye(3) * 1e-3)
    for i, name in enumerate(UR_JOINT_NAMES):
        placement = previous * pin.SE3(np.eye(3), np.array([0.0, 0.0, dh.d[i]]))
        parent = model.addJoint(
            parent,
            pin.JointModelRZ(),
            placement,
            name,
            np.full(1, np.inf),
            np.full(1, np.inf),
            np.full(1, -2 * math.pi),
            np.full(1, 2 * math.pi),
        )
        model.appendBodyToJoint(parent, inertia, pin.SE3.Identity())
        model.addJointFrame(parent)
        rot_x = pin.utils.rotate("x", dh.alpha[i])
        previous = pin.SE3(rot_x, np.array([dh.a[i], 0.0, 0.0]))
    model.addFrame(pin.Frame("tool0", parent, previous, pin.FrameType.OP_FRAME))
    return model
