"""The placement optimum as one smooth NLP in CasADi/IPOPT (spec section 6, the epigraph form).

    maximise s  over (x, y, yaw, spin, s, q_i, qdot_i[, sigma_i])
    subject to  FK(q_i) = T_B_O(x, y, yaw) T_O_i Rot_z(spin)   (tool point pose, every waypoint)
                J(q_i) qdot_i = s t_hat_i(yaw) [+ sigma_i [0; z_i(yaw)]]   (the task twist at
                                                         feed rate s; with the tool spin rate
                                                         sigma_i free in free spin mode)
                |qdot_i| <= qdot_max,  q_min <= q_i <= q_max,  |q_{i+1} - q_i| <= max_joint_step
                (x, y, yaw, spin) inside the bounds (a variable with one value is fixed)

With ``max_spin_step`` (cam.md section 4) every waypoint also gets its own spin phi_i on top of
the placement's (phi_0 = 0), |phi_{i+1} - phi_i| <= max_spin_step, and each segment's t_hat is
that of the spun poses in closed form: R_{i+1} Rot_z(phi_{i+1} - phi_i) R_i^T, its rotation
vector by atan2 (exact; the series 1 + s^2 / 6 where the turn is below 1e-10 rad).

min_i V_max(i) is not smooth; this form is, and its optimum is the same. The problem is built
once per robot and path; each solve starts from a feasible placement and its joint path on one IK
branch, which IPOPT follows. Its constraint tolerance is 1e-10, not the default 1e-4, so that
results agree with the evaluator to far better than 1e-6. The tool orientation constraint is the
skew part of R_target^T R(q) = 0, which also vanishes at half turns: the start on the right
branch keeps IPOPT away from those.

IPOPT's derivatives are assembled from each waypoint's own (:func:`_derivatives`): the
Jacobian and Hessian of 12 residuals in the waypoint's variables, small SX functions mapped over
the waypoints. On the ERK problem an IPOPT solve went from 0.45 to 0.13 s, with the same
iterations and the same optimum to 3e-15.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import casadi
import numpy as np

from solver.core.progress import Cancelled, Progress
from solver.optimise.methods.casadi_kinematics import symbolic_kinematics
from solver.optimise.search_space import N_VARIABLES, PlacementBounds, variables_of
from solver.path.limits import JointAccelerationLimit
from solver.path.prepare import PreparedPath
from solver.path.problem import PathProblem

# Margins (rad) kept from the joint limits and the step bound, so that a solution on them
# passes the evaluator's strict tests.
_MARGIN = 1e-9

# The decision vector and s lead the NLP's variables.
_HEAD = N_VARIABLES + 1

# casadi's bundled stubs reject valid SX/MX expressions (DM + SX, MX in nlpsol): untyped here.
ca: Any = casadi
MAX_ITERATIONS = 300
NLP_THREADS = 2
"""Threads that evaluate the waypoints' residuals and their derivatives (casadi's thread map).
With casadi's own differentiation of the graph they took IPOPT's four solves from 1.95 to
1.44 s on two cores; with the assembled derivatives (:func:`_derivatives`, 40 % of a solve)
from 0.59 to 0.55 s. The same optimum to the bit either way; a fixed count, not the machine's
cores, so that the answer is the same everywhere."""


class _IterationHook(ca.Callback):  # type: ignore[misc]
    """IPOPT's call after each iteration: reports progress; a :class:`Cancelled` stops IPOPT."""

    def __init__(self, n_variables: int, n_constraints: int) -> None:
        ca.Callback.__init__(self)
        self._sizes = {"x": n_variables, "lam_x": n_variables}
        self._sizes |= {"g": n_constraints, "lam_g": n_constraints, "f": 1}
        self.progress: Progress | None = None
        self.cancelled: Cancelled | None = None
        self.iteration = 0
        self.construct("iteration_hook", {})

    def get_n_in(self) -> int:
        return int(ca.nlpsol_n_out())

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return str(ca.nlpsol_out(i))

    def get_name_out(self, i: int) -> str:
        return "stop"

    def get_sparsity_in(self, i: int) -> Any:
        size = self._sizes.get(str(ca.nlpsol_out(i)), 0)
        return ca.Sparsity.dense(size, 1) if size else ca.Sparsity(0, 0)

    def eval(self, arguments: Any) -> list[int]:
        self.iteration += 1
        if self.progress is not None and self.cancelled is None:
            try:
                self.progress(min(self.iteration / MAX_ITERATIONS, 1.0))
            except Cancelled as stop:
                self.cancelled = stop
        return [1 if self.cancelled is not None else 0]


@dataclass(frozen=True)
class NlpResult:
    """One IPOPT solve: the decision vector, s, IPOPT's status, iterations.

    ``spins`` (N,), rad, each waypoint's spin on top of the placement's, with a spin path.
    ``joint_path`` (N, n), rad, the q_i of the solution (for dof > 6 it also chose the
    redundancy).
    """

    vector: np.ndarray
    speed: float
    spins: np.ndarray | None
    joint_path: np.ndarray
    status: str
    success: bool
    iterations: int
    seconds: float


class PlacementNlp:
    """The epigraph NLP of one robot and path, built once, solved from several starts."""

    def __init__(
        self,
        problem: PathProblem,
        bounds: PlacementBounds,
        *,
        max_spin_step: float | None = None,
        ipopt_options: dict[str, object] | None = None,
        derivatives: bool = True,
    ) -> None:
        """Build the problem.

        Args:
            problem: the arm, the path (its tool positions, orientations and t_hat in {O})
                and the options: the evaluator's bound on a joint's move between waypoints,
                and the spin mode (``free``: the tool spin rate about the tool z axis is a free
                variable per waypoint, cam.md section 2).
            bounds: the placement box (the decision vector).
            max_spin_step: rad, > 0: a spin per waypoint with steps at most this (cam.md
                section 4); None keeps the spin constant.
            ipopt_options: IPOPT options over the defaults (``{"max_iter": 100}``).
            derivatives: give IPOPT the constraint Jacobian and the Lagrangian's Hessian
                assembled from each waypoint's own (:func:`_derivatives`); False leaves them to
                casadi's algorithmic differentiation of the whole graph (the reference).

        The NLP is an MX graph over one waypoint's SX residuals mapped N times: built in about
        0.05 s, where inlining every waypoint in SX took 0.6 s to build (and 2x less per solve);
        the map runs on NLP_THREADS threads.
        """
        robot, path = problem.robot, problem.prepared
        tool_rotation = problem.waypoints[:, :3, :3]  # R_O_i of the tool point
        free_spin = problem.options.spin_mode == "free"
        n, dof = path.n_waypoints, robot.dof
        residual = _waypoint_residual(symbolic_kinematics(robot), dof)
        waypoint_data = np.column_stack(
            [
                path.tool_position,
                tool_rotation.transpose(0, 2, 1).reshape(n, 9),  # column-major R_O
            ]
        ).T
        placement = ca.MX.sym("placement", N_VARIABLES)  # the decision vector
        speed = ca.MX.sym("s")
        joints = ca.MX.sym("q", dof, n)
        joint_speeds = ca.MX.sym("qdot", dof, n)
        spin_rates = ca.MX.sym("sigma", 1, n) if free_spin else ca.DM.zeros(1, n)
        if max_spin_step is None:
            spins, twists = ca.DM.zeros(1, n), ca.DM(path.twist.T)
        else:
            spins = ca.MX.sym("phi", 1, n)
            twists = _spun_twists(path, tool_rotation, spins)
        residuals = residual.map(n, "thread", NLP_THREADS)(
            joints,
            joint_speeds,
            ca.repmat(placement, 1, n),
            ca.repmat(speed, 1, n),
            spin_rates,
            spins,
            twists,
            ca.DM(waypoint_data),
        )
        within = [int(i) for i in np.flatnonzero(path.segment_in_pass)]  # no bound across rapids
        steps = ca.vec(joints[:, [i + 1 for i in within]] - joints[:, within])
        variables = ca.vertcat(placement, speed, ca.vec(joints), ca.vec(joint_speeds))
        if free_spin:
            variables = ca.vertcat(variables, ca.vec(spin_rates))
        self._n_rates = n if free_spin else 0
        self._n_spins = 0 if max_spin_step is None else n
        self._spin_step = max_spin_step
        equalities = ca.vec(residuals)
        constraints = ca.vertcat(equalities, steps)
        if max_spin_step is not None:
            variables = ca.vertcat(variables, ca.vec(spins))
            constraints = ca.vertcat(constraints, ca.vec(spins[1:] - spins[:-1]))
        accelerations, self._acceleration_bound = _acceleration_rows(problem, joints, speed)
        constraints = ca.vertcat(constraints, accelerations)
        self._n_equalities = int(equalities.numel())
        self._n_steps = int(steps.numel())
        self._dof, self._n = dof, n
        self._robot, self._bounds = robot, bounds
        self._step = problem.options.max_joint_step
        options = {
            "print_time": False,
            "ipopt.print_level": 0,
            "ipopt.sb": "yes",
            "ipopt.tol": 1e-10,
            "ipopt.constr_viol_tol": 1e-10,
            "ipopt.max_iter": MAX_ITERATIONS,
            # Every start is feasible and near an optimum: a small barrier parameter from the
            # first iteration (measured: 11-16 iterations instead of 17-280).
            "ipopt.mu_init": 1e-5,
        }
        options.update({f"ipopt.{k}": v for k, v in (ipopt_options or {}).items()})
        self._hook = _IterationHook(int(variables.numel()), int(constraints.numel()))
        options["iteration_callback"] = self._hook
        if derivatives:
            options["jac_g"], options["hess_lag"] = _derivatives(
                residual,
                path,
                tool_rotation,
                waypoint_data,
                variables=variables,
                constraints=constraints,
                layout=_Layout(dof, n, free_spin, max_spin_step is not None),
                n_nonlinear=len(self._acceleration_bound),
            )
        self._solver = ca.nlpsol(
            "placement", "ipopt", {"x": variables, "f": -speed, "g": constraints}, options
        )

    def _spin_bound(self, value: float) -> np.ndarray:
        """Bounds of the waypoint spins: phi_0 = 0 (the placement's spin), the others ``value``."""
        bound = np.full(self._n_spins, value)
        bound[:1] = 0.0
        return bound

    def solve(
        self,
        start: np.ndarray,
        start_speed: float,
        q_path: np.ndarray,
        qdot_path: np.ndarray,
        *,
        progress: Progress | None = None,
    ) -> NlpResult:
        """Solve from a feasible start.

        Args:
            start: the start's decision vector (:mod:`solver.optimise.search_space`).
            start_speed: its mu_path (m/s), the initial s.
            q_path: shape (N, n), rad, the start's joint path on the branch to follow.
            qdot_path: shape (N, n), rad/s, joint speeds there at feed rate ``start_speed``
                (a feasible start for the twist constraints, with spin rate 0 in free mode).
            progress: called after each IPOPT iteration; a :class:`Cancelled` it raises stops
                IPOPT and is raised here.
        """
        robot, bounds, n = self._robot, self._bounds, self._n
        lower = np.concatenate(
            [
                bounds.lower,
                [0.0],
                np.tile(robot.q_lower + _MARGIN, n),
                np.tile(-robot.qdot_max, n),
                np.full(self._n_rates, -np.inf),
                self._spin_bound(-np.inf),
            ]
        )
        upper = np.concatenate(
            [
                bounds.upper,
                [np.inf],
                np.tile(robot.q_upper - _MARGIN, n),
                np.tile(robot.qdot_max, n),
                np.full(self._n_rates, np.inf),
                self._spin_bound(np.inf),
            ]
        )
        step = _inside(self._step)
        spin_step = np.full(max(self._n_spins - 1, 0), _inside(self._spin_step or 0.0))
        lbg = np.concatenate(
            [
                np.zeros(self._n_equalities),
                np.full(self._n_steps, -step),
                -spin_step,
                -self._acceleration_bound,
            ]
        )
        ubg = np.concatenate(
            [
                np.zeros(self._n_equalities),
                np.full(self._n_steps, step),
                spin_step,
                self._acceleration_bound,
            ]
        )
        guess = np.concatenate(
            [
                start,
                [start_speed],
                q_path.ravel(),
                qdot_path.ravel(),
                np.zeros(self._n_rates + self._n_spins),
            ]
        )
        began = time.perf_counter()
        self._hook.progress, self._hook.cancelled, self._hook.iteration = progress, None, 0
        try:
            solution = self._solver(x0=guess, lbx=lower, ubx=upper, lbg=lbg, ubg=ubg)
        finally:
            if self._hook.cancelled is not None:
                raise self._hook.cancelled
        seconds = time.perf_counter() - began
        stats = self._solver.stats()
        x = np.asarray(solution["x"]).ravel()
        return NlpResult(
            vector=x[:N_VARIABLES].copy(),
            speed=float(x[N_VARIABLES]),
            spins=x[len(x) - self._n_spins :].copy() if self._n_spins else None,
            joint_path=x[_HEAD : _HEAD + n * self._dof].reshape(n, self._dof).copy(),
            status=str(stats["return_status"]),
            success=bool(stats["success"]),
            iterations=int(stats["iter_count"]),
            seconds=seconds,
        )


def _waypoint_residual(kinematics: Any, dof: int) -> Any:
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
    target_rotation = turn @ ca.reshape(data[3:12], 3, 3) @ _turn_z(named.spin + phi_1)
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


def _acceleration_rows(
    problem: PathProblem, joints: ca.MX, speed: ca.MX
) -> tuple[ca.MX, np.ndarray]:
    """The rows D_ij s^2 of joint acceleration limits, and their bounds a_j (motion.md s. 3).

    D_i is linear in the joint values: the blend stencil's weights of five waypoints' q
    (:class:`solver.path.limits.BlendStencil`, path-only), so each row is |D_ij| s^2 <= a_j,
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


def _inside(bound: float) -> float:
    """A step bound less the margin, never below half of it (a bound of 1e-300 stays > 0)."""
    return bound - min(_MARGIN, bound / 2)


def _turn_z(angle: ca.SX) -> ca.SX:
    """Rot_z(angle), a 3x3 expression."""
    c, s = ca.cos(angle), ca.sin(angle)
    return ca.vertcat(ca.horzcat(c, -s, 0), ca.horzcat(s, c, 0), ca.horzcat(0, 0, 1))


def _segment_twist() -> Any:
    """t_hat in {O} of a segment whose end is turned by ``delta`` about its tool z (SX).

    Its arguments: delta, R_i and R_{i+1} column-major, u_T and the segment's length. The
    segment turns by R_{i+1} Rot_z(delta) R_i^T (cam.md section 4); its rotation vector over
    its length |dp_i| is the angular part, u_T the linear part (the spin moves no tool point).
    """
    now, following = ca.SX.sym("R", 9), ca.SX.sym("R_next", 9)
    delta, linear, length = ca.SX.sym("delta"), ca.SX.sym("u_T", 3), ca.SX.sym("length")
    turn = ca.reshape(following, 3, 3) @ _turn_z(delta) @ ca.reshape(now, 3, 3).T
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


def _spun_twists(path: PreparedPath, tool_rotation: np.ndarray, spins: ca.MX) -> ca.MX:
    """t_hat in {O} (6 x N) of the path with waypoint i turned by spins[i] about its tool z.

    Segment i's is :func:`_segment_twist` of spins[i + 1] - spins[i]; the last waypoint reuses
    the last segment, as the evaluator does.
    """
    n = path.n_waypoints
    columns = tool_rotation.transpose(0, 2, 1).reshape(n, 9).T  # column-major R_O, (9, N)
    lengths = np.linalg.norm(np.diff(path.tool_position, axis=0), axis=1)
    twists = _segment_twist().map(n - 1)(
        spins[1:] - spins[:-1],
        ca.DM(columns[:, :-1]),
        ca.DM(columns[:, 1:]),
        ca.DM(path.u_T[:-1].T),
        ca.DM(lengths[None, :]),
    )
    return ca.horzcat(twists, twists[:, -1])


@dataclass(frozen=True)
class _Layout:
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
        return _HEAD + 2 * self.dof + int(self.free_spin) + 2 * int(self.spin_path)

    def indices(self) -> np.ndarray:
        """(N, local_size): the decision vector's index of each waypoint's variables."""
        dof, n = self.dof, self.n
        i = np.arange(n)[:, None]
        joints = _HEAD + i * dof + np.arange(dof)
        columns = [np.tile(np.arange(_HEAD), (n, 1)), joints, joints + n * dof]
        after = _HEAD + 2 * n * dof
        if self.free_spin:
            columns.append(after + i)
            after += n
        if self.spin_path:
            first = np.minimum(i, n - 2)  # the segment a waypoint takes
            columns += [after + first, after + first + 1]
        return np.hstack(columns)


def _waypoints_data(
    path: PreparedPath, tool_rotation: np.ndarray, waypoint_data: np.ndarray, layout: _Layout
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


def _tail_derivatives(
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


def _scattered_hessian(blocks: Any, a: np.ndarray, b: np.ndarray, n_x: int) -> Any:
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


def _derivatives(
    residual: Any,
    path: PreparedPath,
    tool_rotation: np.ndarray,
    waypoint_data: np.ndarray,
    *,
    variables: Any,
    constraints: Any,
    layout: _Layout,
    n_nonlinear: int = 0,
) -> tuple[Any, Any]:
    """IPOPT's constraint Jacobian and Lagrangian Hessian, a waypoint at a time.

    Waypoint i's 12 residuals depend only on its own variables (:class:`_Layout`): their
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
    q, qdot = local[_HEAD : _HEAD + dof], local[_HEAD + dof : _HEAD + 2 * dof]
    rest = _HEAD + 2 * dof
    rate = local[rest] if layout.free_spin else 0
    rest += int(layout.free_spin)
    data = ca.SX.sym("data", 12 + (23 if layout.spin_path else 6))
    if layout.spin_path:
        phi_a, phi_b = local[rest], local[rest + 1]
        last = data[12 + 9 + 9 + 3 + 1]  # 1 at the last waypoint, whose own spin is phi_b
        own = last * phi_b + (1 - last) * phi_a  # exact for last in {0, 1}
        twist = _segment_twist()(phi_b - phi_a, data[12:21], data[21:30], data[30:33], data[33])
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

    data_all = _waypoints_data(path, tool_rotation, waypoint_data, layout)
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
    tail = _tail_derivatives(variables, constraints[n_head:], x, lam_g[n_head:])
    if tail is not None:
        g = ca.vertcat(g, tail[0])
        jacobian_all = ca.vertcat(jacobian_all, tail[1])
    jac_g = ca.Function("nlp_jac_g", [x, p], [g, jacobian_all], ["x", "p"], ["g", "jac_g_x"])

    # The Hessian: each waypoint's upper triangle, the shared entries summed.
    hess_blocks = second_order(local_all, ca.DM(data_all), ca.reshape(lam_g[:n_res], 12, n))
    hessian_all = _scattered_hessian(
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
