"""The OPW arms of the catalogue: geometry, joint limits, and where each number comes from.

Geometry (robots.md section 3) from the ROS-Industrial ``opw_parameters_*.yaml`` files and
``opw_parameters_examples.h`` of opw_kinematics; joint position and velocity limits from the
same support packages' URDF macros, as the files write them (``radians(170)`` as
``_deg(170)``, decimals in radians as they are). Angles are in the makers' convention.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from solver.families.opw.parameters import OpwParameters


@dataclass(frozen=True)
class OpwArm:
    """One catalogue arm.

    Attributes:
        name: catalogue name.
        parameters: the OPW geometry (m, rad).
        joint_names: the six joint names of the maker's URDF.
        position_limits: six (lower, upper) pairs, rad.
        velocity_limits: six joint speed limits, rad/s.
        source: the files the numbers come from.
    """

    name: str
    parameters: OpwParameters
    joint_names: tuple[str, ...]
    position_limits: tuple[tuple[float, float], ...]
    velocity_limits: tuple[float, ...]
    source: str


def _deg(*values: float) -> tuple[float, ...]:
    """Degrees, as the xacro files write ``${radians(x)}``, to radians."""
    return tuple(math.radians(v) for v in values)


def _geometry(
    lengths: tuple[float, ...], offsets_deg: tuple[float, ...], signs: tuple[int, ...]
) -> OpwParameters:
    """OpwParameters from a1, a2, b, c1, c2, c3, c4 (m), offsets (deg) and sign corrections."""
    a1, a2, b, c1, c2, c3, c4 = lengths
    return OpwParameters(a1, a2, b, c1, c2, c3, c4, _deg(*offsets_deg), signs)


_KUKA = tuple(f"joint_a{i}" for i in range(1, 7))
_NUMBERED = tuple(f"joint_{i}" for i in range(1, 7))
_KUKA_SIGNS = (-1, 1, 1, -1, 1, -1)
_FANUC_SIGNS = (1, 1, -1, -1, -1, -1)

ARMS: tuple[OpwArm, ...] = (
    OpwArm(
        name="kuka_kr6_r700_sixx",
        parameters=_geometry(
            (0.025, -0.035, 0.0, 0.400, 0.315, 0.365, 0.080), (0, -90, 0, 0, 0, 0), _KUKA_SIGNS
        ),
        joint_names=_KUKA,
        position_limits=tuple(
            zip(
                _deg(-170, -190, -120, -185, -120, -350),
                _deg(170, 45, 156, 185, 120, 350),
                strict=True,
            )
        ),
        velocity_limits=_deg(360, 300, 360, 381, 388, 615),
        source="ros-industrial/kuka_experimental kuka_kr6_support: "
        "urdf/kr6r700sixx_macro.xacro, config/opw_kinematics_kr6r700sixx.yaml",
    ),
    OpwArm(
        name="kuka_kr16_2",
        parameters=_geometry(
            (0.260, 0.035, 0.0, 0.675, 0.680, 0.670, 0.158), (0, -90, 0, 0, 0, 0), _KUKA_SIGNS
        ),
        joint_names=_KUKA,
        position_limits=tuple(
            zip(
                _deg(-185, -155, -130, -350, -130, -350),
                _deg(185, 35, 154, 350, 130, 350),
                strict=True,
            )
        ),
        velocity_limits=_deg(156, 156, 156, 330, 330, 615),
        source="ros-industrial/kuka_experimental kuka_kr16_support: urdf/kr16_2_macro.xacro; "
        "geometry: robots.md's table (opw_kinematics' examples; no yaml in the package)",
    ),
    OpwArm(
        name="abb_irb2400",
        parameters=_geometry(
            (0.100, -0.135, 0.0, 0.615, 0.705, 0.755, 0.085), (0, 0, -90, 0, 0, 0), (1,) * 6
        ),
        joint_names=_NUMBERED,
        position_limits=(
            (-3.1416, 3.1416),
            (-1.7453, 1.9199),
            (-1.0472, 1.1345),
            (-3.49, 3.49),
            (-2.0944, 2.0944),
            (-6.9813, 6.9813),
        ),
        velocity_limits=(2.618, 2.618, 2.618, 6.2832, 6.2832, 7.854),
        source="ros-industrial/abb abb_irb2400_support: urdf/irb2400_macro.xacro; "
        "opw_kinematics opw_parameters_examples.h",
    ),
    OpwArm(
        name="abb_irb4600_60_205",
        parameters=_geometry(
            (0.175, -0.175, 0.0, 0.495, 0.900, 0.960, 0.135), (0, 0, -90, 0, 0, 0), (1,) * 6
        ),
        joint_names=_NUMBERED,
        position_limits=(
            (-3.141, 3.141),
            (-1.570, 2.617),
            (-3.141, 1.308),
            (-6.981, 6.981),
            (-2.181, 2.094),
            (-6.981, 6.981),
        ),
        velocity_limits=(3.054, 3.054, 3.054, 4.363, 4.363, 6.283),
        source="ros-industrial/abb_experimental abb_irb4600_support: "
        "urdf/irb4600_60_205_macro.xacro; geometry: robots.md's table (opw_kinematics' examples)",
    ),
    OpwArm(
        name="fanuc_m20ia",
        parameters=_geometry(
            (0.150, -0.250, 0.0, 0.525, 0.790, 0.835, 0.100), (0, 0, -90, 0, 0, 180), _FANUC_SIGNS
        ),
        joint_names=_NUMBERED,
        position_limits=(
            (-2.967060, 2.967060),
            (-1.745329, 2.792527),
            (-3.228859, 4.766843),
            (-3.490658, 3.490658),
            (-2.443461, 2.443461),
            (-4.712389, 4.712389),
        ),
        velocity_limits=(3.403392, 3.054326, 3.141593, 6.283185, 6.283185, 9.599311),
        source="ros-industrial/fanuc fanuc_m20ia_support: urdf/m20ia_macro.xacro, "
        "config/opw_parameters_m20ia.yaml",
    ),
    OpwArm(
        name="fanuc_r2000ic_165f",
        parameters=_geometry(
            (0.312, -0.225, 0.0, 0.670, 1.075, 1.280, 0.215), (0, 0, -90, 0, 0, 180), _FANUC_SIGNS
        ),
        joint_names=_NUMBERED,
        position_limits=tuple(
            zip(
                _deg(-185, -60, -132, -360, -125, -360),
                _deg(185, 76, 180, 360, 125, 360),
                strict=True,
            )
        ),
        velocity_limits=_deg(130, 115, 125, 180, 180, 260),
        source="ros-industrial/fanuc_experimental fanuc_r2000ic_support: "
        "urdf/r2000ic165f_macro.xacro, config/opw_parameters_r2000ic165f.yaml",
    ),
)
