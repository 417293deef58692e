"""Free spin's spun paths by the compiled kernel equal the numpy arithmetic, cell by cell.

Where the spin moves more than the last joint (an angled or offset spindle), each branch is
solved again at its spun poses (solver/path/exact_spin.py); on a closed-form family that is the
compiled :mod:`solver.kernels.spun_rows`, and with ``compiled=False`` the numpy arithmetic it
replaced (itself checked against forward kinematics and a DTF written in the test in
tests/solver/test_exact_spin.py). As tests/solver/test_map_kernel.py compares the map kernels:
the same reasons, failed waypoints, branches and bottlenecks, mu_path and V_max to 1e-12
relative, mu_acc to the rounding of the joint angles; here for UR and OPW arms, a UR arm read
from its URDF (a base turned half a turn, a flange the family's own is offset from), one tilted
1 mrad, passes, a tight step, a fixed branch and a segment turning nearly half a turn.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import solver.path.exact_spin
from solver.core.family import Branch
from solver.core.robots import Robot, example_robot_data_dir
from solver.families import get_robot, robot_from_urdf
from tests.problems import evaluate_placements, prepare_path
from tests.solver.families.test_opw import build
from tests.solver.test_evaluate import load_path
from tests.solver.test_map_kernel import OPW_CASES, grid, opw_grid, same_cells

FREE = {"spin_mode": "free", "rtol": 1e-11}
"""Free spin, mu_path and V_max compared to 1e-11: the spun paths' schedules carry the rounding
of the joints into the spins (each round's rates come from the LP at the last round's joints),
where some cells are conditioned far beyond the 1e-12 the other kernels hold. Measured on the
IRB 2400 of :func:`test_opw_arms_with_an_angled_tool` (its cell 20): the numpy reference itself,
the placement moved by 1e-16 m, changes V_max by 1.2e-12 and mu_path by 4e-13; the kernel
differs from it there by 1.6e-12, everywhere else by less than 1e-12."""
ANGLED = (0.5, (0.03, 0.0, 0.12))
"""A tool turned 0.5 rad about the flange's y, its point 3 cm off the flange's axis."""


def _tcp(tilt: float, offset: tuple[float, float, float]) -> np.ndarray:
    """A tool point ``offset`` from the flange, its z turned ``tilt`` about the flange's y."""
    tcp = np.eye(4)
    tcp[:3, :3] = Rotation.from_rotvec([0.0, tilt, 0.0]).as_matrix()
    tcp[:3, 3] = offset
    return tcp


def _angled(robot: Robot, tilt: float = ANGLED[0], offset: tuple[float, ...] = ANGLED[1]) -> Robot:
    return robot.with_options(transform_tool_to_tcp=_tcp(tilt, offset))  # type: ignore[arg-type]


def _erk_grid(step: float = 0.05) -> np.ndarray:
    """The ERK 2021 map's area at a coarser step, three yaws."""
    xs = np.arange(-0.25, 0.25 + 1e-9, step)
    ys = np.arange(0.25, 0.65 + 1e-9, step)
    return grid(xs, ys, 0.1, np.array([0.0, 0.6, -2.0]))


def _ur5_urdf(mount: str = "") -> Robot:
    """The UR5 of example-robot-data read from base_link to ee_link (recognised: its DH base
    half a turn from base_link, ee_link turned on the family's flange), on ``mount`` where
    given."""
    urdf = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    if not mount:
        return robot_from_urdf(urdf, base_frame="base_link", tool_frame="ee_link")
    urdf = urdf.replace("</robot>", mount + "</robot>")
    return robot_from_urdf(urdf, base_frame="cell", tool_frame="ee_link")


@pytest.mark.parametrize("accelerations", [None, 10.0])
def test_an_angled_ur5_on_the_erk_area(accelerations: float | None) -> None:
    robot = _angled(get_robot("ur5"))
    result, reasons = same_cells(
        robot, load_path("curved_line"), _erk_grid(), accelerations=accelerations, **FREE
    )
    assert "feasible" in reasons
    assert np.isfinite(result.mu_path).sum() > 50


def test_an_offset_spindle_and_the_s_curve() -> None:
    """Tool z along the flange's, 5 cm off its axis: offset, not angled."""
    robot = _angled(get_robot("ur10"), 0.0, (0.0, 0.05, 0.15))
    placements = grid(np.linspace(-0.6, 0.6, 7), np.linspace(0.2, 1.0, 5), 0.2, np.array([0.5]))
    _, reasons = same_cells(robot, load_path("s_curve"), placements, **FREE)
    assert "feasible" in reasons


@pytest.mark.parametrize(("name", "expected"), OPW_CASES)
def test_opw_arms_with_an_angled_tool(name: str, expected: set[str]) -> None:
    robot = _angled(build(name), 0.4, (0.0, 0.04, 0.1))
    placements = opw_grid(robot)[::3]
    _, reasons = same_cells(robot, load_path("curved_line"), placements, **FREE)
    assert {"feasible", "unreachable"} <= reasons


def test_a_ur5_read_from_its_urdf_turned_offset_and_tilted() -> None:
    """The family solves in a frame turned from {B} for its own flange; then on a cell 1 mrad
    off level (the tilted closed form, its poses written in its frame block by block)."""
    waypoints, placements = load_path("curved_line"), _erk_grid(0.1)
    recognised = _ur5_urdf()
    assert recognised.family.base_turn is not None  # type: ignore[union-attr]
    assert recognised.family.flange_offset is not None  # type: ignore[union-attr]
    _, reasons = same_cells(_angled(recognised), waypoints, placements, **FREE)
    assert "feasible" in reasons
    mount = '<link name="cell"/><joint name="mount" type="fixed"><parent link="cell"/>'
    mount += '<child link="world"/><origin xyz="0 0 0" rpy="0.001 0 0"/></joint>'
    tilted = _ur5_urdf(mount)
    assert tilted.family.tilted  # type: ignore[union-attr]
    _, reasons = same_cells(_angled(tilted), waypoints, placements, **FREE)
    assert "feasible" in reasons


def test_passes_a_tight_step_and_a_fixed_branch() -> None:
    robot = _angled(get_robot("ur5e"))
    waypoints, placements = load_path("curved_line"), _erk_grid(0.1)
    _, tight = same_cells(robot, waypoints, placements, max_joint_step=0.02, **FREE)
    assert "discontinuous" in tight
    same_cells(robot, waypoints, placements, passes=[(0, 60), (60, 133)], **FREE)
    fixed = Branch.named(shoulder="right", elbow="down", wrist="noflip")
    result, _ = same_cells(robot, waypoints, placements, branch=fixed, **FREE)
    assert set(result.branch) == {robot.family.branch_index(fixed)}  # type: ignore[union-attr]


def _nearly_half_turn() -> np.ndarray:
    """A straight line whose tool turns 3.14 rad about its own x between waypoints 3 and 4."""
    poses = np.tile(np.eye(4), (8, 1, 1))
    poses[:, 0, 3] = np.linspace(0.0, 0.07, 8)
    turn = Rotation.from_rotvec([math.pi - 1.6e-3, 0.0, 0.0]).as_matrix()
    poses[4:, :3, :3] = turn @ Rotation.from_rotvec([0.2, 0.0, 0.0]).as_matrix()
    poses[:4, :3, :3] = Rotation.from_rotvec([0.2, 0.0, 0.0]).as_matrix()
    return poses


def test_a_segment_turning_nearly_half_a_turn_is_solved_as_numpy_does(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Within 1e-2 rad of a half turn the rotation vector is pinocchio's log3 (numpy): the
    kernel hands such rows back to the numpy arithmetic, and the answers are the reference's."""
    handed_back = []
    numpy_arithmetic = solver.path.exact_spin._spun_numpy

    def counted(*args: object, **kwargs: object) -> object:
        handed_back.append(True)
        return numpy_arithmetic(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(solver.path.exact_spin, "_spun_numpy", counted)
    robot = _angled(get_robot("ur5"))
    placements = grid(np.linspace(-0.2, 0.2, 3), np.array([0.4, 0.5]), 0.1, np.zeros(1))
    result = evaluate_placements(
        robot,
        prepare_path(robot, _nearly_half_turn()),
        placements,
        spin_mode="free",
        max_joint_step=4.0,
    )
    assert handed_back and np.isfinite(result.mu_path).any()
    same_cells(robot, _nearly_half_turn(), placements, max_joint_step=4.0, **FREE)


def test_the_kernel_is_what_solves_a_closed_form_familys_spun_paths(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Else the equality above is moot: an angled UR5's map never takes the numpy arithmetic,
    which ``compiled=False`` takes."""

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("the numpy arithmetic ran")

    monkeypatch.setattr(solver.path.exact_spin, "_spun_numpy", refuse)
    robot = _angled(get_robot("ur5"))
    path = prepare_path(robot, load_path("curved_line"))
    cell = np.array([[0.0, 0.45, 0.1, 0.0]])
    result = evaluate_placements(robot, path, cell, spin_mode="free")
    assert np.isfinite(result.mu_path[0])
    with pytest.raises(AssertionError, match="numpy arithmetic"):
        evaluate_placements(robot, path, cell, spin_mode="free", compiled=False)
