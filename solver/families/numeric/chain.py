"""A serial chain read from a pinocchio model, with batched forward kinematics and Jacobians.

The numeric family needs FK and the Jacobian at many configurations at once (placements x seeds
x branches). Pinocchio computes one configuration per call, so the chain's constant parts are
read from the pinocchio model once (each joint's placement in its parent, its axis, whether it
turns or slides; the tool frame's placement; {B} in the root frame) and the product of
exponentials is evaluated here with numpy over the batch. The tests check it against pinocchio.

Layout: batch first, as numpy's matmul wants it: configurations (M, n), rotations (M, 3, 3),
positions (M, 3), Jacobians (M, 6, n), all in {B}.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from solver.core.exceptions import RobotModelError, quoted


@dataclass(frozen=True)
class SerialChain:
    """The constant geometry of a chain from {B} to the flange {F}.

    Attributes:
        joint_rotation: shape (n, 3, 3), each joint frame in its parent's at q = 0.
        joint_translation: shape (n, 3), m, its origin there.
        axis: shape (n, 3), unit axis of each joint in its own frame.
        revolute: shape (n,), True for a revolute joint, False for a prismatic one.
        base_rotation: shape (3, 3), R_B_root. base_translation: shape (3,), m.
        tool_rotation: shape (3, 3), R_n_F, the flange in the last joint's frame.
        tool_translation: shape (3,), m.
        coupling: shape (n_joints, dof), the joints' angles per unit of each coordinate, for a
            chain with mimic joints (URDF ``<mimic>``: q_j = multiplier q_leader + offset);
            None: every joint is a coordinate of its own.
        coupling_offset: shape (n_joints,), the joints' angles at q = 0 (None likewise).
    """

    joint_rotation: np.ndarray
    joint_translation: np.ndarray
    axis: np.ndarray
    revolute: np.ndarray
    base_rotation: np.ndarray
    base_translation: np.ndarray
    tool_rotation: np.ndarray
    tool_translation: np.ndarray
    coupling: np.ndarray | None = None
    coupling_offset: np.ndarray | None = None

    @property
    def dof(self) -> int:
        """Number of coordinates n (the joints less the mimic joints)."""
        return len(self.revolute) if self.coupling is None else self.coupling.shape[1]

    @property
    def q_revolute(self) -> np.ndarray:
        """Which coordinates turn a revolute joint, shape (n,)."""
        if self.coupling is None:
            return self.revolute
        return np.array([self.revolute[np.argmax(column != 0)] for column in self.coupling.T])

    def joint_angles(self, q: np.ndarray) -> np.ndarray:
        """Every joint's angle, (M, n) -> (M, n_joints): the mimic joints' from their leaders."""
        if self.coupling is None or self.coupling_offset is None:
            return q
        angles: np.ndarray = q @ self.coupling.T + self.coupling_offset
        return angles

    @classmethod
    def from_model(cls, model: pin.Model, *, base_frame: str, tool_frame: str) -> SerialChain:
        """Read the chain of ``model`` from ``base_frame`` (fixed to the root) to ``tool_frame``.

        Raises:
            RobotModelError: the joints are not one serial chain of 1-DOF joints that all move
                ``tool_frame``.
        """
        last = model.frames[model.getFrameId(tool_frame)].parentJoint
        serial = all(model.parents[j] == j - 1 for j in range(1, model.njoints))
        mimics = [j for j in range(1, model.njoints) if _is_mimic(model.joints[j])]
        coordinates = model.njoints - 1 - len(mimics)
        if not serial or last != model.njoints - 1 or model.nq != coordinates:
            raise RobotModelError(
                "robot.tool_frame",
                f"numeric IK needs one serial chain of 1-DOF joints ending at {quoted(tool_frame)}",
            )
        data = model.createData()
        q0 = pin.neutral(model)
        axes, revolute = [], []
        coupling = np.zeros((model.njoints - 1, model.nq))
        offset = np.zeros(model.njoints - 1)
        for j in range(1, model.njoints):
            joint = model.joints[j]
            if j in mimics:
                mimic = joint.extract()
                coupling[j - 1, mimic.idx_q] = mimic.scaling
                offset[j - 1] = mimic.offset
                axis, turns = _mimic_motion(model, j, mimic.idx_q, mimic.scaling)
                axes.append(axis)
                revolute.append(turns)
                continue
            coupling[j - 1, joint.idx_q] = 1.0
            # The joint's motion subspace in its own frame: [v; w] per unit joint speed.
            motion = pin.computeJointJacobian(model, data, q0, j)[:, joint.idx_v]
            turns = bool(np.linalg.norm(motion[3:]) > 0.5)
            axes.append(motion[3:] if turns else motion[:3])
            revolute.append(turns)
        placements = [model.jointPlacements[j] for j in range(1, model.njoints)]
        pin.framesForwardKinematics(model, data, q0)
        base = data.oMf[model.getFrameId(base_frame)].inverse()
        tool = model.frames[model.getFrameId(tool_frame)].placement
        return cls(
            joint_rotation=np.array([p.rotation for p in placements]),
            joint_translation=np.array([p.translation for p in placements]),
            axis=np.array(axes),
            revolute=np.array(revolute),
            base_rotation=base.rotation.copy(),
            base_translation=base.translation.copy(),
            tool_rotation=tool.rotation.copy(),
            tool_translation=tool.translation.copy(),
            coupling=coupling if mimics else None,
            coupling_offset=offset if mimics else None,
        )

    def packed(self) -> tuple[np.ndarray, ...]:
        """The geometry as the compiled chain takes it (:mod:`~.chain_kernel`, :mod:`~.ik_kernel`).

        Each joint frame is turned by A_j (A_j z = its axis), so that every joint turns about
        its own z and a joint's rotation costs two columns, not a 3 x 3 product: joint
        rotations M_j = A_{j-1}^T R_j A_j (n, 3, 3), translations A_{j-1}^T t_j (n, 3), the
        axes (n, 3) as given, revolute (n,) bool, the base rotation (3, 3) and translation (3,),
        the tool's A_n^T R_n_F (3, 3) and A_n^T t_n_F (3,). An axis along z gives A = I and
        an axis along x or y a permutation, so most chains are taken exactly.

        Raises:
            RobotModelError: the chain has mimic joints (the compiled chain has no coupling).
        """
        if self.coupling is not None:
            raise RobotModelError("robot.urdf", "the compiled chain has no mimic joints")
        aligned = [_aligned_to_z(axis) for axis in self.axis]
        before = [np.eye(3), *aligned[:-1]]
        rotation = [
            b.T @ r @ a for b, r, a in zip(before, self.joint_rotation, aligned, strict=True)
        ]
        translation = [b.T @ t for b, t in zip(before, self.joint_translation, strict=True)]
        return tuple(
            np.ascontiguousarray(a, dtype=bool if a is self.revolute else float)
            for a in (
                np.array(rotation),
                np.array(translation),
                self.axis,
                self.revolute,
                self.base_rotation,
                self.base_translation,
                aligned[-1].T @ self.tool_rotation,
                aligned[-1].T @ self.tool_translation,
            )
        )

    def frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Every joint frame and the flange in {B}.

        Args:
            q: shape (M, n), rad (m for prismatic joints).

        Returns:
            joint axes (M, n_joints, 3) and origins (M, n_joints, 3, m) in {B} (every joint,
            the mimic joints too); the flange's rotation
            (M, 3, 3) and position (M, 3, m) in {B}.
        """
        m, n_joints = len(q), len(self.revolute)
        q = self.joint_angles(q)
        rotation = np.broadcast_to(self.base_rotation, (m, 3, 3))
        position = np.broadcast_to(self.base_translation, (m, 3))
        axes = np.empty((m, n_joints, 3))
        origins = np.empty((m, n_joints, 3))
        cos, sin = np.cos(q), np.sin(q)
        for j in range(n_joints):
            position = position + _times(rotation, self.joint_translation[j])
            rotation = _times(rotation, self.joint_rotation[j])
            axis = self.axis[j]
            axes[:, j] = _times(rotation, axis)
            origins[:, j] = position
            if self.revolute[j]:  # Rodrigues: R exp([a] q) = c R + s R [a] + (1 - c) (R a) a^T
                c, s = cos[:, j, None, None], sin[:, j, None, None]
                rotation = (
                    c * rotation
                    + s * _times(rotation, _skew(axis))
                    + (1.0 - c) * axes[:, j, :, None] * axis
                )
            else:
                position = position + axes[:, j] * q[:, j, None]
        flange_position = position + _times(rotation, self.tool_translation)
        return axes, origins, _times(rotation, self.tool_rotation), flange_position

    def forward(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The flange pose in {B}: rotation (M, 3, 3) and position (M, 3, m), for q (M, n)."""
        _, _, rotation, position = self.frames(q)
        return rotation, position

    def jacobian(
        self, q: np.ndarray, point: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The geometric Jacobian at a point, {B} axes (pinocchio LOCAL_WORLD_ALIGNED).

        Args:
            q: shape (M, n), rad.
            point: shape (M, 3) or (3,), m in {B}; ``None`` is the flange origin.

        Returns:
            jacobian (M, 6, n), linear rows first; the flange's rotation (M, 3, 3) and
            position (M, 3, m) in {B}.
        """
        axes, origins, rotation, position = self.frames(q)
        at = position if point is None else np.broadcast_to(point, position.shape)
        # Both halves are set below; np.zeros would release the GIL (see ik.COMPACT_MIN_ROWS).
        jacobian = np.empty((len(q), 6, len(self.revolute)))
        turning = np.cross(axes, at[:, None, :] - origins)  # (M, n, 3)
        jacobian[:, :3] = np.where(self.revolute[:, None], turning, axes).transpose(0, 2, 1)
        jacobian[:, 3:] = np.where(self.revolute[:, None], axes, 0.0).transpose(0, 2, 1)
        if self.coupling is not None:  # d(pose)/dq = sum over joints of J_j dq_j/dq
            jacobian = jacobian @ self.coupling
        return jacobian, rotation, position


def _is_mimic(joint: pin.JointModel) -> bool:
    """Whether a pinocchio joint is a mimic joint (read with ``mimic=True``)."""
    return bool(joint.shortname() == "JointModelMimic")


def _mimic_motion(
    model: pin.Model, j: int, leader_q: int, scaling: float
) -> tuple[np.ndarray, bool]:
    """The axis of mimic joint ``j`` in its own frame, and whether it turns.

    pinocchio keeps the mimicked joint's type out of reach; its motion is read from the frames
    instead: turning the leader by delta moves joint j's frame, relative to its placement in
    its parent, by scaling * delta about (or along) its axis.
    """
    data = model.createData()
    relative = []
    for delta in (0.0, 0.25):
        q = pin.neutral(model)
        q[leader_q] += delta
        pin.forwardKinematics(model, data, q)
        fixed = data.oMi[model.parents[j]] * model.jointPlacements[j]
        relative.append(fixed.inverse() * data.oMi[j])
    step = relative[1] * relative[0].inverse()
    turn = pin.log3(step.rotation)
    if np.linalg.norm(turn) > 1e-9:
        return turn / np.linalg.norm(turn) * np.sign(scaling), True
    slide = relative[1].translation - relative[0].translation
    return slide / np.linalg.norm(slide) * np.sign(scaling), False


def _aligned_to_z(axis: np.ndarray) -> np.ndarray:
    """A rotation A (3, 3) with A z = ``axis``: the identity for z, a permutation for x or y."""
    z = axis / np.linalg.norm(axis)
    for candidate in np.eye(3):
        # Exactly along a coordinate axis: a signed permutation. Not |candidate . z| == 1,
        # which rounds to true for a tilt under 1.5e-8 rad and paired that tilted z with an
        # x square to the coordinate axis, a frame skewed by the tilt (answers 7e-9 m off; the
        # robots audit of stop 55).
        if np.array_equal(np.abs(z), candidate):
            x = np.roll(candidate, 1) if candidate[2] == 0.0 else np.array([1.0, 0.0, 0.0])
            x = x * np.sign(candidate @ z) if candidate[2] == 0.0 else x * np.sign(z[2])
            break
    else:
        least = np.eye(3)[np.argmin(np.abs(z))]
        x = np.cross(least, z)
        x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _skew(axis: np.ndarray) -> np.ndarray:
    """[a], shape (3, 3): [a] v = a x v."""
    return np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])


def _times(rotation: np.ndarray, constant: np.ndarray) -> np.ndarray:
    """(M, 3, 3) @ (3, 3) or (M, 3, 3) @ (3,) as one 2-D product (BLAS, not M small ones)."""
    product: np.ndarray = (rotation.reshape(-1, 3) @ constant).reshape(
        rotation.shape[:-1] + constant.shape[1:]
    )
    return product
