"""Helpers of the numeric-map tests: arms given as URDFs, and maps compared cell by cell.

The URDF arms get the numeric family explicitly (not whatever family the registry would give a
URDF it recognises), so these tests always measure numeric IK.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from solver.core.codes import FEASIBLE, TIE_RTOL
from solver.core.robots import Robot, example_robot_data_dir
from solver.families import get_robot, robot_from_urdf
from solver.families.numeric.family import NumericFamily
from solver.families.opw.family import OpwFamily
from solver.families.ur.catalogue import _exact_right_angles
from solver.path.pipeline import run_chunk
from solver.path.placed import check_placements
from solver.path.problem import PathProblem


def numeric_arm(robot: Robot, *, base_frame: str, tool_frame: str, compiled: bool) -> Robot:
    """``robot`` with the numeric family of its own model (compiled chain or numpy chain)."""
    family = NumericFamily(
        robot.model, base_frame=base_frame, tool_frame=tool_frame, compiled=compiled
    )
    return dataclasses.replace(robot, family=family)


def ur5_from_urdf(*, compiled: bool = True) -> Robot:
    """The catalogue UR5's URDF from example-robot-data, read as a user's URDF."""
    path = example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"
    robot = robot_from_urdf(
        _exact_right_angles(path.read_text()), base_frame="base", tool_frame="tool0", name="ur5"
    )
    return numeric_arm(robot, base_frame="base", tool_frame="tool0", compiled=compiled)


def _text(vector: np.ndarray | tuple[float, ...]) -> str:
    """A URDF vector attribute: three numbers."""
    return " ".join(repr(float(v)) for v in vector)


def opw_urdf(name: str) -> str:
    """A URDF of a catalogue OPW arm written from its parameters (robots.md section 3).

    The paper's frames: joint 1 about z at the base, joint 2 about y at (a1, b, c1), joint 3
    about y c2 above it, joint 4 about z at (a2, 0, c3), joints 5 (y) and 6 (z) at the wrist
    centre, the flange c4 along joint 6; each axis times its sign correction, each joint's
    placement turned by minus its offset (the maker's zero).
    """
    robot = get_robot(name)
    family = robot.family
    assert isinstance(family, OpwFamily)
    p = family.parameters
    x, y, z = np.eye(3)
    joints = (
        ((0.0, 0.0, 0.0), z),
        ((p.a1, p.b, p.c1), y),
        ((0.0, 0.0, p.c2), y),
        ((p.a2, 0.0, p.c3), z),
        ((0.0, 0.0, 0.0), y),
        ((0.0, 0.0, 0.0), z),
    )
    links = ['<link name="base_link"/>'] + [f'<link name="link_{i + 1}"/>' for i in range(6)]
    parts = [f'<robot name="{name}_from_opw">', *links, '<link name="tool0"/>']
    for i, (origin, axis) in enumerate(joints):
        parent = "base_link" if i == 0 else f"link_{i}"
        signed = axis * p.sign_corrections[i]
        parts.append(
            f'<joint name="joint_{i + 1}" type="revolute"><parent link="{parent}"/>'
            f'<child link="link_{i + 1}"/><origin xyz="{_text(origin)}" '
            f'rpy="{_text(axis * -p.offsets[i])}"/><axis xyz="{_text(signed)}"/>'
            f'<limit lower="{float(robot.q_lower[i])!r}" upper="{float(robot.q_upper[i])!r}" '
            f'effort="1" velocity="{float(robot.qdot_max[i])!r}"/></joint>'
        )
    parts.append(
        '<joint name="flange" type="fixed"><parent link="link_6"/><child link="tool0"/>'
        f'<origin xyz="0 0 {float(p.c4)!r}" rpy="0 0 0"/></joint></robot>'
    )
    return "\n".join(parts)


def opw_from_urdf(name: str, *, compiled: bool = True) -> Robot:
    """The OPW arm ``name`` as a user's URDF (:func:`opw_urdf`) with the numeric family."""
    robot = robot_from_urdf(opw_urdf(name), base_frame="base_link", tool_frame="tool0")
    return numeric_arm(robot, base_frame="base_link", tool_frame="tool0", compiled=compiled)


@dataclasses.dataclass(frozen=True)
class Cells:
    """Each cell of a map with its chosen branch's joint path and the paths tied with it.

    Attributes:
        reason: shape (P,), the reason code (``FEASIBLE`` where feasible).
        failed: shape (P,), the first failing waypoint, -1 where feasible.
        mu_path: shape (P,), m/s, NaN where infeasible.
        chosen: shape (P, n, W), rad, the chosen branch's joint path.
        tied: per cell, the joint paths (k, n, W) of the feasible branches whose mu_path is
            the cell's within ``TIE_RTOL`` (the branches ``auto`` may take).
    """

    reason: np.ndarray
    failed: np.ndarray
    mu_path: np.ndarray
    chosen: np.ndarray
    tied: list[np.ndarray]


def map_cells(robot: Robot, path: np.ndarray, placements: np.ndarray, chunk: int = 32) -> Cells:
    """The pipeline at every placement (P, 5), chunk by chunk, reduced to :class:`Cells`."""
    problem = PathProblem.of(robot, path)
    placements = check_placements(placements)
    reason, failed, mu, chosen, tied = [], [], [], [], []
    for start in range(0, len(placements), chunk):
        run = run_chunk(problem, placements[start : start + chunk])
        feasible = run.tracked.reason == FEASIBLE  # (B, C)
        for c, b in enumerate(run.pick):
            reason.append(run.tracked.reason[b, c])
            failed.append(run.tracked.failed_waypoint[b, c])
            mu.append(run.mu_path[b, c] if feasible[b, c] else np.nan)
            chosen.append(run.tracked.q[:, b, c])
            top = run.mu_path[b, c]
            near = feasible[:, c] & (run.mu_path[:, c] >= top - TIE_RTOL * abs(top))
            tied.append(run.tracked.q[:, near, c].transpose(1, 0, 2))
    return Cells(np.array(reason), np.array(failed), np.array(mu), np.array(chosen), tied)


def erk_placements(xs: np.ndarray, ys: np.ndarray, z: float) -> np.ndarray:
    """The grid's placements (P, 5), x fastest, yaw and spin 0."""
    grid_y, grid_x = np.meshgrid(ys, xs, indexing="ij")
    count = grid_x.size
    return np.column_stack(
        [grid_x.ravel(), grid_y.ravel(), np.full(count, z), *np.zeros((2, count))]
    )


def same_path(a: np.ndarray, b: np.ndarray, atol: float) -> bool:
    """Two joint paths (n, W) equal to ``atol``, revolute copies 2 pi apart counted equal."""
    difference = a - b
    difference -= 2 * math.pi * np.round(difference / (2 * math.pi))
    return bool(np.all(np.abs(difference) <= atol))
