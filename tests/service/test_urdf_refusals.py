"""URDFs the service refuses, and why (issue 27): the joint count limit, the parser's reason
cut to 100 characters, and a mimic joint between base and tool named in the 422.

Fixtures are example-robot-data's UR5 URDF edited in the test.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.config import get_settings
from solver.core.robots import example_robot_data_dir

UR5 = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
UR5_JOINTS = len(re.findall(r"<joint\s", UR5))
LONG = "L" * 5000


def ur5_with_fixed_links(extra: int) -> str:
    """The UR5 with ``extra`` links hung on tool0 by fixed joints."""
    links = "".join(
        f'<link name="extra_{k}"/><joint name="extra_joint_{k}" type="fixed">'
        f'<parent link="tool0"/><child link="extra_{k}"/></joint>'
        for k in range(extra)
    )
    return UR5.replace("</robot>", links + "</robot>")


def refusal(client: TestClient, body: dict[str, Any], urdf: str) -> dict[str, Any]:
    body["robot"] = {"urdf": urdf, "base_frame": "base", "tool_frame": "tool0"}
    response = client.post("/v1/evaluate", json=body)
    assert response.status_code == 422, response.text
    detail: dict[str, Any] = response.json()["detail"][0]
    assert detail["loc"] == ["body", "robot", "urdf"]
    return detail


@pytest.fixture
def joint_limit(monkeypatch: pytest.MonkeyPatch) -> Iterator[int]:
    """DTF_MAX_URDF_JOINTS = 20, set through the environment as a deployment would."""
    monkeypatch.setenv("DTF_MAX_URDF_JOINTS", "20")
    get_settings.cache_clear()
    yield 20
    get_settings.cache_clear()


def test_a_urdf_over_the_joint_limit_is_refused_naming_the_setting(
    client: TestClient, evaluate_body: dict[str, Any], joint_limit: int
) -> None:
    at_limit = ur5_with_fixed_links(joint_limit - UR5_JOINTS)
    evaluate_body["robot"] = {"urdf": at_limit, "base_frame": "base", "tool_frame": "tool0"}
    assert client.post("/v1/evaluate", json=evaluate_body).status_code == 200
    over = ur5_with_fixed_links(joint_limit - UR5_JOINTS + 1)
    detail = refusal(client, evaluate_body, over)
    assert f"{joint_limit + 1} joints" in detail["msg"] and "DTF_MAX_URDF_JOINTS" in detail["msg"]


def test_a_200_joint_urdf_is_refused_by_default(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    detail = refusal(client, evaluate_body, ur5_with_fixed_links(200 - UR5_JOINTS))
    assert "200 joints" in detail["msg"]
    assert f"DTF_MAX_URDF_JOINTS = {get_settings().max_urdf_joints}" in detail["msg"]


@pytest.mark.parametrize(
    ("edit", "reason"),
    [
        (
            lambda urdf: urdf.replace('lower="-6.28318530718"', 'lower="abc"', 1),
            "joint [shoulder_pan_joint]: lower value (abc) is not a valid float",
        ),
        (
            lambda urdf: urdf.replace('<parent link="base_link"/>', f'<parent link="{LONG}"/>', 1),
            "Failed to build tree: parent link [LLLL",
        ),
    ],
    ids=["not-a-float", "5000-character-link-name"],
)
def test_a_refused_urdf_carries_the_parsers_reason_cut_to_100_characters(
    client: TestClient, evaluate_body: dict[str, Any], edit: Any, reason: str
) -> None:
    edited = edit(UR5)
    assert edited != UR5
    message = refusal(client, evaluate_body, edited)["msg"]
    assert message.startswith("cannot parse the URDF: ") and reason in message
    assert len(message) <= len("cannot parse the URDF: ") + 100 + len("...")


def test_a_missing_frame_does_not_echo_a_5000_character_link_name(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    renamed = UR5.replace('"base_link"', f'"{LONG}"')
    evaluate_body["robot"] = {"urdf": renamed, "base_frame": "base", "tool_frame": "nowhere"}
    response = client.post("/v1/evaluate", json=evaluate_body)
    assert response.status_code == 422
    message = response.json()["detail"][0]["msg"]
    assert "'nowhere'" in message and LONG not in message and "L" * 100 + "..." in message


def test_a_mimic_joint_following_no_joint_of_the_chain_is_a_422_naming_it(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    """Mimic joints are honoured (tests/solver/families/test_mimic.py) where the leader is a
    joint of the chain; one following a joint elsewhere is named in the 422."""
    start = UR5.index('<joint name="wrist_2_joint"')
    end = UR5.index("</joint>", start)
    coupled = UR5[:end] + '<mimic joint="nowhere_joint" multiplier="-1"/>' + UR5[end:]
    message = refusal(client, evaluate_body, coupled)["msg"]
    assert "'wrist_2_joint' mimics 'nowhere_joint'" in message


def test_a_urdf_nested_1000_deep_is_a_422_on_evaluate_and_dtf(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    """A continuous joint and elements 1,001 deep: a RecursionError, answered 500, on both."""
    urdf = (
        '<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="continuous">'
        '<parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>'
        + "<x>" * 1000
        + "</x>" * 1000
        + "</robot>"
    )
    robot = {"urdf": urdf, "base_frame": "a", "tool_frame": "b", "joint_velocity_limits": [1.0]}
    dtf = client.post("/v1/dtf", json={"robot": robot, "q": [0.0], "u_T": [1, 0, 0], "h": 0})
    assert dtf.status_code == 422, dtf.text[:300]
    assert dtf.json()["detail"][0]["loc"] == ["body", "robot", "urdf"]
    detail = refusal(client, evaluate_body, urdf.replace('name="a"', 'name="base"', 1))
    assert "nest 1001 deep, more than 100" in detail["msg"]


@pytest.mark.parametrize("route", ["/v1/evaluate", "/v1/map"])
def test_a_zero_joint_axis_is_a_422_naming_the_joint(
    client: TestClient, evaluate_body: dict[str, Any], route: str
) -> None:
    """The numeric kernels met a chain of NaN: LinAlgError, answered 500 (and a job failed)."""
    urdf = UR5.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1)
    body = {**evaluate_body, "robot": {"urdf": urdf, "base_frame": "base", "tool_frame": "tool0"}}
    if route == "/v1/map":
        axis = {"min": 0.0, "max": 0.1, "step": 0.1}
        body = {k: v for k, v in body.items() if k != "placement"}
        body["grid"] = {"x": axis, "y": axis, "z": 0.1, "yaw": 0.0}
    response = client.post(route, json=body)
    assert response.status_code == 422, response.text[:300]
    detail = response.json()["detail"][0]
    assert detail["loc"] == ["body", "robot", "urdf"]
    assert detail["msg"].startswith("joint 'shoulder_pan_joint': its axis (0 0 0) has length 0")


BASE_MESH = "package://example-robot-data/robots/ur_description/meshes/ur5/collision/base.stl"
FAR_SPHERE = {
    "shape": "sphere",
    "radius": 0.01,
    "pose": {"position": [3, 3, 3], "orientation": [0, 0, 0, 1]},
}
NOT_WELL_FORMED = {
    "junk after </robot>": lambda urdf: urdf + "<junk/>",
    "a second root": lambda urdf: urdf + '<robot name="b"/>',
    "an undefined entity": lambda urdf: urdf.replace(
        '<robot name="ur5"', '<robot a="&b;" name="ur5"'
    ),
}


@pytest.mark.parametrize("edit", NOT_WELL_FORMED.values(), ids=NOT_WELL_FORMED.keys())
def test_a_urdf_that_is_not_well_formed_xml_is_a_422(
    client: TestClient, evaluate_body: dict[str, Any], edit: Any
) -> None:
    """pinocchio's parser reads these, while every check of the document (its axes, mimics,
    collision meshes) parses it as XML and skipped a document it could not: a zero axis was a
    500 (LinAlgError), a mesh named anywhere on the server was read (the hostile-input audit)."""
    urdf = edit(UR5.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1))
    detail = refusal(client, evaluate_body, urdf)
    assert detail["msg"].startswith("cannot parse the URDF: not well-formed XML: "), detail
    outside = str(example_robot_data_dir() / "ur_description/meshes/ur5/collision/base.stl")
    evaluate_body["cell"] = {"fixed": [FAR_SPHERE]}
    detail = refusal(client, evaluate_body, edit(UR5.replace(BASE_MESH, outside)))
    assert detail["msg"].startswith("cannot parse the URDF: not well-formed XML: "), detail


def test_a_urdf_in_an_xml_namespace_is_a_422(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    """With a cell, its collision geometry was parsed from the checks' rewrite (ns0:robot),
    which pinocchio cannot read: a 500."""
    evaluate_body["cell"] = {"fixed": [FAR_SPHERE]}
    urdf = UR5.replace('<robot name="ur5"', '<robot xmlns="urn:x" name="ur5"')
    detail = refusal(client, evaluate_body, urdf)
    assert detail["msg"] == (
        "cannot parse the URDF: its root element is '{urn:x}robot', not 'robot' (a URDF's "
        "elements are in no XML namespace)"
    )


def test_a_mesh_outside_the_share_is_not_read(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    """The well-formed document's mesh named by its path (not package://): approximated."""
    outside = str(example_robot_data_dir() / "ur_description/meshes/ur5/collision/base.stl")
    evaluate_body["cell"] = {"fixed": [FAR_SPHERE]}
    evaluate_body["robot"] = {
        "urdf": UR5.replace(BASE_MESH, outside),
        "base_frame": "base",
        "tool_frame": "tool0",
    }
    response = client.post("/v1/evaluate", json=evaluate_body)
    assert response.status_code == 200, response.text[:300]
    assert response.json()["cell_approximated"] == ["base"]


def test_a_robot_of_more_collision_elements_than_a_cell_may_hold_is_a_422(
    client: TestClient, evaluate_body: dict[str, Any]
) -> None:
    """Every two of a robot's collision elements are checked against each other: 1,800 small
    boxes in a 186 KB URDF took minutes and 8 GB (the hostile-input audit). Over
    DTF_MAX_CELL_OBJECTS (100) with a cell, refused before any work; without a cell its
    collision elements are not read."""
    boxes = "".join(
        f'<collision><origin xyz="0 0 {0.001 * k}"/><geometry><box size="0.01 0.01 0.01"/>'
        "</geometry></collision>"
        for k in range(93)
    )  # the UR5's own 8: 101
    urdf = UR5.replace('<link name="wrist_3_link">', f'<link name="wrist_3_link">{boxes}', 1)
    assert urdf != UR5
    evaluate_body["robot"] = {"urdf": urdf, "base_frame": "base", "tool_frame": "tool0"}
    assert client.post("/v1/evaluate", json=evaluate_body).status_code == 200
    evaluate_body["cell"] = {"fixed": [FAR_SPHERE]}
    detail = refusal(client, evaluate_body, urdf)
    assert detail["msg"].startswith(
        "101 collision elements; a robot checked against a cell may have at most 100 "
        "(DTF_MAX_CELL_OBJECTS)"
    ), detail
    job = client.post("/v1/jobs", json={"kind": "evaluate", "request": evaluate_body})
    assert job.status_code == 422, job.text[:300]
    assert job.json()["detail"][0]["loc"] == ["body", "request", "robot", "urdf"]
    first = boxes[: boxes.index("</collision>") + len("</collision>")]
    evaluate_body["robot"]["urdf"] = urdf.replace(first, "", 1)  # 100: taken
    assert client.post("/v1/evaluate", json=evaluate_body).status_code == 200


def test_a_link_defined_twice_is_named(client: TestClient, evaluate_body: dict[str, Any]) -> None:
    """The parser said "2 root links ('world', 'world')" (the hostile-input audit)."""
    urdf = UR5.replace("</robot>", '<link name="stray"/><link name="stray"/></robot>')
    detail = refusal(client, evaluate_body, urdf)
    assert detail["msg"] == (
        "cannot read the URDF: link 'stray' is defined 2 times: each link is one <link> element"
    )
