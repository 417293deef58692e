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

IPOPT's derivatives are assembled from each waypoint's own
(:func:`~solver.optimise.methods.nlp_derivatives.derivatives`): the Jacobian and Hessian of 12
residuals in the waypoint's variables, small SX functions mapped over the waypoints. On the ERK
problem an IPOPT solve went from 0.45 to 0.13 s, with the same iterations and the same optimum
to 3e-15.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import casadi
import numpy as np

from solver.core.progress import Progress
from solver.optimise.methods.casadi_kinematics import symbolic_kinematics
from solver.optimise.methods.ipopt_iterations import MAX_ITERATIONS, IterationHook
from solver.optimise.methods.nlp_derivatives import NLP_THREADS, Layout
from solver.optimise.methods.nlp_derivatives import derivatives as assembled_derivatives
from solver.optimise.methods.nlp_terms import (
    HEAD,
    acceleration_rows,
    spun_twists,
    waypoint_residual,
)
from solver.optimise.search_space import N_VARIABLES, PlacementBounds
from solver.path.problem import PathProblem

# Margins (rad) kept from the joint limits and the step bound, so that a solution on them
# passes the evaluator's strict tests.
_MARGIN = 1e-9

# casadi's bundled stubs reject valid SX/MX expressions (DM + SX, MX in nlpsol): untyped here.
ca: Any = casadi


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
                assembled from each waypoint's own (:func:`assembled_derivatives`); False
                leaves them to casadi's algorithmic differentiation of the whole graph (the
                reference).

        The NLP is an MX graph over one waypoint's SX residuals mapped N times: built in about
        0.05 s, where inlining every waypoint in SX took 0.6 s to build (and 2x less per solve);
        the map runs on NLP_THREADS threads.
        """
        robot, path = problem.robot, problem.prepared
        tool_rotation = problem.waypoints[:, :3, :3]  # R_O_i of the tool point
        free_spin = problem.options.spin_mode == "free"
        n, dof = path.n_waypoints, robot.dof
        residual = waypoint_residual(symbolic_kinematics(robot), dof)
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
            twists = spun_twists(path, tool_rotation, spins)
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
        accelerations, self._acceleration_bound = acceleration_rows(problem, joints, speed)
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
        self._hook = IterationHook(int(variables.numel()), int(constraints.numel()))
        options["iteration_callback"] = self._hook
        if derivatives:
            options["jac_g"], options["hess_lag"] = assembled_derivatives(
                residual,
                path,
                tool_rotation,
                waypoint_data,
                variables=variables,
                constraints=constraints,
                layout=Layout(dof, n, free_spin, max_spin_step is not None),
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
            joint_path=x[HEAD : HEAD + n * self._dof].reshape(n, self._dof).copy(),
            status=str(stats["return_status"]),
            success=bool(stats["success"]),
            iterations=int(stats["iter_count"]),
            seconds=seconds,
        )


def _inside(bound: float) -> float:
    """A step bound less the margin, never below half of it (a bound of 1e-300 stays > 0)."""
    return bound - min(_MARGIN, bound / 2)
