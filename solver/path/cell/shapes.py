"""What a cell holds (cell.md section 1): obstacles, the tool, the clearance and the step.

Obstacles are frozen dataclasses that make their coal shapes (:meth:`Shape.geometries`: one, or
one per separate part of a mesh) and their pose (4 x 4, in {B} for ``fixed`` objects, in {O}
for ``workpiece`` objects). Sizes are in m.
"""

from __future__ import annotations

import abc
import math
from dataclasses import dataclass, field

import coal
import numpy as np
import scipy.sparse
import scipy.sparse.csgraph

from solver.core.exceptions import InvalidInputError

DEFAULT_CLEARANCE = 0.005  # m, cell.md section 1
DEFAULT_COLLISION_STEP = 0.05  # rad, cell.md section 3
MIN_COLLISION_STEP = 0.001  # rad: finer checks weigh 50x the default's sub-steps and more
DEFAULT_CUTTING_LENGTH = 0.02  # m, cell.md section 1
MAX_SIZE = 100.0  # m: no cell object is larger (a halfspace's offset likewise)


def _positive(value: float, where: str, *, upper: float = MAX_SIZE) -> float:
    """``value`` as a float, finite, > 0 and <= ``upper``; InvalidInputError on ``where``."""
    number = float(value)
    if not (math.isfinite(number) and 0.0 < number <= upper):
        raise InvalidInputError(where, f"{number:.6g} must be > 0 and <= {upper:g}")
    return number


class Shape(abc.ABC):
    """An obstacle: a coal shape at a pose."""

    name: str | None
    pose: np.ndarray

    @abc.abstractmethod
    def geometry(self) -> coal.CollisionGeometry:
        """The coal shape, in its own frame."""

    def geometries(self) -> list[coal.CollisionGeometry]:
        """The coal shapes it is checked as, in its own frame: itself, or a mesh's parts."""
        return [self.geometry()]

    def check(self, where: str) -> None:  # noqa: B027  (shapes without sizes check nothing)
        """Raise InvalidInputError on ``where`` when a size is not finite and > 0."""


@dataclass(frozen=True)
class Box(Shape):
    """A box centred on its pose; size: (lx, ly, lz), m."""

    size: tuple[float, float, float]
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    name: str | None = None

    def check(self, where: str) -> None:
        """Each side finite and > 0."""
        for k, side in enumerate(self.size):
            _positive(side, f"{where}.size.{k}")

    def geometry(self) -> coal.CollisionGeometry:
        """A coal box."""
        return coal.Box(*(float(s) for s in self.size))


@dataclass(frozen=True)
class Cylinder(Shape):
    """A cylinder along its pose's z, centred; radius and length in m."""

    radius: float
    length: float
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    name: str | None = None

    def check(self, where: str) -> None:
        """Radius and length finite and > 0."""
        _positive(self.radius, f"{where}.radius")
        _positive(self.length, f"{where}.length")

    def geometry(self) -> coal.CollisionGeometry:
        """A coal cylinder."""
        return coal.Cylinder(float(self.radius), float(self.length))


@dataclass(frozen=True)
class Sphere(Shape):
    """A sphere at its pose's origin; radius in m."""

    radius: float
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    name: str | None = None

    def check(self, where: str) -> None:
        """Radius finite and > 0."""
        _positive(self.radius, f"{where}.radius")

    def geometry(self) -> coal.CollisionGeometry:
        """A coal sphere."""
        return coal.Sphere(float(self.radius))


@dataclass(frozen=True)
class Halfspace(Shape):
    """The points p with n . p <= d (a floor, a table top), n a unit normal; d in m."""

    normal: tuple[float, float, float]
    offset: float
    name: str | None = None
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))

    def check(self, where: str) -> None:
        """A finite, non-zero normal and a finite offset within MAX_SIZE."""
        n = np.asarray(self.normal, dtype=float)
        if n.shape != (3,) or not np.all(np.isfinite(n)) or np.linalg.norm(n) < 1e-9:
            raise InvalidInputError(f"{where}.normal", "needs three finite values, not all 0")
        if not (math.isfinite(self.offset) and abs(self.offset) <= MAX_SIZE):
            raise InvalidInputError(f"{where}.offset", f"{self.offset:.6g} m must be finite")

    def geometry(self) -> coal.CollisionGeometry:
        """A coal halfspace with its normal made unit (the offset scaled alike)."""
        n = np.asarray(self.normal, dtype=float)
        norm = float(np.linalg.norm(n))
        return coal.Halfspace(n / norm, float(self.offset) / norm)


@dataclass(frozen=True)
class Mesh(Shape):
    """A triangle mesh (read from an STL, :mod:`solver.path.cell.stl`) at its pose.

    Attributes:
        triangles: shape (T, 3, 3), m, the corners of each triangle in the mesh's frame.
    """

    triangles: np.ndarray
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    name: str | None = None

    def geometry(self) -> coal.CollisionGeometry:
        """The whole mesh as its convex hull (as the robot's meshes, :mod:`robot_geometry`)."""
        return convex_hull(np.asarray(self.triangles, dtype=float).reshape(-1, 3))

    def geometries(self) -> list[coal.CollisionGeometry]:
        """Each separate part of the mesh as its convex hull (:meth:`parts`).

        One hull of a fixture of two clamp blocks either side of the part filled the space
        between them where the tool works: every placement of the cell audit's map (stop 53)
        collided, where coal on the triangles keeps the wrist 19 mm clear. A part's own hull
        still fills its concave pockets (an L-bracket, a vice's jaws): it contains the part.
        """
        return [convex_hull(part.reshape(-1, 3)) for part in self.parts()]

    def parts(self) -> tuple[np.ndarray, ...]:
        """The triangles of each connected part (triangles sharing a corner), in file order.

        Corners are the same point when they are equal to JOIN_TOLERANCE of the mesh's size
        (an STL repeats each shared corner, in binary as float32). Not kept on the mesh: a
        cell's content is its pickle (the checkers' cache keys).
        """
        triangles = np.asarray(self.triangles, dtype=float)
        label = self.part_labels()
        order = np.argsort(label, kind="stable")  # each part's triangles in file order
        ends = np.cumsum(np.bincount(label))[:-1]
        return tuple(triangles[rows] for rows in np.split(order, ends))

    def part_count(self) -> int:
        """How many connected parts the mesh has (:meth:`parts`), without gathering them."""
        label = self.part_labels()
        return int(label.max()) + 1 if label.size else 0

    def part_labels(self) -> np.ndarray:
        """Per triangle, its part's number, parts numbered in the order they start in the file.

        Grouped by sorting: a mask a part over every triangle took 3.4 s for a soup of 50,000
        unjoined triangles, before the object limit refused it.
        """
        triangles = np.asarray(self.triangles, dtype=float)
        corners = triangles.reshape(-1, 3)
        size = float(np.ptp(corners, axis=0).max()) if len(corners) else 0.0
        grid = np.round(corners / max(size * JOIN_TOLERANCE, 1e-12)).astype(np.int64)
        _, point = np.unique(grid, axis=0, return_inverse=True)
        point = point.reshape(-1, 3)
        n = int(point.max()) + 1 if point.size else 0
        edges = np.concatenate([point[:, [0, 1]], point[:, [1, 2]]])
        graph = scipy.sparse.coo_matrix(
            (np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n)
        )
        _, label = scipy.sparse.csgraph.connected_components(graph, directed=False)
        of_triangle = label[point[:, 0]]
        _, first, numbered = np.unique(of_triangle, return_index=True, return_inverse=True)
        rank = np.empty(len(first), dtype=np.int64)
        rank[np.argsort(first, kind="stable")] = np.arange(len(first))  # by first triangle
        renumbered: np.ndarray = rank[numbered.reshape(-1)]
        return renumbered


JOIN_TOLERANCE = 1e-6
"""Corners of a mesh this close (a fraction of its size) are one point (:meth:`Mesh.parts`)."""


FLAT = 1e-6  # m: a mesh thinner than this in a direction is given that thickness (a sheet)
FLAT_RATIO = 1e-6
"""A mesh thinner than this fraction of its size in a direction is given that thickness too.

coal's hull of a slab thinner than some 1e-7 of its size kills the process (a 20 m triangle
made 1 um thick: a segmentation fault in ``ConvexBase.convexHull``; measured: slabs of 5e6 to
1 built, 2e7 to 1 crashed). A sheet of 20 m is so 40 um thick, 20 um each side of its plane."""


def _solid(points: np.ndarray) -> np.ndarray:
    """The points, with copies moved by +-t / 2 along each direction in which they are flat.

    qhull cannot make the hull of a flat set (and coal's binding then crashes): a sheet, or a
    line, becomes a slab t thick, t = max(FLAT, FLAT_RATIO times the set's largest extent).
    """
    centred = points - points.mean(axis=0)
    # Only the right singular vectors are used: U stays thin (full, it is P x P: 0.2 s for a
    # robot's meshes); below three points the full set of three directions is needed.
    _, _, directions = np.linalg.svd(centred, full_matrices=len(centred) < 3)
    extents = [np.ptp(centred @ direction) for direction in directions]
    thickness = max(FLAT, FLAT_RATIO * max(extents))
    for direction, extent in zip(directions, extents, strict=True):
        if extent < thickness:
            shift = thickness / 2 * direction
            points = np.concatenate([points + shift, points - shift])
    return points


def convex_hull(points: np.ndarray) -> coal.ConvexBase:
    """The convex hull of points (m, shape (P, 3)) as a coal shape, its faces kept.

    Built by ``ConvexBase.convexHull`` with the triangles kept: the hull that
    ``BVHModel.buildConvexRepresentation(False)`` makes without them gave distances up to 7 cm
    too large (the UR5's shoulder mesh against a plane: 0.145 m where its lowest vertex is
    0.074 m above it), and changing with the previous query.
    """
    vertices = coal.StdVec_Vec3s()
    for point in _solid(np.unique(np.asarray(points, dtype=float), axis=0)):
        vertices.append(np.ascontiguousarray(point))
    return coal.ConvexBase.convexHull(vertices, True, "Qt")


@dataclass(frozen=True)
class Tool:
    """The spindle and holder: a cylinder along tool z ending at the tool point (cell.md s. 1).

    Attributes:
        radius: m. length: m, from where it starts to the tool point. cutting_length: m, the
            last part, ending at the tool point, that may touch ``workpiece`` objects.
    """

    radius: float
    length: float
    cutting_length: float = DEFAULT_CUTTING_LENGTH

    def check(self) -> None:
        """Sizes finite and > 0, the cutting length no longer than the tool."""
        _positive(self.radius, "cell.tool.radius")
        _positive(self.length, "cell.tool.length")
        _positive(self.cutting_length, "cell.tool.cutting_length")
        if self.cutting_length > self.length:
            raise InvalidInputError(
                "cell.tool.cutting_length",
                f"{self.cutting_length:.6g} m is longer than the tool ({self.length:.6g} m)",
            )


@dataclass(frozen=True, eq=False)
class Cell:
    """The robot's surroundings (cell.md section 1).

    Attributes:
        fixed: objects in {B}. workpiece: objects in {O}, moving with the placement.
        tool: the tool cylinder, or None (no tool geometry).
        clearance: m, >= 0, the least distance any checked pair may come to.
        collision_step: rad, in [MIN_COLLISION_STEP, pi], the largest joint move between two
            checks.
        link_radii: m, capsule radii per link of an arm that has no collision geometry
            (base, then one per joint); None takes the robot's published ones.
    """

    fixed: tuple[Shape, ...] = ()
    workpiece: tuple[Shape, ...] = ()
    tool: Tool | None = None
    clearance: float = DEFAULT_CLEARANCE
    collision_step: float = DEFAULT_COLLISION_STEP
    link_radii: tuple[float, ...] | None = None

    def turns_into_itself(self) -> bool:
        """Whether the cell is the same after a turn of the placement about the base z axis.

        The workpiece objects, the tool and the robot turn with the placement; the fixed
        objects must turn into themselves: each a halfspace whose normal (posed) is the base z
        axis (a floor or table top). A fixture beside the robot does not.
        """
        for shape in self.fixed:
            if not isinstance(shape, Halfspace):
                return False
            normal = np.asarray(shape.pose, dtype=float)[:3, :3] @ np.asarray(shape.normal, float)
            if np.linalg.norm(np.cross(normal, [0.0, 0.0, 1.0])) > 1e-12 * np.linalg.norm(normal):
                return False
        return True

    def check(self) -> None:
        """Raise InvalidInputError on the first bad field, named as the request names it."""
        for group, shapes in (("fixed", self.fixed), ("workpiece", self.workpiece)):
            for k, shape in enumerate(shapes):
                shape.check(f"cell.{group}.{k}")
        if self.tool is not None:
            self.tool.check()
        if not (math.isfinite(self.clearance) and 0.0 <= self.clearance <= 1.0):
            raise InvalidInputError("cell.clearance", f"{self.clearance:.6g} m must be in [0, 1]")
        step = float(self.collision_step)
        if not (math.isfinite(step) and MIN_COLLISION_STEP <= step <= math.pi):
            raise InvalidInputError(
                "cell.collision_step", f"{step:.6g} rad must be in [{MIN_COLLISION_STEP:g}, pi]"
            )
        for k, radius in enumerate(self.link_radii or ()):
            _positive(radius, f"cell.link_radii.{k}", upper=1.0)

    def obstacle_name(self, index: int) -> str:
        """The name of obstacle ``index`` (fixed first, then workpiece), or its place."""
        shapes = self.fixed + self.workpiece
        group = "fixed" if index < len(self.fixed) else "workpiece"
        local = index if index < len(self.fixed) else index - len(self.fixed)
        return shapes[index].name or f"{group}[{local}]"
