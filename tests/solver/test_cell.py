"""The cell (cell.md): collisions and clearances against coal, geometry and the map.

Known answers come from a pinocchio ``GeometryModel`` built here from the same URDF, with coal
distances at the answer's joint angles (cell.md section 5), and from geometry: a halfspace above
the base, a far box, a box around the tool point.
"""

from __future__ import annotations

import math
import struct
import subprocess
import sys

import coal
import numpy as np
import pinocchio as pin
import pytest

from solver.core.exceptions import InvalidInputError
from solver.core.parallel import SERIAL, ThreadRunner
from solver.core.robots import Robot, example_robot_data_dir
from solver.core.spatial import Placement
from solver.families import get_robot, robot_from_urdf
from solver.optimise.optimize import optimize_placement
from solver.optimise.search_space import PlacementBounds
from solver.path.capability_map import CapabilityMap, capability_map, grid_axis
from solver.path.cell.checker import CellChecker
from solver.path.cell.robot_geometry import robot_geometry
from solver.path.cell.shapes import Box, Cell, Halfspace, Mesh, Tool
from solver.path.cell.stl import read_stl
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem
from tests.cases import ROOT
from tests.solver.test_evaluate import load_path

PLACEMENT = Placement(0.0, 0.45, 0.1, 0.0)
XS, YS = np.array([-0.1, 0.0, 0.1]), np.array([0.35, 0.45, 0.55])
DISTANCE_ATOL = 1e-6  # m, cell.md section 5: both use the same shapes


def pose(x: float, y: float, z: float) -> np.ndarray:
    """A translation as a 4 x 4 pose."""
    matrix = np.eye(4)
    matrix[:3, 3] = [x, y, z]
    return matrix


def problem(cell: Cell | None, robot: str = "ur5", tcp: float = 0.0) -> PathProblem:
    """The curved line on ``robot`` (its tool point ``tcp`` m along the flange's z), ``cell``."""
    arm = get_robot(robot)
    if tcp:
        arm = arm.with_options(transform_tool_to_tcp=pose(0.0, 0.0, tcp))
    return PathProblem.of(arm, load_path("curved_line"), PathOptions(cell=cell))


def ur5_geometry() -> tuple[pin.Model, pin.GeometryModel]:
    """UR5's collision elements read here from its URDF, meshes as convex hulls (faces kept)."""
    robot = get_robot("ur5")
    robots = example_robot_data_dir()
    urdf = (robots / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    geometry = pin.buildGeomFromUrdfString(
        robot.model, urdf, pin.COLLISION, package_dirs=[str(robots.parent.parent)]
    )
    for obj in geometry.geometryObjects:
        if isinstance(obj.geometry, coal.BVHModelBase):
            vertices = coal.StdVec_Vec3s()
            for k in range(obj.geometry.num_vertices):
                vertices.append(obj.geometry.vertex(k))
            obj.geometry = coal.ConvexBase.convexHull(vertices, True, "Qt")
    return robot.model, geometry


def substeps(q: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Waypoints and the evenly spaced configurations between them, no joint moving > step."""
    rows, owners = [], []
    for i in range(len(q) - 1):
        count = max(1, math.ceil(np.abs(q[i + 1] - q[i]).max() / step - 1e-12))
        for k in range(count):
            rows.append(q[i] + k / count * (q[i + 1] - q[i]))
            owners.append(i)
    return np.array([*rows, q[-1]]), np.array([*owners, len(q) - 1])


def coal_distances(
    q: np.ndarray, fixed: list[tuple[coal.CollisionGeometry, np.ndarray]], placement: Placement
) -> list[tuple[float, int, str, str]]:
    """Per configuration, the least distance, its waypoint, robot part and other object.

    Pairs of cell.md: every robot link a joint moves relative to a fixed object (not the base;
    not the shoulder, which joint 1 turns about the base's z, against a halfspace whose normal
    is z); links on joints neither the same nor adjacent, apart (> clearance) at the zero
    configuration.
    """
    model, geometry = ur5_geometry()
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    world_to_base = data.oMf[model.getFrameId("base")]
    n_robot = geometry.ngeoms
    for k, (shape, where) in enumerate(fixed):
        geometry.addGeometryObject(
            pin.GeometryObject(f"o{k}", 0, world_to_base * pin.SE3(where), shape)
        )
    objects = geometry.geometryObjects
    pairs = [(a, n_robot + k) for a in range(n_robot) for k in range(len(fixed))]
    pairs = [(a, b) for a, b in pairs if not _still(objects[a].parentJoint, fixed[b - n_robot][0])]
    candidates = []
    for a in range(n_robot):
        for b in range(a + 1, n_robot):
            ja, jb = objects[a].parentJoint, objects[b].parentJoint
            if abs(ja - jb) > 1:  # a serial chain: adjacent joints differ by one
                candidates.append((a, b))
    gdata = geometry.createData()
    pin.updateGeometryPlacements(model, data, geometry, gdata, pin.neutral(model))
    pairs += [(a, b) for a, b in candidates if _distance(geometry, gdata, a, b) > Cell().clearance]
    configurations, owners = substeps(q, Cell().collision_step)
    out = []
    for configuration, owner in zip(configurations, owners, strict=True):
        pin.updateGeometryPlacements(model, data, geometry, gdata, configuration)
        best = min((_distance(geometry, gdata, a, b), a, b) for a, b in pairs)
        other = objects[best[2]].name
        out.append((best[0], int(owner), objects[best[1]].name, other))
    return out


def _still(joint: int, shape: coal.CollisionGeometry) -> bool:
    """Whether a part on ``joint`` keeps its distance to ``shape`` (a fixed object) whatever q."""
    upright = isinstance(shape, coal.Halfspace) and abs(abs(float(shape.n[2])) - 1.0) < 1e-12
    return joint == 0 or (joint == 1 and upright)


def _distance(geometry: pin.GeometryModel, gdata: pin.GeometryData, a: int, b: int) -> float:
    """coal's distance between objects a and b at their current placements."""
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    objects = geometry.geometryObjects
    return float(
        coal.distance(
            objects[a].geometry,
            coal.Transform3s(gdata.oMg[a].rotation, gdata.oMg[a].translation),
            objects[b].geometry,
            coal.Transform3s(gdata.oMg[b].rotation, gdata.oMg[b].translation),
            request,
            result,
        )
    )


FIXTURE = Box((0.1, 0.1, 0.6), pose(-0.2, 0.55, 0.3), name="fixture")
TABLE = Halfspace((0.0, 0.0, 1.0), 0.0, name="table")


@pytest.mark.parametrize(
    ("shapes", "collides"),
    [((TABLE,), False), ((TABLE, FIXTURE), True)],
    ids=["feasible", "fixture"],
)
def test_collision_and_min_clearance_agree_with_coal(shapes: tuple, collides: bool) -> None:
    evaluation = evaluate_path(problem(Cell(fixed=shapes)), PLACEMENT)
    plain = evaluate_path(problem(None), PLACEMENT)
    assert plain.feasible and plain.q is not None
    # At the answer's joint angles: the velocity-best branch (wrist noflip) brings wrist_1 within
    # the clearance of wrist_3 at waypoint 50, so a feasible answer is the next branch's.
    answer_q = plain.q if collides else evaluation.q
    assert answer_q is not None
    reference = coal_distances(answer_q, [(s.geometry(), s.pose) for s in shapes], PLACEMENT)
    if collides:
        assert evaluation.reason == "collision"
        first = next(r for r in reference if r[0] < Cell().clearance)
        contact = evaluation.collision
        assert contact is not None
        assert contact.distance == pytest.approx(first[0], abs=DISTANCE_ATOL)
        assert (contact.waypoint, contact.robot_part) == (first[1], first[2])
        assert evaluation.failed_waypoint == first[1]
        assert contact.obstacle_name == "fixture" and contact.obstacle == 1
    else:
        closest = min(reference)
        assert evaluation.feasible and evaluation.min_clearance is not None
        assert evaluation.mu_path == pytest.approx(plain.mu_path, rel=1e-12)  # a tie, wrist flip
        assert evaluation.min_clearance.distance == pytest.approx(closest[0], abs=DISTANCE_ATOL)
        assert evaluation.min_clearance.waypoint == closest[1]
        assert evaluation.min_clearance.robot_part == closest[2]


FAR_FLOOR = Halfspace((0.0, 0.0, 1.0), -1.0, name="floor")


@pytest.mark.parametrize(
    "joints",
    [(-1.2, 1.6, -1.57, 1.57, 0.0), (-1.5, 1.5, -1.0, -1.57, 0.5)],
    ids=["wrist-3-nearest", "wrist-2-nearest"],
)
def test_the_closest_pair_is_the_closest_of_coal_at_every_configuration(joints: tuple) -> None:
    # An evaluation's closest pair. Coal computes only the pairs that may come nearer than the
    # closest so far; here the shoulder turns 0.4 rad in 200 steps past a box 10 cm outside the
    # wrist's circle (slowly: a pair proven clear of the clearance alone would be skipped at
    # its least distance), and the answer is the least of coal at every configuration and pair.
    q = np.tile([0.0, *joints], (201, 1))
    q[:, 0] = np.linspace(0.0, 0.4, 201)
    model = get_robot("ur5").model
    data = model.createData()
    pin.forwardKinematics(model, data, q[100])
    base = get_robot("ur5").transform_world_to_base
    wrist = np.linalg.solve(base, np.append(data.oMi[6].translation, 1.0))[:3]
    out = wrist[:2] * (1.0 + 0.1 / np.hypot(*wrist[:2]))
    shapes = (FAR_FLOOR, Box((0.05, 0.05, 0.05), pose(*out, wrist[2]), name="box"))
    verdict = CellChecker(get_robot("ur5"), Cell(fixed=shapes)).check(
        q, np.ones(200, dtype=bool), PLACEMENT.transform_workpiece_to_base(), closest=True
    )
    distance, waypoint, part, other = min(
        coal_distances(q, [(s.geometry(), s.pose) for s in shapes], PLACEMENT)
    )
    assert other == "o1"  # the box (coal_distances' name): not a pair proven clear throughout
    assert verdict.collision is None and verdict.closest is not None
    assert verdict.closest.distance == pytest.approx(distance, abs=DISTANCE_ATOL)
    assert (verdict.closest.waypoint, verdict.closest.robot_part) == (waypoint, part)
    assert verdict.closest.obstacle_name == "box"


def small_map(cell: Cell | None, robot: str = "ur5", tcp: float = 0.0) -> CapabilityMap:
    """A 3 x 3 map of the curved line at yaw 0."""
    return capability_map(problem(cell, robot, tcp), xs=XS, ys=YS, z=0.1, yaws=np.zeros(1))


@pytest.mark.parametrize("robot", ["ur5", "ur5e"])
def test_a_halfspace_just_above_the_base_collides_everywhere(robot: str) -> None:
    plain = small_map(None, robot)
    above_base = Halfspace((0.0, 0.0, 1.0), 0.1, name="above the base")
    cells = small_map(Cell(fixed=(above_base,)), robot)
    feasible = plain.reason == -1
    assert feasible.any()
    assert np.all(cells.reason[feasible] == 4)  # REASONS.index("collision")
    assert np.all(cells.reason[~feasible] == plain.reason[~feasible])
    assert np.all(np.isnan(cells.mu_path))


def test_a_far_box_changes_no_cell() -> None:
    plain = small_map(Cell())  # the robot against itself only
    far = small_map(Cell(fixed=(Box((1.0, 1.0, 1.0), pose(20.0, 20.0, 20.0)),)))
    for name in ("mu_path", "reason", "failed_waypoint", "branch", "bottleneck_waypoint"):
        np.testing.assert_array_equal(getattr(far, name), getattr(plain, name))


def tool_point_box(side: float) -> Box:
    """A cube of ``side`` around the tool point of the path's middle waypoint, in {O}."""
    middle = load_path("curved_line")[66]
    return Box((side, side, side), middle.copy())


TOOL = Tool(radius=0.02, length=0.1, cutting_length=0.02)
TCP = 0.12  # m, the tool point along the flange's z: the tool ends there, 2 cm clear of it


@pytest.mark.parametrize(
    ("group", "side", "collides"),
    [("workpiece", 0.01, False), ("workpiece", 0.08, True), ("fixed", 0.01, True)],
    ids=["workpiece-within-the-cutting-length", "workpiece-past-it", "fixed"],
)
def test_a_box_around_the_tool_point(group: str, side: float, collides: bool) -> None:
    box = tool_point_box(side)
    if group == "fixed":  # the same box, put in {B} at the placement
        box = Box(box.size, PLACEMENT.transform_workpiece_to_base() @ box.pose)
    cell = Cell(tool=TOOL, **{group: (box,)})
    evaluation = evaluate_path(problem(cell, tcp=TCP), PLACEMENT)
    if not collides:
        assert evaluation.feasible and evaluation.min_clearance is not None
        return
    assert evaluation.reason == "collision" and evaluation.collision is not None
    assert evaluation.collision.robot_part in ("tool", "tool_cutting", "wrist_3_link_0")
    if group == "workpiece":  # in {O}: every placement of the map collides
        plain, cells = small_map(None, tcp=TCP), small_map(cell, tcp=TCP)
        assert (plain.reason == -1).any()
        assert np.all(cells.reason[plain.reason == -1] == 4)


def test_auto_takes_the_next_branch_when_the_best_collides() -> None:
    plain = evaluate_path(problem(Cell()), PLACEMENT)  # the best branch clear of itself
    assert plain.q is not None
    model = get_robot("ur5").model
    data = model.createData()
    pin.forwardKinematics(model, data, plain.q[66])
    elbow = data.oMi[5].translation  # the second wrist joint: where the wrist branches differ
    base = get_robot("ur5").transform_world_to_base
    where = np.linalg.solve(base, np.append(elbow, 1.0))[:3]
    cell = Cell(fixed=(Box((0.05, 0.05, 0.05), pose(*where), name="at the elbow"),))
    evaluation = evaluate_path(problem(cell), PLACEMENT)
    assert evaluation.branch != plain.branch
    if evaluation.feasible:
        assert evaluation.mu_path is not None and plain.mu_path is not None
        assert evaluation.mu_path <= plain.mu_path
    else:
        assert evaluation.reason == "collision"
    cells = capability_map(
        problem(cell),
        xs=np.array([PLACEMENT.x]),
        ys=np.array([PLACEMENT.y]),
        z=0.1,
        yaws=np.zeros(1),
    )
    assert cells.mu_path[0, 0, 0, 0] == pytest.approx(
        evaluation.mu_path or math.nan, nan_ok=True, rel=1e-12
    )


def cube_triangles(side: float) -> np.ndarray:
    """The 12 triangles of a cube of ``side`` centred on the origin."""
    h = side / 2.0
    corners = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])
    faces = [
        (0, 1, 3),
        (0, 3, 2),
        (4, 6, 7),
        (4, 7, 5),
        (0, 4, 5),
        (0, 5, 1),
        (2, 3, 7),
        (2, 7, 6),
        (0, 2, 6),
        (0, 6, 4),
        (1, 5, 7),
        (1, 7, 3),
    ]
    return corners[np.array(faces)]


def ascii_stl(triangles: np.ndarray) -> bytes:
    """An ASCII STL of the triangles."""
    lines = ["solid cube"]
    for triangle in triangles:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += [f"vertex {x:.9g} {y:.9g} {z:.9g}" for x, y, z in triangle]
        lines += ["endloop", "endfacet"]
    return ("\n".join([*lines, "endsolid cube"]) + "\n").encode()


def binary_stl(triangles: np.ndarray) -> bytes:
    """A binary STL of the triangles."""
    body = b"".join(
        struct.pack("<12fH", 0.0, 0.0, 0.0, *triangle.ravel(), 0) for triangle in triangles
    )
    return b"\0" * 80 + struct.pack("<I", len(triangles)) + body


def upper_case_ascii_stl(triangles: np.ndarray) -> bytes:
    """An ASCII STL of the triangles in upper case (SOLID, FACET NORMAL, VERTEX), as some CAD
    exporters write it: it was read as a binary STL of 1,414,677,846 triangles and refused."""
    return ascii_stl(triangles).upper()


@pytest.mark.parametrize("writer", [ascii_stl, binary_stl, upper_case_ascii_stl])
def test_an_stl_cube_is_the_box_for_coal(writer: object) -> None:
    triangles = read_stl(writer(cube_triangles(100.0)), max_triangles=12, units="mm")  # type: ignore[operator]
    np.testing.assert_allclose(triangles, cube_triangles(0.1), atol=1e-7)
    mesh, box = Mesh(triangles).geometry(), coal.Box(0.1, 0.1, 0.1)
    sphere = coal.Sphere(0.05)
    for offset in ([0.3, 0.0, 0.0], [0.2, 0.2, 0.1]):
        where = coal.Transform3s(np.eye(3), np.array(offset))
        distances = [
            coal.distance(
                shape,
                coal.Transform3s(),
                sphere,
                where,
                coal.DistanceRequest(),
                coal.DistanceResult(),
            )
            for shape in (mesh, box)
        ]
        assert distances[0] == pytest.approx(distances[1], abs=1e-6)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"not a mesh at all, just words" * 10, "not an STL"),
        (
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nendloop\nendfacet\n",
            "not an STL",
        ),
        (binary_stl(cube_triangles(1.0)), "max_mesh_triangles"),
    ],
    ids=["text", "two-vertices-missing", "too-many"],
)
def test_a_bad_stl_is_an_input_error(data: bytes, message: str) -> None:
    with pytest.raises(InvalidInputError, match=message) as caught:
        read_stl(data, max_triangles=11, field="cell.fixed.0.stl")
    assert caught.value.field == "cell.fixed.0.stl"


@pytest.mark.parametrize(
    ("cell", "field"),
    [
        (Cell(fixed=(Box((0.1, -1.0, 0.1)),)), "cell.fixed.0.size.1"),
        (Cell(tool=Tool(0.02, 0.01, 0.02)), "cell.tool.cutting_length"),
        (Cell(clearance=-0.001), "cell.clearance"),
        (Cell(collision_step=0.0), "cell.collision_step"),
    ],
)
def test_a_bad_cell_names_its_field(cell: Cell, field: str) -> None:
    with pytest.raises(InvalidInputError) as caught:
        evaluate_path(problem(cell), PLACEMENT)
    assert caught.value.field == field


def test_an_arm_without_collision_geometry_or_radii_needs_link_radii() -> None:
    with pytest.raises(InvalidInputError) as caught:
        evaluate_path(problem(Cell(), "ur3e"), PLACEMENT)
    assert caught.value.field == "cell.link_radii"


def test_a_flat_mesh_is_a_sheet_not_a_crash() -> None:
    sheet = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    above = coal.Transform3s(np.eye(3), np.array([0.5, 0.5, 0.3]))
    distance = coal.distance(
        Mesh(sheet).geometry(),
        coal.Transform3s(),
        coal.Sphere(0.1),
        above,
        coal.DistanceRequest(),
        coal.DistanceResult(),
    )
    assert distance == pytest.approx(0.2, abs=1e-6)


_LARGE_SHEET = """
import coal, numpy as np
from solver.path.cell.shapes import Mesh
sheet = np.array([[[20.0, 0, 0], [-20.0, 0, 0], [0, 20.0, 0]]])
above = coal.Transform3s(np.eye(3), np.array([0.0, 1.0, 0.3]))
print(coal.distance(Mesh(sheet).geometry(), coal.Transform3s(), coal.Sphere(0.1), above,
                    coal.DistanceRequest(), coal.DistanceResult()))
"""


def test_a_large_flat_mesh_is_a_slab_not_a_crash() -> None:
    """A 40 m triangle in the plane z = 0: its hull killed the process (coal, a 1 um slab).

    Run in a process of its own, which a crash ends with a signal. The sheet is made a slab
    FLAT_RATIO of its 40 m extent thick, 20 um each side: a sphere of 0.1 m at 0.3 m above it
    is 0.2 m - 20 um away (geometry).
    """
    done = subprocess.run(
        [sys.executable, "-c", _LARGE_SHEET], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert done.returncode == 0, (done.returncode, done.stderr[-500:])
    assert float(done.stdout) == pytest.approx(0.2 - 2e-5, abs=1e-6)


def test_an_stl_corner_beyond_the_coordinate_limit_is_an_input_error() -> None:
    """1e308 mm (about 1e305 m) was taken, its hull's arithmetic overflowing; 999 m is taken."""

    def corners(size: float) -> bytes:
        return (
            f"solid t\nfacet normal 0 0 1\nouter loop\nvertex {size} 0 0\nvertex {-size} 0 0\n"
            f"vertex 0 {size} 0\nendloop\nendfacet\nendsolid t\n"
        ).encode()

    with pytest.raises(InvalidInputError, match="beyond") as caught:
        read_stl(corners(1e308), max_triangles=10, units="mm", field="cell.workpiece.0.stl")
    assert caught.value.field == "cell.workpiece.0.stl"
    assert read_stl(corners(999.0), max_triangles=10)[0, 0, 0] == 999.0


OPT_BOUNDS = PlacementBounds(x=(-0.1, 0.1), y=(0.35, 0.55), yaw=(-0.3, 0.3), z=0.1)


def blocking_cell() -> dict:
    """The velocity-best placement of a small box, and a cell whose fixture blocks its elbow."""
    plain = optimize_placement(problem(None), bounds=OPT_BOUNDS, method="casadi")
    assert plain.evaluation is not None and plain.evaluation.q is not None
    robot = get_robot("ur5")
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, plain.evaluation.q[66])
    elbow = np.linalg.solve(robot.transform_world_to_base, np.append(data.oMi[3].translation, 1))
    fixture = Box((0.06, 0.06, 0.06), pose(*elbow[:3]), name="fixture")
    return {"plain": plain, "shapes": (TABLE, fixture)}


@pytest.fixture(scope="module")
def blocked() -> dict:
    """:func:`blocking_cell`, once for the module."""
    return blocking_cell()


@pytest.mark.parametrize("method", ["casadi", "scipy"])
def test_the_optimisers_answer_collision_free_placements(blocked: dict, method: str) -> None:
    shapes = blocked["shapes"]
    cell = Cell(fixed=shapes)
    before = evaluate_path(problem(cell), blocked["plain"].placement)
    assert before.reason == "collision"  # the velocity-best placement hits the fixture
    optimum = optimize_placement(problem(cell), bounds=OPT_BOUNDS, method=method)
    assert optimum.found and optimum.evaluation is not None and optimum.mu_path is not None
    q = optimum.evaluation.q
    reference = coal_distances(q, [(s.geometry(), s.pose) for s in shapes], optimum.placement)
    assert min(reference)[0] >= cell.clearance  # coal: no configuration closer than clearance
    closest = optimum.evaluation.min_clearance  # the answer's clearance: coal's least
    assert closest is not None
    assert closest.distance == pytest.approx(min(reference)[0], abs=DISTANCE_ATOL)
    assert (closest.waypoint, closest.robot_part) == min(reference)[1:3]
    grid = capability_map(
        problem(cell),
        xs=grid_axis(*OPT_BOUNDS.x, 0.02, field="x"),
        ys=grid_axis(*OPT_BOUNDS.y, 0.02, field="y"),
        z=0.1,
        yaws=grid_axis(*OPT_BOUNDS.yaw, math.radians(15), field="yaw"),
    )
    assert optimum.mu_path >= float(np.nanmax(grid.mu_path)) * (1 - 1e-9)
    assert optimum.mu_path <= blocked["plain"].mu_path * (1 + 1e-9)


def test_a_urdf_whose_meshes_cannot_be_read_gets_capsules_where_it_has_no_primitive() -> None:
    robots = example_robot_data_dir()
    urdf = (robots / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    elsewhere = urdf.replace("package://example-robot-data/", "package://not-installed/")
    arm = robot_from_urdf(elsewhere, base_frame="base", tool_frame="tool0", name="ur5-elsewhere")
    checker = CellChecker(arm, Cell())
    # every link's collision element is a mesh but the ee_link's box, fixed to wrist_3_link:
    # wrist_3_link has none of its own, so it gets a capsule too
    assert checker.approximated == (
        "base",
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    )
    assert CellChecker(get_robot("ur5"), Cell()).approximated == ()
    assert CellChecker(get_robot("ur5e"), Cell()).approximated == ()  # Menagerie's capsules


def test_a_link_without_geometry_is_a_capsule_whatever_its_fixed_links_carry() -> None:
    """The UR5 whose meshes cannot be read keeps ee_link's 1 cm box on the wrist's joint, but
    wrist_3_link, the link that joint moves, has nothing: a box 3 cm from the wrist's axis was
    answered clear by 15.5 mm (ee_link to the box), 26 mm inside the wrist's capsule. The
    distance is coal's, from a capsule made here: wrist_3_joint's origin to tool0, r = 0.05."""
    robots = example_robot_data_dir()
    urdf = (robots / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    elsewhere = urdf.replace("package://example-robot-data/", "package://not-installed/")
    arm = robot_from_urdf(elsewhere, base_frame="base", tool_frame="tool0", name="ur5-elsewhere")
    path, at = load_path("curved_line")[60:62], Placement(0.0, 0.45, 0.1, 0.0)
    plain = evaluate_path(PathProblem.of(arm, path), at)
    assert plain.q is not None
    model, data = arm.model, arm.model.createData()
    pin.framesForwardKinematics(model, data, plain.q[0])
    wrist = model.getJointId("wrist_3_joint")
    tool0 = model.frames[model.getFrameId("tool0")].placement.translation
    side = data.oMi[wrist].rotation[:, 0]  # across the wrist's axis, 3 cm from it
    centre = data.oMi[wrist].act(tool0 / 2) + 0.03 * side
    base = data.oMf[model.getFrameId("base")]
    pin_box = Box((0.01, 0.01, 0.01), base.actInv(pin.SE3(np.eye(3), centre)).homogeneous)
    evaluation = evaluate_path(
        PathProblem.of(arm, path, PathOptions(cell=Cell(fixed=(pin_box,)))), at
    )
    geometry = pin.GeometryModel()
    length = float(np.linalg.norm(tool0))
    turn = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), tool0 / length).matrix()
    capsule = coal.Capsule(0.05, length)
    geometry.addGeometryObject(pin.GeometryObject("w3", wrist, pin.SE3(turn, tool0 / 2), capsule))
    geometry.addGeometryObject(
        pin.GeometryObject("box", 0, pin.SE3(np.eye(3), centre), pin_box.geometry())
    )
    gdata = geometry.createData()
    pin.updateGeometryPlacements(model, data, geometry, gdata)
    expected = _distance(geometry, gdata, 0, 1)
    assert expected < -0.02
    assert evaluation.reason == "collision" and evaluation.collision is not None
    assert evaluation.collision.robot_part == "wrist_3_joint_capsule"
    assert evaluation.collision.waypoint == 0
    assert evaluation.collision.distance == pytest.approx(expected, abs=DISTANCE_ATOL)


def test_a_table_top_between_the_pandas_base_and_joint_1_collides_with_link_1() -> None:
    """cell.md section 5: a halfspace just above the base collides everywhere. The Panda's
    joint 1 is at 0.333 m, above such a table, but its link 1 hangs down to its base: left
    unchecked as a link joint 1 turns about the table's normal, the placements ran. The
    distance is geometry: link 1's lowest convex-hull vertex, read here, below the table top."""
    arm = get_robot("panda")
    robots = example_robot_data_dir()
    urdf = (robots / "panda_description" / "urdf" / "panda.urdf").read_text()
    geometry = pin.buildGeomFromUrdfString(
        arm.model, urdf, pin.COLLISION, package_dirs=[str(robots.parent.parent)]
    )
    data = arm.model.createData()
    pin.framesForwardKinematics(arm.model, data, pin.neutral(arm.model))
    gdata = geometry.createData()
    pin.updateGeometryPlacements(arm.model, data, geometry, gdata)
    base = data.oMf[arm.model.getFrameId("panda_link0")]

    def lowest(name: str) -> tuple[float, float]:
        """The z range in {B} of a collision object's mesh vertices."""
        k = geometry.getGeometryId(name)
        mesh = geometry.geometryObjects[k].geometry
        vertices = np.array([mesh.vertex(i) for i in range(mesh.num_vertices)])
        placed = base.actInv(gdata.oMg[k])
        heights = (vertices @ placed.rotation.T + placed.translation)[:, 2]
        return float(heights.min()), float(heights.max())

    table = lowest("panda_link0_0")[1] + 0.01
    assert lowest("panda_link1_0")[0] < table < arm.model.jointPlacements[1].translation[2]
    top = Halfspace((0.0, 0.0, 1.0), table, name="table")
    path = load_path("curved_line")
    plain = PathProblem.of(arm, path)
    xs, ys = np.array([0.35, 0.45, 0.55]), np.array([0.0, 0.1, 0.2])
    free = capability_map(plain, xs=xs, ys=ys, z=table + 0.15, yaws=np.array([0.0, 0.5]))
    assert (free.reason == -1).any()
    cut = PathProblem.of(arm, path, PathOptions(cell=Cell(fixed=(top,))))
    cells = capability_map(cut, xs=xs, ys=ys, z=table + 0.15, yaws=np.array([0.0, 0.5]))
    runs = free.reason == -1
    assert np.all(cells.reason[runs] == 4)  # REASONS.index("collision")
    _, yaw, y, x = np.argwhere(runs)[0]  # [spin, yaw, y, x]
    evaluation = evaluate_path(cut, Placement(xs[x], ys[y], table + 0.15, [0.0, 0.5][yaw]))
    assert evaluation.collision is not None
    assert evaluation.collision.robot_part == "panda_link1_0"
    assert evaluation.collision.distance == pytest.approx(
        lowest("panda_link1_0")[0] - table, abs=DISTANCE_ATOL
    )


def joint_1_capsule(arm: Robot, radius: float) -> pin.GeometryObject:
    """A capsule on joint 1 from its origin to joint 2's, made here with coal."""
    end = np.asarray(arm.model.jointPlacements[2].translation)
    turn = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), end / np.linalg.norm(end))
    placement = pin.SE3(turn.matrix(), end / 2.0)
    return pin.GeometryObject("j1", 1, placement, coal.Capsule(radius, np.linalg.norm(end)))


@pytest.mark.parametrize("name", ["abb_irb2400", "kuka_kr16_2"])
def test_a_link_joint_1_turns_about_the_tables_normal_is_reported_not_checked(name: str) -> None:
    # An OPW arm has no collision geometry: capsules along its kinematic segments, joint 1's
    # from its origin at the foot to joint 2's, so 5 cm into a table at z = 0 whatever joint 1's
    # angle. Checked, it made every placement collide: every OPW arm on its table, and the
    # ROS-Industrial ABB and FANUC URDFs whose meshes are elsewhere.
    arm, radius = get_robot(name), 0.05
    cell = Cell(fixed=(TABLE,), link_radii=(radius,) * 7)
    geometry = pin.GeometryModel()
    geometry.addGeometryObject(joint_1_capsule(arm, radius))
    table = pin.SE3(arm.transform_world_to_base)
    geometry.addGeometryObject(pin.GeometryObject("table", 0, table, TABLE.geometry()))
    model, data, gdata = arm.model, arm.model.createData(), geometry.createData()
    distances = []
    for q in np.random.default_rng(4).uniform(-3.0, 3.0, (6, model.nq)):
        pin.forwardKinematics(model, data, q)
        pin.updateGeometryPlacements(model, data, geometry, gdata)
        distances.append(_distance(geometry, gdata, 0, 1))
    assert distances == pytest.approx([-radius] * 6, abs=1e-12)  # into the table, at every q
    checker = CellChecker(arm, cell)
    unchecked = {pair.robot_part: pair for pair in checker.unchecked}
    assert sorted(unchecked) == ["base_capsule", f"{arm.joint_names[0]}_capsule"]
    shoulder = unchecked[f"{arm.joint_names[0]}_capsule"]
    assert (shoulder.obstacle, shoulder.obstacle_name) == (0, "table")
    assert shoulder.distance == pytest.approx(distances[0], abs=DISTANCE_ATOL)
    on_table = PathProblem.of(arm, load_path("curved_line"), PathOptions(cell=cell))
    plain = PathProblem.of(arm, load_path("curved_line"))
    evaluation = evaluate_path(on_table, Placement(0.9, 0.0, 0.3, 0.0))
    assert evaluation.feasible and evaluation.cell_unchecked == checker.unchecked
    assert evaluation.mu_path == evaluate_path(plain, Placement(0.9, 0.0, 0.3, 0.0)).mu_path
    # the link is checked against what it turns past: a post around joint 1's segment
    post = Box((0.1, 0.1, 0.1), pose(0.0, 0.0, 0.3), name="post")
    posted = Cell(fixed=(TABLE, post), link_radii=(radius,) * 7)
    hit = evaluate_path(
        PathProblem.of(arm, load_path("curved_line"), PathOptions(cell=posted)),
        Placement(0.9, 0.0, 0.3, 0.0),
    )
    assert hit.reason == "collision" and hit.collision is not None
    assert (hit.collision.robot_part, hit.collision.obstacle_name) == (shoulder.robot_part, "post")
    # a table top 6 cm above joint 1's origin cuts the arm's turning part (cell.md section 5:
    # a halfspace above the base collides everywhere): checked, 0.06 + r into it at waypoint 0
    above = Halfspace((0.0, 0.0, 1.0), 0.06, name="above")
    raised = Cell(fixed=(above,), link_radii=(radius,) * 7)
    assert [p.robot_part for p in CellChecker(arm, raised).unchecked] == ["base_capsule"]
    cut = evaluate_path(
        PathProblem.of(arm, load_path("curved_line"), PathOptions(cell=raised)),
        Placement(0.9, 0.0, 0.3, 0.0),
    )
    assert cut.reason == "collision" and cut.collision is not None
    assert (cut.collision.waypoint, cut.collision.robot_part) == (0, shoulder.robot_part)
    assert cut.collision.distance == pytest.approx(-(0.06 + radius), abs=DISTANCE_ATOL)


def test_threads_give_the_serial_map() -> None:
    """Each check poses the workpiece objects in its own copy of the geometry."""
    part = Box((0.3, 0.12, 0.2), pose(0.0, 0.06, -0.09), name="part")
    cell = Cell(fixed=(TABLE, FIXTURE), workpiece=(part,), tool=TOOL)
    xs, ys = np.linspace(-0.2, 0.2, 5), np.linspace(0.3, 0.6, 4)
    maps = [
        capability_map(
            problem(cell, tcp=TCP), xs=xs, ys=ys, z=0.1, yaws=np.zeros(1), runner=runner, chunk=2
        )
        for runner in (SERIAL, ThreadRunner(2))
    ]
    np.testing.assert_array_equal(maps[0].reason, maps[1].reason)
    np.testing.assert_array_equal(maps[0].mu_path, maps[1].mu_path)


def test_a_mesh_links_distance_to_a_plane_is_its_lowest_vertex() -> None:
    """coal on the robot's hulls against geometry: a link's distance to a plane below it is the
    height of its lowest mesh vertex (the meshes read by pinocchio here, placed by its FK)."""
    robot = get_robot("ur5")
    model, meshes = ur5_geometry_meshes()
    ours = robot_geometry(robot, tool=None, link_radii=None).geometry
    data = model.createData()
    rng = np.random.default_rng(7)
    plane = coal.Halfspace(np.array([0.0, 0.0, 1.0]), -1.0)
    checked = 0
    for q in rng.uniform(-math.pi, math.pi, size=(5, model.nq)):
        mesh_data, our_data = meshes.createData(), ours.createData()
        pin.updateGeometryPlacements(model, data, meshes, mesh_data, q)
        pin.updateGeometryPlacements(model, data, ours, our_data, q)
        for k, obj in enumerate(meshes.geometryObjects):
            if not isinstance(obj.geometry, coal.BVHModelBase):
                continue
            place = mesh_data.oMg[k]
            vertices = np.array([obj.geometry.vertex(v) for v in range(obj.geometry.num_vertices)])
            lowest = float((vertices @ place.rotation.T + place.translation)[:, 2].min()) + 1.0
            hull = ours.geometryObjects[ours.getGeometryId(obj.name)]
            where = our_data.oMg[ours.getGeometryId(obj.name)]
            distance = coal.distance(
                hull.geometry,
                coal.Transform3s(where.rotation, where.translation),
                plane,
                coal.Transform3s(),
                coal.DistanceRequest(),
                coal.DistanceResult(),
            )
            assert distance == pytest.approx(lowest, abs=1e-9), obj.name
            checked += 1
    assert checked == 5 * 7


def ur5_geometry_meshes() -> tuple[pin.Model, pin.GeometryModel]:
    """UR5's collision elements as pinocchio reads them: the meshes themselves, no hulls."""
    robots = example_robot_data_dir()
    urdf = (robots / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    model = get_robot("ur5").model
    return model, pin.buildGeomFromUrdfString(
        model, urdf, pin.COLLISION, package_dirs=[str(robots.parent.parent)]
    )


def test_an_arms_meshes_are_read_once_whatever_the_cell(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every request with a cell the checkers' cache had not met read the UR5's meshes and made
    their hulls again (0.07 to 0.09 s): each edit of a cell on the page. The arm's URDF geometry
    is now kept, whatever the tool point; each answer is its own copy, which the tool's parts
    are added to."""
    robots = example_robot_data_dir()
    urdf = (robots / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    urdf = urdf.replace("</robot>", "<!-- read once (test_cell) --></robot>")  # no kept one
    frames = {"base_frame": "base_link", "tool_frame": "tool0"}
    arm = robot_from_urdf(urdf, **frames)
    reads = []
    build = pin.buildGeomFromUrdfString

    def counted(*args: object, **kwargs: object) -> pin.GeometryModel:
        reads.append(args[1])
        return build(*args, **kwargs)

    monkeypatch.setattr(pin, "buildGeomFromUrdfString", counted)
    bare = robot_geometry(arm, tool=None, link_radii=None)
    tipped = arm.with_options(transform_tool_to_tcp=pose(0.0, 0.0, 0.1))  # the tool's tip
    tooled = robot_geometry(tipped, tool=Tool(radius=0.03, length=0.1), link_radii=None)
    again = robot_geometry(arm, tool=None, link_radii=None)
    assert len(reads) == 1
    assert tooled.geometry.ngeoms == bare.geometry.ngeoms + 2  # the holder and cutting part
    assert again.geometry.ngeoms == bare.geometry.ngeoms  # the tool added to a copy only
    assert [o.name for o in again.geometry.geometryObjects] == [
        o.name for o in bare.geometry.geometryObjects
    ]
    assert again.keys == bare.keys and again.approximated == bare.approximated == ()
    # another URDF is read: the forearm's collision element out, the forearm approximated
    start = urdf.index("<collision>", urdf.index('<link name="forearm_link">'))
    cut = urdf[:start] + urdf[urdf.index("</collision>", start) + len("</collision>") :]
    other = robot_geometry(robot_from_urdf(cut, **frames), tool=None, link_radii=None)
    assert len(reads) == 2
    assert other.approximated == ("elbow_joint",)
