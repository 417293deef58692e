"""Published collision geometry of the arms that ship without a URDF (cell.md section 2).

The UR5e and UR10e: MuJoCo Menagerie's collision model (google-deepmind/mujoco_menagerie,
``universal_robots_ur5e/ur5e.xml`` and ``universal_robots_ur10e/ur10e.xml``, BSD-3-Clause: the
geoms of class ``collision``, a capsule or two a link around its joint housing and its tube, and
a cylinder at the flange), given below as numbers in Menagerie's body frames, with the bodies'
positions, orientations and joint axes from the same files.

Why not capsules along the DH segments (what this service did before, with Menagerie's radii):
the UR DH model folds the arm's sideways offsets (UR5e: shoulder 0.138 m, elbow -0.131 m,
wrist 0.127 m) into d4, so its upper-arm segment runs 0.138 m beside the real upper arm. The
cell audit (stop 53): a sphere 2 mm into Menagerie's upper arm was 'clear by 136 mm'; and the
elbow's segment capsule reached into wrist 2's where Menagerie's model is clear by 21 to 45 mm,
refusing 10 of 18 map cells for a self-collision the arm does not have.

Placed on the service's model (:func:`published_geometry`): Menagerie's chain at the zero
configuration gives each body's frame; turned about z so that its joint axes are the model's
(a quarter turn), each body's frame is a constant transform in the model's joint frame
(orientation to 1e-15 rad; positions 1.9 mm apart at most over random configurations: the two
models' lengths differ by up to 0.7 mm each, Menagerie rounding to the millimetre). The base
has no collision geometry in Menagerie and gets none here: the shoulder's capsule reaches down
to 3 mm above the mounting face (UR5e), over the base's height. (A base capsule of the same
radius on the same axis also tied with it, so which of the two a contact named was down to
rounding.)
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from solver.core.kinematics import revolute_axis
from solver.core.robots import Robot

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]  # w, x, y, z as MuJoCo writes it
_NO_TURN: Quaternion = (1.0, 0.0, 0.0, 0.0)
_QUARTER_Y: Quaternion = (1.0, 0.0, 1.0, 0.0)  # a quarter turn about y
_QUARTER_X: Quaternion = (1.0, 1.0, 0.0, 0.0)  # a quarter turn about x: a part along y
_Y: Vector = (0.0, 1.0, 0.0)
_Z: Vector = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Part:
    """A collision geom: a capsule or cylinder along its frame's z, in its body's frame.

    Attributes:
        shape: ``capsule`` or ``cylinder``.
        radius: m.
        half_length: m, of the segment (a capsule) or the cylinder, as MuJoCo's ``size``.
        position: m, the geom's centre.
        orientation: the geom's frame.
    """

    shape: str
    radius: float
    half_length: float
    position: Vector = (0.0, 0.0, 0.0)
    orientation: Quaternion = _NO_TURN


@dataclass(frozen=True)
class Body:
    """A moving body of the chain: its frame in its parent's, its joint axis, its geoms."""

    position: Vector
    orientation: Quaternion
    axis: Vector
    parts: tuple[Part, ...]


@dataclass(frozen=True)
class PublishedArm:
    """An arm's collision model as published: the base body's orientation, then its 6 bodies."""

    source: str
    base_orientation: Quaternion
    bodies: tuple[Body, ...]


def _capsule(radius: float, half: float, at: Vector, turn: Quaternion = _NO_TURN) -> Part:
    return Part("capsule", radius, half, at, turn)


PUBLISHED: dict[str, PublishedArm] = {
    "ur5e": PublishedArm(
        "MuJoCo Menagerie, universal_robots_ur5e/ur5e.xml",
        (1.0, 0.0, 0.0, 1.0),
        (
            Body((0, 0, 0.163), _NO_TURN, _Z, (_capsule(0.06, 0.06, (0, 0, -0.04)),)),
            Body(
                (0, 0.138, 0),
                _QUARTER_Y,
                _Y,
                (
                    _capsule(0.06, 0.06, (0, -0.04, 0), _QUARTER_X),
                    _capsule(0.05, 0.2, (0, 0, 0.2)),
                ),
            ),
            Body(
                (0, -0.131, 0.425),
                _NO_TURN,
                _Y,
                (
                    _capsule(0.055, 0.06, (0, 0.08, 0), _QUARTER_X),
                    _capsule(0.038, 0.19, (0, 0, 0.2)),
                ),
            ),
            Body(
                (0, 0, 0.392),
                _QUARTER_Y,
                _Y,
                (_capsule(0.04, 0.07, (0, 0.05, 0), _QUARTER_X),),
            ),
            Body(
                (0, 0.127, 0),
                _NO_TURN,
                _Z,
                (
                    _capsule(0.04, 0.06, (0, 0, 0.04)),
                    _capsule(0.04, 0.04, (0, 0.02, 0.1), _QUARTER_X),
                ),
            ),
            Body(
                (0, 0, 0.1),
                _NO_TURN,
                _Y,
                (Part("cylinder", 0.04, 0.02, (0, 0.08, 0), _QUARTER_X),),
            ),
        ),
    ),
    "ur10e": PublishedArm(
        "MuJoCo Menagerie, universal_robots_ur10e/ur10e.xml",
        (1.0, 0.0, 0.0, 1.0),
        (
            Body((0, 0, 0.181), _NO_TURN, _Z, (_capsule(0.078, 0.08, (0, 0, -0.05)),)),
            Body(
                (0, 0.176, 0),
                _QUARTER_Y,
                _Y,
                (
                    _capsule(0.078, 0.08, (0, -0.05, 0), _QUARTER_X),
                    _capsule(0.06, 0.3, (0, 0, 0.3)),
                ),
            ),
            Body(
                (0, -0.137, 0.613),
                _NO_TURN,
                _Y,
                (
                    _capsule(0.058, 0.065, (0, 0.08, 0), _QUARTER_X),
                    _capsule(0.043, 0.28, (0, 0, 0.29)),
                ),
            ),
            Body(
                (0, 0, 0.571),
                _QUARTER_Y,
                _Y,
                (_capsule(0.05, 0.07, (0, 0.06, 0), _QUARTER_X),),
            ),
            Body(
                (0, 0.135, 0),
                _NO_TURN,
                _Z,
                (
                    _capsule(0.046, 0.065, (0, 0, 0.05)),
                    _capsule(0.046, 0.043, (0, 0.028, 0.12), _QUARTER_X),
                ),
            ),
            Body(
                (0, 0, 0.12),
                _NO_TURN,
                _Y,
                (Part("cylinder", 0.046, 0.02, (0, 0.097, 0), _QUARTER_X),),
            ),
        ),
    ),
}
"""The published collision models, by the catalogue's name."""

FIT_TOLERANCE = 0.005
"""m: the most a published body's frame may sit from its place on the model (checked)."""


def _rotation(quaternion: Quaternion) -> np.ndarray:
    """The rotation of a (w, x, y, z) quaternion, normalised as MuJoCo normalises it."""
    w, x, y, z = np.asarray(quaternion, dtype=float) / np.linalg.norm(quaternion)
    rotation: np.ndarray = pin.Quaternion(w, x, y, z).toRotationMatrix()
    return rotation


def _frame(position: Vector, orientation: Quaternion) -> pin.SE3:
    return pin.SE3(_rotation(orientation), np.asarray(position, dtype=float))


def body_frames(arm: PublishedArm, q: np.ndarray) -> list[pin.SE3]:
    """Each body's frame in the published model's world at joint angles ``q`` (rad)."""
    frame = _frame((0.0, 0.0, 0.0), arm.base_orientation)
    frames = []
    for body, angle in zip(arm.bodies, q, strict=True):
        turn = pin.SE3(pin.exp3(np.asarray(body.axis, dtype=float) * angle), np.zeros(3))
        frame = frame * _frame(body.position, body.orientation) * turn
        frames.append(frame)
    return frames


def _world_to_model(arm: PublishedArm, model: pin.Model, joints: list[pin.SE3]) -> pin.SE3:
    """The turn about z that takes the published world's joint-2 axis to the model's."""
    published = body_frames(arm, np.zeros(len(arm.bodies)))[1]
    theirs = published.rotation @ np.asarray(arm.bodies[1].axis, dtype=float)
    axis = revolute_axis(model, 2)
    if axis is None:
        return pin.SE3.Identity()  # not the published arm: published_geometry's check refuses
    ours = joints[1].rotation @ axis
    angle = np.arctan2(ours[1], ours[0]) - np.arctan2(theirs[1], theirs[0])
    return pin.SE3(pin.exp3(np.array([0.0, 0.0, angle])), np.zeros(3))


def published_geometry(robot: Robot) -> pin.GeometryModel | None:
    """The arm's published collision geometry on ``robot.model``, or None where none is known.

    None also where the model's joints are not where the published bodies are (to
    :data:`FIT_TOLERANCE` at the zero configuration and at three others): the capsules would be
    somewhere else.
    """
    arm = PUBLISHED.get(robot.name)
    model = robot.model
    if arm is None or model.njoints != len(arm.bodies) + 1:
        return None
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    joints = [data.oMi[j].copy() for j in range(1, model.njoints)]
    to_model = _world_to_model(arm, model, joints)
    bodies = body_frames(arm, np.zeros(len(arm.bodies)))
    offsets = [joint.actInv(to_model * body) for joint, body in zip(joints, bodies, strict=True)]
    for q in (np.full(6, 0.7), np.array([1.0, -2.0, 1.5, -0.5, 2.5, -1.0]), np.full(6, -2.2)):
        pin.forwardKinematics(model, data, q)
        for j, (offset, body) in enumerate(zip(offsets, body_frames(arm, q), strict=True)):
            apart = (data.oMi[j + 1] * offset).actInv(to_model * body)
            turned = np.linalg.norm(pin.log3(apart.rotation))
            if np.linalg.norm(apart.translation) > FIT_TOLERANCE or turned > 1e-9:
                return None
    geometry = pin.GeometryModel()
    for j, (body, offset) in enumerate(zip(arm.bodies, offsets, strict=True)):
        for k, part in enumerate(body.parts):
            shape = (
                coal.Capsule(part.radius, 2.0 * part.half_length)
                if part.shape == "capsule"
                else coal.Cylinder(part.radius, 2.0 * part.half_length)
            )
            placement = offset * _frame(part.position, part.orientation)
            name = f"{model.names[j + 1]}_{part.shape}_{k}"
            geometry.addGeometryObject(pin.GeometryObject(name, j + 1, placement, shape))
    return geometry
