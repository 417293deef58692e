"""The UR5e and UR10e in a cell: MuJoCo Menagerie's collision capsules where the arm is.

Checked against the test's own forward kinematics of Menagerie's chain (numpy and scipy's
rotations; the bodies' numbers as the published files give them), not the service's
placement of them: every part where Menagerie puts it at random configurations. And the cell
audit's two findings (stop 53), both from capsules on the DH segments: a sphere 2 mm into the
real upper arm was clear by 136 mm; the elbow's segment capsule hit wrist 2's where the arm is
clear, refusing placements for a self-collision.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from solver.core.spatial import Placement
from solver.families import get_robot
from solver.path.capability_map import capability_map, grid_axis
from solver.path.cell.checker import CellChecker
from solver.path.cell.published_geometry import PUBLISHED, published_geometry
from solver.path.cell.shapes import Box, Cell, Halfspace, Sphere
from solver.path.problem import PathOptions, PathProblem
from tests.problems import evaluate_path
from tests.solver.test_evaluate import load_path


def _transform(position: tuple[float, ...], wxyz: tuple[float, ...]) -> np.ndarray:
    matrix = np.eye(4)
    w, x, y, z = wxyz
    matrix[:3, :3] = Rotation.from_quat([x, y, z, w]).as_matrix()
    matrix[:3, 3] = position
    return matrix


def menagerie_parts(name: str, q: np.ndarray) -> list[np.ndarray]:
    """Each collision part's frame in the UR base frame {B} at q, body by body, part by part.

    Menagerie's world is {B} turned a quarter turn about z (its joint-2 axis at q = 0 is -x,
    the UR DH model's -y).
    """
    arm = PUBLISHED[name]
    to_base = _transform((0.0, 0.0, 0.0), (np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)))
    frame = to_base @ _transform((0.0, 0.0, 0.0), arm.base_orientation)
    parts = []
    for body, angle in zip(arm.bodies, q, strict=True):
        turn = np.eye(4)
        turn[:3, :3] = Rotation.from_rotvec(np.asarray(body.axis) * angle).as_matrix()
        frame = frame @ _transform(body.position, body.orientation) @ turn
        parts += [frame @ _transform(part.position, part.orientation) for part in body.parts]
    return parts


@pytest.mark.parametrize("name", ["ur5e", "ur10e"])
def test_every_part_is_where_menagerie_puts_it(name: str) -> None:
    robot = get_robot(name)
    geometry = published_geometry(robot)
    assert geometry is not None and geometry.ngeoms == sum(
        len(b.parts) for b in PUBLISHED[name].bodies
    )
    data, gdata = robot.model.createData(), geometry.createData()
    rng = np.random.default_rng(5)
    for _ in range(50):
        q = rng.uniform(-np.pi, np.pi, 6)
        pin.updateGeometryPlacements(robot.model, data, geometry, gdata, q)
        for k, expected in enumerate(menagerie_parts(name, q)):
            placed = gdata.oMg[k]
            # the models' lengths differ by up to 0.7 mm each (Menagerie rounds to the mm)
            assert np.linalg.norm(placed.translation - expected[:3, 3]) < 2.5e-3
            np.testing.assert_allclose(placed.rotation, expected[:3, :3], atol=1e-9)


def test_a_sphere_in_the_upper_arm_collides() -> None:
    """Before: capsules on the DH segments, 0.138 m beside the upper arm: 'clear by 136 mm'."""
    robot, path = get_robot("ur5e"), load_path("curved_line")
    placement = Placement(0.0, 0.45, 0.1, 0.0)
    free = evaluate_path(robot, path, placement)
    assert free.feasible and free.q is not None
    tube = menagerie_parts("ur5e", free.q[60])[2]  # the upper arm's tube, along its z
    side = np.cross(tube[:3, 2], [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    centre = tube[:3, 3] + (0.05 + 0.005 - 0.002) * side  # 2 mm into the 0.05 m tube
    pin_cell = Cell(fixed=(Sphere(0.005, _at(centre), name="pin"),))  # fixed: in {B}
    evaluation = evaluate_path(robot, path, placement, cell=pin_cell, branch=free.branch)
    assert evaluation.reason == "collision"
    assert evaluation.collision is not None
    assert evaluation.collision.robot_part.startswith("shoulder_lift_joint")  # the upper arm
    assert evaluation.collision.waypoint <= 60


def test_no_self_collision_where_the_arm_is_clear() -> None:
    """Before: the elbow's DH capsule in wrist 2's at waypoint 0 (-27.9 mm), where Menagerie's
    parts are 20.8 mm apart or more along the whole path: the placement was refused."""
    robot, path = get_robot("ur5e"), load_path("curved_line")
    placement = Placement(-0.15, 0.3, 0.1, -1.0)
    far = Cell(fixed=(Sphere(0.005, _at(np.array([5.0, 5.0, 5.0])), name="far"),))
    plain = evaluate_path(robot, path, placement)
    evaluation = evaluate_path(robot, path, placement, cell=far)
    assert plain.feasible and evaluation.feasible
    assert evaluation.mu_path == pytest.approx(plain.mu_path, rel=1e-12)
    assert evaluation.branch == plain.branch
    checker = CellChecker(robot, far)
    assert checker.approximated == ()


def _at(position: np.ndarray) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = position
    return pose


# Our capsule along the link, and the Menagerie part (index into menagerie_parts) on its line.
ON_MENAGERIE_LINES = {
    "shoulder_pan_joint_capsule": 1,  # the shoulder's housing, along joint 2's axis
    "shoulder_lift_joint_capsule": 2,  # the upper arm's tube
    "shoulder_lift_joint_housing_capsule": 3,  # the elbow's housing
    "elbow_joint_capsule": 4,  # the forearm's tube
    "elbow_joint_housing_capsule": 5,  # wrist 1's housing
}


@pytest.mark.parametrize("name", ["ur5e", "ur10e"])
def test_link_radii_capsules_follow_the_links(name: str) -> None:
    """With link_radii the capsules run along the links (UR's shoulder and elbow offsets), not
    the DH segments: each on the axis of Menagerie's part there, to 1.5 mm, and parallel."""
    robot = get_robot(name)
    checker = CellChecker(robot, Cell(link_radii=(0.05,) * 7))
    geometry = checker.geometry
    names = [obj.name for obj in geometry.geometryObjects]
    data, gdata = robot.model.createData(), geometry.createData()
    rng = np.random.default_rng(2)
    for _ in range(20):
        q = rng.uniform(-np.pi, np.pi, 6)
        pin.updateGeometryPlacements(robot.model, data, geometry, gdata, q)
        parts = menagerie_parts(name, q)
        for ours, theirs in ON_MENAGERIE_LINES.items():
            placed = gdata.oMg[names.index(ours)]
            axis, their = placed.rotation[:, 2], parts[theirs]
            off_line = np.cross(their[:3, 3] - placed.translation, axis)
            assert np.linalg.norm(off_line) < 1.5e-3, (ours, np.linalg.norm(off_line))
            assert abs(abs(axis @ their[:3, 2]) - 1.0) < 1e-9


def _table(kind: str, top: float) -> Halfspace | Box:
    if kind == "halfspace":
        return Halfspace((0.0, 0.0, 1.0), top, name="table")
    return Box((3.0, 3.0, 0.1), _at(np.array([0.0, 0.0, top - 0.05])), name="table")


@pytest.mark.parametrize("kind", ["halfspace", "box"])
@pytest.mark.parametrize("name", ["ur5e", "ur10e"])
def test_a_table_at_the_mounting_face_changes_nothing(name: str, kind: str) -> None:
    """The contract audit (stop 54): Menagerie's UR10e shoulder capsule reaches 27 mm below the
    face the arm stands on, and every placement on a table there collided; the UR5e's, 3 mm
    above it, collided on a box table. Against a far sphere (self-collision on in both), the
    same map cell for cell; a table top 5 cm up cuts the shoulder: every cell collides."""
    robot, path = get_robot(name), load_path("curved_line")[::4]
    axes = {
        "xs": grid_axis(-0.2, 0.2, 0.2, field="x"),
        "ys": grid_axis(0.4, 0.6, 0.2, field="y"),
        "z": 0.1,
        "yaws": np.array([0.0]),
    }
    far = Cell(fixed=(Sphere(0.005, _at(np.array([5.0, 5.0, 5.0])), name="far"),))
    maps = [
        capability_map(PathProblem.of(robot, path, PathOptions(cell=cell)), **axes)  # type: ignore[arg-type]
        for cell in (far, Cell(fixed=(_table(kind, 0.0),)), Cell(fixed=(_table(kind, 0.05),)))
    ]
    assert (maps[0].reason == -1).sum() >= 4
    np.testing.assert_array_equal(maps[1].reason, maps[0].reason)
    np.testing.assert_array_equal(maps[1].mu_path, maps[0].mu_path)
    assert np.all(maps[2].reason == 4)  # collision everywhere
