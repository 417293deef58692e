"""The NLP's symbolic terms: a waypoint's residuals, the acceleration rows, the spun twists.

The placement NLP (:mod:`solver.optimise.methods.placement_nlp`) maps these over the waypoints;
:mod:`solver.optimise.methods.nlp_derivatives` differentiates them a waypoint at a time.
"""

from __future__ import annotations

from typing import Any

import casadi
import numpy as np

from solver.optimise.search_space import N_VARIABLES, variables_of
from solver.path.limits import JointAccelerationLimit
from solver.path.prepare import PreparedPath
from solver.path.problem import PathProblem

# casadi's bundled stubs reject valid SX/MX expressions (DM + SX, MX in nlpsol): untyped here.
ca: Any = casadi

HEAD = N_VARIABLES + 1
"""The decision vector and s lead the NLP's variables."""


def waypoint_residual(kinematics: Any, dof: int) -> Any:
    """One waypoint's 12 residuals as an SX function (mapped over the waypoints by the NLP).

    Its arguments: q, qdot, the decision vector, s, the spin rate sigma, the waypoint's spin
    phi, t_hat in {O} and the waypoint's data (p_O, R_O column-major); its residuals: the tool
    point's position, its orientation (the skew part of R_target^T R) and J qdot - s t - sigma
    [0; z_tool], all in {B}.
    """
    q, qdot = ca.SX.sym("q", dof), ca.SX.sym("qdot", dof)
    where = ca.SX.sym("placement", N_VARIABLES)  # the decision vector
    speed_1, spin_1 = ca.SX.sym("s"), ca.SX.sym("sigma")
    phi_1, twist_1 = ca.SX.sym("phi"), ca.SX.sym("twist", 6)  # waypoint spin, t_hat in {O}
    data = ca.SX.sym("waypoint", 3 + 9)  # p_O, R_O (column-major)
    named = variables_of(where)
    c, s = ca.cos(named.yaw), ca.sin(named.yaw)
    turn = ca.vertcat(ca.horzcat(c, -s, 0), ca.horzcat(s, c, 0), ca.horzcat(0, 0, 1))
    position, rotation, jacobian = kinematics(q)
    target_rotation = turn @ ca.reshape(data[3:12], 3, 3) @ turn_z(named.spin + phi_1)
    error = target_rotation.T @ rotation
    spin_twist = ca.vertcat(ca.DM.zeros(3), turn @ data[9:12])  # tool z (column 3 of R_O)
    return ca.Function(
        "waypoint_residual",
        [q, qdot, where, speed_1, spin_1, phi_1, twist_1, data],
        [
            ca.vertcat(
                position - (turn @ data[:3] + ca.vertcat(named.x, named.y, named.z)),
                error[2, 1] - error[1, 2],
                error[0, 2] - error[2, 0],
                error[1, 0] - error[0, 1],
                jacobian @ qdot
                - speed_1 * ca.vertcat(turn @ twist_1[:3], turn @ twist_1[3:])
                - spin_1 * spin_twist,
            )
        ],
    )


def acceleration_rows(
    problem: PathProblem, joints: ca.MX, speed: ca.MX
) -> tuple[ca.MX, np.ndarray]:
    """The rows D_ij s^2 of joint acceleration limits, and their bounds a_j (motion.md s. 3).

    D_i is linear in the joint values: the blend stencil's weights of five waypoints' q
    (:class:`solver.path.blend_stencil.BlendStencil`, path-only), so each row is |D_ij| s^2 <= a_j,
    as -a_j <= D_ij s^2 <= a_j. None (no rows) without acceleration limits.

    Returns:
        the rows (dof K, column-major over the K constrained waypoints) and their bounds
        (rad/s^2), both empty without acceleration limits.
    """
    for limit in problem.final_path_limits:
        if isinstance(limit, JointAccelerationLimit) and limit.stencil.waypoints.size:
            stencil, n = limit.stencil, problem.prepared.n_waypoints
            k = len(stencil.waypoints)
            columns = np.repeat(np.arange(k), stencil.index.shape[1])
            # One entry per (waypoint, constrained waypoint): repeated indices summed.
            keys, where = np.unique(stencil.index.ravel() * k + columns, return_inverse=True)
            values = np.zeros(len(keys))
            np.add.at(values, where, stencil.weight.ravel())
            weights = ca.DM.triplet(
                (keys // k).tolist(), (keys % k).tolist(), values.tolist(), n, k
            )  # (N, K)
            second = ca.mtimes(joints, weights)  # (dof, K): D_i of every joint
            return ca.vec(second) * speed**2, np.tile(limit.qddot_max, len(stencil.waypoints))
    return ca.MX(0, 1), np.zeros(0)


def turn_z(angle: ca.SX) -> ca.SX:
    """Rot_z(angle), a 3x3 expression."""
    c, s = ca.cos(angle), ca.sin(angle)
    return ca.vertcat(ca.horzcat(c, -s, 0), ca.horzcat(s, c, 0), ca.horzcat(0, 0, 1))


def segment_twist() -> Any:
    """t_hat in {O} of a segment whose end is turned by ``delta`` about its tool z (SX).

    Its arguments: delta, R_i and R_{i+1} column-major, u_T and the segment's length. The
    segment turns by R_{i+1} Rot_z(delta) R_i^T (cam.md section 4); its rotation vector over
    its length |dp_i| is the angular part, u_T the linear part (the spin moves no tool point).
    """
    now, following = ca.SX.sym("R", 9), ca.SX.sym("R_next", 9)
    delta, linear, length = ca.SX.sym("delta"), ca.SX.sym("u_T", 3), ca.SX.sym("length")
    turn = ca.reshape(following, 3, 3) @ turn_z(delta) @ ca.reshape(now, 3, 3).T
    axis = 0.5 * ca.vertcat(
        turn[2, 1] - turn[1, 2], turn[0, 2] - turn[2, 0], turn[1, 0] - turn[0, 1]
    )
    sine2 = ca.dot(axis, axis)
    cosine = (ca.trace(turn) - 1) / 2
    ratio = ca.if_else(  # angle / sin(angle), evaluated lazily: sqrt is not smooth at 0
        sine2 < 1e-20, 1 + sine2 / 6, ca.atan2(ca.sqrt(sine2), cosine) / ca.sqrt(sine2), True
    )
    return ca.Function(
        "segment_twist",
        [delta, now, following, linear, length],
        [ca.vertcat(linear, axis * ratio / length)],
    )


def spun_twists(path: PreparedPath, tool_rotation: np.ndarray, spins: ca.MX) -> ca.MX:
    """t_hat in {O} (6 x N) of the path with waypoint i turned by spins[i] about its tool z.

    Segment i's is :func:`segment_twist` of spins[i + 1] - spins[i]; the last waypoint reuses
    the last segment, as the evaluator does.
    """
    n = path.n_waypoints
    columns = tool_rotation.transpose(0, 2, 1).reshape(n, 9).T  # column-major R_O, (9, N)
    lengths = np.linalg.norm(np.diff(path.tool_position, axis=0), axis=1)
    twists = segment_twist().map(n - 1)(
        spins[1:] - spins[:-1],
        ca.DM(columns[:, :-1]),
        ca.DM(columns[:, 1:]),
        ca.DM(path.u_T[:-1].T),
        ca.DM(lengths[None, :]),
    )
    return ca.horzcat(twists, twists[:, -1])
