"""Analytic structure recognised in a URDF chain: an OPW arm given as a URDF gets its closed form.

robots.md sections 3 and 4. Numeric IK from seeds cannot promise every branch; an arm whose
chain is an OPW arm's (most KUKA, ABB and FANUC arms, whose URDFs users bring) has all eight in
closed form. The chain's joint lines at q = 0 propose the parameters
(:func:`solver.families.opw.fit.fit_opw`); they are kept only when the paper's forward formula
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


def recognised_family(chain: SerialChain) -> KinematicsFamily | None:
    """The analytic family of a URDF chain, where its structure is one we solve in closed form."""
    return recognised_opw(chain)
