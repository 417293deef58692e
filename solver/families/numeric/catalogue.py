"""Arms with no analytic IK in the catalogue: URDFs of example-robot-data, loaded by path.

Each gets the numeric family (robots.md section 4). Limits are the URDFs' own, checked against
the makers' datasheets:

- ``panda`` (Franka Emika Panda, 7 joints): {B} ``panda_link0``, flange ``panda_link8``;
  positions and speeds as Franka's datasheet (joint 4 -3.0718..-0.0698 rad, joint 6
  -0.0175..3.7525 rad; 2.175 rad/s on joints 1-4, 2.61 rad/s on 5-7).
- ``xarm7`` (UFactory xArm7): {B} ``link_base``, flange ``link_eef``; joints 1, 3, 5, 7 +-2 pi,
  the others limited; 3.14 rad/s on every joint (datasheet: 180 deg/s).
- ``kinova_jaco2`` (Kinova Jaco2 j2s6s200, 6 joints, spherical wrist): {B}
  ``j2s6s200_link_base``, flange ``j2s6s200_end_effector``; speeds 0.628 rad/s (joints 1-3,
  36 deg/s) and 0.838 rad/s (4-6, 48 deg/s). The URDF's continuous joints (1, 4, 6) are read as
  revolute with the +-2 pi its ``<limit>`` tags give, as UR joints are (as a request's URDF is
  read: :func:`solver.core.urdf_structure.continuous_as_revolute`).
  Its chain is an OPW arm's whose flange is turned half a turn on the OPW flange: the same URDF
  in a request is recognised (:mod:`solver.families.recognise`; maps equal cell for cell). The
  catalogue entry keeps numeric IK, given here, as the catalogue's six-joint numeric arm.
"""

from __future__ import annotations

from solver.core.robots import Robot, chain_from_urdf, example_robot_data_dir
from solver.core.urdf_structure import continuous_as_revolute
from solver.families import robot_from_urdf
from solver.families.numeric.family import NumericFamily

# name: (file under example-robot-data's robots/, base frame, flange)
ARMS = {
    "panda": ("panda_description/urdf/panda.urdf", "panda_link0", "panda_link8"),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", "link_base", "link_eef"),
    "kinova_jaco2": (
        "kinova_description/robots/kinova.urdf",
        "j2s6s200_link_base",
        "j2s6s200_end_effector",
    ),
}


def robots() -> dict[str, Robot]:
    """The numeric-IK arms by name."""
    arms: dict[str, Robot] = {}
    for name, (file, base_frame, tool_frame) in ARMS.items():
        # read as a request's URDF reads it (its answers then say nothing of it)
        urdf, _ = continuous_as_revolute((example_robot_data_dir() / file).read_text())
        family = NumericFamily(
            chain_from_urdf(urdf, tool_frame=tool_frame),
            base_frame=base_frame,
            tool_frame=tool_frame,
        )
        arms[name] = robot_from_urdf(
            urdf, base_frame=base_frame, tool_frame=tool_frame, name=name, family=family
        )
    return arms
