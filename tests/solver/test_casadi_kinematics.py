"""The CasADi chain equals pinocchio: FK and Jacobian at the tool point in {B}, to 1e-12."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.robots import example_robot_data_dir
from solver.families import get_robot, robot_from_urdf
from solver.optimise.methods.casadi_kinematics import symbolic_kinematics
from tests.cases import OPW_MODELS, UR_MODELS


def _robot(name: str):
    if name == "panda":
        urdf = (example_robot_data_dir() / "panda_description/urdf/panda.urdf").read_text()
        return robot_from_urdf(urdf, base_frame="panda_link0", tool_frame="panda_link8")
    return get_robot(name)


@pytest.mark.parametrize("name", [*UR_MODELS, *OPW_MODELS, "panda"])
def test_symbolic_chain_equals_pinocchio(name: str) -> None:
    tcp = np.eye(4)
    tcp[:3, :3] = pin.utils.rotate("y", 0.3)
    tcp[:3, 3] = [0.02, 0.0, 0.17]
    robot = _robot(name).with_options(transform_tool_to_tcp=tcp)
    kinematics = symbolic_kinematics(robot)
    rng = np.random.default_rng(14)
    for _ in range(50):
        q = rng.uniform(np.maximum(robot.q_lower, -7), np.minimum(robot.q_upper, 7))
        p, rotation, jacobian = (np.array(v) for v in kinematics(q))
        pose = tool_pose_in_base(robot, q)
        np.testing.assert_allclose(p.ravel(), pose[:3, 3], rtol=0, atol=1e-12)
        np.testing.assert_allclose(rotation, pose[:3, :3], rtol=0, atol=1e-12)
        np.testing.assert_allclose(jacobian, jacobian_in_base(robot, q), rtol=0, atol=1e-12)
