"""An arm on a wall or a ceiling, read from its cell's frame, keeps its closed form.

A URDF's chain from a frame in which joint 1 is not upright (a cell's floor frame, the arm
fixed to a wall or hanging from a ceiling) was numeric IK: the closed forms solve in a frame
whose z is joint 1's axis. The chain is now read in {B} tilted onto that axis
(:func:`solver.families.recognise.first_axis_tilt`). The known answer: the same arm read from
its own root, given the path moved into that root by the mounting's transform (pinocchio's
``rpyToMatrix`` of the URDF's ``rpy``) and placed at the origin: the same feasibility, mu_path
and joint path at every placement, in fixed and free spin. Numeric IK on the tilted chain
gives the same map too.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import solver.path.placements
from solver.core.kinematics import tool_pose_in_base
from solver.core.robots import Robot, chain_from_urdf, example_robot_data_dir
from solver.core.spatial import Placement
from solver.families import robot_from_urdf
from solver.families.base import ClosedFormFamily
from solver.families.kernels import TILT_PARAMETERS, TILTED
from solver.families.numeric.family import NumericFamily
from solver.families.opw.arms import ARMS
from solver.optimise.search_space import PlacementBounds
from solver.path.capability_map import CapabilityMap, grid_axis
from tests.cases import FK_IK_ATOL, MAP_EVALUATE_RTOL
from tests.problems import capability_map, evaluate_path, optimize_placement
from tests.solver.families.test_opw_recognised import urdf_text
from tests.solver.test_evaluate import load_path
from tests.solver.test_map_kernel import grid as map_grid
from tests.solver.test_map_kernel import same_cells

WALL = ((0.1, 0.2, 0.6), (math.pi / 2, 0.3, 0.2))  # xyz, rpy: on a wall, turned a little
CEILING = ((0.0, 0.1, 1.2), (math.pi, 0.0, 0.4))  # hanging: joint 1's axis along -z
SLOPE = ((0.0, 0.1, 0.3), (math.pi / 4, 0.0, 0.3))  # on a 45 degree slope


def mounted(text: str, root: str, mount: tuple[tuple[float, ...], tuple[float, ...]]) -> str:
    """URDF text with a new root ``cell`` holding the old root ``root`` at ``mount``."""
    xyz, rpy = (" ".join(repr(float(v)) for v in values) for values in mount)
    return text.replace(
        "</robot>",
        f'<link name="cell"/><joint name="mount" type="fixed"><parent link="cell"/>'
        f'<child link="{root}"/><origin xyz="{xyz}" rpy="{rpy}"/></joint></robot>',
    )


def ur5_text() -> str:
    return (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()


ARMS_MOUNTED = {  # name: (URDF text, its root, a grid of placements in front of the mount)
    "ur5": (ur5_text(), "world", 0.6),
    ARMS[0].name: (urdf_text(ARMS[0]), "base_link", ARMS[0].parameters.c2 + ARMS[0].parameters.c3),
}


def robots(name: str, mount: tuple[tuple[float, ...], tuple[float, ...]]) -> tuple[Robot, Robot]:
    """The arm read from the cell's frame, and from its own root."""
    text, root, _ = ARMS_MOUNTED[name]
    tilted = robot_from_urdf(mounted(text, root, mount), base_frame="cell", tool_frame="tool0")
    return tilted, robot_from_urdf(text, base_frame=root, tool_frame="tool0")


def in_root(mount: tuple[tuple[float, ...], tuple[float, ...]], placement: Placement) -> np.ndarray:
    """T_root_O: the placement's workpiece frame in the arm's root (pinocchio's rpy)."""
    xyz, rpy = mount
    cell_root = pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz)).homogeneous
    return np.linalg.inv(cell_root) @ placement.transform_workpiece_to_base()


def grid(name: str, mount: tuple[tuple[float, ...], tuple[float, ...]]) -> dict[str, object]:
    """A small grid of placements around the arm's reach from its mount, in the cell's frame."""
    reach = ARMS_MOUNTED[name][2]
    (x, y, z), _ = mount
    low = -0.7 * reach if mount is WALL else -0.5 * reach
    return {
        "xs": grid_axis(x - 0.5 * reach, x + 0.5 * reach, reach / 6, field="x"),
        "ys": grid_axis(y + low, y + low + 0.6 * reach, reach / 6, field="y"),
        "z": z - 0.8 * reach if mount is CEILING else z - 0.3 * reach,
        "yaws": np.array([0.0, 1.5]),
    }


# The KR6 hanging from a ceiling is an OPW arm as it is (its fit takes joint 1 along -z); its
# joint 2 range keeps it from anything below it, so it has no case here.
CASES = [
    ("ur5", WALL),
    ("ur5", CEILING),
    ("ur5", SLOPE),
    (ARMS[0].name, WALL),
    (ARMS[0].name, SLOPE),
]
IDS = [
    f"{name}-{('wall', 'ceiling', 'slope')[[WALL, CEILING, SLOPE].index(m)]}" for name, m in CASES
]


@pytest.mark.parametrize(("name", "mount"), CASES, ids=IDS)
def test_the_tilted_chain_is_recognised_and_mapped_by_the_kernel(
    name: str, mount: tuple[tuple[float, ...], tuple[float, ...]]
) -> None:
    tilted, own = robots(name, mount)
    family = tilted.family
    assert isinstance(family, ClosedFormFamily) and family.name == own.family.name
    assert family.recognised is not None and "tilted by" in family.recognised
    kernel, upright = family.map_kernel(), own.family.map_kernel()
    assert family.tilted and kernel is not None and upright is not None
    assert kernel[0] == upright[0] + TILTED  # the family's own pose kernel, the frame first
    frame = kernel[1][:TILT_PARAMETERS]
    turn = frame[:9].reshape(3, 3)  # R_A_B: a rotation whose z row is joint 1's axis in {B}
    np.testing.assert_allclose(turn @ turn.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(turn) == pytest.approx(1.0, abs=1e-12)
    make = type(family).kernel_parameters_function
    assert make is not None  # the family's own parameters after the frame
    np.testing.assert_array_equal(kernel[1][TILT_PARAMETERS:], make(family.parameters))
    assert family.path_cost(10) == own.family.path_cost(10) == 10


@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
def test_a_tilted_arms_map_never_runs_the_numpy_pipeline(
    monkeypatch: pytest.MonkeyPatch, spin_mode: str
) -> None:
    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("the numpy pipeline ran")

    monkeypatch.setattr(solver.path.placements, "run_chunk", refuse)
    tilted, _ = robots("ur5", WALL)
    cmap = capability_map(
        tilted, load_path("curved_line"), spin_mode=spin_mode, **grid("ur5", WALL)
    )
    assert np.isfinite(cmap.mu_path).any()


@pytest.mark.parametrize("accelerations", [None, 10.0])
@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
@pytest.mark.parametrize(("name", "mount"), CASES, ids=IDS)
def test_the_kernels_map_equals_the_numpy_pipelines(
    name: str,
    mount: tuple[tuple[float, ...], tuple[float, ...]],
    spin_mode: str,
    accelerations: float | None,
) -> None:
    """The compiled kernel of a tilted family against the numpy pipeline (which solves in the
    family's frame by :meth:`BaseTurn.vectors_in` and ``points_in``), cell by cell, as
    tests/solver/test_map_kernel.py compares an upright arm's."""
    tilted, _ = robots(name, mount)
    cells = grid(name, mount)
    placements = map_grid(cells["xs"], cells["ys"], cells["z"], cells["yaws"])  # type: ignore[arg-type]
    _, reasons = same_cells(
        tilted,
        load_path("curved_line"),
        placements,
        spin_mode=spin_mode,
        accelerations=accelerations,
    )
    assert "feasible" in reasons and len(reasons) > 1  # feasible cells and failures both


@pytest.mark.parametrize("spin_mode", ["fixed", "free"])
@pytest.mark.parametrize(("name", "mount"), CASES, ids=IDS)
def test_every_cell_is_the_arms_own_answer_on_the_path_moved_into_its_root(
    name: str, mount: tuple[tuple[float, ...], tuple[float, ...]], spin_mode: str
) -> None:
    tilted, own = robots(name, mount)
    path = load_path("curved_line")
    cmap = capability_map(tilted, path, spin_mode=spin_mode, **grid(name, mount))
    feasible = 0
    for (_, w, iy, ix), value in np.ndenumerate(cmap.mu_path):
        placement = Placement(float(cmap.xs[ix]), float(cmap.ys[iy]), cmap.z, float(cmap.yaws[w]))
        moved = in_root(mount, placement) @ path
        expected = evaluate_path(own, moved, Placement(0.0, 0.0, 0.0, 0.0), spin_mode=spin_mode)
        if not expected.feasible:
            assert math.isnan(value), placement
            continue
        feasible += 1
        assert value == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL), placement
        if feasible % 8 == 1:  # the evaluation there: its mu_path, and its joint path's FK
            answer = evaluate_path(tilted, path, placement, spin_mode=spin_mode)
            assert answer.mu_path == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
            assert answer.q is not None
            # A spherical wrist's flipped branch ties exactly; either may be chosen.
            placed = placement.transform_workpiece_to_base() @ path
            spins = np.zeros(len(path)) if answer.spins is None else answer.spins
            for i in range(0, len(path), 19):
                turn = np.eye(4)
                turn[:2, :2] = [
                    [math.cos(spins[i]), -math.sin(spins[i])],
                    [math.sin(spins[i]), math.cos(spins[i])],
                ]
                pose = tool_pose_in_base(tilted, answer.q[i])
                np.testing.assert_allclose(pose, placed[i] @ turn, atol=FK_IK_ATOL)
    assert 0 < feasible < cmap.mu_path.size  # placements that run and placements that do not


def test_numeric_ik_on_the_tilted_chain_maps_it_alike() -> None:
    """An independent IK on the same chain: the map of the UR5 on a wall, cell for cell."""
    text, root, _ = ARMS_MOUNTED["ur5"]
    urdf = mounted(text, root, WALL)
    frames = {"base_frame": "cell", "tool_frame": "tool0"}
    numeric = NumericFamily(chain_from_urdf(urdf, tool_frame="tool0"), **frames)
    path = load_path("curved_line")
    maps: list[CapabilityMap] = [
        capability_map(robot, path, **grid("ur5", WALL))
        for robot in (
            robot_from_urdf(urdf, **frames),
            robot_from_urdf(urdf, **frames, family=numeric),
        )
    ]
    closed, by_seeds = (m.mu_path for m in maps)
    np.testing.assert_array_equal(np.isnan(closed), np.isnan(by_seeds))
    np.testing.assert_allclose(closed, by_seeds, rtol=1e-9)
    assert np.isfinite(closed).any()


@pytest.mark.parametrize("method", ["casadi", "scipy"])
def test_the_optimisers_reach_the_best_cell_of_a_map_on_the_wall(method: str) -> None:
    """The UR5 on a wall: its best placement lies on the box's yaw bound, which both methods
    reach (the casadi method's coarse map samples the box's edges)."""
    tilted, _ = robots("ur5", ((0.0, 0.0, 0.6), (math.pi / 2, 0.0, 0.0)))
    path = load_path("curved_line")
    bounds = PlacementBounds(x=(-0.3, 0.3), y=(-0.7, -0.1), yaw=(-0.5, 0.5), z=0.4)
    grid = capability_map(
        tilted,
        path,
        xs=grid_axis(-0.3, 0.3, 0.05, field="x"),
        ys=grid_axis(-0.7, -0.1, 0.05, field="y"),
        z=0.4,
        yaws=np.linspace(-0.5, 0.5, 11),
    )
    optimum = optimize_placement(tilted, path, bounds=bounds, method=method)
    assert optimum.found and optimum.mu_path is not None
    assert optimum.mu_path >= float(np.nanmax(grid.mu_path))
