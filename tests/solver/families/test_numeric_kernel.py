"""The compiled numeric chain and IK against the numpy reference, pinocchio, finite differences.

:mod:`solver.families.numeric.chain_kernel` and ``ik_kernel`` are the compiled twins of the
numpy chain (:class:`SerialChain`) and IK (:mod:`solver.families.numeric.ik`); the numpy code
stays the reference (``NumericFamily(compiled=False)``), and every level is held to it: FK and
the Jacobian, one Levenberg-Marquardt solve per row, the seeded and followed branches of a
path, the joint speeds, and the map cell by cell.
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.kinematics import jacobian_in_base
from solver.core.robots import Robot
from solver.families import get_robot
from solver.families.numeric import (
    chain_kernel,
    follow_kernel,
    ik,
    ik_kernel,
    lu_kernel,
    redundant_kernel,
    seed_kernel,
)
from solver.families.numeric.family import NumericFamily
from solver.kernels import spin_lp
from solver.path.placed import flange_at_spin, turn_by_yaw
from solver.path.problem import PathProblem
from tests.cases import NUMERIC_MODELS
from tests.solver.families.numeric_maps import (
    erk_placements,
    map_cells,
    numeric_arm,
    opw_from_urdf,
    ur5_from_urdf,
)
from tests.solver.families.test_numeric_ik import random_configurations
from tests.solver.test_evaluate import load_path

ROBOTS = (*NUMERIC_MODELS, "ur5_urdf", "kr6_urdf")
FRAMES = {
    "panda": ("panda_link0", "panda_link8"),
    "xarm7": ("link_base", "link_eef"),
    "kinova_jaco2": ("j2s6s200_link_base", "j2s6s200_end_effector"),
}
# Compiled against numpy: the same algorithm summed in another order. Converged solutions
# agree to the IK's own tolerance (1e-12 on the pose) times the chain's conditioning.
Q_ATOL = 1e-9
MU_RTOL = 1e-9


def arm(name: str, *, compiled: bool = True) -> Robot:
    """The arm ``name`` with the numeric family, compiled or the numpy reference."""
    if name == "ur5_urdf":
        return ur5_from_urdf(compiled=compiled)
    if name == "kr6_urdf":
        return opw_from_urdf("kuka_kr6_r700_sixx", compiled=compiled)
    base, tool = FRAMES[name]
    return numeric_arm(get_robot(name), base_frame=base, tool_frame=tool, compiled=compiled)


def family(robot: Robot) -> NumericFamily:
    assert isinstance(robot.family, NumericFamily)
    return robot.family


@pytest.mark.parametrize("name", ROBOTS)
def test_compiled_chain_equals_numpy_chain_and_pinocchio(name: str) -> None:
    robot = arm(name)
    chain, packed = family(robot).chain, family(robot).chain.packed()
    q = random_configurations(robot, 40, seed=3)
    rotation, position = chain_kernel.forward(packed, q)
    reference_rotation, reference_position = chain.forward(q)
    np.testing.assert_allclose(rotation, reference_rotation, rtol=0, atol=1e-14)
    np.testing.assert_allclose(position, reference_position, rtol=0, atol=1e-14)
    point = position + np.random.default_rng(4).uniform(-0.1, 0.1, position.shape)
    jacobian = chain_kernel.jacobians(packed, q, point)
    reference, _, _ = chain.jacobian(q, point)
    np.testing.assert_allclose(jacobian, reference, rtol=0, atol=1e-14)
    for i in range(5):  # pinocchio at the flange (robot.tool is the flange here)
        np.testing.assert_allclose(
            chain_kernel.jacobians(packed, q[i : i + 1], position[i : i + 1])[0],
            jacobian_in_base(robot, q[i]),
            rtol=0,
            atol=1e-12,
        )


@pytest.mark.parametrize("name", ROBOTS)
def test_compiled_jacobian_equals_finite_differences(name: str) -> None:
    """Each column: the flange's velocity (linear; angular from R' R^T) per unit joint speed."""
    robot = arm(name)
    packed = family(robot).chain.packed()
    q = random_configurations(robot, 10, seed=5)
    _, position = chain_kernel.forward(packed, q)
    jacobian = chain_kernel.jacobians(packed, q, position)
    step = 1e-6
    for j in range(robot.dof):
        shift = np.zeros(robot.dof)
        shift[j] = step
        r_plus, p_plus = chain_kernel.forward(packed, q + shift)
        r_minus, p_minus = chain_kernel.forward(packed, q - shift)
        linear = (p_plus - p_minus) / (2 * step)
        spin = (
            (r_plus - r_minus) / (2 * step) @ chain_kernel.forward(packed, q)[0].transpose(0, 2, 1)
        )
        angular = np.stack([spin[:, 2, 1], spin[:, 0, 2], spin[:, 1, 0]], axis=-1)
        np.testing.assert_allclose(jacobian[:, :3, j], linear, rtol=0, atol=1e-8)
        np.testing.assert_allclose(jacobian[:, 3:, j], angular, rtol=0, atol=1e-8)


@pytest.mark.parametrize("clip", [True, False])
@pytest.mark.parametrize("name", ROBOTS)
def test_compiled_solve_equals_numpy_solve(name: str, clip: bool) -> None:
    """One damped least-squares solve per row, from near and far starts, with or without the box."""
    robot = arm(name)
    numeric = family(robot)
    q = random_configurations(robot, 60, seed=6)
    rotation, position = numeric.chain.forward(q)
    spread = np.where(np.arange(len(q)) % 2, 0.2, 1.5)[:, None]  # near and far starts
    start = q + spread * np.random.default_rng(7).normal(size=q.shape)
    box = (numeric.lower, numeric.upper) if clip else None
    constants = np.array([ik.TOLERANCE, ik.DAMPING_SCALE, ik.DAMPING_FLOOR])
    solved, converged = ik_kernel.solve_rows(
        numeric.chain.packed(), start, rotation, position, 8, box, constants
    )
    limits = {"lower": numeric.lower, "upper": numeric.upper} if clip else {}
    reference, reference_converged = ik.solve(
        numeric.chain, start, rotation, position, iterations=8, **limits
    )
    assert 0 < converged.sum() < len(q)  # both kinds of row are compared
    np.testing.assert_array_equal(converged, reference_converged)
    np.testing.assert_allclose(solved[converged], reference[converged], rtol=0, atol=Q_ATOL)


@pytest.mark.parametrize("name", ROBOTS)
def test_seeds_given_up_on_a_stall_alike_and_only_those(name: str) -> None:
    """Seeds' solves with the stall rule: compiled = numpy, and a subset of the full solves.

    Until a problem is given up its iterates are those without the rule, so the problems that
    converge with it converge without it too, to the same q; and some rows stop early (their
    last iterate is not the one without the rule).
    """
    robot = arm(name)
    numeric = family(robot)
    targets = random_configurations(robot, 12, seed=8)
    rotation, position = numeric.chain.forward(targets)
    start = np.tile(numeric.seeds, (len(targets), 1))
    rotation = np.repeat(rotation, len(numeric.seeds), axis=0)
    position = np.repeat(position, len(numeric.seeds), axis=0)
    box = (numeric.lower, numeric.upper)
    constants = np.array([ik.TOLERANCE, ik.DAMPING_SCALE, ik.DAMPING_FLOOR])
    stall = (ik.STALL_STEPS, ik.STALL_RATIO)
    args = (numeric.chain.packed(), start, rotation, position, ik.SEED_ITERATIONS, box, constants)
    solved, converged = ik_kernel.solve_rows(*args, stall)
    whole, whole_converged = ik_kernel.solve_rows(*args)
    reference, reference_converged = ik.solve(
        numeric.chain,
        start,
        rotation,
        position,
        iterations=ik.SEED_ITERATIONS,
        lower=numeric.lower,
        upper=numeric.upper,
        stall=stall,
    )
    np.testing.assert_array_equal(converged, reference_converged)
    np.testing.assert_allclose(solved[converged], reference[converged], rtol=0, atol=Q_ATOL)
    assert not np.any(converged & ~whole_converged)
    np.testing.assert_array_equal(solved[converged], whole[converged])
    assert converged.any()
    assert np.any(solved[~converged] != whole[~converged])


def path_poses(robot: Robot, placements: np.ndarray, waypoints: int) -> tuple[np.ndarray, ...]:
    """The flange poses of the README path at placements (P, 5): (3, 3, P, W), (3, P, W)."""
    problem = PathProblem.of(robot, load_path("curved_line")[:waypoints])
    rotation_o, position_o = flange_at_spin(problem.prepared, 0.0)
    yaws = placements[:, 3]
    rotation = turn_by_yaw(rotation_o.transpose(1, 2, 0), yaws)
    position = turn_by_yaw(position_o.T, yaws) + placements[:, :3].T[:, :, None]
    return rotation, position


@pytest.mark.parametrize("name", ROBOTS)
def test_compiled_paths_equal_numpy_paths(name: str) -> None:
    """solve_path and solve: the same slots, statuses and counts, q to Q_ATOL."""
    compiled, reference = family(arm(name)), family(arm(name, compiled=False))
    x = 0.55 if name == "kr6_urdf" else 0.0
    placements = erk_placements(np.array([x - 0.1, x, x + 0.1]), np.array([0.3, 0.5]), 0.1)
    placements[1::2, 3] = 1.0  # two yaws
    rotation, position = path_poses(arm(name), placements, 40)
    ours, theirs = compiled.solve_path(rotation, position), reference.solve_path(rotation, position)
    np.testing.assert_array_equal(ours.branches_found, theirs.branches_found)
    assert ours.branches_found.max() >= 2  # solutions to compare
    np.testing.assert_array_equal(ours.status, theirs.status)
    np.testing.assert_array_equal(np.isnan(ours.q), np.isnan(theirs.q))
    np.testing.assert_allclose(ours.q, theirs.q, rtol=0, atol=Q_ATOL)
    q, status = compiled.solve(rotation[..., 0], position[..., 0])
    reference_q, reference_status = reference.solve(rotation[..., 0], position[..., 0])
    np.testing.assert_array_equal(status, reference_status)
    np.testing.assert_allclose(q, reference_q, rtol=0, atol=Q_ATOL)


@pytest.mark.parametrize("name", ROBOTS)
def test_compiled_joint_speeds_equal_numpy(name: str) -> None:
    robot = arm(name)
    compiled, reference = family(robot), family(arm(name, compiled=False))
    q = random_configurations(robot, 30, seed=8).T[:, :, None]  # (n, 30, 1)
    q[:, 3] = np.nan  # a branch without a solution
    if robot.dof == 7:  # the xArm7 loses rank at q = 0: numpy (its SVD, the LP) decides there
        q[:, 5] = np.clip(0.0, robot.q_lower, robot.q_upper)[:, None]
    rng = np.random.default_rng(9)
    twist = rng.normal(size=(6, 30, 1))
    point = rng.uniform(-0.5, 0.5, (3, 30, 1))
    ours = compiled.joint_speeds_per_unit_twist(q, twist, point, qdot_max=robot.qdot_max)
    theirs = reference.joint_speeds_per_unit_twist(q, twist, point, qdot_max=robot.qdot_max)
    assert np.isnan(ours[:, 3]).all()
    np.testing.assert_allclose(ours, theirs, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("name", ["panda", "xarm7"])
def test_compiled_free_spin_directions_equal_numpy(name: str) -> None:
    """A seven-joint free spin's least-norm J^+ t and null space (the QR's, numpy's SVD's)."""
    robot = arm(name)
    compiled, reference = family(robot), family(arm(name, compiled=False))
    q = random_configurations(robot, 40, seed=12).T[:, :, None]  # (n, 40, 1)
    q[:, 3] = np.nan
    q[:, 5] = np.clip(0.0, robot.q_lower, robot.q_upper)[:, None]  # the xArm7 loses rank here
    rng = np.random.default_rng(13)
    twist = rng.normal(size=(6, 40, 1))
    point = rng.uniform(-0.5, 0.5, (3, 40, 1))
    ours = compiled.joint_speeds_per_unit_twist(q, twist, point)
    theirs = reference.joint_speeds_per_unit_twist(q, twist, point)
    np.testing.assert_allclose(ours, theirs, rtol=1e-9, atol=1e-12)
    null, null_reference = compiled.null_space(q, point), reference.null_space(q, point)
    assert np.isnan(null[:, 3]).all()
    sign = np.sign(np.sum(null * null_reference, axis=0))  # a null vector's sign is arbitrary
    np.testing.assert_allclose(null * sign, null_reference, rtol=0, atol=1e-9)
    jacobians = [jacobian_in_base(robot, q[:, m, 0]) for m in range(40) if m != 3]
    products = [
        j @ v for j, v in zip(jacobians, np.delete(null[:, :, 0], 3, axis=1).T, strict=True)
    ]
    assert np.abs(products).max() < 1e-9  # J b = 0, pinocchio's J


@pytest.mark.parametrize("name", ROBOTS)
def test_compiled_map_equals_numpy_map_cell_by_cell(name: str) -> None:
    """Reasons, failing waypoints, mu_path and the chosen joint path on every cell."""
    x = 0.4 if name == "kr6_urdf" else 0.0
    xs, ys = np.linspace(x - 0.25, x + 0.25, 4), np.linspace(0.25, 0.65, 3) - (x > 0) * 0.45
    placements = erk_placements(xs, ys, 0.1)
    path = load_path("curved_line")[:50]
    ours = map_cells(arm(name), path, placements)
    theirs = map_cells(arm(name, compiled=False), path, placements)
    np.testing.assert_array_equal(ours.reason, theirs.reason)
    np.testing.assert_array_equal(ours.failed, theirs.failed)
    np.testing.assert_allclose(ours.mu_path, theirs.mu_path, rtol=MU_RTOL, atol=0)
    feasible = np.isfinite(ours.mu_path)
    assert feasible.any()
    np.testing.assert_allclose(ours.chosen[feasible], theirs.chosen[feasible], rtol=0, atol=Q_ATOL)


def test_every_compiled_function_releases_the_gil() -> None:
    """numba's nogil: a map on a worker thread leaves the GIL to the event loop (stop 19)."""
    functions = [
        getattr(module, name)
        for module in (
            chain_kernel,
            ik_kernel,
            lu_kernel,
            seed_kernel,
            follow_kernel,
            redundant_kernel,
            spin_lp,
        )
        for name in dir(module)
        if hasattr(getattr(module, name), "targetoptions")
    ]
    assert len(functions) >= 10
    assert all(function.targetoptions.get("nogil") for function in functions)
