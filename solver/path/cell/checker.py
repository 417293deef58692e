"""Distances between the robot, its tool and the cell's objects along a joint path (cell.md s. 3).

The robot's geometry, the obstacles and the pairs to check are built once per robot and cell
(:mod:`solver.path.cell.scene`); the checker places the ``workpiece`` objects at each
placement's T_B_O and gives every checked pair's distance by coal (``pin.computeDistances``).

A map's check runs the compiled sweep (:mod:`solver.path.cell.fast`): closed-form distances
and bounds decide most pairs, coal the rest, with the answers of coal alone (``reference=True``;
an evaluation, and a robot or cell the sweep lacks a joint or shape for, use coal alone).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from solver.core.robots import Robot
from solver.path.cell import batch, fast, kinematics
from solver.path.cell.coal_data import CoalData
from solver.path.cell.scene import build_scene
from solver.path.cell.shapes import Cell
from solver.path.cell.verdict import CellVerdict, Contact

_WINDOW = 32  # configurations looked ahead at once when skipping


class CellChecker:
    """The cell's pairs for one robot, checked along joint paths."""

    def __init__(self, robot: Robot, cell: Cell) -> None:
        """Build the geometry and choose the pairs (:func:`solver.path.cell.scene.build_scene`).

        Raises:
            InvalidInputError: a bad cell field (:meth:`Cell.check`) or link radii.
        """
        cell.check()
        self.robot, self.cell = robot, cell
        scene = build_scene(robot, cell)
        self.approximated = scene.approximated
        self.unchecked = scene.unchecked
        self.geometry = scene.geometry
        self._n_robot = scene.n_robot
        self._world_to_base = scene.world_to_base
        self._workpiece_ids = scene.workpiece_ids
        self._owners = scene.owners
        self._pairs = scene.pairs
        self._weights = scene.weights
        self._fast = scene.compiled
        self._coal_data = CoalData(robot.model, self.geometry, self._workpiece_ids)
        # collides_at's own copies: the sweep's coal calls see the data they saw before.
        self._hint_data = CoalData(robot.model, self.geometry, self._workpiece_ids)
        objects = self.geometry.geometryObjects
        self._pair_of = {
            (objects[a].name, objects[b].name): p for p, (a, b) in enumerate(self._pairs)
        }

    @property
    def pair_count(self) -> int:
        """How many pairs the check computes at each configuration (what its work grows with)."""
        return len(self._pairs)

    def configurations(
        self, q: np.ndarray, segment_in_pass: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The waypoints and the sub-steps between them: configurations and their waypoint.

        Within a pass, ceil(max_j |dq_j| / collision_step) - 1 evenly spaced sub-steps between
        neighbours, so no joint moves more than ``collision_step`` between two checks.

        Args:
            q: shape (W, n), rad, the joint path.
            segment_in_pass: shape (W - 1,), False where a rapid joins two passes (not checked
                between).

        Returns:
            shape (M, n), rad; shape (M,), the waypoint each follows.
        """
        steps = np.abs(np.diff(q, axis=0)).max(axis=1) if len(q) > 1 else np.zeros(0)
        counts = np.where(
            segment_in_pass, np.ceil(steps / self.cell.collision_step - 1e-12), 1
        ).astype(int)
        counts = np.append(np.maximum(counts, 1), 1)  # the last waypoint: itself
        owners = np.repeat(np.arange(len(q)), counts)
        starts = np.cumsum(counts) - counts
        fractions = (np.arange(len(owners)) - starts[owners]) / counts[owners]
        following = np.minimum(owners + 1, len(q) - 1)
        rows = q[owners] + fractions[:, None] * (q[following] - q[owners])
        return rows, owners

    def check(
        self,
        q: np.ndarray,
        segment_in_pass: np.ndarray,
        transform_workpiece_to_base: np.ndarray,
        *,
        closest: bool,
        reference: bool = False,
    ) -> CellVerdict:
        """Check a joint path at one placement.

        Args:
            q: shape (W, n), rad, the tracked joint path.
            segment_in_pass: shape (W - 1,), False between passes.
            transform_workpiece_to_base: shape (4, 4), T_B_O of the placement.
            closest: also give the closest pair over every configuration (an evaluation);
                False stops at the first collision (a map). Both skip the configurations
                where no pair can come within the clearance (nor, with ``closest``, nearer than
                the closest so far): :meth:`_scan`.
            reference: coal at every checked configuration, as the compiled sweep
                (:mod:`solver.path.cell.fast`) must agree with; also where the sweep lacks a
                joint or shape, and for ``closest`` (an evaluation).
        """
        placed = self._world_to_base * pin.SE3(np.asarray(transform_workpiece_to_base, float))
        if not self._pairs:
            return CellVerdict(None, None, 0)
        if self._fast is not None and not reference and not closest:
            configurations, owners = kinematics.substeps(
                np.ascontiguousarray(q, dtype=float),
                np.asarray(segment_in_pass, dtype=np.bool_),
                float(self.cell.collision_step),
            )
            return self._fast_check(configurations, owners, placed)
        configurations, owners = self.configurations(np.asarray(q, float), segment_in_pass)
        geometry = self._placed_geometry(placed)
        return self._scan(geometry, configurations, owners, closest=closest)

    def _placed_geometry(self, placed: pin.SE3) -> pin.GeometryModel:
        """A copy of the geometry with the workpiece objects at ``placed`` (threads share self)."""
        geometry = self.geometry.copy()
        for gid, pose in self._workpiece_ids:
            geometry.geometryObjects[gid].placement = placed * pose
        return geometry

    def check_many(
        self,
        joint_paths: np.ndarray,
        segment_in_pass: np.ndarray,
        transforms_workpiece_to_base: np.ndarray,
    ) -> list[CellVerdict]:
        """:meth:`check` of a map (``closest=False``) for N joint paths, the same verdicts.

        The compiled sweep runs over every path in one call (:mod:`solver.path.cell.batch`);
        coal then decides, path by path, where a bound cannot.

        Args:
            joint_paths: shape (N, W, n), rad, tracked joint paths.
            segment_in_pass: shape (W - 1,), False between passes.
            transforms_workpiece_to_base: shape (N, 4, 4), T_B_O of each path's placement.
        """
        if not len(joint_paths):
            return []
        if not self._pairs or self._fast is None:
            return [
                self.check(q, segment_in_pass, transform, closest=False)
                for q, transform in zip(joint_paths, transforms_workpiece_to_base, strict=True)
            ]
        placed = [
            self._world_to_base * pin.SE3(transform) for transform in transforms_workpiece_to_base
        ]
        return batch.check_paths(
            self._fast,
            np.ascontiguousarray(joint_paths, dtype=float),
            np.asarray(segment_in_pass, dtype=np.bool_),
            {
                gid - self._n_robot: [at * pose for at in placed]
                for gid, pose in self._workpiece_ids
            },
            (self._weights, self.cell.clearance, self.cell.collision_step),
            lambda c, configurations: self._coal_distances(configurations, placed[c]),
            self._finish,
        )

    def _fast_check(
        self, configurations: np.ndarray, owners: np.ndarray, placed: pin.SE3
    ) -> CellVerdict:
        """:meth:`check` of a map by the compiled sweep, coal only where it cannot decide."""
        assert self._fast is not None
        moved = {gid - self._n_robot: placed * pose for gid, pose in self._workpiece_ids}
        obstacles = self._fast.obstacle_pack(moved)
        hit, checks = fast.first_collision(
            self._fast,
            configurations,
            obstacles,
            self._weights,
            self.cell.clearance,
            self._coal_distances(configurations, placed),
        )
        return self._finish(hit, checks, owners)

    def _finish(
        self, hit: tuple[int, int, float] | None, checks: int, owners: np.ndarray
    ) -> CellVerdict:
        """The verdict of the compiled sweep's answer (configuration, pair, coal's distance)."""
        collision = None if hit is None else self._contact(int(owners[hit[0]]), hit[1], hit[2])
        return CellVerdict(collision, None, checks)

    def _coal_distances(self, configurations: np.ndarray, placed: pin.SE3) -> fast.CoalDistances:
        """The coal distances of some pairs at a configuration, the workpiece at ``placed``."""
        made: list[tuple[pin.GeometryModel, pin.GeometryData, pin.Data]] = []

        def coal_distances(index: int, due: np.ndarray) -> np.ndarray:
            if not made:
                made.append(self._coal_data.at(placed))
            geometry, gdata, data = made[0]
            model = self.robot.model
            pin.updateGeometryPlacements(model, data, geometry, gdata, configurations[index])
            return np.array(
                [pin.computeDistance(geometry, gdata, int(p)).min_distance for p in due]
            )

        return coal_distances

    def _scan(
        self,
        geometry: pin.GeometryModel,
        configurations: np.ndarray,
        owners: np.ndarray,
        *,
        closest: bool,
    ) -> CellVerdict:
        """The first collision along the configurations (with ``closest``, else the closest pair).

        Each pair is computed by coal only where due: at a configuration its last distance
        does not prove clear (:mod:`solver.path.cell.bounds`: it cannot close in faster than
        its weights times the joints' moves), and a configuration where no pair is due is
        skipped. Clear means above the clearance; with ``closest``, also above the closest
        distance so far plus ``fast.MARGIN`` (coal's own error is far below it): a pair skipped
        there can neither collide nor be the closest, so the answer is the one of coal at every
        pair and configuration (tests/solver/test_cell.py computes that). Against coal at every
        pair and configuration, the same verdicts (2026-12-04, same session, best of 5): the
        UR5 on the ERK path with bench/cell.py's cell 8.2 -> 5.2 ms (median of 18 feasible
        placements; the pairs a path's joints cannot move are computed once), a KR16-2 (capsules)
        along a 17,073-waypoint CL program with a table and a box 0.33 -> 0.17 s (40 % of the
        configurations computed); an optimisation's whole-path checks are such evaluations.
        """
        model = self.robot.model
        data, gdata = model.createData(), geometry.createData()
        clear_until = np.full(len(self._pairs), -1)  # the last configuration proven clear
        index, checks, clearance = 0, 0, self.cell.clearance
        best: tuple[float, int, int] | None = None  # distance, configuration, pair
        while index < len(configurations):
            due = np.flatnonzero(clear_until < index)
            pin.updateGeometryPlacements(model, data, geometry, gdata, configurations[index])
            checks += 1
            distances = np.array(
                [pin.computeDistance(geometry, gdata, int(p)).min_distance for p in due]
            )
            low = int(np.argmin(distances))
            if distances[low] < clearance:
                hit = self._contact(int(owners[index]), int(due[low]), float(distances[low]))
                return CellVerdict(hit, None, checks)
            if closest and (best is None or distances[low] < best[0]):
                best = (float(distances[low]), index, int(due[low]))
            window = configurations[index + 1 : index + 1 + _WINDOW]
            if not len(window):
                break
            floor = clearance if best is None else max(clearance, best[0] + fast.MARGIN)
            moved = np.abs(window - configurations[index]) @ self._weights[due].T  # (m, due)
            exceeded = moved >= distances - floor
            first = np.where(exceeded.any(axis=0), exceeded.argmax(axis=0), len(window))
            clear_until[due] = index + first
            index = int(clear_until.min()) + 1
        near = None if best is None else self._contact(int(owners[best[1]]), best[2], best[0])
        return CellVerdict(None, near, checks)

    def collides_at(
        self, configuration: np.ndarray, transform_workpiece_to_base: np.ndarray, contact: Contact
    ) -> bool:
        """Whether coal finds ``contact``'s pair under the clearance less ``fast.MARGIN`` there.

        The quick test of :meth:`solver.path.cell.limit.CellLimit.refuses_at`: where a path's
        waypoint is that close, no bound proves it clear, so the check reaches it (or stops
        before) and coal's distance there (within its tolerance, well under the margin)
        refuses the path too. ``configuration`` (n,), rad; T_B_O (4, 4).
        """
        objects = self.geometry.geometryObjects
        other = contact.obstacle_name  # another robot part's (self-collision)
        if contact.obstacle_slot is not None:  # an obstacle: its geometry object (_contact)
            other = objects[self._n_robot + contact.obstacle_slot].name
        pair = self._pair_of.get((contact.robot_part, other))
        if pair is None:
            return False
        placed = self._world_to_base * pin.SE3(np.asarray(transform_workpiece_to_base, float))
        geometry, gdata, data = self._hint_data.at(placed)
        pin.updateGeometryPlacements(self.robot.model, data, geometry, gdata, configuration)
        distance = pin.computeDistance(geometry, gdata, pair).min_distance
        return bool(distance < self.cell.clearance - fast.MARGIN)

    def _contact(self, waypoint: int, pair: int, distance: float) -> Contact:
        """The contact of pair ``pair`` (an index into the checked pairs)."""
        a, b = self._pairs[pair]
        objects = self.geometry.geometryObjects
        if b >= self._n_robot:
            slot = b - self._n_robot
            k = self._owners[slot]
            name = self.cell.obstacle_name(k)
            return Contact(waypoint, objects[a].name, k, name, distance, obstacle_slot=slot)
        return Contact(waypoint, objects[a].name, None, objects[b].name, distance)
