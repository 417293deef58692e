"""CAM programs through every route (issue 10): CL data and CSV as path forms, passes, the feed.

Known answers come from the same path sent in the form the solver already had (tool-axis
waypoints), from each pass evaluated on its own, and from the definition of the feed check.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from tests.cases import ROOT

CAM = ROOT / "examples" / "cam"
PROGRAM_MM = (CAM / "sweep_mm.cl").read_text()
PROGRAM_INCH = (CAM / "sweep_inch.cl").read_text()
PASSES = json.loads((CAM / "sweep_tool_axis_waypoints.json").read_text())["passes"]
PLACEMENT = {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0}
ROBOT = {"model": "ur5"}


def evaluate(client: TestClient, path: dict[str, Any], **extra: Any) -> dict[str, Any]:
    body = {"robot": ROBOT, "path": path, "placement": PLACEMENT, **extra}
    answer = client.post("/v1/evaluate", json=body)
    assert answer.status_code == 200, answer.text
    result: dict[str, Any] = answer.json()
    return result


def one_pass_program(k: int) -> str:
    """Pass k of the example as a CL program of its own (MULTAX, mm, a feed)."""
    lines = ["UNITS/MM", "MULTAX/ON", "FEDRAT/MMPM, 1500"]
    for point in PASSES[k]:
        x, y, z = (1000.0 * c for c in point["position"])
        i, j, kk = point["axis"]
        lines.append(f"GOTO/{x:.6f}, {y:.6f}, {z:.6f}, {i:.6f}, {j:.6f}, {kk:.6f}")
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("k", range(len(PASSES)))
def test_a_cl_pass_evaluates_as_the_same_tool_axis_waypoints(client: TestClient, k: int) -> None:
    from_cl = evaluate(client, {"cl_data": one_pass_program(k)})
    from_axes = evaluate(client, {"tool_axis_waypoints": PASSES[k]})
    assert from_cl["feasible"] and from_axes["feasible"]
    assert from_cl["mu_path"] == pytest.approx(from_axes["mu_path"], rel=1e-12)
    # the same waypoint and joint; the CL data's names its line too
    assert from_cl["bottleneck"] == {
        **from_axes["bottleneck"],
        "line": from_cl["bottleneck"]["line"],
    }
    assert from_axes["bottleneck"]["line"] is None


def test_a_program_runs_as_fast_as_its_slowest_pass_on_one_branch(client: TestClient) -> None:
    program = evaluate(client, {"cl_data": PROGRAM_MM}, feed=None)
    assert program["feasible"]
    branch = program["branch"]
    passes = [
        evaluate(client, {"tool_axis_waypoints": points}, ik={"branch": branch})["mu_path"]
        for points in PASSES
    ]
    assert program["mu_path"] == pytest.approx(min(passes), rel=1e-12)


def test_inch_and_mm_programs_evaluate_alike(client: TestClient) -> None:
    mm, inch = (
        evaluate(client, {"cl_data": PROGRAM_MM}),
        evaluate(client, {"cl_data": PROGRAM_INCH}),
    )
    assert mm["mu_path"] == pytest.approx(inch["mu_path"], rel=1e-12)
    assert mm["feed_check"]["feed"] == pytest.approx(inch["feed_check"]["feed"], rel=1e-12)


def test_the_csv_of_pass_one_evaluates_as_its_tool_axis_waypoints(client: TestClient) -> None:
    csv = evaluate(client, {"csv": (CAM / "sweep_pass1.csv").read_text(), "units": "mm"})
    axes = evaluate(client, {"tool_axis_waypoints": PASSES[0]})
    assert csv["mu_path"] == pytest.approx(axes["mu_path"], rel=1e-12)


def test_map_and_optimize_take_a_program(client: TestClient) -> None:
    grid = {"x": {"min": -0.1, "max": 0.1, "step": 0.1}, "y": {"min": 0.4, "max": 0.5, "step": 0.1}}
    answer = client.post(
        "/v1/map",
        json={
            "robot": ROBOT,
            "path": {"cl_data": PROGRAM_MM},
            "grid": {**grid, "z": 0.1, "yaw": 0},
        },
    )
    assert answer.status_code == 200, answer.text
    cell = answer.json()["cells"][0]
    placement = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"]}
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM_MM}, "placement": placement}
    single = client.post("/v1/evaluate", json=body).json()
    assert cell["mu_path"] == pytest.approx(single["mu_path"], rel=1e-9)
    optimum = client.post(
        "/v1/optimize",
        json={
            "robot": ROBOT,
            "path": {"cl_data": PROGRAM_MM},
            "bounds": {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.2, 0.2]},
            "z": 0.1,
        },
    )
    assert optimum.status_code == 200, optimum.text
    assert optimum.json()["mu_path"] >= optimum.json()["start"]["mu_path"]


def test_import_shows_the_program(client: TestClient) -> None:
    answer = client.post("/v1/paths/import", json={"path": {"cl_data": PROGRAM_INCH}})
    assert answer.status_code == 200, answer.text
    read = answer.json()
    assert read["passes"] == [[0, 13], [13, 26], [26, 39]]
    assert read["units"] == "inches"
    assert read["feed"] == pytest.approx(60 * 0.0254 / 60, rel=1e-12)  # the highest: IPM 60
    tips = np.array([w["position"] for w in read["waypoints"]])
    expected = np.array([p["position"] for points in PASSES for p in points])
    np.testing.assert_allclose(tips, expected, atol=1e-12)
    # tool z = -axis: the quaternion's third column is minus the CAM axis
    q = np.array(read["waypoints"][0]["orientation"])  # x, y, z, w
    x, y, z, w = q
    tool_z = np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])
    np.testing.assert_allclose(
        tool_z, -np.array(PASSES[0][0]["axis"]) / np.linalg.norm(PASSES[0][0]["axis"]), atol=1e-9
    )


@pytest.mark.parametrize(
    ("text", "line"),
    [
        ("UNITS/MM\nMULTAX/ON\nCIRCLE/0, 0, 0, 0, 0, 1, 5\n", 3),
        ("UNITS/MM\nMULTAX/ON\nGOTO/0, 0, 0, 0, 0, 1\nGODLTA/3\n", 4),
        ("UNITS/MM\nMULTAX/ON\nGOTO/0, 0, 0, 0, 0\n", 3),
        ("UNITS/MM\nFEDRAT/0\nGOTO/0, 0, 0\nGOTO/1, 0, 0\n", 2),
        ("UNITS/MM\nFEDRAT/MMPM,1e-310\nGOTO/0, 0, 0\nGOTO/1, 0, 0\n", 2),
    ],
    ids=[
        "circle without its end",
        "record not applied",
        "goto of 5 numbers",
        "zero feed",
        "subnormal feed (a 500: its margin infinite)",
    ],
)
def test_a_record_that_cannot_be_read_is_a_422_naming_its_line(
    client: TestClient, text: str, line: int
) -> None:
    answer = client.post(
        "/v1/evaluate", json={"robot": ROBOT, "path": {"cl_data": text}, "placement": PLACEMENT}
    )
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"][0]
    assert detail["loc"] == ["body", "path", "cl_data"]
    assert detail["msg"].startswith(f"line {line}:")


def test_a_csv_with_a_ragged_row_is_a_422_naming_its_line(client: TestClient) -> None:
    answer = client.post(
        "/v1/paths/import",
        json={"path": {"csv": "0,0,0,0,0,1\n1,0,0,0,0\n2,0,0,0,0,1\n", "units": "mm"}},
    )
    assert answer.status_code == 422, answer.text
    assert answer.json()["detail"][0]["msg"].startswith("line 2")


def test_the_feed_check_is_the_definition(client: TestClient) -> None:
    mu = evaluate(client, {"cl_data": PROGRAM_MM})["mu_path"]
    for feed, feasible in ((mu * (1 - 1e-9), True), (mu * (1 + 1e-9), False), (0.3 * mu, True)):
        answer = evaluate(client, {"cl_data": PROGRAM_MM}, feed=feed)
        check = answer["feed_check"]
        assert check["feasible"] is feasible
        assert check["margin"] == pytest.approx(mu / feed, rel=1e-12)
        use = np.array(
            [[np.nan if u is None else u for u in w["use"]] for w in answer["waypoints"]]
        )
        assert np.nanmax(use) == pytest.approx(feed / mu, rel=1e-9)
        robots = client.get("/v1/robots").json()["robots"]
        limits = np.array(next(r["qdot_max"] for r in robots if r["name"] == "ur5"))
        qdot = np.array(
            [[np.nan if v is None else v for v in w["qdot_at_feed"]] for w in answer["waypoints"]]
        )
        np.testing.assert_allclose(np.abs(qdot) / limits, use, rtol=1e-6)


def test_the_program_feed_is_the_default_and_a_request_feed_wins(client: TestClient) -> None:
    default = evaluate(client, {"cl_data": PROGRAM_MM})["feed_check"]["feed"]
    assert default == pytest.approx(1524.0 / 1000 / 60, rel=1e-12)  # the highest FEDRAT
    assert evaluate(client, {"cl_data": PROGRAM_MM}, feed=0.01)["feed_check"]["feed"] == 0.01
    assert evaluate(client, {"tool_axis_waypoints": PASSES[0]})["feed_check"] is None


def test_the_joint_use_picture_at_the_feed(client: TestClient) -> None:
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM_MM}, "placement": PLACEMENT}
    answer = client.post("/v1/evaluate", json=body, headers={"accept": "image/png"})
    assert answer.status_code == 200, answer.text
    assert answer.headers["content-type"] == "image/png"
    assert answer.content.startswith(b"\x89PNG\r\n\x1a\n")
    far = {**body, "placement": {**PLACEMENT, "x": 5.0}}
    assert client.post("/v1/evaluate", json=far).json()["feasible"] is False
    for route, headers in (("/v1/evaluate", {"accept": "image/png"}), ("/v1/evaluate/png", {})):
        # not an input error (api.md): a picture saying the path does not run there
        told = client.post(route, json=far, headers=headers)
        assert told.status_code == 200 and told.content.startswith(b"\x89PNG\r\n\x1a\n")


FLIPPED = """UNITS/MM
FEDRAT/MMPM,1000
GOTO/0,400,100,0,0,1
GOTO/10,400,100,0,0,1
GOTO/20,400,100,0,0,1
RAPID
GOTO/0,450,100,0,0,1
FEDRAT/MMPM,1000
GOTO/10,450,100,0,0,1
GOTO/15,450,100,0,0,1
"""
"""Two passes; the lines FLIP then add to the second a tool axis turned about half a turn."""
FLIP = "GOTO/20,450,100,0.0017,0,-0.99999\nGOTO/30,450,100,0.0017,0,-0.99999\n"


def test_an_error_in_a_later_pass_names_the_program_and_the_waypoint_of_the_path(
    client: TestClient,
) -> None:
    """A tool axis that turns half a turn between two points of the second pass: every route
    and the import refuse it alike, naming ``path.cl_data`` and the waypoint as the import
    lists the program (the second pass's end in the program without the flip: the flipped
    point follows it), where they named ``path.waypoints`` and the waypoint within its pass."""
    before = client.post("/v1/paths/import", json={"path": {"cl_data": FLIPPED}}).json()
    (_, first_stop), (second_start, flipped) = before["passes"]
    assert second_start == first_stop > 0
    path = {"cl_data": FLIPPED + FLIP}
    answers = [
        client.post("/v1/paths/import", json={"path": path}),
        client.post("/v1/evaluate", json={"robot": ROBOT, "path": path, "placement": PLACEMENT}),
    ]
    for answer in answers:
        assert answer.status_code == 422, answer.text
        (detail,) = answer.json()["detail"]
        assert detail["loc"] == ["body", "path", "cl_data", flipped]
        assert f"turns by 180.000000 deg from waypoint {flipped - 1}:" in detail["msg"]


def test_the_import_refuses_a_path_every_route_refuses(client: TestClient) -> None:
    """A waypoint repeating the one before: the import answered 200 (repeated_points 0) for a
    path /v1/evaluate refuses; now the same 422, naming the waypoint."""
    waypoints = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())["path"]
    waypoints = waypoints["waypoints"]
    path = {"waypoints": [*waypoints[:5], waypoints[4], *waypoints[5:]]}
    imported = client.post("/v1/paths/import", json={"path": path})
    evaluated = client.post(
        "/v1/evaluate", json={"robot": ROBOT, "path": path, "placement": PLACEMENT}
    )
    assert imported.status_code == evaluated.status_code == 422
    assert imported.json()["detail"] == evaluated.json()["detail"]
    assert imported.json()["detail"][0]["loc"] == ["body", "path", "waypoints", 5]


def test_the_units_an_import_answers_can_be_sent_back(client: TestClient) -> None:
    """A CSV or a CL program without units given ``inch`` was answered ``inches``, which the
    request refused (audit 24): sent back, it reads the same waypoints."""
    csv = "x,y,z,i,j,k\n0,0,0,0,0,1\n10,0,0,0,0,1\n20,0,1,0,0,1\n"
    cl = "GOTO/0,0,0,0,0,1\nGOTO/10,0,0,0,0,1\nGOTO/20,0,1,0,0,1\nFINI\n"
    for path in ({"csv": csv, "units": "inch"}, {"cl_data": cl, "units": "inch"}):
        first = client.post("/v1/paths/import", json={"path": path})
        assert first.status_code == 200, first.text
        assert first.json()["units"] == "inches"
        again = client.post("/v1/paths/import", json={"path": {**path, "units": "inches"}})
        assert again.status_code == 200, again.text
        assert again.json()["waypoints"] == first.json()["waypoints"]
        assert first.json()["waypoints"][1]["position"][0] == pytest.approx(0.254)
