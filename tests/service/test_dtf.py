from __future__ import annotations

import math
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from fastapi.testclient import TestClient

PANDA_BASE = "panda_link0"
PANDA_TOOL = "panda_link8"
PANDA_READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]  # rad, franka's "ready" pose


def post(client: TestClient, body: dict[str, Any]) -> dict[str, Any]:
    response = client.post("/v1/dtf", json=body)
    assert response.status_code == 200, response.text
    result: dict[str, Any] = response.json()
    return result


def test_ur5e_closed_form_puts_the_limiting_joint_on_its_limit(
    client: TestClient, dtf_body: dict[str, Any]
) -> None:
    result = post(client, dtf_body)
    assert result["v_max"] > 0
    assert result["method"] == "closed_form"
    limiting = result["limiting_joint"]
    assert abs(abs(result["qdot"][limiting]) - math.pi) <= 1e-12  # ur5e: pi rad/s everywhere
    assert all(abs(speed) <= math.pi + 1e-12 for speed in result["qdot"])
    assert result["limiting_joint_name"] == "elbow_joint"
    assert result["omega_max"] == pytest.approx(result["v_max"] / dtf_body["h"], rel=1e-12)
    assert result["yoshikawa"] > 0
    assert result["chiu"] > 0


def test_lp_agrees_with_closed_form(client: TestClient, dtf_body: dict[str, Any]) -> None:
    closed_form = post(client, dtf_body)
    lp = post(client, {**dtf_body, "method": "lp"})
    assert lp["method"] == "lp"
    assert lp["v_max"] == pytest.approx(closed_form["v_max"], rel=1e-9)


def test_joint_velocity_limits_scale_the_speed(
    client: TestClient, dtf_body: dict[str, Any]
) -> None:
    default = post(client, dtf_body)
    dtf_body["robot"]["joint_velocity_limits"] = [1.0] * 6  # pi rad/s -> 1 rad/s on every joint
    slower = post(client, dtf_body)
    assert slower["v_max"] == pytest.approx(default["v_max"] / math.pi, rel=1e-12)
    assert abs(slower["qdot"][slower["limiting_joint"]]) == pytest.approx(1.0, abs=1e-12)


def test_tcp_moves_the_tool_point(client: TestClient, dtf_body: dict[str, Any]) -> None:
    flange = post(client, dtf_body)
    dtf_body["robot"]["tcp"] = {"position": [0.0, 0.0, 0.0], "orientation": [0.0, 0.0, 0.0, 1.0]}
    assert post(client, dtf_body)["v_max"] == pytest.approx(flange["v_max"], rel=1e-12)
    dtf_body["robot"]["tcp"]["position"] = [0.0, 0.0, 0.2]
    assert post(client, dtf_body)["v_max"] != pytest.approx(flange["v_max"], rel=1e-3)


def test_pure_translation_and_pure_reorientation(
    client: TestClient, dtf_body: dict[str, Any]
) -> None:
    translation = post(client, {**dtf_body, "h": None, "u_R": None})
    assert translation["v_max"] > 0
    assert translation["omega_max"] == 0
    reorientation = post(client, {**dtf_body, "h": 0, "u_T": None})
    assert reorientation["v_max"] == 0
    assert reorientation["omega_max"] > 0


def test_panda_urdf_uses_lp_and_beats_the_pseudo_inverse(
    client: TestClient, panda_urdf: str
) -> None:
    u_T, u_R, h = [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.2
    robot = {"urdf": panda_urdf, "base_frame": PANDA_BASE, "tool_frame": PANDA_TOOL}
    body = {"robot": robot, "q": PANDA_READY, "u_T": u_T, "u_R": u_R, "h": h}
    result = post(client, body)
    assert result["method"] == "lp"
    # Independently: pinocchio on the arm (fingers locked), pseudo-inverse DTF. panda_link0 is
    # the URDF's root, so the world frame is {B}.
    full = pin.buildModelFromXML(panda_urdf)
    fingers = [full.getJointId(name) for name in full.names if "finger" in name]
    arm = pin.buildReducedModel(full, fingers, pin.neutral(full))
    jacobian = pin.computeFrameJacobian(
        arm,
        arm.createData(),
        np.array(PANDA_READY),
        arm.getFrameId(PANDA_TOOL),
        pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
    )
    twist = np.concatenate([u_T, np.array(u_R) / h])
    pinv_speed = 1.0 / np.max(np.abs(np.linalg.pinv(jacobian) @ twist) / arm.velocityLimit)
    assert result["v_max"] >= pinv_speed * (1 - 1e-9)
    limiting = result["limiting_joint"]
    assert abs(result["qdot"][limiting]) == pytest.approx(arm.velocityLimit[limiting], rel=1e-9)


def test_too_few_joint_positions_are_counted_and_the_joints_named(
    client: TestClient, dtf_body: dict[str, Any]
) -> None:
    """The refusal read as debug output: "q_arr.shape=(5,) but the robot has 6 joints"."""
    dtf_body["q"] = dtf_body["q"][:5]
    response = client.post("/v1/dtf", json=dtf_body)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"][0]
    assert detail["loc"] == ["body", "q"]
    assert detail["msg"] == (
        "5 joint positions; the robot has 6 joints ('shoulder_pan_joint', 'shoulder_lift_joint', "
        "'elbow_joint', 'wrist_1_joint', 'wrist_2_joint', 'wrist_3_joint')"
    )
