"""Analytic structure recognised in a URDF chain: an OPW or UR arm as a URDF gets its closed form.

robots.md sections 2 to 4. Numeric IK from seeds cannot promise every branch; an arm whose
chain is an OPW arm's (most KUKA, ABB and FANUC arms, whose URDFs users bring) or a UR arm's
has all eight in closed form. The chain proposes the parameters (OPW: its joint lines at q = 0,
:func:`solver.families.opw.fit.fit_opw`; UR: its flange positions, linear in the six lengths,
:func:`solver.families.ur.fit.fit_ur`); they are kept only when the family's forward formula
equals the chain's forward kinematics at ``CHECK_CONFIGURATIONS`` random configurations to
``FIT_ATOL``. The family then says so (:attr:`KinematicsFamily.recognised`), and answers name it.
"""

from __future__ import annotations

import math

import numpy as np

from solver.core.family import KinematicsFamily
from solver.families.numeric.chain import SerialChain
from solver.families.opw.family import OpwFamily
from solver.families.opw.fit import fit_opw
from solver.families.opw.ik import forward_kinematics
from solver.families.ur.family import UrFamily
from solver.families.ur.fit import fit_ur
from solver.families.ur.ik import forward_kinematics_dh

# Forward kinematics of the fitted parameters must equal the chain's to this (m, and rad as
# rotation-matrix entries) at every check configuration: the tolerance FK(IK(T)) = T is held to.
FIT_ATOL = 1e-9
CHECK_CONFIGURATIONS = 32
CHECK_SEED = 27


def recognised_opw(chain: SerialChain) -> OpwFamily | None:
    """The OPW family of ``chain``, when the chain is an OPW arm's (forward kinematics equal).

    Args:
        chain: a serial chain from {B} to the flange.

    Returns:
        An :class:`OpwFamily` whose ``recognised`` says where its parameters came from, or None.
    """
    if chain.dof != 6 or not chain.revolute.all():
        return None
    axes, origins, rotation, position = chain.frames(np.zeros((1, 6)))
    parameters = fit_opw(axes[0], origins[0], rotation[0], position[0])
    if parameters is None:
        return None
    q = np.random.default_rng(CHECK_SEED).uniform(-math.pi, math.pi, (CHECK_CONFIGURATIONS, 6))
    chain_rotation, chain_position = chain.forward(q)
    paper = forward_kinematics(parameters, q)
    error = max(
        float(np.abs(chain_rotation - paper[:, :3, :3]).max()),
        float(np.abs(chain_position - paper[:, :3, 3]).max()),
    )
    if error > FIT_ATOL:
        return None
    family = OpwFamily(parameters)
    p = parameters
    family.recognised = (
        "the URDF chain is an OPW arm (forward kinematics equal to "
        f"{FIT_ATOL:g} at {CHECK_CONFIGURATIONS} random configurations): closed-form IK with "
        f"a1={p.a1:.6g}, a2={p.a2:.6g}, b={p.b:.6g}, c1={p.c1:.6g}, c2={p.c2:.6g}, "
        f"c3={p.c3:.6g}, c4={p.c4:.6g} m"
    )
    return family


def recognised_ur(chain: SerialChain) -> UrFamily | None:
    """The UR family of ``chain``, when the chain is a UR arm's in {B} (the DH base frame).

    Args:
        chain: a serial chain from {B} to the flange.

    Returns:
        A :class:`UrFamily` whose ``recognised`` says where its lengths came from, or None.
    """
    if chain.dof != 6 or not chain.revolute.all():
        return None
    q = np.random.default_rng(CHECK_SEED).uniform(-math.pi, math.pi, (CHECK_CONFIGURATIONS, 6))
    rotation, position = chain.forward(q)
    lengths = fit_ur(q, rotation, position)
    if lengths is None:
        return None
    check = np.random.default_rng(CHECK_SEED + 1).uniform(-math.pi, math.pi, (16, 6))
    chain_rotation, chain_position = chain.forward(check)
    dh = forward_kinematics_dh(lengths, check)
    error = max(
        float(np.abs(chain_rotation - dh[:, :3, :3]).max()),
        float(np.abs(chain_position - dh[:, :3, 3]).max()),
    )
    if error > FIT_ATOL:
        return None
    family = UrFamily(lengths)
    family.recognised = (
        "the URDF chain is a UR arm in its DH base frame (forward kinematics equal to "
        f"{FIT_ATOL:g} at random configurations): closed-form IK with d1={lengths.d1:.6g}, "
        f"a2={lengths.a2:.6g}, a3={lengths.a3:.6g}, d4={lengths.d4:.6g}, d5={lengths.d5:.6g}, "
        f"d6={lengths.d6:.6g} m"
    )
    return family


def recognised_family(chain: SerialChain) -> KinematicsFamily | None:
    """The analytic family of a URDF chain, where its structure is one we solve in closed form.

    A chain with mimic joints is not one (its joints are coupled).
    """
    if chain.coupling is not None:
        return None
    return recognised_opw(chain) or recognised_ur(chain)
