"""The fast cell check: compiled bounds decide, coal only where a bound cannot (cell.md s. 4).

The compiled sweep (:mod:`solver.path.cell.sweep`) gives every checked pair a lower bound on
its distance at a configuration: the exact distance for capsules, spheres, boxes and
halfspaces (:mod:`closed_form`), the distance between bounding capsules for meshes and
cylinders (:mod:`capsules`). A pair goes to coal (the reference's own call, the same numbers)
only where its bound is within the clearance plus :data:`MARGIN`. So the answer is the
reference's (:meth:`solver.path.cell.checker.CellChecker.check` with ``reference=True``): the
first configuration closer than the clearance, the pair and coal's distance there.

An evaluation (every configuration's closest pair) stays with coal: there the bounds cost more
than they save (one ERK path: 29 ms against coal's 16 ms for the UR5, 15 against 12 ms for the
UR5e, loaded machine).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin

from solver.path.cell import sweep
from solver.path.cell.capsules import Primitive, primitive
from solver.path.cell.pair_tables import TablePack, build_tables

# m: a bound within this of the clearance (or of an evaluation's closest distance) goes to
# coal, whose GJK distances for boxes and meshes may differ from the exact ones by its
# tolerance (well under 1e-6 m in tests/solver/test_cell_closed_form.py).
MARGIN = 1e-5

_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}

# coal's distance of pair p at configuration m: (m, pair indices) -> distances
CoalDistances = Callable[[int, np.ndarray], np.ndarray]


def _joint_pack(model: pin.Model) -> tuple[np.ndarray, ...] | None:
    """The model's joints for the sweep's forward kinematics; None for a joint it lacks."""
    count = model.njoints
    kind, axis = np.zeros(count, dtype=np.int64), np.zeros((count, 3))
    q_index = np.zeros(count, dtype=np.int64)
    for j in range(1, count):
        joint = model.joints[j]
        name = joint.shortname().removeprefix("JointModel")
        if joint.nq != 1 or joint.nv != 1 or joint.idx_q != joint.idx_v:
            return None
        if name in ("RX", "RY", "RZ", "PX", "PY", "PZ"):
            axis[j] = _AXES[name[1]]
        elif name in ("RevoluteUnaligned", "PrismaticUnaligned"):
            axis[j] = np.asarray(joint.extract().axis, dtype=float)
        else:
            return None
        kind[j] = 1 if name.startswith("R") else 2
        q_index[j] = joint.idx_q
    rotations = np.array([np.asarray(p.rotation) for p in model.jointPlacements])
    translations = np.array([np.asarray(p.translation) for p in model.jointPlacements])
    parents = np.array(list(model.parents), dtype=np.int64)
    return parents, rotations, translations, kind, axis, q_index


def _vertex_pack(shapes: list[Primitive]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Offsets (S + 1,) into the stacked vertices (V, 3), and each shape's ball radius (S,)."""
    counts = [len(p.vertices) for p in shapes]
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    stacked = [p.vertices for p in shapes if len(p.vertices)]
    vertices = np.vstack(stacked) if stacked else np.zeros((0, 3))
    return offsets, vertices.astype(float), np.array([p.ball for p in shapes], dtype=float)


class FastCell:
    """The compiled side of a :class:`CellChecker`: its robot parts and obstacles as primitives.

    Attributes:
        robot: the sweep's robot pack.
        pairs: shape (P, 2), the checked pairs (robot parts; obstacles after them).
        tables: the self pairs' tables (:mod:`solver.path.cell.pair_tables`), made at first
            use: an evaluation (coal alone) never needs them.
    """

    def __init__(
        self,
        model: pin.Model,
        geometry: pin.GeometryModel,
        n_robot: int,
        pairs: list[tuple[int, int]],
        *,
        weights: np.ndarray,
        clearance: float,
        keys: Sequence[str] | None = None,
    ) -> None:
        """Build the packs; raise NotImplementedError for a joint or shape the sweep lacks.

        Args:
            model: the robot's model.
            geometry: the robot's parts (``n_robot``), then the obstacles.
            n_robot: how many geometry objects are the robot's.
            pairs: the checked pairs (geometry indices).
            weights: shape (P, nv), :func:`solver.path.cell.bounds.pair_weights` of the pairs.
            clearance: m, the cell's.
            keys: the robot parts' content keys (RobotGeometry.keys), whose tables are kept
                across checkers; None makes them anew.
        """
        joints = _joint_pack(model)
        if joints is None:
            raise NotImplementedError("a joint the sweep has no kinematics for")
        objects = geometry.geometryObjects
        parts = [
            primitive(objects[g].geometry, robot_part=True).placed(objects[g].placement)
            for g in range(n_robot)
        ]
        self.robot = (
            *joints,
            np.array([int(objects[g].parentJoint) for g in range(n_robot)], dtype=np.int64),
            np.array([p.ends for p in parts]),
            np.array([p.radius for p in parts]),
            np.array([p.exact for p in parts], dtype=np.bool_),
            *_vertex_pack(parts),
        )
        self.obstacles = [
            primitive(objects[g].geometry, robot_part=False) for g in range(n_robot, len(objects))
        ]
        placements = [objects[g].placement for g in range(n_robot, len(objects))]
        self._pack = self._packed(
            [s.placed(at) for s, at in zip(self.obstacles, placements, strict=True)], placements
        )
        self.pairs = np.array(pairs, dtype=np.int64).reshape(-1, 2)
        self._table_inputs = (model, geometry, weights, clearance + MARGIN, keys)
        self._tables: TablePack | None = None
        self._tables_lock = threading.Lock()  # threads share a checker: one of them makes them

    @property
    def tables(self) -> TablePack:
        """The self pairs' tables, made at the first call."""
        with self._tables_lock:
            if self._tables is None:
                model, geometry, weights, near, keys = self._table_inputs
                self._tables = build_tables(
                    model, geometry, self.robot, self.pairs, weights, near, keys
                )
            return self._tables

    @staticmethod
    def _packed(placed: list[Primitive], placements: list[pin.SE3]) -> tuple[np.ndarray, ...]:
        """The sweep's obstacle pack of placed primitives."""
        rotations = np.array([np.asarray(at.rotation) for at in placements]).reshape(-1, 3, 3)
        centres = np.array([np.asarray(at.translation) for at in placements]).reshape(-1, 3)
        return (
            np.array([p.kind for p in placed], dtype=np.int64),
            np.array([p.ends for p in placed]).reshape(-1, 2, 3),
            np.array([p.radius for p in placed], dtype=float),
            rotations,
            centres,
            np.array([p.half for p in placed]).reshape(-1, 3),
            np.array([p.exact for p in placed], dtype=np.bool_),
            *_vertex_pack(placed),
        )

    def obstacle_pack(self, moved: dict[int, pin.SE3]) -> tuple[np.ndarray, ...]:
        """The sweep's obstacle pack, obstacle k at ``moved[k]`` if given, else as built.

        The arrays a placement changes are copied (threads share the built ones).
        """
        kind, ends, radius, rotations, centres, half, exact, offsets, vertices, ball = self._pack
        if moved:
            ends, radius, rotations = ends.copy(), radius.copy(), rotations.copy()
            centres, vertices = centres.copy(), vertices.copy()
        for k, at in moved.items():
            shape = self.obstacles[k].placed(at)
            ends[k], radius[k] = shape.ends, shape.radius
            rotations[k], centres[k] = at.rotation, at.translation
            vertices[offsets[k] : offsets[k + 1]] = shape.vertices
        return kind, ends, radius, rotations, centres, half, exact, offsets, vertices, ball


def first_collision(
    fast: FastCell,
    configurations: np.ndarray,
    obstacles: tuple[np.ndarray, ...],
    weights: np.ndarray,
    clearance: float,
    coal_distances: CoalDistances,
) -> tuple[tuple[int, int, float] | None, int]:
    """The first configuration closer than the clearance: (index, pair, coal's distance).

    Returns:
        That contact (None on a clear path) and how many configurations went to coal.
    """
    count = len(fast.pairs)
    clear_until = np.full(count, -1, dtype=np.int64)
    need = np.zeros(count, dtype=np.bool_)
    index = int(
        sweep.first_due(
            configurations, fast.robot, obstacles, fast.pairs, weights, fast.tables,
            clearance + MARGIN, clearance, clear_until, 0, np.full(count, np.nan), need,
        )
    )  # fmt: skip
    return resume(
        fast, configurations, obstacles, weights, clearance, coal_distances,
        (index, clear_until, need),
    )  # fmt: skip


def resume(
    fast: FastCell,
    configurations: np.ndarray,
    obstacles: tuple[np.ndarray, ...],
    weights: np.ndarray,
    clearance: float,
    coal_distances: CoalDistances,
    state: tuple[int, np.ndarray, np.ndarray],
) -> tuple[tuple[int, int, float] | None, int]:
    """:func:`first_collision` from where :func:`sweep.first_due` stopped.

    Args:
        fast: the compiled side of the checker.
        configurations: shape (M, n), the path's configurations.
        obstacles: the obstacle pack at the path's placement.
        weights: shape (P, n), :func:`sweep.first_due`'s.
        clearance: m.
        coal_distances: coal's distances at the path's placement.
        state: that configuration (the configuration count: the path is clear), the pairs'
            last configurations proven clear (P,) and the pairs coal must decide there (P,),
            both updated in place.
    """
    index, clear_until, need = state
    known = np.full(len(fast.pairs), np.nan)
    coal_checks = 0
    while index < len(configurations):
        due = np.flatnonzero(need)
        distances = coal_distances(index, due)
        coal_checks += 1
        low = int(np.argmin(distances))
        if distances[low] < clearance:
            return (index, int(due[low]), float(distances[low])), coal_checks
        known[:] = np.nan
        known[due] = distances
        index = int(
            sweep.first_due(
                configurations, fast.robot, obstacles, fast.pairs, weights, fast.tables,
                clearance + MARGIN, clearance, clear_until, index, known, need,
            )
        )  # fmt: skip
    return None, coal_checks
