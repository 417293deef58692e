"""A URDF changed before it is read says so on every route: stray links, continuous joints.

Stray links (issue 27's corpus):
The ROS 2 generated UR5e of the acceptance corpus has ``<link name="world"/>`` and no joint to it
(its generator left the joint out): pinocchio refuses such a document (two root links), though
the link has no pose and is no part of the arm. The fixture is example-robot-data's UR5 with its
``world_joint`` taken out, the same case; each route's answer must be the one of the same URDF
with the link deleted by hand, and say what was left out (``robot_read``); a map job's result
too. A UR5 with a link that carries collision geometry and no joint is refused, naming the roots.

Continuous joints (Kinova's files): read as revolute joints, with no position limit where the
file gives none; the answer is the one of the same arm with that joint revolute over +-1000 rad
(which no path here reaches), and says which joints.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pinocchio as pin
import pytest
from fastapi.testclient import TestClient

from service.schemas import DtfRequest
from solver.core.native_stderr import native_stderr
from solver.core.robots import example_robot_data_dir
from tests.cases import ROOT
from tests.service.conftest import example_body
from tests.service.test_job_results import done_job

UR5 = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
_START = UR5.index('<joint name="world_joint"')
STRAY = UR5[:_START] + UR5[UR5.index("</joint>", _START) + len("</joint>") :]
BY_HAND = STRAY.replace('<link name="world"/>', "")
PATH = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())["path"]
AXIS = {"min": -0.1, "max": 0.1, "step": 0.1}
EXTRA = {
    "evaluate": {"placement": {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0}, "detail": "summary"},
    "map": {"grid": {"x": AXIS, "y": {"min": 0.4, "max": 0.5, "step": 0.1}, "z": 0.1, "yaw": 0.0}},
    "optimize": {"bounds": {"x": [-0.1, 0.1], "y": [0.4, 0.5], "yaw": [-0.2, 0.2]}, "z": 0.1},
}
READ = {
    "left_out_links": ["world"],
    "left_out_count": 1,
    "continuous_joints": [],
    "unlimited_joints": [],
    "locked_joints": [],
}


def body(route: str, urdf: str) -> dict[str, Any]:
    robot = {"urdf": urdf, "base_frame": "base", "tool_frame": "tool0"}
    if route == "dtf":  # the example's configuration and direction, on this robot
        return {**example_body(DtfRequest), "robot": robot}
    return {"robot": robot, "path": PATH, **EXTRA[route]}


def answer(client: TestClient, route: str, urdf: str) -> dict[str, Any]:
    response = client.post(f"/v1/{route}", json=body(route, urdf))
    assert response.status_code == 200, response.text[:300]
    result: dict[str, Any] = response.json()
    return result


def test_the_document_has_a_stray_link_pinocchio_refuses() -> None:
    # The fixture is the corpus's case: a second root that no joint names, which pinocchio's
    # parser refuses; deleted by hand, the document is read.
    assert STRAY.count('<link name="world"/>') == 1 and "world_joint" not in STRAY
    with native_stderr(), pytest.raises((RuntimeError, ValueError)):
        pin.buildModelFromXML(STRAY)
    assert pin.buildModelFromXML(BY_HAND).nq == 6


@pytest.mark.parametrize("route", ["evaluate", "map", "optimize", "dtf"])
def test_each_route_answers_as_without_the_link_and_says_it(client: TestClient, route: str) -> None:
    left_out, by_hand = answer(client, route, STRAY), answer(client, route, BY_HAND)
    assert left_out["robot_read"] == READ and by_hand["robot_read"] is None
    if route == "optimize":
        assert left_out["evaluation"]["robot_read"] is None  # said once, at the top
        for key in ("solver",):  # its wall time differs
            left_out.pop(key), by_hand.pop(key)
    assert {**left_out, "robot_read": None} == by_hand


def test_the_map_picture_of_it_is_drawn(client: TestClient) -> None:
    response = client.post("/v1/map/png", json=body("map", STRAY))
    assert response.status_code == 200 and response.content.startswith(b"\x89PNG")


def test_a_map_job_says_it_as_the_route(client: TestClient, own_store: Path) -> None:
    submitted = client.post("/v1/jobs", json={"kind": "map", "request": body("map", STRAY)})
    assert submitted.status_code in (200, 201, 202), submitted.text
    job = done_job(client, submitted.json()["id"])
    assert job["status"] == "done", job
    assert job["result"] == answer(client, "map", STRAY)


def test_a_link_with_collision_geometry_and_no_joint_is_refused(client: TestClient) -> None:
    table = '<link name="table"><collision><geometry><box size="1 1 0.1"/></geometry></collision>'
    urdf = STRAY.replace('<link name="world"/>', table + "</link>")
    response = client.post("/v1/evaluate", json=body("evaluate", urdf))
    assert response.status_code == 422, response.text[:300]
    (detail,) = response.json()["detail"]
    assert detail["loc"] == ["body", "robot", "urdf"]
    assert "2 root links ('base_link', 'table')" in detail["msg"]


def test_a_continuous_joint_is_read_as_revolute_and_said(client: TestClient) -> None:
    start = UR5.index('<joint name="wrist_3_joint"')
    end = UR5.index("</joint>", start)
    joint = re.sub(r' (lower|upper)="[^"]*"', "", UR5[start:end])
    unlimited = UR5[:start] + joint.replace('type="revolute"', 'type="continuous"') + UR5[end:]
    wide = UR5[:start] + joint.replace("<limit ", '<limit lower="-1000" upper="1000" ') + UR5[end:]
    for route in ("evaluate", "map", "dtf"):
        read, plain = answer(client, route, unlimited), answer(client, route, wide)
        assert read["robot_read"] == {
            "left_out_links": [],
            "left_out_count": 0,
            "continuous_joints": ["wrist_3_joint"],
            "unlimited_joints": ["wrist_3_joint"],
            "locked_joints": [],
        }
        assert plain["robot_read"] is None
        assert {**read, "robot_read": None} == plain


def test_errors_name_a_urdf_robot_by_its_own_name(client: TestClient) -> None:
    # Not "urdf" (the solver's name of every request's URDF): <robot name="ur5"> as "ur5 (URDF)".
    assert '<robot name="ur5"' in UR5
    rails = "".join(
        f'<link name="rail{k}"/><joint name="rail{k}_joint" type="prismatic">'
        f'<parent link="rail{k}"/><child link="{child}"/><axis xyz="1 0 0"/>'
        '<limit lower="0" upper="2" effort="100" velocity="1"/></joint>'
        for k, child in ((0, "rail1"), (1, "world"))
    )  # two rails under the arm's root: eight joints
    request = body("evaluate", UR5.replace("</robot>", rails + "</robot>"))
    request["robot"]["base_frame"] = "rail0"
    # A few waypoints: an arm of more than seven joints weighs an LP a branch and a waypoint
    # (solver/families/numeric/costs.py), and the README path's 133 are over the size limit.
    request["path"] = {"waypoints": request["path"]["waypoints"][:5]}
    response = client.post("/v1/evaluate", json={**request, "spin_mode": "free"})
    assert response.status_code == 422, response.text[:300]
    assert "six- and seven-joint arms; 'ur5 (URDF)' has 8 joints" in response.text
    rows = [[0.0] * 5] * len(PATH["waypoints"])  # five values a row for a six-joint arm
    request = {**body("evaluate", UR5), "joint_path": rows}
    response = client.post("/v1/evaluate", json=request)
    assert response.status_code == 422, response.text[:300]
    assert "5 values but 'ur5 (URDF)' has 6 joints" in response.text


def test_joints_that_move_no_tool_are_named_locked_and_catalogue_robots_say_nothing(
    client: TestClient, panda_urdf: str
) -> None:
    # The Panda's URDF with its hand: the fingers move, not the flange (panda_link8). The
    # oracle is a regex reading of the file: its joints that are not fixed, less the chain's.
    moving = re.findall(r'<joint name="([^"]+)" type="(?!fixed)[a-z]+"', panda_urdf)
    chain = [f"panda_joint{k}" for k in range(1, 8)]
    assert set(chain) < set(moving)
    robot = {"urdf": panda_urdf, "base_frame": "panda_link0", "tool_frame": "panda_link8"}
    request = {"robot": robot, "path": PATH, **EXTRA["evaluate"]}
    read = client.post("/v1/evaluate", json=request).json()["robot_read"]
    assert read["locked_joints"] == [name for name in moving if name not in chain]
    assert read["locked_joints"] == ["panda_finger_joint1", "panda_finger_joint2"]
    catalogue = client.post("/v1/evaluate", json={**request, "robot": {"model": "panda"}})
    assert catalogue.json()["robot_read"] is None  # the same fingers, the catalogue's own
