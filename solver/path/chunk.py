"""A chunk of a map's placements as the branch-dropping passes see it (robots.md section 4).

Both ways a map drops branches that cannot be a cell's best, in steps
(:mod:`solver.path.pruning`) and in one compiled pass (:mod:`solver.path.bounded`), hold the
chunk's poses batch first, as a :class:`solver.core.follows_in_steps.FollowsInSteps` family
follows them, and measure followed branches as the pipeline does: V_max at some waypoints (the
bound on mu_path so far) and mu_path of whole branches.
"""

from __future__ import annotations

import numpy as np

from solver.core.codes import FEASIBLE
from solver.core.follows_in_steps import FollowsInSteps
from solver.path.limits import JointMotion, bound_by_limits
from solver.path.problem import PathProblem
from solver.path.tracking import track


class Chunk:
    """One chunk's paths, the family and limits, and the bounds of V_max along them."""

    def __init__(
        self,
        problem: PathProblem,
        rotation: np.ndarray,
        flange_position: np.ndarray,
        twist: np.ndarray,
        tool_position: np.ndarray,
    ) -> None:
        """Hold the chunk's poses batch first, as the family follows them."""
        self.problem = problem
        family = problem.family
        assert isinstance(family, FollowsInSteps)
        self.family = family
        n_cells, n_waypoints = flange_position.shape[1:]
        shape = (n_cells, n_waypoints)
        self.rotations = np.ascontiguousarray(
            np.moveaxis(np.broadcast_to(rotation, (3, 3, *shape)), (0, 1), (-2, -1))
        )
        self.positions = np.ascontiguousarray(np.moveaxis(flange_position, 0, -1))
        self.twist = np.broadcast_to(twist, (6, *shape))
        self.tool = np.broadcast_to(tool_position, (3, *shape))

    def v_max(self, q: np.ndarray, cells: np.ndarray, waypoints: np.ndarray) -> np.ndarray:
        """V_max as the pipeline computes it: q (n, M, w) at ``cells`` (M,), waypoints (M, w)."""
        problem = self.problem
        column = cells[:, None]
        qd_unit = problem.family.joint_speeds_per_unit_twist(
            q,
            self.twist[:, column, waypoints],
            self.tool[:, column, waypoints],
            qdot_max=problem.robot.qdot_max,
        )
        speed, _, _ = bound_by_limits(problem.waypoint_limits, JointMotion(q=q, qd_unit=qd_unit))
        v_max: np.ndarray = np.where(problem.prepared.pure_rotation[waypoints], 0.0, speed)
        return v_max

    def mu_path(self, q: np.ndarray, status: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """mu_path of whole branches q (n, M, W), status (M, W) at ``cells``; -inf infeasible."""
        problem, robot = self.problem, self.problem.robot
        tracked = track(
            q,
            status,
            lower=robot.q_lower,
            upper=robot.q_upper,
            max_joint_step=problem.options.max_joint_step,
            segment_checked=problem.prepared.segment_in_pass,
        )
        every = np.broadcast_to(np.arange(q.shape[-1]), (len(cells), q.shape[-1]))
        v_max = self.v_max(tracked.q, cells, every)
        feasible = tracked.reason == FEASIBLE
        mu: np.ndarray = np.where(feasible, v_max.min(axis=-1), -np.inf)
        return mu
