"""The cell on the routes (cell.md): collisions reported, inputs bounded, errors named."""

from __future__ import annotations

import base64
import json
from collections.abc import Iterator
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from fastapi.testclient import TestClient

from service.config import get_settings
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.path.cell.cost import CELL_POSE_COST
from solver.path.cell.shapes import Box, Cell, Halfspace
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem
from tests.cases import EXAMPLES
from tests.service.test_errors import assert_names
from tests.service.test_job_routes import EXAMPLE, route_body
from tests.service.test_urdf_mimic_limits import MIMIC_SPEED
from tests.service.test_urdf_mimic_limits import body as mimic_body
from tests.solver.families.test_mimic import arm as mimic_arm
from tests.solver.test_cell import _distance as coal_distance
from tests.solver.test_cell import binary_stl, cube_triangles, ur5_geometry
from tests.solver.test_evaluate import load_path

TABLE = {"shape": "halfspace", "name": "table", "normal": [0, 0, 1], "offset": 0.0}
FIXTURE = {
    "shape": "box",
    "name": "fixture",
    "size": [0.1, 0.1, 0.6],
    "pose": {"position": [-0.2, 0.55, 0.3], "orientation": [0, 0, 0, 1]},
}


@pytest.fixture
def body() -> dict[str, Any]:
    """The example evaluate request: ur5 on the curved line at (0, 0.45, 0.1)."""
    return json.loads((EXAMPLES / "evaluate_request.json").read_text())


@pytest.fixture
def setting(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """Set DTF_<NAME> settings for one test."""

    def set_(**values: Any) -> None:
        for name, value in values.items():
            monkeypatch.setenv(f"DTF_{name.upper()}", str(value))
        get_settings.cache_clear()

    yield set_
    get_settings.cache_clear()


def solver_answer(fixed: tuple) -> Any:
    """evaluate_path at the example's placement with a cell of ``fixed`` objects."""
    problem = PathProblem.of(
        get_robot("ur5"), load_path("curved_line"), PathOptions(cell=Cell(fixed=fixed))
    )
    return evaluate_path(problem, Placement(0.0, 0.45, 0.1, 0.0))


def test_evaluate_reports_the_collision(client: TestClient, body: dict) -> None:
    body["cell"] = {"fixed": [TABLE, FIXTURE]}
    answer = client.post("/v1/evaluate", json=body).json()
    fixture = Box(
        (0.1, 0.1, 0.6),
        np.array([[1, 0, 0, -0.2], [0, 1, 0, 0.55], [0, 0, 1, 0.3], [0, 0, 0, 1.0]]),
        "fixture",
    )
    expected = solver_answer((Halfspace((0, 0, 1), 0.0, "table"), fixture))
    assert answer["feasible"] is False and answer["reason"] == "collision"
    contact = answer["collision"]
    assert contact["obstacle"] == 1 and contact["obstacle_name"] == "fixture"
    assert contact["waypoint"] == answer["failed_waypoint"] == expected.collision.waypoint
    assert contact["distance"] == pytest.approx(expected.collision.distance, abs=1e-9)
    assert answer["min_clearance"] is None


def test_evaluate_reports_the_min_clearance(client: TestClient, body: dict) -> None:
    body["cell"] = {"fixed": [TABLE]}
    answer = client.post("/v1/evaluate", json=body).json()
    expected = solver_answer((Halfspace((0, 0, 1), 0.0, "table"),))
    assert answer["feasible"] is True and answer["collision"] is None
    assert answer["min_clearance"]["distance"] == pytest.approx(
        expected.min_clearance.distance, abs=1e-9
    )
    plain = client.post("/v1/evaluate", json={k: v for k, v in body.items() if k != "cell"})
    # the velocity-best branch (wrist noflip) brings the wrist within the clearance of the
    # forearm: the answer is its tie, the wrist flipped, equal to the last bits
    assert answer["mu_path"] == pytest.approx(plain.json()["mu_path"], rel=1e-12)


def map_request(body: dict) -> dict[str, Any]:
    """Three placements of the example path with a halfspace over the base."""
    return {
        "robot": body["robot"],
        "path": body["path"],
        "grid": {
            "x": {"min": -0.1, "max": 0.1, "step": 0.1},
            "y": {"min": 0.45, "max": 0.45, "step": 0.1},
            "z": 0.1,
            "yaw": 0.0,
        },
        "cell": {"fixed": [{"shape": "halfspace", "normal": [0, 0, 1], "offset": 0.1}]},
    }


def test_the_map_marks_collision_cells(client: TestClient, body: dict) -> None:
    response = client.post("/v1/map", json=map_request(body))
    assert response.status_code == 200, response.text
    reasons = {cell["reason"] for cell in response.json()["cells"]}
    assert reasons == {"collision"}


def test_the_map_names_its_capsules_and_unchecked_parts_as_an_evaluation_does(
    client: TestClient, body: dict
) -> None:
    request = map_request(body)
    request["robot"] = {"model": "abb_irb2400"}
    request["grid"] = {**request["grid"], "x": {"min": 0.8, "max": 1.0, "step": 0.1}}
    request["grid"]["y"] = {"min": 0.0, "max": 0.0, "step": 0.1}
    request["grid"]["z"] = 0.3
    request["cell"] = {"fixed": [TABLE], "link_radii": [0.05] * 7}
    answer = client.post("/v1/map", json=request).json()
    assert answer["feasible_cells"] > 0
    at = {"x": 0.9, "y": 0.0, "z": 0.3, "yaw": 0.0}
    evaluated = client.post(
        "/v1/evaluate",
        json={k: request[k] for k in ("robot", "path", "cell")} | {"placement": at},
    ).json()
    assert evaluated["feasible"] is True
    for field in ("cell_approximated", "cell_unchecked"):
        assert answer[field] == evaluated[field]
    assert [p["robot_part"] for p in answer["cell_unchecked"]] == [
        "base_capsule",
        "joint_1_capsule",
    ]
    assert len(answer["cell_approximated"]) == 7  # the base and six links, no geometry
    del request["cell"]
    plain = client.post("/v1/map", json=request).json()
    assert plain["cell_approximated"] is None and plain["cell_unchecked"] is None


def mesh(stl: str, units: str = "m") -> dict[str, Any]:
    """A mesh object of an STL."""
    return {"shape": "mesh", "stl": stl, "units": units}


CUBE = base64.b64encode(binary_stl(cube_triangles(0.1))).decode()
TWO_CUBES = base64.b64encode(
    binary_stl(np.concatenate([cube_triangles(0.1), cube_triangles(0.1) + [0.5, 0.0, 0.0]]))
).decode()


@pytest.mark.parametrize(
    ("cell", "settings", "loc", "words"),
    [
        ({"fixed": [TABLE, FIXTURE]}, {"max_cell_objects": 1}, ["cell"], "DTF_MAX_CELL_OBJECTS"),
        (  # one object, two separate parts: two hulls, two objects against the limit
            {"fixed": [mesh(TWO_CUBES)]},
            {"max_cell_objects": 1},
            ["cell"],
            "2 objects, each separate part of a mesh one",
        ),
        (
            {"fixed": [mesh(CUBE)]},
            {"max_mesh_triangles": 11},
            ["cell", "fixed", 0, "mesh", "stl"],  # as the schema's own errors of the field
            "DTF_MAX_MESH_TRIANGLES",
        ),
        (
            {"workpiece": [mesh("hello, not a mesh")]},
            {},
            ["cell", "workpiece", 0, "mesh", "stl"],
            "not an STL",
        ),
        ({"fixed": [mesh("c29saWQ=")]}, {}, ["cell", "fixed", 0, "mesh", "stl"], "not an STL"),
        ({"fixed": [{"shape": "box", "size": [0.1, -0.1, 0.1]}]}, {}, ["cell", "fixed", 0], ""),
        ({"fixed": [{"shape": "cone", "radius": 0.1}]}, {}, ["cell", "fixed", 0], ""),
        ({"tool": {"radius": 0.02, "length": 0.01}}, {}, ["cell", "tool", "cutting_length"], ""),
        ({"link_radii": [0.05, 0.05]}, {}, ["cell", "link_radii"], "give 7"),
        ({"collision_step": 1e-4}, {}, ["cell", "collision_step"], "0.001"),
    ],
    ids=[
        "objects",
        "mesh parts",
        "triangles",
        "text",
        "base64-not-stl",
        "size",
        "shape",
        "tool",
        "radii",
        "step",
    ],  # fmt: skip
)
def test_a_bad_cell_is_a_422_naming_its_field(
    client: TestClient,
    body: dict,
    setting: Any,
    cell: dict,
    settings: dict,
    loc: list,
    words: str,
) -> None:
    setting(**settings)
    body["cell"] = cell
    response = client.post("/v1/evaluate", json=body)
    assert_names(response, 422, ["body", *loc])
    assert words in json.dumps(response.json())


def test_link_radii_for_an_arm_whose_links_all_carry_geometry_are_a_422(
    client: TestClient, body: dict
) -> None:
    """The UR5's URDF meshes every link: radii of 0.05 or 0.9 m answered alike, nothing said
    they sized nothing (the hostile-input audit, on the Panda)."""
    body["cell"] = {"fixed": [TABLE], "link_radii": [0.9] * 7}
    response = client.post("/v1/evaluate", json=body)
    assert_names(response, 422, ["body", "cell", "link_radii"])
    assert response.json()["detail"][0]["msg"] == (
        "every link of 'ur5' carries its URDF's collision geometry, and link_radii size only the "
        "capsules of links without any: leave them out"
    )


def test_a_map_in_a_cell_weighs_its_collision_work(
    client: TestClient, body: dict, setting: Any
) -> None:
    setting(max_map_poses=1000)  # 3 placements x 133 waypoints = 399 poses: fine without a cell
    request = map_request(body)
    response = client.post("/v1/map", json=request)
    assert_names(response, 422, ["body", "grid"])
    assert "in a cell" in response.json()["detail"][0]["msg"]
    del request["cell"]
    assert client.post("/v1/map", json=request).status_code == 200


def test_a_cell_of_many_objects_weighs_its_pairs(
    client: TestClient, body: dict, setting: Any
) -> None:
    """The check computes every moving robot part against every object, so its work grows with
    the objects: 100 small spheres 5 m away (no collision, nothing stops early) took the UR5's
    map 3 times the weight of 50 a pose, a URDF of 100 collision elements 26 times
    (solver.path.cell.cost.PAIRS_IN_WEIGHT). At a limit that admits the map at 50 a pose
    (3 placements x 133 waypoints x 51), 20 spheres are admitted and 100 refused."""
    request = map_request(body)
    setting(max_map_poses=3 * 133 * (1 + int(CELL_POSE_COST)) + 1)

    def spheres(count: int) -> list[dict[str, Any]]:
        return [
            {
                "shape": "sphere",
                "radius": 0.01,
                "pose": {"position": [5.0, 0.1 * k - 5.0, 0.5], "orientation": [0, 0, 0, 1]},
            }
            for k in range(count)
        ]

    request["cell"] = {"fixed": spheres(20)}
    admitted = client.post("/v1/map", json=request)
    assert admitted.status_code == 200, admitted.text
    assert {cell["reason"] for cell in admitted.json()["cells"]} == {None}  # all feasible
    request["cell"] = {"fixed": spheres(100)}
    refused = client.post("/v1/map", json=request)
    assert_names(refused, 422, ["body", "grid"])
    assert "in a cell" in refused.json()["detail"][0]["msg"]


def test_a_numeric_arm_in_a_cell_adds_the_check_to_its_ik_work(
    client: TestClient, setting: Any
) -> None:
    """The check's weight (50 a pose) is added to a numeric arm's (tens of thousands a
    placement), not multiplied by it: the mimic fixture arm (numpy chain, 40 waypoints) maps 3 x 3
    placements with a far table where its map without a cell is admitted, and is refused by a
    limit just under the two together. Until 2026-12-04 the product (50 times the IK's) refused
    the corpus IRB 5400's 3 x 3 map with a cell whose 9 x 11 map without ran in the same time."""
    request = mimic_body(None)
    del request["placement"]
    axis = {"min": -0.1, "max": 0.1, "step": 0.1}
    request["grid"] = {"x": axis, "y": axis, "z": 0.0, "yaw": 0.0}
    far = {"fixed": [{"shape": "halfspace", "normal": [0, 0, 1], "offset": -5.0}]}
    family = mimic_arm(MIMIC_SPEED)[0].family
    assert family is not None
    bare = 9 * family.map_cost(40)  # each placement's figure, every branch followed
    with_cell = bare + 9 * 40 * CELL_POSE_COST
    setting(max_map_poses=int(with_cell) + 1)  # the product would be 50 times ``bare``
    answer = client.post("/v1/map", json={**request, "cell": far})
    assert answer.status_code == 200, answer.text
    assert "collision" not in {cell["reason"] for cell in answer.json()["cells"]}
    setting(max_map_poses=int(with_cell) - 1)
    refused = client.post("/v1/map", json={**request, "cell": far})
    assert_names(refused, 422, ["body", "grid"])
    assert "(numeric IK in a cell)" in refused.json()["detail"][0]["msg"]
    assert client.post("/v1/map", json=request).status_code == 200  # bare fits that limit


def test_a_finer_collision_step_weighs_its_sub_steps(
    client: TestClient, body: dict, setting: Any
) -> None:
    """3 placements x 133 waypoints x 50: 19,950 poses; at a tenth of the step, ten times that."""
    setting(max_map_poses=100_000)
    request = map_request(body)
    assert client.post("/v1/map", json=request).status_code == 200
    request["cell"]["collision_step"] = 0.005
    response = client.post("/v1/map", json=request)
    assert_names(response, 422, ["body", "grid"])
    assert "in a cell" in response.json()["detail"][0]["msg"]


def test_a_tool_without_thickness_is_checked(client: TestClient, body: dict) -> None:
    """A 5e-324 m tool (schemathesis found it: a table grid sized by 0 was a 500) answers."""
    body["robot"]["tcp"] = {"position": [0.0, 0.0, 0.12], "orientation": [0, 0, 0, 1]}
    body["cell"] = {
        "fixed": [TABLE],
        "tool": {"radius": 5e-324, "length": 0.12, "cutting_length": 5e-324},
        "collision_step": 0.001,
    }
    response = client.post("/v1/evaluate", json=body)
    assert response.status_code == 200, response.text


def test_a_tool_behind_the_flange_is_a_422(client: TestClient, body: dict) -> None:
    """cell.md: the tool runs from the flange to the tool point. A 12 cm tool with the tool
    point left at the flange (no tcp) would start 120 mm behind it, inside the wrist."""
    body["cell"] = {"tool": {"radius": 0.03, "length": 0.12}}
    response = client.post("/v1/evaluate", json=body)
    assert_names(response, 422, ["body", "cell", "tool", "length"])
    message = response.json()["detail"][0]["msg"]
    assert "120.0 mm behind the flange" in message and "at most 0 m" in message
    body["robot"]["tcp"] = {"position": [0.0, 0.0, 0.1], "orientation": [0, 0, 0, 1]}
    response = client.post("/v1/evaluate", json=body)
    assert_names(response, 422, ["body", "cell", "tool", "length"])
    assert "20.0 mm behind the flange" in response.json()["detail"][0]["msg"]
    body["robot"]["tcp"] = {"position": [0.0, 0.0, 0.12], "orientation": [0, 0, 0, 1]}
    assert client.post("/v1/evaluate", json=body).status_code == 200


def test_an_optimisation_in_a_cell_weighs_its_collision_work(
    client: TestClient, body: dict
) -> None:
    box = {
        "robot": body["robot"],
        "path": body["path"],
        "bounds": {"x": [-0.35, 0.35], "y": [0.15, 0.75], "yaw": [-3.14159, 3.14159]},
        "z": 0.1,
        "cell": {"fixed": [TABLE]},
    }
    response = client.post("/v1/optimize", json=box)  # 816 coarse cells x 133 x 50: over 5 M
    assert_names(response, 422, ["body", "bounds"])
    assert "coarse map" in response.json()["detail"][0]["msg"]
    assert "POST /v1/jobs runs bigger searches" in response.json()["detail"][0]["msg"]


@pytest.mark.parametrize(("model", "count"), [("ur5", 0), ("ur5e", 7)])
def test_the_answer_names_the_links_given_capsules(
    client: TestClient, body: dict, model: str, count: int
) -> None:
    """The UR5's URDF meshes every link (link radii for it are a 422: the test above)."""
    body["robot"] = {"model": model}
    body["cell"] = {"fixed": [TABLE]} | ({"link_radii": [0.05] * 7} if count else {})
    answer = client.post("/v1/evaluate", json=body).json()
    assert len(answer["cell_approximated"]) == count


def test_an_opw_arm_on_its_table_says_which_parts_are_not_checked(
    client: TestClient, body: dict
) -> None:
    # Its capsules (5 cm) along the kinematic segments: the base's a ball at the foot, joint 1's
    # from there to joint 2; both 5 cm into the table whatever the joints (joint 1 turns about
    # its normal), so neither is checked, and the answer says so.
    body["robot"] = {"model": "abb_irb2400"}
    body["placement"] = {"x": 0.9, "y": 0.0, "z": 0.3, "yaw": 0.0}
    body["cell"] = {"fixed": [TABLE], "link_radii": [0.05] * 7}
    answer = client.post("/v1/evaluate", json=body).json()
    assert answer["feasible"] is True
    pairs = {(p["robot_part"], p["obstacle"], p["obstacle_name"]) for p in answer["cell_unchecked"]}
    assert pairs == {("base_capsule", 0, "table"), ("joint_1_capsule", 0, "table")}
    assert [p["distance"] for p in answer["cell_unchecked"]] == pytest.approx([-0.05] * 2)
    body["robot"], body["placement"] = {"model": "ur5"}, {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0}
    body["cell"] = {"fixed": [TABLE, FIXTURE]}  # the UR5's meshes: the base and the shoulder
    answer = client.post("/v1/evaluate", json=body).json()
    parts = {(p["robot_part"], p["obstacle_name"]) for p in answer["cell_unchecked"]}
    assert parts == {
        ("base_link_0", "table"),
        ("base_link_0", "fixture"),
        ("shoulder_link_0", "table"),
    }


@pytest.mark.parametrize("kind", ["evaluate", "map", "optimize"])
def test_a_job_with_a_bad_cell_is_refused_at_submit_as_its_route_refuses_it(
    client: TestClient, kind: str
) -> None:
    body = route_body(kind, EXAMPLE["path"])
    body["cell"] = {"workpiece": [mesh("hello, not a mesh")]}
    direct = client.post(f"/v1/{kind}", json=body)
    assert_names(direct, 422, ["body", "cell", "workpiece", 0, "mesh", "stl"])
    submitted = client.post("/v1/jobs", json={"kind": kind, "request": body})
    assert submitted.status_code == 422, submitted.text
    (expected,), (detail,) = direct.json()["detail"], submitted.json()["detail"]
    assert detail == {**expected, "loc": ["body", "request", *expected["loc"][1:]]}


SWEEP = "UNITS/MM\nMULTAX/ON\nFEDRAT/MMPM,1000\n" + "".join(
    f"GOTO/{10 * i},0,0,0,0,1\n" for i in range(11)
)


def test_a_larger_clearance_never_checks_fewer_self_pairs(client: TestClient) -> None:
    """The UR5's upper arm through its wrist 2 at the path's start, at every clearance.

    The self pairs were those apart by more than the request's clearance at q = 0: at 0.5 m
    another contact was named and at 0.9 m no pair was left, the path feasible. Independent:
    coal's distance between the two parts at the answer's first configuration, in a
    GeometryModel built here from the URDF (tests/solver/test_cell.py).
    """
    body: dict[str, Any] = {
        "robot": {"model": "ur5"},
        "path": {"cl_data": SWEEP},
        "placement": {"x": 0.1, "y": 0.1, "z": 0.0, "yaw": 0.0},
        "ik": {"branch": {"shoulder": "left", "elbow": "up", "wrist": "noflip"}},
    }
    free = client.post("/v1/evaluate", json=body).json()
    assert free["feasible"], free
    model, geometry = ur5_geometry()
    data, gdata = model.createData(), geometry.createData()
    pin.updateGeometryPlacements(model, data, geometry, gdata, np.array(free["waypoints"][0]["q"]))
    names = [o.name for o in geometry.geometryObjects]
    a, b = names.index("upper_arm_link_0"), names.index("wrist_2_link_0")
    expected = coal_distance(geometry, gdata, a, b)
    assert expected < -0.02  # they overlap
    for clearance in (0.005, 0.05, 0.5, 0.9):
        answer = client.post("/v1/evaluate", json={**body, "cell": {"clearance": clearance}})
        found = answer.json()
        assert not found["feasible"] and found["reason"] == "collision", (clearance, found)
        collision = found["collision"]
        assert collision["waypoint"] == 0
        assert {collision["robot_part"], collision["obstacle_name"]} == set(
            names[k] for k in (a, b)
        )
        assert collision["distance"] == pytest.approx(expected, abs=1e-6)


def test_a_meshs_errors_have_one_loc_whoever_finds_them(client: TestClient) -> None:
    """An empty STL (the schema's error) was at cell.fixed.0.mesh.stl, one that is no STL (the
    reader's) at cell.fixed.0.stl: a client (the page) showing errors beside fields put the
    second on another line."""
    body = route_body("evaluate", EXAMPLE["path"])
    locs = []
    for stl in ("", "hello, not a mesh"):
        body["cell"] = {"fixed": [mesh(stl)]}
        (detail,) = client.post("/v1/evaluate", json=body).json()["detail"]
        locs.append(detail["loc"])
    assert locs == [["body", "cell", "fixed", 0, "mesh", "stl"]] * 2


def test_a_halfspace_normal_of_any_length_is_the_same_halfspace(
    client: TestClient, body: dict
) -> None:
    """n . p <= d with n not of unit length (the schema takes components within 1.001): the
    offset scales with the normal. Dropping that scaling passed every cell test (audit 24). A
    floor 2 cm above the base's foot, the example's closest obstacle (9.3 mm from the upper
    arm; the wrist's own links are 13.6 mm apart), written three ways (one plane), gives one
    clearance, to the floor."""
    answers = []
    for k in (1.0, 0.5, 0.25):
        floor = {"shape": "halfspace", "name": "floor", "normal": [0, 0, k], "offset": 0.02 * k}
        answer = client.post("/v1/evaluate", json={**body, "cell": {"fixed": [floor]}}).json()
        assert answer["feasible"], answer
        assert answer["min_clearance"]["obstacle_name"] == "floor"
        answers.append(answer["min_clearance"]["distance"])
    assert answers[0] < 0.0136  # nearer than the wrist's own links: the floor is measured
    assert answers[1] == pytest.approx(answers[0], abs=1e-12)
    assert answers[2] == pytest.approx(answers[0], abs=1e-12)


def test_when_every_branch_collides_the_answer_is_the_fastest_branchs_collision(
    client: TestClient, body: dict
) -> None:
    # A floor 0.2 m below the base at a clearance of 13.7 mm: every branch of the example
    # collides, two of them only at waypoints 27 and 48 (audit 24's D8). The answer is the
    # branch auto takes without the cell, where it first collides (README, the cell), as its
    # own pinned evaluation and the map's cell say it; not the branch that collides furthest.
    plain = client.post("/v1/evaluate", json=body).json()
    body["cell"] = {
        "fixed": [{"shape": "halfspace", "normal": [0, 0, 1], "offset": -0.2}],
        "clearance": 0.0137,
    }
    answer = client.post("/v1/evaluate", json=body).json()
    pinned = client.post("/v1/evaluate", json={**body, "ik": {"branch": plain["branch"]}}).json()
    furthest = 0
    for shoulder in ("left", "right"):
        for elbow in ("up", "down"):
            for wrist in ("noflip", "flip"):
                branch = {"shoulder": shoulder, "elbow": elbow, "wrist": wrist}
                each = client.post("/v1/evaluate", json={**body, "ik": {"branch": branch}})
                assert each.json()["reason"] == "collision", branch
                furthest = max(furthest, each.json()["failed_waypoint"])
    assert answer["reason"] == pinned["reason"] == "collision"
    assert answer["branch"] == plain["branch"]
    assert answer["failed_waypoint"] == pinned["failed_waypoint"] < furthest
    assert answer["collision"] == pinned["collision"]
    grid = {
        "x": {"min": 0.0, "max": 0.0, "step": 0.1},
        "y": {"min": 0.45, "max": 0.45, "step": 0.1},
    }
    request = {k: body[k] for k in ("robot", "path", "cell")}
    cells = client.post("/v1/map", json={**request, "grid": {**grid, "z": 0.1, "yaw": 0.0}})
    assert cells.status_code == 200, cells.text
    (cell,) = cells.json()["cells"]
    assert cell["reason"] == "collision" and cell["failed_waypoint"] == answer["failed_waypoint"]
