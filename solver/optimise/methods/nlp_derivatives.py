"""IPOPT's derivatives of the placement NLP, assembled a waypoint at a time.

Waypoint i's 12 residuals (:func:`solver.optimise.methods.nlp_terms.waypoint_residual`) depend
only on its own variables (:class:`Layout`); their Jacobian and Hessian are small SX functions
mapped over the waypoints and scattered into the NLP's sparse matrices.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi
import numpy as np

from solver.optimise.methods.nlp_terms import HEAD, segment_twist
from solver.optimise.search_space import N_VARIABLES
from solver.path.prepare import PreparedPath

# casadi's bundled stubs reject valid SX/MX expressions (DM + SX, MX in nlpsol): untyped here.
ca: Any = casadi

NLP_THREADS = 2
"""Threads that evaluate the waypoints' residuals and their derivatives (casadi's thread map).
With casadi's own differentiation of the graph they took IPOPT's four solves from 1.95 to
1.44 s on two cores; with the assembled derivatives (:func:`derivatives`, 40 % of a solve)
from 0.59 to 0.55 s. The same optimum to the bit either way; a fixed count, not the machine's
cores, so that the answer is the same everywhere."""


@dataclass(frozen=True)
class Layout:
    """Where a waypoint's variables sit in the decision vector (see PlacementNlp).

    The vector is [placement (N_VARIABLES), s, q_0 .. q_{N-1}, qdot_0 .. qdot_{N-1}, (sigma_0 ..
    sigma_{N-1}), (phi_0 .. phi_{N-1})]; waypoint i's own variables are the placement, s, q_i,
    qdot_i, sigma_i in free spin, and with a spin path the spins phi_a, phi_b of the segment
    whose twist it takes (a, b = i, i + 1; the last waypoint takes the last segment's).
    """

    dof: int
    n: int
    free_spin: bool
    spin_path: bool

    def local_size(self) -> int:
        """Variables of one waypoint."""
        return HEAD + 2 * self.dof + int(self.free_spin) + 2 * int(self.spin_path)

    def indices(self) -> np.ndarray:
        """(N, local_size): the decision vector's index of each waypoint's variables."""
        dof, n = self.dof, self.n
        i = np.arange(n)[:, None]
        joints = HEAD + i * dof + np.arange(dof)
        columns = [np.tile(np.arange(HEAD), (n, 1)), joints, joints + n * dof]
        after = HEAD + 2 * n * dof
        if self.free_spin:
            columns.append(after + i)
            after += n
        if self.spin_path:
            first = np.minimum(i, n - 2)  # the segment a waypoint takes
            columns += [after + first, after + first + 1]
        return np.hstack(columns)


def waypoints_data(
    path: PreparedPath, tool_rotation: np.ndarray, waypoint_data: np.ndarray, layout: Layout
) -> np.ndarray:
    """Each waypoint's data for its derivatives, shape (len(data), N).

    p_O and R_O, then its twist; or, with a spin path, its segment's two rotations, u_T,
    length, and whether it is the last waypoint.
    """
    n = layout.n
    if layout.spin_path:
        columns = tool_rotation.transpose(0, 2, 1).reshape(n, 9)  # column-major R_O
        first = np.minimum(np.arange(n), n - 2)
        lengths = np.linalg.norm(np.diff(path.tool_position, axis=0), axis=1)
        extra = np.column_stack(
            [
                columns[first],
                columns[first + 1],
                path.u_T[first],
                lengths[first],
                (np.arange(n) == n - 1).astype(float),
            ]
        )
    else:
        extra = path.twist
    data: np.ndarray = np.vstack([waypoint_data, extra.T])
    return data


def tail_derivatives(
    variables: Any, tail: Any, x: Any, weights: Any
) -> tuple[Any, Any, Any] | None:
    """The last constraints' values, Jacobian and weighted Hessian (upper triangle) at ``x``.

    They are the joint acceleration rows (few, each of a few waypoints' variables), left to
    casadi's differentiation; None where there are none.
    """
    count = int(tail.numel())
    if not count:
        return None
    symbols = ca.MX.sym("lam_tail", count)
    first = ca.Function("tail", [variables], [tail, ca.jacobian(tail, variables)])
    second = ca.Function(
        "tail_hessian",
        [variables, symbols],
        [ca.triu(ca.hessian(ca.dot(symbols, tail), variables)[0])],
    )
    value, jacobian = first(x)
    return value, jacobian, second(x, weights)


def scattered_hessian(blocks: Any, a: np.ndarray, b: np.ndarray, n_x: int) -> Any:
    """The waypoints' Hessian entries as one upper triangle (n_x x n_x), shared places summed.

    ``blocks`` holds the entries at rows ``a`` and columns ``b`` of the NLP's variables; the
    entries of the placement and s, which every waypoint has, add up.
    """
    upper_rows, upper_cols = np.minimum(a, b), np.maximum(a, b)
    pattern, target = ca.Sparsity.triplet(n_x, n_x, upper_rows.tolist(), upper_cols.tolist(), True)
    summing = ca.DM(
        ca.Sparsity.triplet(
            pattern.nnz(), len(upper_rows), list(target), list(range(len(upper_rows)))
        ),
        1.0,
    )
    return ca.MX(pattern, ca.mtimes(summing, ca.vec(blocks)))


def derivatives(
    residual: Any,
    path: PreparedPath,
    tool_rotation: np.ndarray,
    waypoint_data: np.ndarray,
    *,
    variables: Any,
    constraints: Any,
    layout: Layout,
    n_nonlinear: int = 0,
) -> tuple[Any, Any]:
    """IPOPT's constraint Jacobian and Lagrangian Hessian, a waypoint at a time.

    Waypoint i's 12 residuals depend only on its own variables (:class:`Layout`): their
    Jacobian (12 x m) and the Hessian of lambda_i . r_i (m x m) are small SX functions, mapped
    over the waypoints and scattered into the sparse matrices (the shared placement and s
    entries of the Hessian summed). The objective (-s) and the step constraints are linear:
    nothing in the Hessian, constant Jacobian entries. casadi's own differentiation of the MX
    graph colours the whole Jacobian and Hessian and sweeps it once per colour: about 15 ms
    each per IPOPT iteration on the ERK problem, where this takes a fraction of it.

    The last ``n_nonlinear`` constraints (the joint acceleration rows, D_ij s^2, each of a few
    q and s) are differentiated by casadi and appended.

    Returns:
        ``jac_g`` (x, p) -> (g, dg/dx) and ``hess_lag`` (x, p, lam_f, lam_g) -> the upper
        triangle of d2(lam_f f + lam_g . g)/dx2, as nlpsol's options of those names take.
    """
    dof, n, m = layout.dof, layout.n, layout.local_size()
    local = ca.SX.sym("local", m)
    where, speed = local[:N_VARIABLES], local[N_VARIABLES]
    q, qdot = local[HEAD : HEAD + dof], local[HEAD + dof : HEAD + 2 * dof]
    rest = HEAD + 2 * dof
    rate = local[rest] if layout.free_spin else 0
    rest += int(layout.free_spin)
    data = ca.SX.sym("data", 12 + (23 if layout.spin_path else 6))
    if layout.spin_path:
        phi_a, phi_b = local[rest], local[rest + 1]
        last = data[12 + 9 + 9 + 3 + 1]  # 1 at the last waypoint, whose own spin is phi_b
        own = last * phi_b + (1 - last) * phi_a  # exact for last in {0, 1}
        twist = segment_twist()(phi_b - phi_a, data[12:21], data[21:30], data[30:33], data[33])
    else:
        own, twist = 0, data[12:18]
    r = residual(q, qdot, where, speed, rate, own, twist, data[:12])
    weights = ca.SX.sym("lambda", 12)
    jacobian = ca.jacobian(r, local)
    hessian = ca.triu(ca.hessian(ca.dot(weights, r), local)[0])
    jac_rows, jac_cols = jacobian.sparsity().get_triplet()
    hess_rows, hess_cols = hessian.sparsity().get_triplet()
    first_order = ca.Function(
        "waypoint_jacobian", [local, data], [r, ca.vertcat(*jacobian.nonzeros())]
    ).map(n, "thread", NLP_THREADS)
    second_order = ca.Function(
        "waypoint_hessian", [local, data, weights], [ca.vertcat(*hessian.nonzeros())]
    ).map(n, "thread", NLP_THREADS)

    data_all = waypoints_data(path, tool_rotation, waypoint_data, layout)
    index = layout.indices()  # (N, m)
    x = ca.MX.sym("x", variables.numel())
    p = ca.MX.sym("p", 0)
    lam_f = ca.MX.sym("lam_f")
    n_g = int(constraints.numel())
    n_head = n_g - n_nonlinear  # the residuals and the linear rows
    lam_g = ca.MX.sym("lam_g", n_g)
    local_all = ca.reshape(x[index.ravel().tolist()], m, n)  # column i: waypoint i
    n_res = 12 * n

    # The Jacobian: the residual blocks, then the linear rows (constant entries).
    steps = constraints[n_res:n_head]
    linear = ca.Function("linear", [variables], [steps])
    # The linear rows' Jacobian does not depend on x: its sparsity and values, once.
    linear_jacobian = ca.Function("linear_jacobian", [variables], [ca.jacobian(steps, variables)])(
        np.zeros(variables.numel())
    )
    lin_rows, lin_cols = linear_jacobian.sparsity().get_triplet()
    lin_values = np.asarray(linear_jacobian.nonzeros())
    rows = np.concatenate(
        [
            (12 * np.arange(n)[:, None] + np.asarray(jac_rows)[None, :]).ravel(),
            n_res + np.asarray(lin_rows, dtype=int),
        ]
    )
    cols = np.concatenate([index[:, jac_cols].ravel(), np.asarray(lin_cols, dtype=int)])
    sparsity, where_nz = ca.Sparsity.triplet(
        n_head, int(x.numel()), rows.tolist(), cols.tolist(), True
    )
    if sparsity.nnz() != len(rows):  # each entry its own nonzero, or the reordering is wrong
        raise RuntimeError("the NLP's Jacobian entries overlap")
    values_r, blocks = first_order(local_all, ca.DM(data_all))
    entries = ca.vertcat(ca.vec(blocks), ca.DM(lin_values))
    order = np.empty(len(rows), dtype=int)
    order[np.asarray(where_nz)] = np.arange(len(rows))
    jacobian_all = ca.MX(sparsity, entries[order.tolist()])
    g = ca.vertcat(ca.vec(values_r), linear(x))
    tail = tail_derivatives(variables, constraints[n_head:], x, lam_g[n_head:])
    if tail is not None:
        g = ca.vertcat(g, tail[0])
        jacobian_all = ca.vertcat(jacobian_all, tail[1])
    jac_g = ca.Function("nlp_jac_g", [x, p], [g, jacobian_all], ["x", "p"], ["g", "jac_g_x"])

    # The Hessian: each waypoint's upper triangle, the shared entries summed.
    hess_blocks = second_order(local_all, ca.DM(data_all), ca.reshape(lam_g[:n_res], 12, n))
    hessian_all = scattered_hessian(
        hess_blocks, index[:, hess_rows].ravel(), index[:, hess_cols].ravel(), int(x.numel())
    )
    if tail is not None:
        hessian_all = hessian_all + tail[2]
    hess_lag = ca.Function(
        "nlp_hess_l",
        [x, p, lam_f, lam_g],
        [hessian_all],
        ["x", "p", "lam_f", "lam_g"],
        ["triu_hess_gamma_x_x"],
    )
    return jac_g, hess_lag
