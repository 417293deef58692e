"""A request's limits on an arm with a mimic joint (issue 27): the mimic joint's own limit holds.

The fixture arm of tests/solver/families/test_mimic.py: ``j5b`` mimics ``j5`` with q_j5b =
-1.5 q_j5 + 0.2 and a speed limit of its own, 0.5 rad/s, so ``j5`` may turn at most at
0.5 / 1.5 rad/s. A request's ``joint_velocity_limits`` has one value per coordinate (the mimic
joint has no entry): a value for ``j5`` above 1/3 rad/s would let ``j5b`` pass its own limit, so
it is refused, naming both joints; at or below it the answer's joint path keeps ``j5b`` within
its limit. The speeds are measured here from the answer's joint angles alone: at the constant
feed mu_path the time between waypoints is the tool's distance over mu_path, and j5b's angle is
the coupling applied to j5's.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from fastapi.testclient import TestClient

from tests.solver.families.test_mimic import MULTIPLIER, OFFSET, SPEED, arm_urdf
from tests.solver.families.test_mimic import arm as mimic_arm

MIMIC_SPEED = 0.5  # rad/s, j5b's own limit in the URDF
LEADER_BOUND = MIMIC_SPEED / abs(MULTIPLIER)  # rad/s, the fastest j5 may turn
# Finite differences over the 40 waypoints of a smooth joint motion average the speed between
# neighbours: 1.2 % under the binding waypoint's (the refused limits overshoot by a factor 9).
DIFFERENCE_RTOL = 2e-2


def body(limits: list[float] | None, **robot: Any) -> dict[str, Any]:
    """An /v1/evaluate body on the fixture arm at placement 0, with these speed limits."""
    _, path = mimic_arm(MIMIC_SPEED)
    waypoints = [
        {"position": list(pose[:3, 3]), "orientation": list(pin.Quaternion(pose[:3, :3]).coeffs())}
        for pose in path
    ]
    arm: dict[str, Any] = {"urdf": arm_urdf(MIMIC_SPEED), "base_frame": "l0", "tool_frame": "tool0"}
    if limits is not None:
        arm["joint_velocity_limits"] = limits
    return {
        "robot": {**arm, **robot},
        "path": {"waypoints": waypoints},
        "placement": {"x": 0.0, "y": 0.0, "z": 0.0, "yaw": 0.0},
    }


def mimic_speeds(answer: dict[str, Any], positions: np.ndarray) -> np.ndarray:
    """j5b's speed (rad/s) between waypoints at the answer's feed mu_path, from its q alone.

    Args:
        answer: the /v1/evaluate answer (feasible).
        positions: shape (N, 3), m, the tool's positions along the path.
    """
    q = np.array([w["q"] for w in answer["waypoints"]])  # (N, 6), the coordinates
    mimic = MULTIPLIER * q[:, 4] + OFFSET  # (N,), j5b's angle
    seconds = np.linalg.norm(np.diff(positions, axis=0), axis=1) / answer["mu_path"]
    speeds: np.ndarray = np.abs(np.diff(mimic)) / seconds
    return speeds


@pytest.mark.parametrize(
    "j5_limit",
    [LEADER_BOUND, 0.2, SPEED],  # at the bound, below it, the URDF's own j5 limit (9x j5b's)
)
def test_no_answer_drives_the_mimic_joint_past_its_own_speed_limit(
    client: TestClient, j5_limit: float
) -> None:
    limits = [SPEED, SPEED, SPEED, SPEED, j5_limit, SPEED]
    request = body(limits)
    response = client.post("/v1/evaluate", json=request)
    if response.status_code == 200:  # whatever is answered keeps j5b within its own limit
        answer = response.json()
        assert answer["feasible"]
        positions = np.array([w["position"] for w in request["path"]["waypoints"]])
        speeds = mimic_speeds(answer, positions)
        assert speeds.max() <= MIMIC_SPEED * (1 + DIFFERENCE_RTOL)
        if j5_limit == LEADER_BOUND:  # the mimic is what binds: it reaches its limit somewhere
            assert speeds.max() == pytest.approx(MIMIC_SPEED, rel=DIFFERENCE_RTOL)
    # j5b would reach 1.5 j5_limit past the bound: refused, naming both joints and the bound
    assert response.status_code == (422 if j5_limit > LEADER_BOUND else 200), response.text
    if response.status_code == 422:
        detail = response.json()["detail"][0]
        assert detail["loc"] == ["body", "robot", "joint_velocity_limits"]
        assert "joint 4 ('j5')" in detail["msg"] and "'j5b'" in detail["msg"]
        assert repr(LEADER_BOUND) in detail["msg"]  # the largest value that is accepted


def test_without_limits_the_mimic_joint_keeps_its_own(client: TestClient) -> None:
    """The URDF's limits alone: j5's narrowed by j5b's through the multiplier."""
    request = body(None)
    response = client.post("/v1/evaluate", json=request)
    assert response.status_code == 200, response.text
    positions = np.array([w["position"] for w in request["path"]["waypoints"]])
    speeds = mimic_speeds(response.json(), positions)
    assert speeds.max() == pytest.approx(MIMIC_SPEED, rel=DIFFERENCE_RTOL)


@pytest.mark.parametrize("route", ["/v1/dtf", "/v1/map"])
def test_every_route_refuses_the_limit_the_mimic_joint_cannot_follow(
    client: TestClient, route: str
) -> None:
    request = body([SPEED] * 6)
    if route == "/v1/dtf":
        request = {
            "robot": request["robot"],
            "q": [0.1, 0.3, -0.6, 0.2, 0.7, 0.1],
            "u_T": [1.0, 0.0, 0.0],
            "u_R": [0.0, 0.0, 1.0],
            "h": None,
        }
    else:
        del request["placement"]
        axis = {"min": 0.0, "max": 0.0, "step": 0.01}
        request["grid"] = {"x": axis, "y": axis, "z": 0.0, "yaw": 0.0}
    response = client.post(route, json=request)
    assert response.status_code == 422, response.text
    assert response.json()["detail"][0]["loc"] == ["body", "robot", "joint_velocity_limits"]


def test_acceleration_limits_are_per_coordinate_and_position_limits_not_taken(
    client: TestClient,
) -> None:
    """The URDF gives a mimic joint no acceleration limit (``<limit>`` has none), so a request's
    acceleration limits, one per coordinate, drop nothing: seven values (one for j5b too) are
    refused naming the six coordinates; and a URDF arm takes no position limits from the request
    (they are the URDF's, narrowed by the mimic's), so the field is refused, not ignored."""
    seven = body(None, joint_acceleration_limits=[10.0] * 7)
    response = client.post("/v1/evaluate", json=seven)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"][0]
    assert detail["loc"][:3] == ["body", "robot", "joint_acceleration_limits"]
    assert "7 values for the 6 joints" in detail["msg"] and "'j5b'" not in detail["msg"]
    positions = body(None, joint_position_limits=[[-1.0, 1.0]] * 6)
    response = client.post("/v1/evaluate", json=positions)
    assert response.status_code == 422, response.text
    assert "joint_position_limits" in str(response.json()["detail"])
