"""The symmetry of placements about the first joint's axis (spec section 6).

When joint 1 turns about the base z axis, turning a placement about that axis by alpha
(position rotated, yaw + alpha) only shifts q1 by alpha, so mu_path depends on
(r, psi) = (sqrt(x^2 + y^2), yaw - atan2(y, x)) alone. The placements of one (r, psi) form an
arc; :func:`arc_point` picks one of them inside the bounds, deterministically.

A cell keeps the symmetry only where its ``fixed`` objects turn into themselves about that axis
(a floor or table top: a halfspace whose normal is the base z axis): a fixture beside the robot
does not turn with the placement, so the map and the local searches then work over (x, y, yaw)
(:func:`symmetric_search`). The workpiece objects, the tool and the robot itself turn with it.
"""

from __future__ import annotations

import math

import numpy as np

from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.robots import Robot
from solver.optimise.search_space import PlacementBounds
from solver.path.problem import PathProblem

_TWO_PI = 2 * math.pi


def turns_about_base_z(robot: Robot) -> bool:
    """Whether joint 1 turns about the base z axis (through the origin) with a full turn to spare.

    Then mu_path depends on (r, psi) only: the shift of q1 fits its limits whenever the path's
    q1 range is under a turn.
    """
    if robot.q_upper[0] - robot.q_lower[0] < 2 * _TWO_PI - 1e-9:
        return False
    rng = np.random.default_rng(0)
    q = rng.uniform(-1.0, 1.0, robot.dof)
    jacobian = jacobian_in_base(robot, q)
    point = tool_pose_in_base(robot, q)[:3, 3]
    axis = jacobian[3:, 0]
    about_z = np.allclose(np.abs(axis), [0.0, 0.0, 1.0], atol=1e-12)
    through_origin = np.allclose(jacobian[:3, 0], np.cross(axis, point), atol=1e-12)
    return bool(about_z and through_origin)


def symmetric_search(problem: PathProblem) -> bool:
    """Whether the optimisers search over (r, psi).

    Joint 1 turns about the base z axis (:func:`turns_about_base_z`), and every limit and path
    check of the problem keeps a turn of the placement about it
    (:attr:`PathProblem.keeps_base_turn`: the cell's, where its fixed objects turn into
    themselves). A limit or check that does not say so breaks the symmetry: the search then
    runs over (x, y, yaw), slower but right (a joint-1 range searched over (r, psi) was
    silently wrong: the seams audit).
    """
    return turns_about_base_z(problem.robot) and problem.keeps_base_turn


def arc_coordinates(x: float, y: float, yaw: float) -> tuple[float, float]:
    """(r, psi) of a placement: r = |(x, y)| (m), psi = yaw - atan2(y, x) wrapped to [-pi, pi)."""
    psi = yaw - math.atan2(y, x)
    return math.hypot(x, y), (psi + math.pi) % _TWO_PI - math.pi


def _yaw_in_range(angle: float, bounds: PlacementBounds) -> float | None:
    """The copy angle + 2 pi k inside the yaw range nearest its middle; None if there is none."""
    low, high = bounds.yaw
    middle = (low + high) / 2
    value = middle + (angle - middle + math.pi) % _TWO_PI - math.pi
    for candidate in (value, value - _TWO_PI, value + _TWO_PI):
        if low - 1e-12 <= candidate <= high + 1e-12:
            return min(max(candidate, low), high)
    return None


def arc_point(
    r: float, psi: float, bounds: PlacementBounds, *, near: float
) -> tuple[float, float, float] | None:
    """The placement of the arc (r, psi) inside the bounds whose polar angle is nearest ``near``.

    Args:
        r: m, distance of the placement from the base z axis.
        psi: rad, yaw minus the polar angle.
        bounds: the box.
        near: rad, the polar angle to be near (the start's).

    Returns:
        (x, y, yaw), or None when no point of the arc is inside the box.
    """
    if r < 1e-12:  # the arc is the point (0, 0): only the yaw is left
        point = _point(0.0, psi, near, bounds)
        return point
    critical = []
    for edge in bounds.x:
        if abs(edge) <= r:
            critical += [math.acos(edge / r), -math.acos(edge / r)]
    for edge in bounds.y:
        if abs(edge) <= r:
            critical += [math.asin(edge / r), math.pi - math.asin(edge / r)]
    if bounds.yaw[1] - bounds.yaw[0] < _TWO_PI:
        critical += [bounds.yaw[0] - psi, bounds.yaw[1] - psi]
    # The inside of the arc is a union of pieces between these angles; the point nearest
    # `near` is `near` itself or an end of a piece.
    best: tuple[float, tuple[float, float, float]] | None = None
    for theta in sorted({near % _TWO_PI, *(c % _TWO_PI for c in critical)}):
        point = _point(r, psi, theta, bounds)
        distance = abs((theta - near + math.pi) % _TWO_PI - math.pi)
        if point is not None and (best is None or distance < best[0]):
            best = (distance, point)
    return None if best is None else best[1]


def _point(
    r: float, psi: float, theta: float, bounds: PlacementBounds
) -> tuple[float, float, float] | None:
    """(x, y, yaw) at polar angle theta if inside the box (edges clamped by 1e-12), else None."""
    x = min(max(r * math.cos(theta), bounds.x[0]), bounds.x[1])
    y = min(max(r * math.sin(theta), bounds.y[0]), bounds.y[1])
    if abs(x - r * math.cos(theta)) > 1e-12 or abs(y - r * math.sin(theta)) > 1e-12:
        return None
    yaw = _yaw_in_range(psi + theta, bounds)
    return None if yaw is None else (x, y, yaw)
