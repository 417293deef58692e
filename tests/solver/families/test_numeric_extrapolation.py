"""A six-joint numeric arm's waypoint solves start from the extrapolated solutions before them.

``ik.PREDICT_SMOOTH``: where the last four joint steps are smooth, the next solve starts at
q_(w-1) + 4 s_1 - 6 s_2 + 4 s_3 - s_4 (one damped step then meets the tolerance, against three
from q_(w-1)); at a corner of the path, from q_(w-1). Known answers: the extrapolation is exact
for a quartic (algebra); a raster's corners are where its Cartesian steps change (geometry); the
maps
equal the analytic UR5's on every cell of a raster with its corners, as on the ERK path
(tests/solver/families/test_numeric_vs_analytic_map.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.spatial import Placement
from solver.families import get_robot
from solver.families.numeric import ik
from solver.families.numeric.ik_kernel import extrapolated
from solver.path.capability_map import grid_axis
from tests.solver.families.numeric_maps import erk_placements, map_cells, same_path, ur5_from_urdf

MU_RTOL = 1e-10  # as tests/solver/families/test_numeric_vs_analytic_map.py
Q_ATOL = 1e-8
REVOLUTE = np.ones(6, dtype=bool)


def raster(step: float = 0.005, stepover: float = 0.01, rows: int = 4) -> np.ndarray:
    """A zig-zag of ``rows`` lines 120 mm long along x, the tool straight down: (W, 4, 4).

    Each line is followed the other way from the one before, a stepover apart in y: two right
    angles at each end.
    """
    line = np.arange(-0.06, 0.06 + 1e-12, step)
    points = [(x, r * stepover) for r in range(rows) for x in (line if r % 2 == 0 else line[::-1])]
    poses = np.tile(np.eye(4), (len(points), 1, 1))
    poses[:, :3, :3] = np.diag([1.0, -1.0, -1.0])
    poses[:, :2, 3] = points
    return poses


def test_a_quartic_joint_path_is_extrapolated_exactly() -> None:
    # q(w) = a + b w + c w^2 + d w^3 + e w^4 per joint, dyadic numbers: every sum is exact.
    a = np.array([1, -2, 3, 0, 5, -8]) / 64.0
    b = np.array([8, -8, 6, 10, -7, 9]) / 64.0
    c = np.array([1, 0, 2, -1, 1, 0]) / 256.0
    d = np.array([0, 1, -1, 1, 0, 2]) / 1024.0
    e = np.array([1, 0, 0, -1, 1, 0]) / 8192.0
    q = np.array([a + b * w + c * w**2 + d * w**3 + e * w**4 for w in range(6)])  # (6, 6)
    start, predicted = ik.extrapolated(q[4][None], q[None, :5])
    assert bool(predicted[0])
    np.testing.assert_array_equal(start[0], q[5])


@pytest.mark.parametrize(
    "steps",
    [
        [0.01, 0.01, 0.01, -0.01],  # a reversal: 4 s_1 - 6 s_2 + 4 s_3 - s_4 = -7 s
        [0.01, 0.01, 0.01, 0.03],  # a step three times the one before
        [0.0, 0.0, 0.0, 0.0],  # standing still: nothing to extrapolate
        [0.01, 0.01, np.nan, 0.01],  # a waypoint without a solution
    ],
)
def test_a_corner_or_no_motion_starts_from_the_last_solution(steps: list[float]) -> None:
    history = np.zeros((1, 5, 6))
    history[0, 1:, 0] = np.cumsum(steps)  # joint 1 moves, the others stand
    start, predicted = ik.extrapolated(history[:, 4], history)
    assert not predicted[0]
    np.testing.assert_array_equal(start, history[:, 4])


def test_the_compiled_rule_is_the_numpy_rule() -> None:
    """On wrapped solutions (the kernels' q), across the +-pi seam too, as the numpy reference."""
    rng = np.random.default_rng(7)
    flags = []
    for case in range(200):
        base = rng.uniform(-np.pi, np.pi, 6)
        moves = rng.normal(0.0, 0.05, 6) * np.arange(5)[:, None]  # (5, 6), straight
        noise = rng.normal(0.0, 10.0 ** rng.uniform(-6, -1), (5, 6))  # smooth or not, at random
        history = base + moves + noise  # (5, 6), unwrapped
        start, predicted = ik.extrapolated(history[4][None], history[None])
        wrapped = (history + np.pi) % (2 * np.pi) - np.pi
        qs = np.full((6, 7), np.nan)
        qs[:, 1:6] = wrapped.T  # waypoints 1..5 solved, waypoint 6 next
        slot = history[4].copy()
        moved = extrapolated(slot, qs, 6, REVOLUTE, ik.PREDICT_SMOOTH)
        assert moved == predicted[0], case
        np.testing.assert_allclose(slot, start[0], rtol=0, atol=1e-13)
        flags.append(moved)
    assert 20 < sum(flags) < 180  # both kinds of history were compared


def test_the_raster_is_extrapolated_along_its_lines_and_not_at_its_corners() -> None:
    """The rule on the analytic UR5's joint path: smooth where the Cartesian steps are equal."""
    path = raster()
    placement = Placement(x=0.0, y=0.45, z=0.1, yaw=0.0)
    poses = placement.transform_workpiece_to_base() @ path
    robot = get_robot("ur5")
    q, status = robot.family.solve(poses[:, :3, :3].transpose(1, 2, 0), poses[:, :3, 3].T)
    branch = int(np.flatnonzero(np.all(np.isfinite(q[0]), axis=-1))[0])
    joints = np.unwrap(q[:, branch].T, axis=0)  # (W, 6)
    points = path[:, :3, 3]
    for w in range(5, len(path)):
        _, predicted = ik.extrapolated(joints[w - 1][None], joints[None, w - 5 : w])
        steps = np.diff(points[w - 5 : w], axis=0)
        straight = bool(np.allclose(steps, steps[0], rtol=0, atol=1e-12))
        assert predicted[0] == straight, w


def test_a_raster_maps_as_the_analytic_ur5_on_every_cell() -> None:
    path = raster()
    placements = erk_placements(
        grid_axis(-0.25, 0.25, 0.05, field="x"), grid_axis(0.25, 0.65, 0.05, field="y"), 0.1
    )
    analytic = map_cells(get_robot("ur5"), path, placements)
    ours = map_cells(ur5_from_urdf(), path, placements)
    feasible = np.isfinite(analytic.mu_path)
    assert feasible.sum() > 50
    np.testing.assert_array_equal(ours.reason, analytic.reason)
    np.testing.assert_array_equal(ours.failed, analytic.failed)
    np.testing.assert_allclose(ours.mu_path, analytic.mu_path, rtol=MU_RTOL, atol=0)
    for cell in np.flatnonzero(feasible):
        assert any(same_path(ours.chosen[cell], q, Q_ATOL) for q in analytic.tied[cell]), cell
