"""URDF text of an OPW arm written from its parameters as the ROS-Industrial support packages do.

Every link frame is parallel to base_link at q = 0 (joint origins carry translations only, as
in the makers' URDFs), each joint's axis is its direction there, and its origin is moved along
its own axis by a seeded amount (URDFs put joint origins anywhere on the axis). tool0 carries
the flange's orientation. The joint lines come from the paper's chain (Brandstotter et al.
2014) at the maker's zero, theta = -offset, written here with numpy, not with the solver's fit.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from solver.families.opw.parameters import OpwParameters


def _rot(axis: np.ndarray, angle: float) -> np.ndarray:
    return np.asarray(pin.exp3(np.asarray(axis, dtype=float) * angle))


def opw_urdf(
    parameters: OpwParameters,
    *,
    limits: np.ndarray,
    speeds: np.ndarray,
    joint_names: tuple[str, ...],
    slide_seed: int = 0,
) -> str:
    """The URDF of the arm: base_link, link_1..link_6, tool0 (flange), joints as named.

    Args:
        parameters: the arm's geometry (m, rad).
        limits: shape (6, 2), rad, the maker's joint limits.
        speeds: shape (6,), rad/s.
        joint_names: the six joint names.
        slide_seed: seed of the slides of each joint origin along its axis (0.05 m at most).
    """
    p = parameters
    x, y, z = np.eye(3)
    theta = -np.asarray(p.offsets, dtype=float)
    steps = (  # (translation in the previous frame, paper axis)
        (np.zeros(3), z),
        (np.array([p.a1, p.b, p.c1]), y),
        (np.array([0.0, 0.0, p.c2]), y),
        (np.array([p.a2, 0.0, p.c3]), z),
        (np.zeros(3), y),
        (np.zeros(3), z),
    )
    rotation, position = np.eye(3), np.zeros(3)
    points, axes = [], []
    for (translation, axis), angle, sign in zip(steps, theta, p.sign_corrections, strict=True):
        position = position + rotation @ translation
        axes.append(sign * (rotation @ axis))
        points.append(position.copy())
        rotation = rotation @ _rot(axis, angle)
    flange = position + p.c4 * rotation[:, 2]
    slides = np.random.default_rng(slide_seed).uniform(-0.05, 0.05, 6)
    origins = [
        point + slide * axis for point, slide, axis in zip(points, slides, axes, strict=True)
    ]
    lines = ["<robot name='opw_arm'>", "  <link name='base_link'/>"]
    lines += [f"  <link name='link_{i}'/>" for i in range(1, 7)] + ["  <link name='tool0'/>"]
    previous = np.zeros(3)
    for i in range(6):
        parent = "base_link" if i == 0 else f"link_{i}"
        xyz = " ".join(repr(float(v)) for v in origins[i] - previous)
        axis_text = " ".join(repr(float(v)) for v in axes[i])
        lower, upper = (float(v) for v in limits[i])
        speed = float(speeds[i])
        lines += [
            f"  <joint name='{joint_names[i]}' type='revolute'>",
            f"    <parent link='{parent}'/><child link='link_{i + 1}'/>",
            f"    <origin xyz='{xyz}' rpy='0 0 0'/><axis xyz='{axis_text}'/>",
            f"    <limit lower='{lower!r}' upper='{upper!r}' effort='0' velocity='{speed!r}'/>",
            "  </joint>",
        ]
        previous = origins[i]
    rpy = " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(rotation))
    xyz = " ".join(repr(float(v)) for v in flange - previous)
    lines += [
        "  <joint name='link_6-tool0' type='fixed'>",
        "    <parent link='link_6'/><child link='tool0'/>",
        f"    <origin xyz='{xyz}' rpy='{rpy}'/>",
        "  </joint>",
        "</robot>",
    ]
    return "\n".join(lines)
