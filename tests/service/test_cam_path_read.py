"""How a CAM program was read, in every answer computed from it (``path_read``, cam.md 9).

An inch NX listing with no UNITS record (examples/cam/nx_slot_plate.cls: the units inferred from
its FEDRAT/IPM record) through /v1/evaluate, /v1/optimize, /v1/map and their jobs: each answer
says inches, inferred, and the record's line, found here by reading the file's lines; and each
gives what /v1/paths/import gives for the program. A path of poses or tool axes has none.
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.cli import CUT, INFEASIBLE, OK, main
from service.config import Settings
from tests.cases import ROOT
from tests.service.conftest import served_with

PROGRAM = ROOT / "examples" / "cam" / "nx_slot_plate.cls"
TEXT = PROGRAM.read_text()
IPM_LINE = next(n for n, line in enumerate(TEXT.splitlines(), 1) if line.startswith("FEDRAT/IPM"))
ROBOT = {"model": "ur5e"}
AT = {"x": 0.0, "y": 0.3, "z": 0.0, "yaw": 0.0}
AXIS = {"min": -0.1, "max": 0.1, "step": 0.1}
GRID = {"x": AXIS, "y": {"min": 0.3, "max": 0.3, "step": 0.1}, "z": 0.0, "yaw": 0.0}
BOUNDS = {"bounds": {"x": [-0.05, 0.05], "y": [0.25, 0.35], "yaw": [-0.2, 0.2]}, "z": 0.0}
POSES = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())["path"]
AXES = json.loads((ROOT / "examples" / "cam" / "sweep_tool_axis_waypoints.json").read_text())
READ_FIELDS = (
    "units",
    "units_source",
    "units_note",
    "feed",
    "pass_details",
    "skipped_records",
    "repeated_points",
    "one_point_passes",
    "arcs",
    "ended",
    "end_note",
)


def body_of(route: str, path: dict[str, Any]) -> dict[str, Any]:
    """A request of ``route`` for ``path`` on the UR5e near (0, 0.3)."""
    extra = {"evaluate": {"placement": AT}, "map": {"grid": GRID}, "optimize": BOUNDS}[route]
    return {"robot": ROBOT, "path": path, **extra}


def answer_of(client: TestClient, route: str, path: dict[str, Any]) -> dict[str, Any]:
    answer = client.post(f"/v1/{route}", json=body_of(route, path))
    assert answer.status_code == 200, answer.text
    result: dict[str, Any] = answer.json()
    return result


def imported(client: TestClient, path: dict[str, Any]) -> dict[str, Any]:
    """What /v1/paths/import reports of the path, its waypoints and poses-only fields left out."""
    answer = client.post("/v1/paths/import", json={"path": path})
    assert answer.status_code == 200, answer.text
    return {key: answer.json()[key] for key in READ_FIELDS}


@pytest.mark.parametrize("route", ["evaluate", "optimize", "map"])
def test_an_inch_program_says_inches_inferred_and_the_line(client: TestClient, route: str) -> None:
    read = answer_of(client, route, {"cl_data": TEXT})["path_read"]
    assert read["form"] == "cl_data"
    assert (read["units"], read["units_source"]) == ("inches", "inferred")
    assert f"FEDRAT/IPM at line {IPM_LINE}" in read["units_note"]
    assert read["feed"] == pytest.approx(20 * 0.0254 / 60, rel=1e-12)  # FEDRAT/IPM 20
    assert {key: read[key] for key in READ_FIELDS} == imported(client, {"cl_data": TEXT})
    words = {record["word"]: record["count"] for record in read["skipped_records"]}
    assert words["PAINT"] == sum(line.startswith("PAINT/") for line in TEXT.splitlines())


def test_optimize_says_it_once(client: TestClient) -> None:
    answer = answer_of(client, "optimize", {"cl_data": TEXT})
    assert answer["found"] and answer["evaluation"]["path_read"] is None
    assert answer["path_read"]["units_source"] == "inferred"


def test_a_csv_says_the_request_gave_its_units(client: TestClient) -> None:
    csv = "x,y,z,i,j,k\n0,0,0,0,0,1\n10,0,0,0,0,1\n20,0,1,0,0,1\n"
    read = answer_of(client, "evaluate", {"csv": csv, "units": "mm"})["path_read"]
    assert (read["form"], read["units"], read["units_source"]) == ("csv", "mm", "request")
    (part,) = read["pass_details"]
    assert part["length"] == pytest.approx((10.0 + np.hypot(10.0, 1.0)) / 1000.0, rel=1e-12)
    assert part == {
        "start": 0, "stop": 3, "operation": None, "feed": None, "length": part["length"],
        "time": None,  # no feed: no time as programmed
    }  # fmt: skip
    assert read["ended"] is None and read["end_note"].startswith("a CSV has no end record")


def test_a_program_cut_short_is_said_by_the_routes_and_the_command(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The NX listing cut after its last move (its END-OF-PATH and listing length gone)."""
    lines = TEXT.splitlines()
    last = max(n for n, line in enumerate(lines, 1) if line.startswith("GOTO/"))
    cut = "\n".join(lines[:last]) + "\n"
    said = f"no FINI or END-OF-PATH after the last move (GOTO at line {last}): "
    whole = imported(client, {"cl_data": TEXT})
    assert whole["ended"] is True and whole["end_note"].startswith("END-OF-PATH at line ")
    read = answer_of(client, "evaluate", {"cl_data": cut})["path_read"]
    assert read["ended"] is False and read["end_note"].startswith(said)
    assert {key: read[key] for key in READ_FIELDS} == imported(client, {"cl_data": cut})
    program = tmp_path / "cut.cls"
    program.write_text(cut)
    assert main(["import", str(program)]) == CUT
    assert f"\nend: WARNING: {said}" in capsys.readouterr().out


COMMANDS = {
    "import": [],
    "evaluate": ["--robot", "ur5e", "--at=0,0.3,0,0"],
    "map": ["--robot", "ur5e", "--x=-0.1:0.1:0.1", "--y=0.3:0.3:0.1", "--z", "0"],
    "optimise": ["--robot", "ur5e", "--x=-0.05:0.05", "--y=0.25:0.35", "--yaw=-0.2:0.2", "--z=0"],
}


@pytest.mark.parametrize("command", COMMANDS)
def test_the_command_exits_7_on_a_program_cut_short_whatever_its_answer(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A post-processor that reads the exit code alone: the answer is of part of the program.

    The same listing whole exits 0 (or 4), its cut exits 7, with the answer printed all the
    same (the import's ``end:`` line, the others' JSON ``path_read.ended`` false). A picture
    beside the program, for the map.
    """
    lines = TEXT.splitlines()
    last = max(n for n, line in enumerate(lines, 1) if line.startswith("GOTO/"))
    programs = {"whole": TEXT, "cut": "\n".join(lines[:last]) + "\n"}
    for name, text in programs.items():
        (tmp_path / f"{name}.cls").write_text(text)
    extra = ["--png", str(tmp_path / "map.png")] if command == "map" else []
    options = [*COMMANDS[command], *extra, *([] if command == "import" else ["--json"])]
    codes = {}
    for name in programs:
        codes[name] = main([command, str(tmp_path / f"{name}.cls"), *options])
        out = capsys.readouterr().out
        if command != "import":
            assert json.loads(out)["path_read"]["ended"] is (name == "whole")
    assert codes["whole"] in (OK, INFEASIBLE) and codes["cut"] == CUT


def test_waypoints_sent_as_json_have_no_end_record(client: TestClient) -> None:
    answer = client.post("/v1/paths/import", json={"path": POSES})
    assert answer.status_code == 200, answer.text
    assert answer.json()["ended"] is None
    assert answer.json()["end_note"].startswith("waypoints sent as JSON have no end record")


@pytest.mark.parametrize("route", ["evaluate", "optimize", "map"])
@pytest.mark.parametrize("form", ["waypoints", "tool_axis_waypoints"])
def test_a_path_of_poses_or_axes_has_no_reading(client: TestClient, route: str, form: str) -> None:
    path = POSES if form == "waypoints" else {"tool_axis_waypoints": AXES["passes"][0]}
    answer = answer_of(client, route, path)
    assert "path_read" in answer and answer["path_read"] is None


@pytest.fixture
def own_store(tmp_path: Path) -> Iterator[Path]:
    """The app with its jobs in ``tmp_path`` (a queue no other test fills), room for the search."""
    with served_with(Settings(data_dir=tmp_path, workers=1, max_job_poses=1_000_000)):
        yield tmp_path


@pytest.mark.parametrize("kind", ["evaluate", "optimize", "map"])
def test_a_job_says_it_as_its_route(client: TestClient, own_store: Path, kind: str) -> None:
    body = body_of(kind, {"cl_data": TEXT})
    submitted = client.post("/v1/jobs", json={"kind": kind, "request": body})
    assert submitted.status_code in (200, 201, 202), submitted.text
    job_id = submitted.json()["id"]
    deadline = time.monotonic() + 120
    job: dict[str, Any] = {}
    while time.monotonic() < deadline:
        job = client.get(f"/v1/jobs/{job_id}").json()
        if job["status"] not in ("queued", "running"):
            break
        time.sleep(0.05)
    assert job["status"] == "done", job
    assert job["result"]["path_read"] == answer_of(client, kind, {"cl_data": TEXT})["path_read"]


@pytest.mark.parametrize(
    "argv",
    [
        ["evaluate", "--at=0,0.3,0,0"],
        ["optimise", "--x=-0.05:0.05", "--y", "0.25:0.35", "--yaw=-0.2:0.2"],
        ["map", "--x=-0.1:0.1:0.1", "--y", "0.3:0.3:0.1", "--png", "{tmp}/map.png"],
    ],
    ids=["evaluate", "optimise", "map"],
)
def test_the_cli_text_says_it(
    argv: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = [argv[0], str(PROGRAM), "--robot", "ur5e"] + [a.format(tmp=tmp_path) for a in argv[1:]]
    code = main(args)
    out = capsys.readouterr().out
    assert code == OK
    lines = out.splitlines()
    assert lines[0].startswith("units: inches (inferred: no UNITS record")
    assert lines[0].endswith(f"FEDRAT/IPM at line {IPM_LINE})")
    assert "PAINT 11 (line 11)" in out
