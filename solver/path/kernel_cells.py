"""The compiled kernels' side of the placements' evaluation: their inputs, and one call.

:func:`solver.path.placements.evaluate_placements` runs a problem's placements through the
compiled kernel of its family (:mod:`solver.kernels.fixed_spin`, in free spin
:mod:`solver.kernels.free_spin`) where :func:`kernel_of` gives one, else through the numpy
pipeline. The kernels compute mu_path only: a problem with final-path limits (joint
accelerations, motion.md) runs the numpy pipeline until they have a hook for those.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solver.kernels.fixed_spin import map_cells
from solver.kernels.free_spin import free_cells
from solver.kernels.positions import limit_modes
from solver.path.pipeline import flange_at_spin
from solver.path.problem import PathProblem


@dataclass(frozen=True)
class KernelInputs:
    """What the compiled kernel takes of a problem at one spin, made once per spin."""

    code: int
    parameters: np.ndarray
    rotation: np.ndarray  # (W, 3, 3), R_O_F at the spin
    position: np.ndarray  # (W, 3), m, p_O_F at the spin
    tool_position: np.ndarray
    twist: np.ndarray
    tool_axis: np.ndarray  # (W, 3), z of the tool in {O}: the spin's axis
    length: np.ndarray  # (W - 1,), m, the segments' lengths
    pure_rotation: np.ndarray
    segment_checked: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    modes: np.ndarray
    arc: np.ndarray
    qdot_max: np.ndarray
    branches: np.ndarray  # the branches followed
    max_joint_step: float
    free_spin: bool


def kernel_inputs(
    problem: PathProblem, spin: float, kernel: tuple[int, np.ndarray]
) -> KernelInputs:
    """The kernel's inputs of the problem's robot and path at ``spin``, as contiguous arrays."""
    robot, path = problem.robot, problem.prepared
    rotation, position = flange_at_spin(path, spin)
    modes, arc = limit_modes(robot.q_lower, robot.q_upper)
    contiguous = np.ascontiguousarray
    return KernelInputs(
        code=kernel[0],
        parameters=kernel[1],
        rotation=contiguous(rotation),
        position=contiguous(position),
        tool_position=contiguous(path.tool_position),
        twist=contiguous(path.twist),
        tool_axis=contiguous(path.tool_rotation[:, :, 2]),
        length=np.linalg.norm(np.diff(path.tool_position, axis=0), axis=1),
        pure_rotation=contiguous(path.pure_rotation),
        segment_checked=contiguous(path.segment_in_pass),
        lower=contiguous(robot.q_lower, dtype=float),
        upper=contiguous(robot.q_upper, dtype=float),
        modes=modes,
        arc=arc,
        qdot_max=contiguous(robot.qdot_max, dtype=float),
        branches=contiguous(problem.branches, dtype=np.int64),
        max_joint_step=float(problem.options.max_joint_step),
        free_spin=problem.options.spin_mode == "free",
    )


def run_kernel(
    inputs: KernelInputs, placements: np.ndarray, with_speeds: bool
) -> tuple[np.ndarray, ...]:
    """The speed columns of :func:`solver.path.placements._chunk` by the compiled kernel.

    At placements of one spin: mu, reason, failed, branch, bottleneck waypoint and joint, V_max.
    """
    n_cells, n_waypoints = len(placements), inputs.rotation.shape[0]
    mu = np.empty(n_cells)
    codes = [np.empty(n_cells, dtype=np.int64) for _ in range(5)]
    v_max = np.empty((n_cells, n_waypoints if with_speeds else 0))
    placed = (
        inputs.code,
        inputs.parameters,
        np.cos(placements[:, 3]),
        np.sin(placements[:, 3]),
        np.ascontiguousarray(placements[:, :3]),
        inputs.rotation,
        inputs.position,
        inputs.tool_position,
        inputs.twist,
    )
    followed = inputs.branches
    if inputs.free_spin:
        free_cells(
            *placed,
            inputs.tool_axis,
            inputs.length,
            inputs.pure_rotation,
            inputs.segment_checked,
            followed,
            inputs.lower,
            inputs.upper,
            inputs.qdot_max,
            inputs.max_joint_step,
            mu,
            *codes,
            v_max,
        )
    else:
        map_cells(
            *placed,
            inputs.pure_rotation,
            inputs.segment_checked,
            followed,
            inputs.lower,
            inputs.upper,
            inputs.modes,
            inputs.arc,
            inputs.qdot_max,
            inputs.max_joint_step,
            mu,
            *codes,
            v_max,
        )
    return (mu, *codes, v_max)


def kernel_of(problem: PathProblem) -> tuple[int, np.ndarray] | None:
    """The compiled pose kernel of the robot's family, where it has one (either spin mode).

    None where the problem has final-path limits (joint accelerations): the kernels compute
    mu_path only, and until they have a hook for those limits such problems run the numpy
    pipeline (the reference the kernels are tested against), at its speed.
    """
    if problem.final_path_limits:
        return None
    return problem.family.map_kernel()
