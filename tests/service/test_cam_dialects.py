"""CL programs as CAM systems write them, through the routes (issue 25, cam.md section 9).

What /v1/paths/import says about a program (skipped records, units and how they were known,
each pass's operation), the 422 on ``path.units`` when a program gives no unit, CSV in inches,
and one counting rule: a program that import accepts, evaluate accepts.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.config import get_settings
from service.schemas.path_cam import CsvPath
from solver.cam.csv_path import read_csv_path
from tests.solver.cam.dialects import NX_LISTING, SOLIDWORKS, text

PLACEMENT = {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0}
INCH = 0.0254


@pytest.fixture
def setting(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """Set DTF_<NAME> settings for one test, as a deployment would."""

    def set_(**values: Any) -> None:
        for name, value in values.items():
            monkeypatch.setenv(f"DTF_{name.upper()}", str(value))
        get_settings.cache_clear()

    yield set_
    get_settings.cache_clear()


def imported(client: TestClient, path: dict[str, Any]) -> dict[str, Any]:
    answer = client.post("/v1/paths/import", json={"path": path})
    assert answer.status_code == 200, answer.text
    result: dict[str, Any] = answer.json()
    return result


def test_import_of_an_nx_listing_says_what_it_read(client: TestClient) -> None:
    read = imported(client, {"cl_data": text(NX_LISTING)})
    assert (read["units"], read["units_source"]) == ("inches", "inferred")
    assert "FEDRAT/IPM at line 18" in read["units_note"]
    assert read["skipped_records"] == [
        {"word": "NX listing header", "count": 5, "first_line": 2, "recognised": True},
        {"word": "TLDATA", "count": 2, "first_line": 8, "recognised": True},
        {"word": "$$", "count": 1, "first_line": 10, "recognised": True},
        {"word": "PAINT", "count": 3, "first_line": 11, "recognised": True},
    ]
    assert [p["operation"] for p in read["pass_details"]] == ["FACE_POCKET", "ARC_FINISH"]
    assert [[p["start"], p["stop"]] for p in read["pass_details"]] == read["passes"]
    assert read["passes"][0] == [0, 4]
    assert (read["repeated_points"], read["one_point_passes"], read["arcs"]) == (1, 1, 1)
    first = np.array(read["waypoints"][0]["position"])
    np.testing.assert_allclose(first, np.array([1.0, 2.0, 0.5]) * INCH, atol=1e-15)  # MSYS origin


def test_import_of_a_solidworks_program(client: TestClient) -> None:
    read = imported(client, {"cl_data": text(SOLIDWORKS)})
    assert (read["units"], read["units_source"], read["units_note"]) == (
        "mm",
        "stated",
        "UNIT/MM at line 2",
    )
    assert {s["word"]: s["count"] for s in read["skipped_records"]}["CUTCOM"] == 2
    assert read["pass_details"][0]["operation"] == "1"
    assert read["pass_details"][0]["feed"] == pytest.approx(1600e-3 / 60, rel=1e-15)


def test_a_coarser_arc_tolerance_gives_fewer_waypoints(client: TestClient) -> None:
    fine = imported(client, {"cl_data": text(SOLIDWORKS)})
    coarse = imported(client, {"cl_data": text(SOLIDWORKS), "arc_tolerance": 1e-3})
    assert len(coarse["waypoints"]) < len(fine["waypoints"])


BARE = "GOTO/0,0,0\nFEDRAT/MMPM,250\nGOTO/10,0,0\nGOTO/10,5,0\n"


@pytest.mark.parametrize("route", ["/v1/paths/import", "/v1/evaluate"])
def test_a_program_without_units_is_a_422_on_path_units(client: TestClient, route: str) -> None:
    body = {"robot": {"model": "ur5"}, "path": {"cl_data": BARE}, "placement": PLACEMENT}
    answer = client.post(route, json=body if route == "/v1/evaluate" else {"path": body["path"]})
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"][0]
    assert detail["loc"] == ["body", "path", "units"]
    assert "FEDRAT/MMPM at line 2" in detail["msg"]


@pytest.mark.parametrize(("units", "scale"), [("mm", 1e-3), ("inch", INCH)])
def test_the_request_gives_the_units(client: TestClient, units: str, scale: float) -> None:
    read = imported(client, {"cl_data": BARE, "units": units})
    assert read["units_source"] == "request"
    np.testing.assert_allclose(read["waypoints"][1]["position"], [10 * scale, 0, 0], atol=1e-15)


def test_a_csv_in_inches(client: TestClient) -> None:
    read = imported(client, {"csv": "0,0,0,0,0,1\n1,2,3,0,0,1\n", "units": "inch"})
    assert (read["units"], read["units_source"]) == ("inches", "request")
    np.testing.assert_allclose(read["waypoints"][1]["position"], [INCH, 2 * INCH, 3 * INCH])


def test_poses_say_their_units_come_from_the_api(client: TestClient) -> None:
    axes = [
        {"position": [0, 0, 0], "axis": [0, 0, 1]},
        {"position": [0.01, 0, 0], "axis": [0, 0, 1]},
    ]
    read = imported(client, {"tool_axis_waypoints": axes})
    assert (read["units"], read["units_source"], read["skipped_records"]) == ("m", "request", [])
    assert read["pass_details"] == [
        {"start": 0, "stop": 2, "operation": None, "feed": None, "length": 0.01, "time": None}
    ]


def repeated_program(n_points: int, repeats: int) -> str:
    """A line of n_points distinct cuts, each of the first ``repeats`` written twice."""
    lines = ["UNITS/MM", "FEDRAT/1000"]
    for i in range(n_points):
        lines += [f"GOTO/{i},0,0"] * (2 if i < repeats else 1)
    return "\n".join(lines) + "\n"


def test_one_counting_rule_what_import_accepts_evaluate_accepts(
    client: TestClient, setting: Any
) -> None:
    setting(max_path_waypoints=30)
    program = repeated_program(30, 10)  # 40 GOTOs, 30 waypoints
    read = imported(client, {"cl_data": program})
    assert len(read["waypoints"]) == 30 and read["repeated_points"] == 10
    body = {"robot": {"model": "ur5"}, "path": {"cl_data": program}, "placement": PLACEMENT}
    assert client.post("/v1/evaluate", json=body).status_code == 200
    over = {"cl_data": repeated_program(31, 0)}
    refused = [
        client.post("/v1/paths/import", json={"path": over}),
        client.post("/v1/evaluate", json={**body, "path": over}),
    ]
    for answer in refused:
        assert answer.status_code == 422
        assert answer.json()["detail"][0]["loc"] == ["body", "path"]
        assert "31 waypoints; the limit is 30" in answer.json()["detail"][0]["msg"]


def test_arcs_count_as_the_waypoints_they_become(client: TestClient, setting: Any) -> None:
    n = len(imported(client, {"cl_data": text(SOLIDWORKS)})["waypoints"])
    setting(max_path_waypoints=n - 1)
    answer = client.post("/v1/paths/import", json={"path": {"cl_data": text(SOLIDWORKS)}})
    assert answer.status_code == 422
    assert f"{n} waypoints; the limit is {n - 1}" in answer.json()["detail"][0]["msg"]


def test_an_nx_listing_that_import_accepts_evaluates(client: TestClient) -> None:
    body = {
        "robot": {"model": "ur5"},
        "path": {"cl_data": text(NX_LISTING)},
        "placement": PLACEMENT,
    }
    answer = client.post("/v1/evaluate", json=body)
    assert answer.status_code == 200, answer.text
    assert answer.json()["feed_check"]["feed"] == pytest.approx(10 * INCH / 60, rel=1e-12)


def test_a_csv_counts_its_waypoints_not_its_lines(client: TestClient, setting: Any) -> None:
    setting(max_path_waypoints=3)
    csv = "x,y,z,i,j,k\n\n0,0,0,0,0,1\n1,0,0,0,0,1\n\n2,0,0,0,0,1\n\n"  # 7 lines, 3 waypoints
    path = {"csv": csv, "units": "mm"}
    assert len(imported(client, path)["waypoints"]) == 3
    body = {"robot": {"model": "ur5"}, "path": path, "placement": PLACEMENT}
    assert client.post("/v1/evaluate", json=body).status_code == 200
    more = {"csv": csv + "3,0,0,0,0,1\n", "units": "mm"}
    answer = client.post("/v1/paths/import", json={"path": more})
    assert answer.status_code == 422
    assert "4 waypoints; the limit is 3" in answer.json()["detail"][0]["msg"]


def test_a_byte_order_mark_does_not_make_the_first_row_a_header_in_the_count() -> None:
    """The waypoint count (the limit's) took a headerless file's marked first row for a
    header: 20,001 rows passed a limit of 20,000. The count is the reader's rows."""
    rows = "\n".join(f"{k},0,0,0,0,1" for k in range(5))
    for csv in (rows, "\ufeff" + rows, "x,y,z,i,j,k\n" + rows, "\ufeffx,y,z,i,j,k\n" + rows):
        assert CsvPath(csv=csv, units="mm").n_waypoints() == 5
        assert len(read_csv_path(csv, units="mm").positions) == 5
