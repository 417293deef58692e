"""``dtf-place`` (issue 25): in-process and as a process, its answers equal to the API's.

Each subcommand's ``--json`` is compared with the route's answer to the same body; the exit
codes are the ones a script tests (0 ok, 2 usage, 3 invalid input, 4 infeasible).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.cli import INFEASIBLE, INVALID, OK, USAGE, main
from tests.cases import ROOT
from tests.solver.cam.dialects import NX_LISTING, text

PROGRAM = ROOT / "examples" / "cam" / "nx_slot_plate.cls"
ROBOT = {"model": "ur5e"}
AT = {"x": 0.0, "y": 0.3, "z": 0.0, "yaw": 0.0}


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def api(client: TestClient, route: str, body: dict[str, Any]) -> dict[str, Any]:
    answer = client.post(route, json=body)
    assert answer.status_code == 200, answer.text
    result: dict[str, Any] = answer.json()
    return result


def test_import_json_is_the_api_answer(
    client: TestClient, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = run(capsys, "import", str(PROGRAM), "--json")
    assert code == OK
    assert json.loads(out) == api(
        client, "/v1/paths/import", {"path": {"cl_data": PROGRAM.read_text()}}
    )


def test_import_summary_names_units_operations_and_skipped(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, out, _ = run(capsys, "import", str(PROGRAM))
    assert code == OK
    assert "units: inches (inferred: no UNITS record" in out
    assert "FLOOR_SLOT" in out and "VARIABLE_CONTOUR" in out
    assert "PAINT: 11 (first at line 11)" in out


def test_evaluate_json_is_the_api_answer(
    client: TestClient, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = run(
        capsys, "evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0", "--json"
    )
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM.read_text()}, "placement": AT}
    expected = api(client, "/v1/evaluate", {**body, "detail": "summary"})
    assert code == OK
    assert json.loads(out) == expected
    assert expected["feasible"] and expected["feed_check"]["feasible"]


def test_an_unreachable_placement_is_exit_infeasible(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "evaluate", str(PROGRAM), "--robot", "ur5e", "--at=3,0,0,0")
    assert code == INFEASIBLE
    assert out.startswith("units: inches (inferred: ")  # how the program was read, first
    assert out.splitlines()[-1].startswith("infeasible: ")


def test_a_feed_the_path_cannot_run_is_exit_infeasible(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(
        capsys, "evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0", "--feed", "50"
    )
    assert code == INFEASIBLE
    assert "does not run" in out


def test_a_robot_from_a_json_file(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robot = {"model": "ur5", "joint_velocity_limits": [1.0, 1.0, 1.5, 2.0, 2.0, 2.0]}
    file = tmp_path / "robot.json"
    file.write_text(json.dumps(robot))
    code, out, _ = run(
        capsys, "evaluate", str(PROGRAM), "--robot", str(file), "--at=0,0.3,0,0", "--json"
    )
    body = {"robot": robot, "path": {"cl_data": PROGRAM.read_text()}, "placement": AT}
    assert code == OK
    assert json.loads(out) == api(client, "/v1/evaluate", {**body, "detail": "summary"})


def test_map_writes_the_png_and_answers_the_api_json(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "map.png"
    code, out, _ = run(
        capsys, "map", str(PROGRAM), "--robot", "ur5e", "--x=-0.1:0.1:0.1", "--y", "0.3:0.4:0.1",
        "--png", str(png), "--json",
    )  # fmt: skip
    assert code == OK
    assert png.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    grid = {"x": {"min": -0.1, "max": 0.1, "step": 0.1}, "y": {"min": 0.3, "max": 0.4, "step": 0.1}}
    body = {
        "robot": ROBOT,
        "path": {"cl_data": PROGRAM.read_text()},
        "grid": {**grid, "z": 0.0, "yaw": 0.0},
    }
    assert json.loads(out) == api(client, "/v1/map", body)


def test_optimise_prints_the_optimum_with_its_controller_frames(
    client: TestClient, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = run(
        capsys, "optimise", str(PROGRAM), "--robot", "ur5e", "--x=-0.1:0.1", "--y", "0.25:0.35",
        "--yaw=-0.5:0.5", "--json",
    )  # fmt: skip
    assert code == OK
    mine = json.loads(out)
    bounds = {"x": [-0.1, 0.1], "y": [0.25, 0.35], "yaw": [-0.5, 0.5]}
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM.read_text()}, "bounds": bounds, "z": 0.0}
    theirs = api(client, "/v1/optimize", {**body, "method": "scipy"})
    for answer in (mine, theirs):
        answer["solver"].pop("seconds")
    assert mine == theirs
    code, out, _ = run(
        capsys, "optimise", str(PROGRAM), "--robot", "ur5e", "--x=-0.1:0.1", "--y", "0.25:0.35",
        "--yaw=-0.5:0.5",
    )  # fmt: skip
    assert "KUKA base (mm, deg): X" in out and "UR base pose (m, rad)" in out


def test_invalid_input_names_the_field_and_exits_invalid(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bare = tmp_path / "bare.cl"
    bare.write_text("GOTO/0,0,0\nFEDRAT/MMPM,250\nGOTO/10,0,0\n")
    code, out, err = run(capsys, "import", str(bare))
    assert (code, out) == (INVALID, "")
    assert err.startswith("error: path.units: ") and "FEDRAT/MMPM at line 2" in err
    broken = tmp_path / "broken.cl"
    broken.write_text("UNITS/MM\nGOTO/0,0,0\nGOTO/1,0,0,0,0\n")
    code, _, err = run(capsys, "import", str(broken))
    assert code == INVALID and err.startswith("error: path.cl_data: line 3: ")


def test_a_csv_needs_its_units_and_errors_name_the_api_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    table = tmp_path / "fan.csv"
    table.write_text("x,y,z,i,j,k\n100,0,0,0,0,1\n110,0,0,0,0,1\n")
    code, out, err = run(capsys, "import", str(table))
    assert (code, out) == (INVALID, "")
    assert err.startswith("error: path.units: ") and "--units" in err
    program = tmp_path / "line.cl"
    program.write_text("UNITS/MM\nGOTO/0,0,0\nGOTO/1,0,0\n")
    code, _, err = run(capsys, "import", "--arc-tolerance", "-1", str(program))
    assert code == INVALID  # the location as the API gives it, without the union's tags
    assert err.startswith("error: path.arc_tolerance: ")


def test_a_robot_file_that_is_not_json_exits_invalid(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    file = tmp_path / "robot.json"
    file.write_text("{model: ur5")
    code, _, err = run(capsys, "evaluate", str(PROGRAM), "--robot", str(file), "--at=0,0.3,0,0")
    assert code == INVALID and err.startswith("error: robot: the file is not JSON")


def test_usage_errors_exit_usage(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as caught:
        main(["evaluate", str(PROGRAM), "--robot", "ur5e", "--at", "1,2"])
    assert caught.value.code == USAGE
    assert "4 numbers" in capsys.readouterr().err


def test_a_progress_bar_only_when_asked(capsys: pytest.CaptureFixture[str]) -> None:
    args = ["map", str(PROGRAM), "--robot", "ur5e", "--x=-0.1:0.1:0.1", "--y", "0.3:0.4:0.1"]
    quiet = run(capsys, *args, "--png", "/dev/null", "--no-progress")
    assert quiet[2] == ""
    shown = run(capsys, *args, "--png", "/dev/null", "--progress")
    assert quiet[0] == shown[0] == OK and quiet[1] == shown[1]
    assert "\r[" in shown[2] and "%" in shown[2]  # drawn on stderr, stdout untouched


def test_the_command_runs_as_a_process(tmp_path: Path) -> None:
    listing = tmp_path / "listing.cls"
    listing.write_text(text(NX_LISTING))
    command = [sys.executable, "-m", "service.cli", "import", str(listing), "--json"]
    done = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert done.returncode == OK, done.stderr
    assert json.loads(done.stdout)["units_source"] == "inferred"
    failed = subprocess.run(
        [sys.executable, "-m", "service.cli", "import", str(tmp_path / "missing.cl")],
        capture_output=True, text=True, cwd=ROOT, timeout=300,
    )  # fmt: skip
    assert failed.returncode == INVALID and "missing.cl" in failed.stderr


def test_the_console_script_is_declared() -> None:
    assert 'dtf-place = "service.cli:main_exit"' in (ROOT / "pyproject.toml").read_text()
