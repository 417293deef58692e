"""Analytic structure recognised in a URDF chain: an OPW or UR arm as a URDF gets its closed form.

robots.md sections 2 to 4. Numeric IK from seeds cannot promise every branch; an arm whose
chain is an OPW arm's (most KUKA, ABB and FANUC arms, whose URDFs users bring) or a UR arm's
has all eight in closed form. The chain proposes the parameters (OPW: its joint lines at q = 0,
:func:`solver.families.opw.fit.fit_opw`; UR: its flange positions, linear in the six lengths,
:func:`solver.families.ur.fit.fit_ur`); they are kept only when the family's forward formula
equals the chain's forward kinematics at ``CHECK_CONFIGURATIONS`` random configurations to
``FIT_ATOL``. The family then says so (:attr:`KinematicsFamily.recognised`), and answers name it.
A UR arm is also recognised in a turn of {B} about z and a shift (ROS's ``base_link`` is half a
turn from the DH frame ``base``), an OPW arm in a shift of {B} (a turn about z is its joint 1's
offset): the family then solves in its own frame (:attr:`KinematicsFamily.base_turn`), which
its answers name. Where joint 1 is not upright in {B} (an arm on a wall or a ceiling, read from
its cell's frame), the chain is read in {B} tilted so that joint 1's axis is z
(:func:`first_axis_tilt`) and recognised there; the compiled kernels take that frame in the
family's kernel parameters (:meth:`solver.families.base.ClosedFormFamily.map_kernel`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pinocchio as pin

from solver.core.family import KinematicsFamily
from solver.core.spatial import BaseTurn, FlangeOffset, rotation_vectors
from solver.families.numeric.chain import SerialChain
from solver.families.opw.family import OpwFamily
from solver.families.opw.fit import fit_opw
from solver.families.opw.ik import forward_kinematics
from solver.families.ur.dh import UrDh
from solver.families.ur.family import UrFamily
from solver.families.ur.fit import fit_ur, fit_ur_flange
from solver.families.ur.ik import forward_kinematics_dh

# Forward kinematics of the fitted parameters must equal the chain's to this (m, and rad as
# rotation-matrix entries) at every check configuration: the tolerance FK(IK(T)) = T is held to.
FIT_ATOL = 1e-9
CHECK_CONFIGURATIONS = 32
CHECK_SEED = 27
_NO_LENGTHS = UrDh(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def recognised_opw(chain: SerialChain, tilt: np.ndarray | None = None) -> OpwFamily | None:
    """The OPW family of ``chain``, when the chain is an OPW arm's (forward kinematics equal).

    Args:
        chain: a serial chain from {B} to the flange.
        tilt: R_B_T, where the chain is read in {B} tilted by it (:func:`first_axis_tilt`).

    Returns:
        An :class:`OpwFamily` whose ``recognised`` says where its parameters came from, or None.
    """
    if chain.dof != 6 or not chain.revolute.all():
        return None
    chain = chain if tilt is None else tilted_chain(chain, tilt)
    axes, origins, rotation, position = chain.frames(np.zeros((1, 6)))
    turn = opw_base_shift(axes[0, 0], origins[0, 0])
    fitted = fit_opw(
        axes[0], turn.points_in(origins[0].T).T, rotation[0], turn.points_in(position[0])
    )
    if fitted is None:
        return None
    parameters, offset = fitted
    q = np.random.default_rng(CHECK_SEED).uniform(-math.pi, math.pi, (CHECK_CONFIGURATIONS, 6))
    chain_rotation, chain_position = _in_turn(turn, *chain.forward(q))
    paper = forward_kinematics(parameters, q)
    if offset is not None:  # the chain's flange on the OPW flange
        paper = paper @ offset.matrix
    error = max(
        float(np.abs(chain_rotation - paper[:, :3, :3]).max()),
        float(np.abs(chain_position - paper[:, :3, 3]).max()),
    )
    if error > FIT_ATOL:
        return None
    family = OpwFamily(parameters)
    turn = turn if tilt is None else turn.tilted(tilt)
    family.base_turn = None if turn.is_identity else turn
    family.flange_offset = offset
    p = parameters
    where = "" if turn.is_identity else f" whose base frame is {_said(turn)}"
    if offset is not None:
        where += f"{' and' if where else ''} whose tool frame is {_said_flange(offset)}"
    family.recognised = (
        f"the URDF chain is an OPW arm{where} (forward kinematics equal to "
        f"{FIT_ATOL:g} at {CHECK_CONFIGURATIONS} random configurations): closed-form IK with "
        + _lengths(a1=p.a1, a2=p.a2, b=p.b, c1=p.c1, c2=p.c2, c3=p.c3, c4=p.c4)
    )
    return family


def opw_base_shift(axis: np.ndarray, point: np.ndarray) -> BaseTurn:
    """The shift of {B} to an OPW arm's base frame, from joint 1's axis at q = 0.

    The OPW base frame's origin is on joint 1's axis (its height is the length c1's; a turn
    about z is joint 1's offset's): where the axis is upright, the shift is its x and y (the
    identity within 1e-12); elsewhere none (the fit then finds no OPW arm).

    Args:
        axis: shape (3,), joint 1's unit axis in {B}.
        point: shape (3,), m, a point of it.
    """
    if abs(abs(float(axis[2])) - 1.0) > FIT_ATOL:
        return BaseTurn.read(0.0, 0.0, 0.0)
    return BaseTurn.read(0.0, point[0], point[1])


def recognised_ur(chain: SerialChain, tilt: np.ndarray | None = None) -> UrFamily | None:
    """The UR family of ``chain``, when the chain is a UR arm's in {B} or in a turn of {B}.

    The DH base frame may be {B} turned about z and moved (ROS's ``base_link`` is half a turn
    from it: :func:`ur_base_turn`); the family then solves in that frame (its ``base_turn``).
    The chain's flange may be the DH flange turned or moved on the last link (ROS's
    ``ee_link``, ``wrist_3_link``): the turn is then read off joint 2's axis
    (:func:`ur_axis_turn`) and the family solves for the DH flange (its ``flange_offset``).

    Args:
        chain: a serial chain from {B} to the flange.
        tilt: R_B_T, where the chain is read in {B} tilted by it (:func:`first_axis_tilt`).

    Returns:
        A :class:`UrFamily` whose ``recognised`` says where its lengths came from, or None.
    """
    if chain.dof != 6 or not chain.revolute.all():
        return None
    chain = chain if tilt is None else tilted_chain(chain, tilt)
    turn = ur_base_turn(chain)
    family = None if turn is None else _ur_fitted(chain, turn, on_flange=True, tilt=tilt)
    if family is None and (turn := ur_axis_turn(chain)) is not None:
        family = _ur_fitted(chain, turn, on_flange=False, tilt=tilt)
    return family


def _ur_fitted(
    chain: SerialChain, turn: BaseTurn, *, on_flange: bool, tilt: np.ndarray | None
) -> UrFamily | None:
    """The UR family of ``chain`` in ``turn``, its flange the DH flange or fixed on it.

    ``tilt``: the chain is read in {B} tilted by it (:func:`tilted_chain`); the family's turn
    is then that too.
    """
    q = np.random.default_rng(CHECK_SEED).uniform(-math.pi, math.pi, (CHECK_CONFIGURATIONS, 6))
    rotation, position = _in_turn(turn, *chain.forward(q))
    offset = None
    if on_flange:
        lengths = fit_ur(q, rotation, position)
    elif (fitted := fit_ur_flange(q, rotation, position)) is not None:
        lengths, offset = fitted[0], FlangeOffset.read(fitted[1], fitted[2])
    else:
        lengths = None
    if lengths is None:
        return None
    check = np.random.default_rng(CHECK_SEED + 1).uniform(-math.pi, math.pi, (16, 6))
    chain_rotation, chain_position = _in_turn(turn, *chain.forward(check))
    dh = forward_kinematics_dh(lengths, check)
    if offset is not None:  # the chain's flange on the DH flange
        dh = dh @ offset.matrix
    error = max(
        float(np.abs(chain_rotation - dh[:, :3, :3]).max()),
        float(np.abs(chain_position - dh[:, :3, 3]).max()),
    )
    if error > FIT_ATOL:
        return None
    family = UrFamily(lengths)
    turn = turn if tilt is None else turn.tilted(tilt)
    family.base_turn = None if turn.is_identity else turn
    family.flange_offset = offset
    where = "in its DH base frame" if turn.is_identity else f"whose DH base frame is {_said(turn)}"
    if offset is not None:
        where += f", whose tool frame is {_said_flange(offset, 'DH')}"
    family.recognised = (
        f"the URDF chain is a UR arm {where} (forward kinematics equal to "
        f"{FIT_ATOL:g} at random configurations): closed-form IK with "
        + _lengths(
            **{name: getattr(lengths, name) for name in ("d1", "a2", "a3", "d4", "d5", "d6")}
        )
    )
    return family


def ur_axis_turn(chain: SerialChain) -> BaseTurn | None:
    """The turn of {B} about z in which a chain may be a UR arm, from joint 2's axis.

    Where the flange is not the DH flange its orientation says nothing of the turn
    (:func:`ur_base_turn`), but joint 2's axis does: it is the DH frame's -y at q = 0
    (alpha1 = pi/2), and joint 1's axis {B}'s z. None where the chain's axes are not so.
    """
    axes, origins, _, _ = chain.frames(np.zeros((1, 6)))
    first, second = axes[0, 0], axes[0, 1]
    if abs(first[2] - 1.0) > FIT_ATOL or abs(second[2]) > FIT_ATOL:
        return None
    angle = math.remainder(math.atan2(second[1], second[0]) + math.pi / 2, 2 * math.pi)
    return BaseTurn.read(angle, origins[0, 0, 0], origins[0, 0, 1])


def ur_base_turn(chain: SerialChain) -> BaseTurn | None:
    """The turn of {B} about z in which a six-joint chain may be a UR arm.

    A UR arm's flange orientation at q = 0 does not depend on its lengths (dtf.md section 8),
    so the chain's there, against the DH formula's, gives the turn; joint 1's axis passes
    through the DH frame's origin, which gives the shift in x and y (a shift along z is the
    length d1's). Whether the chain is a UR arm in that frame is for the fit and its check.

    Returns:
        The turn (the identity within 1e-12 where {B} is the DH frame); None where the chain's
        orientation at q = 0 is no turn about z of a UR arm's (it is no UR arm in such a frame).
    """
    _, origins, rotation, _ = chain.frames(np.zeros((1, 6)))
    zero = forward_kinematics_dh(_NO_LENGTHS, np.zeros(6))[:3, :3]
    turn = rotation[0] @ zero.T
    if abs(turn[2, 2] - 1.0) > FIT_ATOL:
        return None
    return BaseTurn.read(math.atan2(turn[1, 0], turn[0, 0]), origins[0, 0, 0], origins[0, 0, 1])


def _in_turn(
    turn: BaseTurn, rotation: np.ndarray, position: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Flange rotations (M, 3, 3) and positions (M, 3) in {B}, in the turn's frame."""
    if turn.is_identity:
        return rotation, position
    turned = turn.vectors_in(rotation.transpose(1, 2, 0)).transpose(2, 0, 1)
    return turned, turn.points_in(position.T).T


def _said(turn: BaseTurn) -> str:
    """A turn in words: {B} turned by 180 deg about z and moved to (x, y, z) m, either part.

    A tilt first: {B} tilted by 90 deg about (1, 0, 0), then turned about the tilted z.
    """
    parts = []
    tilt = turn.tilt_matrix
    if tilt is not None:
        vector = rotation_vectors(tilt)
        angle = float(np.linalg.norm(vector))
        axis = vector / angle
        parts.append(
            f"tilted by {math.degrees(angle):.6g} deg about "
            "({:.6g}, {:.6g}, {:.6g}) (joint 1's axis its z)".format(*map(_nanometres, axis))
        )
    about = "the tilted z" if tilt is not None else "z"
    parts += [f"turned by {math.degrees(turn.angle):.6g} deg about {about}"] if turn.angle else []
    shift = [_nanometres(v) for v in turn.shift]  # a tilt's 2e-16 m said as 0
    if any(shift):
        parts.append("moved to ({:.6g}, {:.6g}, {:.6g}) m".format(*shift))
    return "{B} " + (" and ".join(parts) or "moved by less than a nanometre")


def _said_flange(offset: FlangeOffset, family: str = "OPW") -> str:
    """A flange offset in words: the OPW (or DH) flange moved by (x, y, z) m and turned by a deg."""
    angle = math.degrees(float(np.linalg.norm(rotation_vectors(offset.rotation))))
    moved = [_nanometres(v) for v in offset.translation]
    parts = ["moved by ({:.6g}, {:.6g}, {:.6g}) m".format(*moved)] if any(moved) else []
    parts += [f"turned by {angle:.6g} deg"] if angle else []
    return f"the {family} flange " + " and ".join(parts)


def _nanometres(value: float) -> float:
    """A length read off a chain, to the nanometre: a fit's 1e-14 m said as 0."""
    return round(float(value), 9) + 0.0


def _lengths(**lengths: float) -> str:
    """Fitted lengths in words: ``a1=0.15, a2=-0.2, ... m``, each to the nanometre."""
    return ", ".join(f"{name}={_nanometres(value):.6g}" for name, value in lengths.items()) + " m"


def recognised_family(chain: SerialChain) -> KinematicsFamily | None:
    """The analytic family of a URDF chain, where its structure is one we solve in closed form.

    A chain with mimic joints is not one (its joints are coupled).
    """
    if chain.coupling is not None:
        return None
    found = recognised_opw(chain) or recognised_ur(chain)
    if found is not None or (tilt := first_axis_tilt(chain)) is None:
        return found
    return recognised_opw(chain, tilt) or recognised_ur(chain, tilt)


def first_axis_tilt(chain: SerialChain) -> np.ndarray | None:
    """R_B_T turning {B}'s z onto joint 1's axis at q = 0, where it is not upright (else None).

    The least turn that does it (about z x axis; half a turn about x for an axis along -z);
    the turn about the new z that is left is the family's own (an OPW arm's joint 1 offset, a
    UR arm's base turn).
    """
    if not len(chain.revolute):
        return None
    axes, _, _, _ = chain.frames(np.zeros((1, chain.dof)))
    axis = axes[0, 0] / np.linalg.norm(axes[0, 0])
    if abs(float(axis[2]) - 1.0) <= FIT_ATOL:
        return None
    if abs(float(axis[2]) + 1.0) <= FIT_ATOL:  # hanging from a ceiling: half a turn about x
        return np.diag([1.0, -1.0, -1.0])
    normal = np.cross([0.0, 0.0, 1.0], axis)
    sine = float(np.linalg.norm(normal))
    return np.asarray(pin.exp3(normal / sine * math.atan2(sine, float(axis[2]))))


def tilted_chain(chain: SerialChain, tilt: np.ndarray) -> SerialChain:
    """``chain`` read in {T} = {B} turned by ``tilt`` (R_B_T): its base pose taken into {T}.

    {T}'s origin is {B}'s: the lengths along joint 1's axis (UR d1, OPW c1) are then from the
    plane through {B}'s origin normal to it.
    """
    return dataclasses.replace(
        chain,
        base_rotation=tilt.T @ chain.base_rotation,
        base_translation=tilt.T @ chain.base_translation,
    )
