"""The compiled kernels' side of the placements' evaluation: their inputs, and one call.

:func:`solver.path.placements.evaluate_placements` runs a problem's placements through the
compiled kernel of its family (:mod:`solver.kernels.fixed_spin`, in free spin
:mod:`solver.kernels.free_spin`) where :func:`kernel_of` gives one, else through the numpy
pipeline. With joint acceleration limits (motion.md) the kernels take the limits and the path's
blend stencil too, and give the acceleration columns as the numpy pipeline does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solver.core.spatial import BaseTurn
from solver.kernels.fixed_spin import map_cells
from solver.kernels.free_spin import free_cells
from solver.kernels.joint_paths import branch_paths, spun_branch_paths
from solver.kernels.positions import limit_modes
from solver.path.limits import JointAccelerationLimit, JointSpeedLimit
from solver.path.placed import flange_at_spin
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
    qddot_max: np.ndarray  # (6,), rad/s^2, or (0,) without acceleration limits
    stencil_index: np.ndarray  # (K, 5), the blend stencil (K = 0 without limits)
    stencil_weight: np.ndarray  # (K, 5), 1/m^2
    stencil_waypoints: np.ndarray  # (K,)
    base_turn: BaseTurn | None  # the family's, where it solves in a frame turned from {B}


def kernel_inputs(
    problem: PathProblem, spin: float, kernel: tuple[int, np.ndarray]
) -> KernelInputs:
    """The kernel's inputs of the problem's robot and path at ``spin``, as contiguous arrays."""
    robot, path = problem.robot, problem.prepared
    rotation, position = flange_at_spin(path, spin)
    if problem.family.flange_offset is not None:  # the poses the family's IK solves for
        rotation, position = problem.family.flange_offset.family_flange_rows(rotation, position)
    modes, arc = limit_modes(robot.q_lower, robot.q_upper)
    contiguous = np.ascontiguousarray
    qddot_max = np.zeros(0)
    index, weight, waypoints = np.zeros((0, 5), np.int64), np.zeros((0, 5)), np.zeros(0, np.int64)
    for limit in problem.final_path_limits:
        if isinstance(limit, JointAccelerationLimit):
            qddot_max = contiguous(limit.qddot_max, dtype=float)
            index = contiguous(limit.stencil.index, dtype=np.int64)
            weight = contiguous(limit.stencil.weight, dtype=float)
            waypoints = contiguous(limit.stencil.waypoints, dtype=np.int64)
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
        qddot_max=qddot_max,
        stencil_index=index,
        stencil_weight=weight,
        stencil_waypoints=waypoints,
        base_turn=problem.family.base_turn,
    )


def run_kernel(
    inputs: KernelInputs, placements: np.ndarray, with_speeds: bool
) -> tuple[np.ndarray, ...]:
    """The columns of :func:`solver.path.placements._chunk` by the compiled kernel.

    At placements of one spin: mu, reason, failed, branch, bottleneck waypoint and joint, V_max;
    then mu_acc, what binds it, its waypoint and joint, V_acc (as the numpy pipeline gives them
    with acceleration limits; :func:`no_acc_columns` without).
    """
    n_cells, n_waypoints = len(placements), inputs.rotation.shape[0]
    mu = np.empty(n_cells)
    codes = [np.empty(n_cells, dtype=np.int64) for _ in range(5)]
    v_max = np.empty((n_cells, n_waypoints if with_speeds else 0))
    accelerations = inputs.qddot_max.shape[0] > 0
    acc_cells = n_cells if accelerations else 0
    mu_acc = np.empty(acc_cells)
    acc_codes = [np.empty(acc_cells, dtype=np.int64) for _ in range(3)]
    v_acc = np.empty((n_cells, n_waypoints if with_speeds and accelerations else 0))
    stencil = (
        inputs.qddot_max,
        inputs.stencil_index,
        inputs.stencil_weight,
        inputs.stencil_waypoints,
    )
    placed = _placed(inputs, placements)
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
            *stencil,
            mu,
            *codes,
            v_max,
            mu_acc,
            *acc_codes,
            v_acc,
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
            *stencil,
            mu,
            *codes,
            v_max,
            mu_acc,
            *acc_codes,
            v_acc,
        )
    if not accelerations:
        return (mu, *codes, v_max, *no_acc_columns(n_cells, v_max.shape[1]))
    return (mu, *codes, v_max, mu_acc, *acc_codes, v_acc)


def kernel_joint_paths(
    inputs: KernelInputs,
    placements: np.ndarray,
    rows: np.ndarray,
    feeds: np.ndarray | None = None,
) -> np.ndarray:
    """The joint path of the family's branch ``rows[c]`` at each placement c, (C, W, 6), rad.

    As :func:`solver.path.pipeline.run_chunk` tracks that branch (the compiled
    :func:`solver.kernels.joint_paths.branch_paths`, tests/solver/test_joint_paths_kernel.py);
    in free spin along its spin schedule at ``feeds`` (C,), m/s, each branch's mu_path there
    (:func:`~solver.kernels.joint_paths.spun_branch_paths`). Meaningful where that branch is
    feasible at its placement.
    """
    out = np.empty((len(placements), inputs.rotation.shape[0], 6))
    rows = np.ascontiguousarray(rows, dtype=np.int64)
    if not inputs.free_spin:
        branch_paths(*_placed(inputs, placements), rows, inputs.lower, inputs.upper, out)
        return out
    if feeds is None:
        raise ValueError("a joint path in free spin needs its feed (the branch's mu_path)")
    spun_branch_paths(
        *_placed(inputs, placements),
        inputs.tool_axis,
        rows,
        np.ascontiguousarray(feeds, dtype=float),
        inputs.length,
        inputs.segment_checked,
        inputs.lower,
        inputs.upper,
        inputs.qdot_max,
        inputs.max_joint_step,
        out,
    )
    return out


def _placed(inputs: KernelInputs, placements: np.ndarray) -> tuple[object, ...]:
    """The kernels' first nine arguments: the family, the placements, the path at the spin.

    The placements in the family's own frame where it solves in a turn of {B} about its z (the
    kernels place the path in the frame they solve in); a tilted family's stay in {B} (its
    kernel code writes the placed poses in its frame, :func:`solver.families.kernels.pose_block`).
    """
    if inputs.base_turn is not None and inputs.base_turn.tilt is None:
        placements = inputs.base_turn.placements_in(placements)
    return (
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


def no_acc_columns(n_cells: int, n_waypoints: int) -> tuple[np.ndarray, ...]:
    """The acceleration columns of a chunk without final-path limits (never reported)."""
    missing = np.full(n_cells, -1, dtype=np.int64)
    return (np.full(n_cells, np.nan), missing, missing, missing, np.zeros((n_cells, n_waypoints)))


def kernel_of(problem: PathProblem) -> tuple[int, np.ndarray] | None:
    """The compiled pose kernel of the robot's family, where it has one (either spin mode).

    With or without joint acceleration limits: the kernels compute mu_acc as the numpy pipeline
    does (:mod:`solver.kernels.accelerations`). None where a limit other than the joint speed
    limits (at each waypoint: the kernels compute the DTF of ``robot.qdot_max`` themselves) and
    the joint accelerations (on the final path) is given: no kernel has its hook, and a new
    limit was silently dropped by the maps and the optimisers while the evaluator applied it
    (the seams audit: a 0.1 m/s feed cap, 0.294 m/s on the map); or in free spin with an
    angled or offset spindle (the spun poses are solved again, :mod:`solver.path.exact_spin`,
    which the free-spin kernel does not): the numpy pipeline runs.
    """
    if any(type(limit) is not JointSpeedLimit for limit in problem.waypoint_limits):
        return None
    if any(type(limit) is not JointAccelerationLimit for limit in problem.final_path_limits):
        return None
    if problem.exact_spin:
        return None
    return problem.family.map_kernel()
