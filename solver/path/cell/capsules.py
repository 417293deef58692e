"""Capsules and primitives for the compiled sweep (:mod:`solver.path.cell.sweep`), made once.

Every coal shape becomes what the sweep computes with, in its own frame: a halfspace, a sphere
or capsule (a segment and a radius), a box; or, for shapes without a closed form (cylinders,
convex meshes, anything else), a capsule that contains it, whose distance is a lower bound of
the shape's. A mesh's capsule lies along its points' principal axis, long enough to cover
every point's projection, its radius the farthest point's distance from the axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

HALFSPACE, CAPSULE, BOX = 0, 1, 2  # the sweep's obstacle kinds


@dataclass(frozen=True)
class Primitive:
    """A shape as the sweep sees it, in the frame of its placement.

    Attributes:
        kind: HALFSPACE, CAPSULE (a sphere when both ends are equal) or BOX.
        ends: shape (2, 3): a capsule's segment; a halfspace's normal in row 0.
        radius: a capsule's radius; a halfspace's offset.
        half: shape (3,), a box's half sizes.
        exact: the shape is the coal shape itself (not a capsule around it).
        vertices: shape (V, 3): with ``ball``, a convex set that contains the shape (the shape
            itself but for a cylinder, a prism around it); none for a halfspace.
        ball: m, the radius swept around the vertices' hull.
    """

    kind: int
    ends: np.ndarray
    radius: float
    half: np.ndarray
    exact: bool
    vertices: np.ndarray
    ball: float

    def placed(self, placement: pin.SE3) -> Primitive:
        """The primitive moved by ``placement``."""
        rotation, translation = placement.rotation, placement.translation
        if self.kind == HALFSPACE:
            normal = rotation @ self.ends[0]
            ends = np.array([normal, np.zeros(3)])
            offset = self.radius + float(normal @ translation)
            return Primitive(HALFSPACE, ends, offset, self.half, self.exact, self.vertices, 0.0)
        ends = self.ends @ rotation.T + translation
        vertices = self.vertices @ rotation.T + translation
        return Primitive(self.kind, ends, self.radius, self.half, self.exact, vertices, self.ball)


_SIDES = 16  # a cylinder's prism: a regular polygon around its circle


def _corners(half: np.ndarray) -> np.ndarray:
    """The 8 corners of the box [-half, half]."""
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    corners: np.ndarray = signs * half
    return corners


def _capsule(half_length: float, radius: float) -> Primitive:
    """A capsule along z from -half_length to half_length (exact)."""
    ends = np.array([[0.0, 0.0, -half_length], [0.0, 0.0, half_length]])
    return Primitive(CAPSULE, ends, radius, np.zeros(3), True, ends, radius)


def _cylinder(half_length: float, radius: float) -> Primitive:
    """A capsule around the cylinder along z; a 16-sided prism around it as its vertices."""
    ends = np.array([[0.0, 0.0, -half_length], [0.0, 0.0, half_length]])
    angles = 2.0 * np.pi * np.arange(_SIDES) / _SIDES
    outer = radius / np.cos(np.pi / _SIDES) * (1.0 + 1e-9)
    ring = np.column_stack([outer * np.cos(angles), outer * np.sin(angles), np.zeros(_SIDES)])
    prism = np.vstack([ring + ends[0], ring + ends[1]])
    return Primitive(CAPSULE, ends, radius, np.zeros(3), False, prism, 0.0)


def _around_points(points: np.ndarray) -> Primitive:
    """A capsule containing ``points`` (n, 3), along their principal axis."""
    centre = points.mean(axis=0)
    spread = points - centre
    axis = np.linalg.eigh(spread.T @ spread)[1][:, -1]
    along = spread @ axis
    off_axis = np.linalg.norm(spread - np.outer(along, axis), axis=1)
    radius = float(off_axis.max()) * (1.0 + 1e-9) + 1e-12
    ends = np.array([centre + along.min() * axis, centre + along.max() * axis])
    return Primitive(CAPSULE, ends, radius, np.zeros(3), False, points, 0.0)


def primitive(shape: coal.CollisionGeometry, *, robot_part: bool) -> Primitive:
    """What the sweep computes with for ``shape`` (a robot part's is always a capsule)."""
    if shape.getSweptSphereRadius() != 0.0:
        raise NotImplementedError("swept-sphere shapes are left to coal")
    if isinstance(shape, coal.Sphere):
        centre = np.zeros((2, 3))
        return Primitive(
            CAPSULE, centre, float(shape.radius), np.zeros(3), True, centre, shape.radius
        )
    if isinstance(shape, coal.Capsule):
        return _capsule(float(shape.halfLength), float(shape.radius))
    if isinstance(shape, coal.Cylinder):
        return _cylinder(float(shape.halfLength), float(shape.radius))
    if isinstance(shape, coal.Halfspace) and not robot_part:
        ends = np.array([np.asarray(shape.n, dtype=float), np.zeros(3)])
        return Primitive(HALFSPACE, ends, float(shape.d), np.zeros(3), True, np.zeros((0, 3)), 0.0)
    if isinstance(shape, coal.Box):
        half = np.asarray(shape.halfSide, dtype=float)
        if not robot_part:
            corners = _corners(half)
            return Primitive(BOX, np.zeros((2, 3)), 0.0, half, True, corners, 0.0)
        return _around_points(_corners(half))
    if isinstance(shape, coal.ConvexBase):
        return _around_points(np.asarray(shape.points(), dtype=float))
    if isinstance(shape, coal.Halfspace):
        raise NotImplementedError("a robot part that is a halfspace is left to coal")
    shape.computeLocalAABB()
    box = shape.aabb_local
    low, high = np.asarray(box.min_, dtype=float), np.asarray(box.max_, dtype=float)
    return _around_points(_corners((high - low) / 2.0) + (high + low) / 2.0)
