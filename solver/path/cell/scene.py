"""The cell's geometry for one robot: its parts, the obstacles, the pairs to check (cell.md s. 3).

One pinocchio ``GeometryModel`` holds the robot's geometry (:mod:`robot_geometry`) and the
obstacles, on the base joint: ``fixed`` ones at their pose in {B}, ``workpiece`` ones at the
placement's T_B_O times their pose (placed by the checker, :mod:`solver.path.cell.checker`).
The pairs: every robot part (the tool included) against every obstacle, except the tool's
cutting part against ``workpiece`` objects (that is machining) and a part against a ``fixed``
object no joint moves it relative to (its weights in :func:`solver.path.cell.bounds.pair_weights`
all zero) and that stands on it: the base, whatever the placement, a part joint 1 turns onto
itself (a sphere on its axis, a capsule or cylinder along it: :func:`_turns_in_place`), and
a link only joint 1 turns about a fixed halfspace's normal, joint 1's origin on or above the
halfspace's boundary
(joint 1's link of an arm on its table; a table top above joint 1 cuts the arm's turning part,
and is checked: it collides everywhere, as cell.md section 5 has it), clear of it or seated in
it (:func:`_seated`: a capsule made along the link, as deep as its radius, or a published
capsule as deep as it reaches below the mounting face; a link's own
geometry reaching into the table, the Panda's link 1 hanging down to its base below a table
top, is checked and collides everywhere). Such a pair's distance is the same at every
configuration and placement: were it checked, an arm whose joint-1 link touches its table (a
capsule along that link from joint 1's origin at the foot, as given to a URDF whose meshes are
elsewhere: ROS-Industrial's ABB IRB 2400 and IRB 5400 read with a table at z = 0) would
collide at every placement, whatever the path. Those pairs and their distance are reported
(:attr:`CellScene.unchecked`), not silently dropped. And the
robot's parts against each other where they are on joints that are neither the same nor
adjacent and do not touch at the zero configuration (come within :data:`TOUCH` there): a
choice of the robot and the cell's shapes, not of the request's clearance, so that a larger
clearance never checks fewer pairs.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from solver.core.kinematics import revolute_axis
from solver.core.robots import Robot
from solver.path.cell import fast
from solver.path.cell.bounds import pair_weights
from solver.path.cell.robot_geometry import robot_geometry
from solver.path.cell.shapes import DEFAULT_CLEARANCE, Cell
from solver.path.cell.verdict import Unchecked

TOUCH = DEFAULT_CLEARANCE
"""m: robot parts this close at the zero configuration touch there (cell.md section 2: such
a pair is no self-collision pair). It was the request's clearance: a clearance of 0.9 m left
the UR5 no self pair, and a path whose upper arm went through its wrist was feasible. At
5 mm (the default clearance) the catalogue arms keep the pairs they had at every clearance
up to 5 mm (none has a pair between 0 and 5 mm at q = 0, 2026-12-05)."""
STILL = 1e-9
"""m/rad: a pair whose every weight is below this is one no joint moves (1e-9 m a turn at most)."""


@dataclass(frozen=True)
class CellScene:
    """A robot and a cell's objects in one geometry model, with the pairs to check.

    Attributes:
        geometry: the robot's parts (indices below ``n_robot``), then the obstacles (``fixed``
            first, then ``workpiece``), the checked pairs registered as collision pairs.
        n_robot: how many geometry objects are the robot's.
        world_to_base: {B} in the model's root frame.
        workpiece_ids: each ``workpiece`` object's geometry index and its pose in {O}.
        pairs: the checked pairs (geometry indices, the robot's part first).
        weights: :func:`solver.path.cell.bounds.pair_weights` of the pairs.
        compiled: the compiled sweep's model; None where it lacks a joint or shape (coal alone).
        approximated: the robot's links given capsules (no readable collision geometry).
        unchecked: the robot parts not checked against a ``fixed`` object because no joint
            moves them relative to it, with their distance (the same at every configuration).
        owners: per obstacle geometry object (index less ``n_robot``), the cell object it is
            (an index into ``fixed`` then ``workpiece``): a mesh is one per separate part.
    """

    geometry: pin.GeometryModel
    n_robot: int
    world_to_base: pin.SE3
    workpiece_ids: list[tuple[int, pin.SE3]]
    pairs: list[tuple[int, int]]
    weights: np.ndarray
    compiled: fast.FastCell | None
    approximated: tuple[str, ...]
    unchecked: tuple[Unchecked, ...] = ()
    owners: tuple[int, ...] = ()


def build_scene(robot: Robot, cell: Cell) -> CellScene:
    """Build the geometry and choose the pairs of a checked cell (:meth:`Cell.check`).

    Raises:
        InvalidInputError: bad link radii.
    """
    made = robot_geometry(robot, tool=cell.tool, link_radii=cell.link_radii)
    geometry = made.geometry
    n_robot = geometry.ngeoms
    world_to_base = pin.SE3(robot.transform_world_to_base)
    shapes = cell.fixed + cell.workpiece
    workpiece_ids, owners = [], []
    for k, shape in enumerate(shapes):
        place = world_to_base * pin.SE3(np.asarray(shape.pose, dtype=float))
        pieces = shape.geometries()
        for p, piece in enumerate(pieces):
            name = f"obstacle_{k}" if len(pieces) == 1 else f"obstacle_{k}_part_{p}"
            gid = geometry.addGeometryObject(pin.GeometryObject(name, 0, place, piece))
            owners.append(k)
            if k >= len(cell.fixed):
                workpiece_ids.append((gid, pin.SE3(np.asarray(shape.pose, dtype=float))))
    n_fixed = sum(1 for k in owners if k < len(cell.fixed))  # the fixed objects' pieces
    pairs = [
        (part, n_robot + slot)
        for part in range(n_robot)
        for slot in range(len(owners))
        if not (part == made.cutting and slot >= n_fixed)
    ]
    pairs, weights, standing = _moving(robot.model, geometry, pairs, n_robot, n_fixed)
    candidates = _self_candidates(robot.model, geometry, n_robot)
    # one coal probe for the standing pairs' distances and the self pairs' at q = 0
    distances = _distances(robot.model, geometry, [p for p, _ in standing] + candidates)
    still, still_distances = [], []
    for (pair, weight), distance in zip(standing, distances[: len(standing)], strict=True):
        if _seated(geometry, pair[0], distance, made.seats):
            still.append(pair)
            still_distances.append(distance)
        else:  # a link that reaches into its table: in collision at every configuration
            pairs.append(pair)
            weights = np.vstack([weights, weight[None]])
    apart = distances[len(standing) :]
    own = [p for p, d in zip(candidates, apart, strict=True) if d > TOUCH]
    pairs += own
    weights = np.vstack([weights, pair_weights(robot.model, geometry, own, n_robot)])
    for a, b in pairs:
        geometry.addCollisionPair(pin.CollisionPair(a, b))
    try:
        compiled: fast.FastCell | None = fast.FastCell(
            robot.model,
            geometry,
            n_robot,
            pairs,
            weights=weights,
            clearance=cell.clearance,
            keys=made.keys,
        )
    except NotImplementedError:
        compiled = None  # a joint or shape the compiled sweep lacks: coal alone
    return CellScene(
        geometry=geometry,
        n_robot=n_robot,
        world_to_base=world_to_base,
        workpiece_ids=workpiece_ids,
        pairs=pairs,
        weights=weights,
        compiled=compiled,
        approximated=made.approximated,
        unchecked=tuple(
            Unchecked(
                geometry.geometryObjects[a].name,
                owners[b - n_robot],
                cell.obstacle_name(owners[b - n_robot]),
                d,
            )
            for (a, b), d in zip(still, still_distances, strict=True)
        ),
        owners=tuple(owners),
    )


def _moving(
    model: pin.Model,
    geometry: pin.GeometryModel,
    pairs: list[tuple[int, int]],
    n_robot: int,
    n_fixed: int,
) -> tuple[list[tuple[int, int]], np.ndarray, list[tuple[tuple[int, int], np.ndarray]]]:
    """The pairs a joint can bring nearer with their weights; the ``fixed`` ones none can.

    See the module docstring; the weights are :func:`pair_weights`' (P, nv). The pairs no joint
    moves, standing on their obstacle (:func:`_stands`), come last with their weights' rows.
    """
    weights = pair_weights(model, geometry, pairs, n_robot, n_fixed=n_fixed)
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    still = np.array(
        [
            b < n_robot + n_fixed
            and (
                (bool(w.max(initial=0.0) < STILL) and _stands(geometry, data, a, b))
                or _turns_in_place(model, geometry, a)
            )
            for (a, b), w in zip(pairs, weights, strict=True)
        ],
        dtype=bool,
    )
    moving = [p for p, s in zip(pairs, still, strict=True) if not s]
    standing = [(p, w) for p, w, s in zip(pairs, weights, still, strict=True) if s]
    return moving, weights[~still], standing


def _seated(
    geometry: pin.GeometryModel, part: int, distance: float, seats: tuple[float, ...]
) -> bool:
    """Whether a standing pair's overlap (``distance`` < 0, the same everywhere) is a seat.

    The base is seated on whatever it stands in (cell.md section 3 checks it against nothing
    fixed). A link's own geometry (a mesh, a URDF primitive) that reaches into the table below
    its joint is in it at every configuration: a table top between the Panda's base (up to
    0.141 m) and joint 1 (0.333 m) cut link 1, which hangs down to the base, and every placement
    ran (the cell audit, stop 53): such a pair is checked. A capsule the service made along the
    link (no geometry of its own) from joint 1's origin on the table is seated as deep as its
    radius (the ROS-Industrial IRB 2400's from its foot); a published capsule as deep as it
    reaches below the mounting face (Menagerie's UR10e shoulder, 27 mm): ``seats``
    (:attr:`solver.path.cell.robot_geometry.RobotGeometry.seats`).
    """
    obj = geometry.geometryObjects[part]
    if int(obj.parentJoint) == 0 or distance >= 0.0:
        return True
    return distance >= -seats[part] - STILL


def _stands(geometry: pin.GeometryModel, data: pin.Data, part: int, obstacle: int) -> bool:
    """Whether ``part`` stands on the fixed ``obstacle`` (a pair no joint moves).

    The base does; so does a link on a joint whose origin is on or above a halfspace's boundary
    (the table top at or below joint 1): joint 1 turning the link about the table's normal
    keeps its distance to the table. Where joint 1's origin is inside the table (a table top
    above it: cell.md section 5's halfspace above the base), the table cuts the arm's turning
    part, and the pair is checked (it collides at every placement).
    """
    joint = int(geometry.geometryObjects[part].parentJoint)
    if joint == 0:
        return True
    obj = geometry.geometryObjects[obstacle]
    if not isinstance(obj.geometry, coal.Halfspace):
        return False
    local = obj.placement.actInv(data.oMi[joint].translation)  # joint's origin, in its frame
    return float(np.dot(obj.geometry.n, local) - obj.geometry.d) >= -STILL


def _turns_in_place(model: pin.Model, geometry: pin.GeometryModel, part: int) -> bool:
    """Whether ``part`` is on the first joint and round about its axis (a pair no joint moves).

    A sphere centred on joint 1's axis, or a capsule or cylinder along it: joint 1 turns it
    onto itself, so its distance to anything fixed is the same at every configuration, whatever
    the object's shape. Menagerie's UR5e shoulder capsule, 3 mm above a box table top at the
    mounting face, collided at every placement (the contract audit, stop 54); on a halfspace
    table it stood (:func:`_stands`).
    """
    obj = geometry.geometryObjects[part]
    joint = int(obj.parentJoint)
    if joint == 0 or int(model.parents[joint]) != 0:
        return False
    shape = obj.geometry
    if not isinstance(shape, (coal.Sphere, coal.Capsule, coal.Cylinder)):
        return False
    axis = revolute_axis(model, joint)
    if axis is None:
        return False
    centre = np.asarray(obj.placement.translation, dtype=float)
    off_axis = np.linalg.norm(centre - (centre @ axis) * axis)
    along = (
        isinstance(shape, coal.Sphere)
        or np.linalg.norm(np.cross(obj.placement.rotation[:, 2], axis)) < 1e-9
    )
    return bool(off_axis < 1e-9 and along)


def _distances(
    model: pin.Model, geometry: pin.GeometryModel, pairs: list[tuple[int, int]]
) -> list[float]:
    """The coal distance of each pair at the zero configuration (obstacles as placed in {B})."""
    probe = pin.GeometryModel()
    for obj in geometry.geometryObjects:
        probe.addGeometryObject(obj)
    for a, b in pairs:
        probe.addCollisionPair(pin.CollisionPair(a, b))
    data = probe.createData()
    pin.computeDistances(model, model.createData(), probe, data, pin.neutral(model))
    return [float(r.min_distance) for r in data.distanceResults]


def _self_candidates(
    model: pin.Model, geometry: pin.GeometryModel, n_robot: int
) -> list[tuple[int, int]]:
    """Robot parts on joints neither the same nor adjacent (checked where apart at q = 0)."""
    pairs = []
    for a in range(n_robot):
        for b in range(a + 1, n_robot):
            ja = int(geometry.geometryObjects[a].parentJoint)
            jb = int(geometry.geometryObjects[b].parentJoint)
            if ja == jb or model.parents[ja] == jb or model.parents[jb] == ja:
                continue
            pairs.append((a, b))
    return pairs
