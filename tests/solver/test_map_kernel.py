"""The compiled map kernel equals the numpy pipeline, its reference, cell by cell (issue 12).

Every comparison runs :func:`solver.path.placements.evaluate_placements` twice on the same
placements: compiled (the default for UR and OPW arms in fixed spin) and ``compiled=False``
(the numpy pipeline, itself checked against an LP, pinocchio and independent IK elsewhere).
mu_path and V_max along the chosen branch agree to 1e-12 relative; the reason, the failed
waypoint, the branch, the bottleneck waypoint and joint are identical. With joint acceleration
limits (``accelerations``: every joint's, rad/s^2) the acceleration columns too: what binds
mu_acc, its waypoint and joint identical, mu_acc and V_acc to the rounding of the joint angles
through D_i (:data:`tests.cases.KERNEL_ACC_ULPS`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import solver.path.placements
from solver.core.codes import REASONS
from solver.core.family import Branch
from solver.core.kinematics import tool_pose_in_base
from solver.core.robots import Robot
from solver.families import get_robot
from solver.families.opw.kernel import kernel_parameters
from solver.path.placements import PlacementResults
from tests.cases import KERNEL_ACC_ULPS
from tests.problems import evaluate_placements, prepare_path
from tests.solver.families.test_opw import build
from tests.solver.test_evaluate import load_path, wrist_singular_path
from tests.solver.test_parallel import grid_placements

COLUMNS = ("reason", "failed_waypoint", "branch", "bottleneck_waypoint", "bottleneck_joint")
ACC_COLUMNS = ("limited_by", "acc_waypoint", "acc_joint")
# Joint acceleration limits the comparisons run with (rad/s^2, every joint's): None (none),
# binding on nearly every cell, so large that the speed limits bind (mu_acc = mu_path), and
# one per joint (each joint's limit its own).
ACCELERATIONS: list[float | tuple[float, ...] | None] = [
    None,
    10.0,
    3.0,
    1e6,
    (12.0, 10.0, 14.0, 30.0, 8.0, 6.0),
]
Accelerations = float | tuple[float, ...] | None


def grid(xs: np.ndarray, ys: np.ndarray, z: float, yaws: np.ndarray) -> np.ndarray:
    """Placements (P, 4), yaw-major, as a map orders them."""
    yaw, y, x = np.meshgrid(yaws, ys, xs, indexing="ij")
    return np.column_stack([x.ravel(), y.ravel(), np.full(x.size, z), yaw.ravel()])


def same_cells(
    robot: Robot,
    waypoints: np.ndarray,
    placements: np.ndarray,
    rtol: float = 1e-12,
    **options: object,
) -> tuple[PlacementResults, set[str]]:
    """Assert the kernel's cells equal the reference's; the results and the reasons seen.

    ``accelerations`` (rad/s^2, every joint's or one per joint; None: no limits) among the
    options; ``rtol`` on mu_path, V_max and mu_acc.
    """
    acceleration = options.pop("accelerations", None)
    if acceleration is not None:
        limits = np.broadcast_to(np.asarray(acceleration, dtype=float), (robot.dof,))
        robot = robot.with_options(qddot_max=list(limits))
    path = prepare_path(robot, waypoints, passes=options.pop("passes", None))  # type: ignore[arg-type]
    compiled = evaluate_placements(robot, path, placements, with_speeds=True, **options)  # type: ignore[arg-type]
    numpy = evaluate_placements(
        robot,
        path,
        placements,
        with_speeds=True,
        compiled=False,
        **options,  # type: ignore[arg-type]
    )
    for name in COLUMNS:
        np.testing.assert_array_equal(getattr(compiled, name), getattr(numpy, name), err_msg=name)
    np.testing.assert_array_equal(np.isnan(compiled.mu_path), np.isnan(numpy.mu_path))
    np.testing.assert_allclose(compiled.mu_path, numpy.mu_path, rtol=rtol, atol=0.0)
    np.testing.assert_allclose(compiled.v_max, numpy.v_max, rtol=rtol, atol=0.0)
    if acceleration is None:
        assert compiled.mu_acc is None and numpy.mu_acc is None
    else:
        lowest = float(np.min(acceleration))  # type: ignore[call-overload]
        same_acceleration_cells(compiled, numpy, lowest, path.options.blend_length, 2 * rtol)
    reasons = {REASONS[r] for r in numpy.reason if r >= 0}
    if np.isfinite(numpy.mu_path).any():
        reasons.add("feasible")
    return compiled, reasons


def same_acceleration_cells(
    compiled: PlacementResults,
    numpy: PlacementResults,
    acceleration: float,
    blend: float,
    rtol: float = 2e-12,
) -> None:
    """Assert the acceleration columns agree: discrete ones identical, mu_acc and V_acc to the
    rounding of the joint angles through D_i (on 1 / V^2, which is linear in |D|; ``acceleration``
    the lowest joint limit), ``rtol`` relative."""
    for name in ACC_COLUMNS:
        np.testing.assert_array_equal(getattr(compiled, name), getattr(numpy, name), err_msg=name)
    assert compiled.mu_acc is not None and numpy.mu_acc is not None
    assert compiled.v_acc is not None and numpy.v_acc is not None
    rounding = KERNEL_ACC_ULPS * np.spacing(2 * math.pi) * 4 / blend**2 / acceleration
    for ours, theirs in ((compiled.mu_acc, numpy.mu_acc), (compiled.v_acc, numpy.v_acc)):
        np.testing.assert_array_equal(np.isnan(ours), np.isnan(theirs))
        np.testing.assert_array_equal(np.isinf(ours), np.isinf(theirs))
        np.testing.assert_allclose(ours**-2.0, theirs**-2.0, rtol=rtol, atol=rounding)
    feasible = ~np.isnan(numpy.mu_acc)
    assert np.all(compiled.mu_acc[feasible] <= compiled.mu_path[feasible])


@pytest.mark.parametrize("acceleration", [None, 10.0])
@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
def test_the_compiled_kernel_is_what_runs(
    monkeypatch: pytest.MonkeyPatch, spin_mode: str, acceleration: float | None
) -> None:
    """A UR map never touches the numpy pipeline, in either spin mode, with or without
    acceleration limits (else the equality is moot): the fixed-spin kernel here, the
    free-spin one in test_free_spin_kernel.py."""

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("the numpy pipeline ran")

    monkeypatch.setattr(solver.path.placements, "run_chunk", refuse)
    robot = get_robot("ur5")
    if acceleration is not None:
        robot = robot.with_options(qddot_max=[acceleration] * 6)
    path = prepare_path(robot, load_path("curved_line"))
    cell = np.array([[0.0, 0.45, 0.1, 0.0]])
    mode = {"spin_mode": spin_mode}
    assert np.isfinite(evaluate_placements(robot, path, cell, **mode).mu_path[0])  # type: ignore[arg-type]
    with pytest.raises(AssertionError, match="numpy pipeline"):
        evaluate_placements(robot, path, cell, compiled=False, **mode)  # type: ignore[arg-type]


@pytest.mark.parametrize("accelerations", ACCELERATIONS)
def test_erk_grid(accelerations: Accelerations) -> None:
    """The ERK 2021 map: UR5, 546 cells, 133 waypoints, one yaw."""
    placements = grid(
        np.arange(-0.25, 0.25 + 1e-9, 0.02), np.arange(0.25, 0.65 + 1e-9, 0.02), 0.1, np.zeros(1)
    )
    robot = get_robot("ur5")
    result, _ = same_cells(robot, load_path("curved_line"), placements, accelerations=accelerations)
    assert len(placements) == 546 and np.isfinite(result.mu_path).all()
    if accelerations is not None:  # the limits bind on every cell, or (1e6) on none
        assert result.limited_by is not None
        assert set(result.limited_by) == {0 if np.min(accelerations) > 100.0 else 1}


@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
@pytest.mark.parametrize("seed", range(4))
def test_seeded_placements_with_acceleration_limits(spin_mode: str, seed: int) -> None:
    """Pruning by mu_acc (solver.kernels.acc_cells) keeps the unpruned choice: seeded
    placements in a random order (so the branch followed first is often not the best, and
    near neighbours share their bottlenecks less), random per-joint limits, each cell against
    the numpy pipeline, which forms mu_acc on every branch."""
    rng = np.random.default_rng(seed)
    placements = np.column_stack(
        [
            rng.uniform(-0.35, 0.35, 60),
            rng.uniform(0.2, 0.75, 60),
            np.full(60, 0.1),
            rng.uniform(-math.pi, math.pi, 60),
        ]
    )
    limits = tuple(rng.uniform(2.0, 40.0, 6))
    result, reasons = same_cells(
        get_robot("ur5"),
        load_path("curved_line"),
        placements,
        accelerations=limits,
        spin_mode=spin_mode,
    )
    assert "feasible" in reasons and result.limited_by is not None
    assert 1 in set(result.limited_by)


@pytest.mark.parametrize("accelerations", [None, 10.0])
def test_eight_yaw_grid(accelerations: float | None) -> None:
    """8 yaws in one call: the kernel takes mixed yaws, the numpy pipeline one at a time."""
    placements = grid_placements()
    rng = np.random.default_rng(3)
    shuffled = placements[rng.permutation(len(placements))]  # yaws mixed in every chunk
    robot, waypoints = get_robot("ur5"), load_path("s_curve")
    _, reasons = same_cells(robot, waypoints, shuffled, accelerations=accelerations)
    assert {"feasible", "unreachable"} <= reasons


@pytest.mark.parametrize("accelerations", [None, 10.0])
def test_wide_grid_with_every_reason(accelerations: float | None) -> None:
    """Unreachable, joint-limit, singular and discontinuous cells, each as the reference says."""
    seen: set[str] = set()
    wide = grid(
        np.linspace(-1.0, 1.0, 11), np.linspace(-1.0, 1.0, 11), 0.1, np.array([0.0, 2.0, -2.5])
    )
    for robot in (
        get_robot("ur5"),
        # Limits narrower than a turn (the arc test) and exactly a turn (the exact test).
        dataclasses.replace(
            get_robot("ur5e"), q_lower=np.full(6, -math.pi / 2), q_upper=np.full(6, math.pi)
        ),
        dataclasses.replace(
            get_robot("ur5e"), q_lower=np.full(6, -math.pi), q_upper=np.full(6, math.pi)
        ),
    ):
        _, reasons = same_cells(robot, load_path("curved_line"), wide, accelerations=accelerations)
        seen |= reasons
    robot = get_robot("ur5e")
    singular = grid(np.array([-0.05, 0.0, 0.05]), np.array([0.0, 0.05]), 0.0, np.array([0.0, 0.2]))
    for branch in (None, Branch.named(shoulder="left", elbow="up", wrist="flip")):
        result, reasons = same_cells(
            robot, wrist_singular_path(robot), singular, branch=branch, accelerations=accelerations
        )
        seen |= reasons
    assert REASONS[result.reason[1]] == "singular" and result.failed_waypoint[1] == 2
    assert {"feasible", "unreachable", "joint_limits", "singular", "discontinuous"} <= seen


@pytest.mark.parametrize("accelerations", ACCELERATIONS)
def test_steps_passes_and_one_branch(accelerations: Accelerations) -> None:
    """A tight step, no step bound, a rapid between passes, a fixed branch."""
    robot = get_robot("ur10")
    waypoints = load_path("s_curve")
    placements = grid(np.linspace(-0.6, 0.6, 7), np.linspace(0.2, 1.0, 5), 0.2, np.array([0.5]))
    acc = {"accelerations": accelerations}
    _, tight = same_cells(robot, waypoints, placements, max_joint_step=0.02, **acc)
    assert "discontinuous" in tight
    same_cells(robot, waypoints, placements, max_joint_step=4.0, **acc)
    half = len(waypoints) // 2
    same_cells(robot, waypoints, placements, passes=[(0, half), (half, len(waypoints))], **acc)
    branch = Branch.named(shoulder="right", elbow="down", wrist="noflip")
    result, _ = same_cells(robot, waypoints, placements, branch=branch, **acc)
    assert set(result.branch) == {robot.family.branch_index(branch)}  # type: ignore[union-attr]


# OPW arms and the reasons their wide grid shows: catalogue limits (narrow arcs), offsets and
# sign corrections, b != 0.
OPW_CASES = [
    ("kuka_kr6_r700_sixx", {"feasible", "unreachable", "joint_limits", "discontinuous"}),
    ("abb_irb2400", {"feasible", "unreachable", "joint_limits", "discontinuous"}),
    ("offsets_everywhere", {"feasible", "unreachable", "joint_limits"}),
]


def opw_grid(robot: Robot) -> np.ndarray:
    """Placements around the arm out to 1.2 times its reach, three yaws."""
    reach = robot.family.parameters.c2 + robot.family.parameters.c3  # type: ignore[union-attr]
    span = np.linspace(-1.2 * reach, 1.2 * reach, 9)
    return grid(span, span, 0.1, np.array([0.0, 1.0, -2.0]))


@pytest.mark.parametrize("accelerations", [None, 10.0])
@pytest.mark.parametrize(("name", "expected"), OPW_CASES)
def test_opw_arms(name: str, expected: set[str], accelerations: float | None) -> None:
    """OPW: catalogue limits (narrow arcs), offsets and sign corrections, b != 0; singular
    cells in test_opw_singular_wrist."""
    robot = build(name)
    grid_ = opw_grid(robot)
    _, reasons = same_cells(robot, load_path("curved_line"), grid_, accelerations=accelerations)
    assert expected <= reasons


def test_opw_singular_wrist() -> None:
    """An OPW path through theta5 = 0 at waypoint 2 of the placement (0, 0, 0, 0): singular
    there on the branch it was made on, on each branch as the reference says."""
    robot = build("kuka_kr6_r700_sixx")
    family = robot.family
    assert family is not None
    p = family.parameters  # type: ignore[attr-defined]
    theta = np.tile([0.3, -0.2, 0.4, 0.5, 0.0, 0.7], (5, 1))
    theta[:, 4] = np.linspace(-0.2, 0.2, 5)
    theta[:, 0] += np.linspace(0.0, 0.1, 5)
    q = (theta + np.array(p.offsets)) * np.array(p.sign_corrections)
    waypoints = np.array([tool_pose_in_base(robot, row) for row in q])
    placements = grid(np.array([-0.02, 0.0]), np.array([0.0, 0.03]), 0.0, np.array([0.0, 0.1]))
    at_origin = []
    for branch in family.branches:
        result, _ = same_cells(robot, waypoints, placements, branch=branch)
        at_origin.append((REASONS[result.reason[1]], int(result.failed_waypoint[1])))
    assert ("singular", 2) in at_origin


def test_opw_kernel_parameters_carry_offsets_as_pairs() -> None:
    p = build("offsets_everywhere").family.parameters  # type: ignore[union-attr]
    values = kernel_parameters(p)
    np.testing.assert_allclose(values[7:13] + 1j * values[13:19], np.exp(1j * np.array(p.offsets)))
    np.testing.assert_array_equal(values[19:], p.sign_corrections)
