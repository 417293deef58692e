"""``dtf-place`` (issue 25): in-process and as a process, its answers equal to the API's.

Each subcommand's ``--json`` is compared with the route's answer to the same body; the exit
codes are the ones a script tests (0 ok, 2 usage, 3 invalid input, 4 infeasible).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import re
import shlex
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numba
import pytest
from fastapi.testclient import TestClient

from service import cli
from service.cli import (
    CLOSED_PIPE,
    CUT,
    INFEASIBLE,
    INTERRUPTED,
    INVALID,
    NOT_WRITTEN,
    OK,
    SETTINGS,
    TERMINATED,
    USAGE,
    main,
)
from service.cli_files import MAX_FILE_BYTES
from service.config import get_settings
from solver.core.robots import example_robot_data_dir
from solver.families.opw.arms import ARMS
from tests.cases import ROOT
from tests.solver.cam.dialects import NX_LISTING, text
from tests.solver.families.recognised import bent_elbow

PROGRAM = ROOT / "examples" / "cam" / "nx_slot_plate.cls"
ROBOT = {"model": "ur5e"}
AT = {"x": 0.0, "y": 0.3, "z": 0.0, "yaw": 0.0}
MAP = ["map", str(PROGRAM), "--robot", "ur5e", "--x=-0.1:0.1:0.1", "--y", "0.3:0.4:0.1"]
"""A 3 x 2 map of the program (GRID the route's)."""
GRID = {"x": {"min": -0.1, "max": 0.1, "step": 0.1}, "y": {"min": 0.3, "max": 0.4, "step": 0.1}}
CELL = {  # a table 5 cm below the base, a fixture box beside the part, a 10 cm spindle
    "fixed": [
        {"shape": "halfspace", "name": "table", "normal": [0, 0, 1], "offset": -0.05},
        {
            "shape": "box",
            "name": "fixture",
            "size": [0.1, 0.1, 0.3],
            "pose": {"position": [0.3, 0.0, 0.1], "orientation": [0, 0, 0, 1]},
        },
    ],
    "tool": {"radius": 0.03, "length": 0.1},
}
TOOLED = {"model": "ur5e", "tcp": {"position": [0, 0, 0.1], "orientation": [0, 0, 0, 1]}}
"""The UR5e with its tool point at the tip of CELL's 10 cm spindle (cell.md: from the flange)."""
RAISED_TABLE = {  # its top 5 cm above the base's foot: every placement collides (cell.md s. 5)
    "fixed": [{"shape": "halfspace", "name": "raised table", "normal": [0, 0, 1], "offset": 0.05}]
}


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
    code, out, _ = run(capsys, "evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0.5")
    assert code == OK  # the placement given, in controller terms (KUKA's A the yaw in degrees)
    assert "KUKA base (mm, deg): X 0.00, Y 300.00, Z 0.00, A 28.65, B 0.00, C 0.00" in out


def _stdin(monkeypatch: pytest.MonkeyPatch, data: bytes) -> None:
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(data)))


def test_a_program_named_dash_is_read_from_standard_input(
    client: TestClient, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # a post-processor pipes its program (`post | dtf-place evaluate - ...`): "-" was "no file"
    _stdin(monkeypatch, PROGRAM.read_bytes())
    code, out, err = run(capsys, "evaluate", "-", "--robot", "ur5e", "--at=0,0.3,0,0", "--json")
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM.read_text()}, "placement": AT}
    assert (code, err) == (OK, "")
    assert json.loads(out) == api(client, "/v1/evaluate", {**body, "detail": "summary"})
    _stdin(monkeypatch, PROGRAM.read_bytes())
    code, out, _ = run(capsys, "import", "-")
    assert code == OK
    assert out.splitlines()[0] == "program: standard input"


def test_standard_input_over_the_file_limit_is_refused_on_the_program(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    _stdin(monkeypatch, b"GOTO/0,0,0\n" * (MAX_FILE_BYTES // 11 + 1))
    code, _, err = run(capsys, "import", "-")
    assert code == INVALID
    assert "program" in err and "standard input is longer than 8,000,000 bytes" in err


def test_values_from_a_negative_number_need_no_equals_sign(
    client: TestClient, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--at -0.05,0.3,0,0`` and ``--x -0.1:0.1:0.1`` as a post-processor writes them: the
    answers of the ``=`` forms argparse always took (it refused these, "expected one
    argument"), the placement the API's."""
    at = ["evaluate", str(PROGRAM), "--robot", "ur5e", "--json"]
    code, spaced, _ = run(capsys, *at, "--at", "-0.05,0.3,0,0")
    _, joined, _ = run(capsys, *at, "--at=-0.05,0.3,0,0")
    assert code == OK and spaced == joined
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM.read_text()}, "detail": "summary"}
    placement = {**AT, "x": -0.05}
    assert json.loads(spaced) == api(client, "/v1/evaluate", {**body, "placement": placement})
    grid = ["map", str(PROGRAM), "--robot", "ur5e", "--json", "--png", "/dev/null"]
    code, spaced, _ = run(
        capsys, *grid, "--x", "-0.1:0.1:0.1", "--y", "0.3:0.4:0.1", "--yaw", "-0.2"
    )
    _, joined, _ = run(capsys, *grid, "--x=-0.1:0.1:0.1", "--y", "0.3:0.4:0.1", "--yaw=-0.2")
    assert code in (OK, INFEASIBLE) and spaced == joined
    assert {cell["x"] for cell in json.loads(spaced)["cells"]} == {-0.1, 0.0, 0.1}


def test_an_unreachable_placement_is_exit_infeasible(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "evaluate", str(PROGRAM), "--robot", "ur5e", "--at=3,0,0,0")
    assert code == INFEASIBLE
    assert out.startswith("units: inches (inferred: ")  # how the program was read, first
    assert out.splitlines()[-1].startswith("infeasible: ")
    # The pass as the import lists it (it listed from 1 and said "pass 0": the audit of stop 55).
    _, listing, _ = run(capsys, "import", str(PROGRAM))
    first = re.search(r"^\s+0\s+waypoints 0-\d+\s+(\S+)", listing, re.M)
    assert first is not None
    # and the program's line of the waypoint: its first cutting GOTO's, after the first FEDRAT
    text = PROGRAM.read_text().splitlines()
    fedrat = next(n for n, line in enumerate(text) if line.startswith("FEDRAT"))
    goto = next(n for n in range(fedrat, len(text)) if text[n].startswith("GOTO")) + 1
    assert out.splitlines()[-1].endswith(f"at waypoint 0 (line {goto}, pass 0, {first.group(1)})")


def test_a_feed_the_path_cannot_run_is_exit_infeasible(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(
        capsys, "evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0", "--feed", "50"
    )
    assert code == INFEASIBLE
    line = re.search(
        r"^feed [0-9.]+ mm/min: does not run, margin ([0-9.]+) \(mu_path / feed\)$", out, re.M
    )
    assert line is not None, out  # the margin said as what it is (was a bare "margin 0.123")
    at = ["evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0", "--feed", "50", "--json"]
    _, answer, _ = run(capsys, *at)
    assert float(line.group(1)) == round(json.loads(answer)["feed_check"]["margin"], 3) < 1.0


def test_a_feed_is_given_in_m_per_s_or_with_its_unit(capsys: pytest.CaptureFixture[str]) -> None:
    """The answers print feeds in mm/min (a CAM program's unit) and --feed took m/s alone:
    508 copied from an answer was refused as "less than or equal to 100", no unit named, and
    50 mm/min would have been checked as 50 m/s (the CLI audit of stop 61)."""
    at = ["evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0.2,0.3,0,1.57", "--json"]
    answers = {}
    for feed in ("508mm/min", "20 in/min", "20IPM", str(508 / 60_000), str(0.0254 * 20 / 60)):
        code, out, _ = run(capsys, *at, "--feed", feed)
        answers[feed] = (code, json.loads(out)["feed_check"])
    assert answers["508mm/min"] == answers[str(508 / 60_000)]
    assert answers["20 in/min"] == answers["20IPM"] == answers[str(0.0254 * 20 / 60)]
    assert answers["508mm/min"][1]["feed"] == pytest.approx(508 / 60_000, rel=1e-15)
    code, out, err = run(capsys, *at, "--feed", "508")
    assert (code, json.loads(out)["detail"][0]["loc"]) == (INVALID, ["body", "feed"])
    assert err.startswith("error: feed (--feed: m/s, or with its unit: 508mm/min, 20in/min): ")
    with pytest.raises(SystemExit) as usage:
        run(capsys, *at, "--feed", "508mm/s")
    assert usage.value.code == 2
    assert "give a number of m/s, or one with m/s, mm/min, in/min, ipm" in capsys.readouterr().err


def test_a_command_that_compiles_kernels_says_so_once(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The first run in an installation or account compiles for one to two minutes, and an
    unattended caller saw nothing on stderr (the CLI audit of stop 61): one note when numba
    compiles (here two signatures of a function of the test's own), none when it loads."""

    @numba.njit(cache=False)
    def fresh(x: float) -> float:
        return x + 1

    reads = cli.import_of

    def compiling(*args: Any, **kwargs: Any) -> Any:
        fresh(1)
        fresh(2.0)
        return reads(*args, **kwargs)

    monkeypatch.setattr(cli, "import_of", compiling)
    code, _, err = run(capsys, "import", str(PROGRAM))
    assert code == 0 and err.splitlines() == [
        "note: compiling the kernels this command needs (their first use in this installation "
        "or account: up to a few minutes, once; later runs load them)"
    ]
    code, _, err = run(capsys, "import", str(PROGRAM))  # compiled now: nothing to say
    assert (code, err) == (0, "")


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
    code, out, _ = run(capsys, *MAP, "--png", str(png), "--json")
    assert code == OK
    assert png.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    body = {
        "robot": ROBOT,
        "path": {"cl_data": PROGRAM.read_text()},
        "grid": {**GRID, "z": 0.0, "yaw": 0.0},
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
    # The text of an optimum, on a smaller box (the same search three times took 15 s)
    code, out, _ = run(
        capsys, "optimise", str(PROGRAM), "--robot", "ur5e", "--x=0:0.02", "--y", "0.3:0.32",
        "--yaw=0:0.1",
    )  # fmt: skip
    assert code == OK
    assert "KUKA base (mm, deg): X" in out and "UR base pose (m, rad)" in out


def test_invalid_input_names_the_field_and_exits_invalid(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bare = tmp_path / "bare.cl"
    bare.write_text("GOTO/0,0,0\nFEDRAT/MMPM,250\nGOTO/10,0,0\n")
    code, out, err = run(capsys, "import", str(bare))
    assert (code, out) == (INVALID, "")
    # the option that fills the field named too (a published NX program was told to "give
    # units with the program", no option named: the CLI audit of stop 61)
    assert err.startswith("error: path.units (--units): ") and "FEDRAT/MMPM at line 2" in err
    broken = tmp_path / "broken.cl"
    broken.write_text("UNITS/MM\nGOTO/0,0,0\nGOTO/1,0,0,0,0\n")
    code, _, err = run(capsys, "import", str(broken))
    assert code == INVALID and err.startswith("error: path.cl_data (PROGRAM): line 3: ")


def test_a_refusal_with_json_is_the_routes_422_body_on_stdout(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """With --json a caller parses stdout; a refusal was only English on stderr (the CLI audit
    of stop 61): now the route's 422 body too, the English lines still on stderr."""
    text = "GOTO/0,0,0\nFEDRAT/MMPM,250\nGOTO/10,0,0\n"
    bare = tmp_path / "bare.cl"
    bare.write_text(text)
    code, out, err = run(capsys, "import", str(bare), "--json")
    route = client.post("/v1/paths/import", json={"path": {"cl_data": text}})
    assert route.status_code == 422
    assert (code, json.loads(out)) == (INVALID, route.json())
    assert err.startswith("error: path.units (--units): ")
    map_png = [*MAP, "--png", str(tmp_path), "--json"]  # a folder: refused on its option
    code, out, _ = run(capsys, *map_png)
    assert code == INVALID
    assert json.loads(out)["detail"][0]["loc"] == ["--png"]


def test_a_program_over_the_character_limit_is_said_as_a_program(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Over 2,000,000 characters the refusal was pydantic's 'String should have at most
    2000000 characters' (the CLI audit of stop 61): said as a program's length, with what to do."""
    line = "GOTO/1.0000,2.0000,3.0000\n"
    long = tmp_path / "long.cl"
    long.write_text("UNITS/MM\n" + line * (2_000_000 // len(line) + 1))
    code, out, err = run(capsys, "import", str(long))
    size = len(long.read_text())
    assert (code, out) == (INVALID, "")
    assert err == (
        f"error: program: {size:,} characters: a program is read up to 2,000,000 (about the "
        "20,000 moves a path may have): split it between passes\n"
    )


def test_units_given_on_the_command_line_are_said_as_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """'units: mm (request: the request's units (the file states none))' where no request was
    sent, and '1 passes' (the CLI audit of stop 61)."""
    table = tmp_path / "fan.csv"
    table.write_text("x,y,z,i,j,k\n100,0,0,0,0,1\n110,0,0,0,0,1\n")
    code, out, _ = run(capsys, "import", str(table), "--units", "mm")
    assert code == 0 and out.splitlines()[1:3] == [
        "waypoints: 2 in 1 pass (0 arcs interpolated; dropped: 0 repeated point(s), 0 one-point "
        "pass(es))",
        "units: mm (given with --units: the file states none)",
    ]


def test_a_csv_needs_its_units_and_errors_name_the_api_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    table = tmp_path / "fan.csv"
    table.write_text("x,y,z,i,j,k\n100,0,0,0,0,1\n110,0,0,0,0,1\n")
    code, out, err = run(capsys, "import", str(table))
    assert (code, out) == (INVALID, "")
    assert err.startswith("error: path.units (--units): ") and "--units mm" in err
    program = tmp_path / "line.cl"
    program.write_text("UNITS/MM\nGOTO/0,0,0\nGOTO/1,0,0\n")
    code, _, err = run(capsys, "import", "--arc-tolerance", "-1", str(program))
    assert code == INVALID  # the location as the API gives it, without the union's tags
    assert err.startswith("error: path.arc_tolerance (--arc-tolerance): ")


def test_a_robot_file_that_is_not_json_exits_invalid(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    file = tmp_path / "robot.json"
    file.write_text("{model: ur5")
    code, _, err = run(capsys, "evaluate", str(PROGRAM), "--robot", str(file), "--at=0,0.3,0,0")
    assert code == INVALID and err.startswith("error: robot (--robot): the file is not JSON")


def test_usage_errors_exit_usage(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as caught:
        main(["evaluate", str(PROGRAM), "--robot", "ur5e", "--at", "1,2"])
    assert caught.value.code == USAGE
    assert "4 numbers" in capsys.readouterr().err


def test_a_progress_bar_only_when_asked(capsys: pytest.CaptureFixture[str]) -> None:
    args = MAP
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


def test_a_reader_that_closes_the_output_early_ends_the_command_quietly(tmp_path: Path) -> None:
    # `dtf-place map ... --json | head`: the map's JSON (about 0.4 MB) is more than the pipe
    # holds; the reader takes ten bytes and closes it. No "error: [Errno 32] Broken pipe" as
    # an invalid input (exit 3), no Python complaint at exit: the shell's 141, nothing said.
    grid = ["--x=-0.2:0.2:0.01", "--y", "0.2:0.6:0.01", "--png", str(tmp_path / "map.png")]
    command = [sys.executable, "-m", "service.cli", *MAP[:4], *grid, "--json"]
    with subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT
    ) as process:
        assert process.stdout is not None and process.stderr is not None
        assert process.stdout.read(10).startswith(b"{")
        process.stdout.close()
        said = process.stderr.read()
        code = process.wait(timeout=300)
    assert (code, said) == (CLOSED_PIPE, b"")


def test_the_console_script_is_declared() -> None:
    assert 'dtf-place = "service.cli:main_exit"' in (ROOT / "pyproject.toml").read_text()


def _file(tmp_path: Path, name: str, value: Any) -> str:
    file = tmp_path / name
    file.write_text(json.dumps(value))
    return str(file)


def _text_file(tmp_path: Path, name: str, text: str) -> str:
    file = tmp_path / name
    file.write_text(text)
    return str(file)


def _contact(contact: dict[str, Any]) -> str:
    """A contact as the command prints it, from the route's JSON."""
    return (
        f"{contact['robot_part']} and {contact['obstacle_name']} at waypoint "
        f"{contact['waypoint']}, {_apart(contact['distance'])}"
    )


def _apart(distance: float) -> str:
    """A distance (m) as the command prints it."""
    mm = 1e3 * distance
    return f"{mm:.1f} mm apart" if mm >= 0 else f"{-mm:.1f} mm into it"


def test_a_cell_file_is_checked_as_the_routes_cell(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cell, robot = _file(tmp_path, "cell.json", CELL), _file(tmp_path, "robot.json", TOOLED)
    at = ["evaluate", str(PROGRAM), "--robot", robot, "--at=0,0.3,0,0", "--cell", cell]
    code, out, _ = run(capsys, *at, "--json")
    body = {"robot": TOOLED, "path": {"cl_data": PROGRAM.read_text()}, "placement": AT}
    expected = api(client, "/v1/evaluate", {**body, "cell": CELL, "detail": "summary"})
    assert code == OK
    assert json.loads(out) == expected
    assert expected["feasible"] and expected["min_clearance"]["distance"] >= 0.005
    code, out, _ = run(capsys, *at)
    assert code == OK
    assert f"least clearance: {_contact(expected['min_clearance'])}" in out.splitlines()
    assert "cell: approximated by capsules" not in out  # the UR5e's published capsules
    unchecked = [  # the shoulder's capsule, along joint 1's axis: joint 1 turns it onto itself
        f"{p['robot_part']} and {p['obstacle_name']} ({_apart(p['distance'])})"
        for p in expected["cell_unchecked"]
    ]
    assert len(unchecked) == 2  # the table and the fixture
    line = "cell: not checked, no joint moves them relative to each other: " + ", ".join(unchecked)
    assert line in out.splitlines()


def test_a_table_above_the_base_makes_evaluate_and_map_infeasible_by_collision(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cell = _file(tmp_path, "raised.json", RAISED_TABLE)
    code, out, _ = run(
        capsys, "evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0", "--cell", cell
    )
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM.read_text()}, "placement": AT}
    answer = api(client, "/v1/evaluate", {**body, "cell": RAISED_TABLE, "detail": "summary"})
    assert code == INFEASIBLE and answer["reason"] == "collision"
    assert answer["collision"]["obstacle_name"] == "raised table"
    lines = out.splitlines()
    assert lines[-2].startswith("infeasible: collision at waypoint ")
    assert lines[-1] == f"collision: {_contact(answer['collision'])} (clearance 5.0 mm)"
    code, out, _ = run(capsys, *MAP, "--png", str(tmp_path / "map.png"), "--cell", cell)
    assert code == INFEASIBLE
    assert out.splitlines()[-1] == (
        f"map: 0 of 6 placements feasible (6 in collision); {tmp_path / 'map.png'}"
    )
    # Nothing approximated, nothing left unchecked: Menagerie's UR5e shoulder capsule (radius
    # 0.06 m, segment 0.12 m long, centred 0.04 m below joint 1 at 0.163 m) reaches 0.003 m
    # above the foot, 0.047 m into this table: the arm's own geometry in its table is checked
    # (it collides everywhere); the base has no geometry of its own in that model.
    assert "cell: approximated" not in out and "cell: not checked" not in out


def test_optimise_in_a_cell_prints_the_routes_collision_free_optimum(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = run(
        capsys, "optimise", str(PROGRAM), "--robot", _file(tmp_path, "robot.json", TOOLED),
        "--x=-0.1:0.1", "--y", "0.25:0.35", "--yaw=-0.5:0.5",
        "--cell", _file(tmp_path, "cell.json", CELL),
    )  # fmt: skip
    bounds = {"x": [-0.1, 0.1], "y": [0.25, 0.35], "yaw": [-0.5, 0.5]}
    body = {"robot": TOOLED, "path": {"cl_data": PROGRAM.read_text()}, "bounds": bounds, "z": 0.0}
    answer = api(client, "/v1/optimize", {**body, "method": "scipy", "cell": CELL})
    assert code == OK and answer["found"]
    nearest = answer["evaluation"]["min_clearance"]
    assert nearest["distance"] >= 0.005  # collision-free, the default clearance kept
    assert f"optimum: mu_path {answer['mu_path']:.4f} m/s" in out
    assert f"least clearance: {_contact(nearest)}" in out.splitlines()


def test_acceleration_limits_print_mu_acc_and_the_cycle_time(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robot = {"model": "ur5e", "joint_acceleration_limits": [3.0] * 6}
    file = _file(tmp_path, "robot.json", robot)
    code, out, _ = run(capsys, "evaluate", str(PROGRAM), "--robot", file, "--at=0,0.3,0,0")
    body = {"robot": robot, "path": {"cl_data": PROGRAM.read_text()}, "placement": AT}
    answer = api(client, "/v1/evaluate", {**body, "detail": "summary"})
    acceleration, cycle = answer["acceleration"], answer["cycle_time"]
    assert code == OK and acceleration["mu_acc"] < answer["mu_path"]
    assert (
        f"mu_acc: {acceleration['mu_acc']:.4f} m/s (a joint {acceleration['limited_by']} limit "
        f"binds: {acceleration['joint_name']} at waypoint {acceleration['waypoint']})"
    ) in out.splitlines()
    assert (
        f"cycle time: {cycle['ramp']:.2f} s at mu_acc with its ramps "
        f"(time-optimal {cycle['time_optimal']:.2f} s)"
    ) in out.splitlines()


def test_a_cell_file_that_is_not_json_or_not_a_cell_exits_invalid(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    at = ["evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0", "--cell"]
    broken = tmp_path / "broken.json"
    broken.write_text("{fixed: [")
    code, out, err = run(capsys, *at, str(broken))
    assert (code, out) == (INVALID, "") and err.startswith(
        "error: cell (--cell): the file is not JSON"
    )
    flat = {"fixed": [{"shape": "box", "size": [0.1, -1.0, 0.1]}]}
    code, out, err = run(capsys, *at, _file(tmp_path, "flat.json", flat))
    assert (code, out) == (INVALID, "") and err.startswith(
        "error: cell.fixed.0.box.size.1 (--cell): "
    )


UR5_URDF = example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"


def _tilted_ur5(folder: Path) -> Path:
    """The UR5's URDF with a frame ``tilted``: base_link turned by a mrad about x."""
    tilted = '<link name="tilted"/><joint name="tilt" type="fixed"><parent link="base_link"/>'
    tilted += '<child link="tilted"/><origin xyz="0 0 0" rpy="0.001 0 0"/></joint></robot>'
    file = folder / "ur5.urdf"
    file.write_text(UR5_URDF.read_text().replace("</robot>", tilted))
    return file


def _bent_ur5(folder: Path) -> Path:
    """The UR5's URDF with its elbow's axis turned by a mrad: no UR or OPW arm (numeric IK)."""
    file = folder / "ur5_bent.urdf"
    file.write_text(bent_elbow(UR5_URDF.read_text()))
    return file


def test_a_urdf_file_is_the_routes_urdf_robot_from_its_controller_frame_to_tool0(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # By default from REP 199's base (the controller's frame: the UR5's DH frame) to tool0;
    # from ROS's base_link, half a turn from it, from base, and from a frame tilted by a mrad
    # (joint 1 not upright in it; {B} is that frame, so the arm is tilted by -1 mrad from it)
    # the UR5 is solved in closed form, and the answer says how.
    file = _tilted_ur5(tmp_path)
    at = ["evaluate", str(PROGRAM), "--robot", str(file), "--at=0,0.3,0,0"]
    path = {"cl_data": PROGRAM.read_text()}
    answers = {}
    for base in ("base", "base_link", "tilted"):
        options = [] if base == "base" else ["--base-frame", base]
        code, out, _ = run(capsys, *at, *options, "--json")
        robot = {"urdf": file.read_text(), "base_frame": base, "tool_frame": "tool0"}
        body = {"robot": robot, "path": path, "placement": AT, "detail": "summary"}
        answers[base] = api(client, "/v1/evaluate", body)
        assert code == (OK if answers[base]["feasible"] else INFEASIBLE)
        assert json.loads(out) == answers[base]
        code, out, _ = run(capsys, *at, *options)
        answers[base]["printed"] = out.splitlines()[0]
    for base in ("base_link", "base", "tilted"):
        assert answers[base]["ik"]["family"] == "ur"
        recognised = answers[base]["ik"]["recognised"]
        assert answers[base]["printed"] == f"robot: {file}, from {base} to tool0; {recognised}"
    assert "turned by 180 deg about z" in answers["base_link"]["ik"]["recognised"]
    assert "tilted by 0.0572958 deg about (-1, 0, 0)" in answers["tilted"]["ik"]["recognised"]
    bent = _bent_ur5(tmp_path)
    code, out, _ = run(capsys, "evaluate", str(PROGRAM), "--robot", str(bent), "--at=0,0.3,0,0")
    assert out.splitlines()[0] == f"robot: {bent}, from base to tool0; numeric IK"


def test_a_urdf_without_the_controllers_frame_starts_from_base_link(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The UR5's URDF with its link "base" (REP 199's controller frame) taken out: the chain
    # starts from base_link, and the first line says so.
    without = tmp_path / "ur5_no_base.urdf"
    text = UR5_URDF.read_text()
    joint = text.index('"base_link-base_fixed_joint"')
    without.write_text(
        text.replace(text[text.index('<link name="base">') : text.index("</joint>", joint) + 8], "")
    )
    at = ["evaluate", str(PROGRAM), "--at=0,0.3,0,0", "--robot", str(without)]
    code, out, _ = run(capsys, *at)
    assert code == OK
    assert out.splitlines()[0].startswith(f"robot: {without}, from base_link to tool0; ")


def test_a_refused_urdf_is_said_once_without_the_parsers_own_lines(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    # urdfdom writes its reason and its source line on the process's stderr; the server's log
    # keeps them (tests/solver/test_urdf_structure.py), the command's error says the reason.
    file = tmp_path / "two_roots.urdf"
    second = (
        '<link name="cart"/><link name="top"/><joint name="j" type="fixed"><parent link="cart"/>'
    )
    second += '<child link="top"/></joint>'  # a second tree, joined to the arm by nothing
    file.write_text(UR5_URDF.read_text().replace("</robot>", second + "</robot>"))
    code = main(["evaluate", str(PROGRAM), "--robot", str(file), "--at=0,0.3,0,0"])
    out, err = capfd.readouterr()
    assert (code, out) == (INVALID, "")
    assert err.splitlines() == [
        "error: robot.urdf (--robot): cannot parse the URDF: 2 root links ('world', 'cart'): "
        "every link but one must be a joint's child; remove the stray link or attach it with a "
        "fixed joint"
    ]


def test_a_link_no_joint_names_is_left_out_and_said_under_the_robots_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # As the ROS 2 generated UR5e: <link name="world"/> and no joint to it (its generator left
    # the joint out). The answer is the same URDF's with the link deleted by hand.
    text = UR5_URDF.read_text()
    start = text.index('<joint name="world_joint"')
    stray = tmp_path / "ur5_stray_world.urdf"
    stray.write_text(text[:start] + text[text.index("</joint>", start) + len("</joint>") :])
    by_hand = tmp_path / "ur5_by_hand.urdf"
    by_hand.write_text(stray.read_text().replace('<link name="world"/>', ""))
    at = ["evaluate", str(PROGRAM), "--at=0,0.3,0,0", "--robot"]
    code, out, _ = run(capsys, *at, str(stray))
    assert code == OK
    lines = out.splitlines()
    assert lines[0].startswith(f"robot: {stray}, from base to tool0; the URDF chain is a UR arm")
    assert lines[1] == "robot: left out of the URDF, no joint names them: 'world'"
    code, plain, _ = run(capsys, *at, str(by_hand))
    assert code == OK and "left out" not in plain
    assert lines[2:] == plain.splitlines()[1:]
    code, out, _ = run(capsys, *at, str(stray), "--json")
    assert json.loads(out)["robot_read"] == {
        "left_out_links": ["world"],
        "left_out_count": 1,
        "continuous_joints": [],
        "unlimited_joints": [],
        "locked_joints": [],
    }


def test_continuous_joints_read_as_revolute_are_said_under_the_robots_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = UR5_URDF.read_text()
    start = text.index('<joint name="wrist_3_joint"')
    end = text.index("</joint>", start)
    joint = re.sub(r' (lower|upper)="[^"]*"', "", text[start:end])
    file = tmp_path / "ur5_continuous_wrist.urdf"
    file.write_text(text[:start] + joint.replace('"revolute"', '"continuous"') + text[end:])
    code, out, _ = run(capsys, "evaluate", str(PROGRAM), "--at=0,0.3,0,0", "--robot", str(file))
    assert code == OK
    assert out.splitlines()[1] == (
        "robot: continuous joints read as revolute: 'wrist_3_joint'; no position limit (the "
        "URDF gives none): 'wrist_3_joint'"
    )


def test_joints_that_move_no_tool_are_said_locked_under_the_robots_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    panda = example_robot_data_dir() / "panda_description" / "urdf" / "panda.urdf"
    frames = ["--base-frame", "panda_link0", "--tool-frame", "panda_link8"]
    at = ["evaluate", str(PROGRAM), "--at=0.4,0,0.1,0", "--robot", str(panda), *frames]
    code, out, _ = run(capsys, *at)
    assert code in (OK, INFEASIBLE)
    assert out.splitlines()[1] == (
        "robot: locked at 0, they move no tool: 'panda_finger_joint1', 'panda_finger_joint2'"
    )


def test_frames_with_a_robot_that_is_no_urdf_or_not_in_it_exit_invalid(
    capsys: pytest.CaptureFixture[str],
) -> None:
    at = ["evaluate", str(PROGRAM), "--at=0,0.3,0,0", "--robot"]
    for option in (["--base-frame", "base"], ["--tool-frame", "tool0"]):
        code, out, err = run(capsys, *at, "ur5e", *option)
        assert (code, out) == (INVALID, "")  # refused, not ignored (even the default's name)
        assert err.startswith(
            "error: robot (--robot): --base-frame and --tool-frame choose a URDF file's"
        )
    code, out, err = run(capsys, *at, str(UR5_URDF), "--tool-frame", "nowhere")
    assert (code, out) == (INVALID, "")
    assert err.startswith("error: robot.tool_frame (--robot): no frame 'nowhere' in the model")


def test_map_takes_lists_of_yaws_and_spins_a_panel_each(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "map.png"
    lists = ["--yaw", "0,1.5708", "--spin=-0.3,0.3", "--spin-mode", "fixed"]
    code, out, _ = run(capsys, *MAP, *lists, "--png", str(png), "--json")
    grid = {**GRID, "z": 0.0, "yaw": [0.0, 1.5708], "spin": [-0.3, 0.3]}
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM.read_text()}, "grid": grid}
    expected = api(client, "/v1/map", {**body, "spin_mode": "fixed"})
    assert code == OK and json.loads(out) == expected
    assert {(c["yaw"], c["spin"]) for c in expected["cells"]} == {
        (yaw, spin) for yaw in (0.0, 1.5708) for spin in (-0.3, 0.3)
    }
    header = png.read_bytes()[16:24]  # the IHDR chunk's width and height
    width, height = int.from_bytes(header[:4], "big"), int.from_bytes(header[4:], "big")
    assert width > 1.5 * height  # panels side by side (one panel is about 1.4 times as wide)


def test_a_map_value_beyond_a_turn_is_noted_before_the_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--yaw 0,1,57`` (a decimal comma) is three yaws, as the API takes them, and said so.

    By hand: 57 - 9 (2 pi) = 0.45133 rad, -7 + 2 pi = -0.71681 rad.
    """
    png = tmp_path / "map.png"
    lists = ["--yaw", "0,1,57", "--spin=-7", "--spin-mode", "fixed", "--json"]
    code, out, err = run(capsys, *MAP, *lists, "--png", str(png))
    assert code == OK
    assert sorted({cell["yaw"] for cell in json.loads(out)["cells"]}) == [0.0, 1.0, 57.0]
    said = [line for line in err.splitlines() if line.startswith("note: --")]  # not the caches'
    assert said == [
        "note: --yaw 57 rad is more than a turn (the same as 0.4513 rad); a list is "
        "comma-separated and a decimal takes a point (1.57)",
        "note: --spin -7 rad is more than a turn (the same as -0.7168 rad); a list is "
        "comma-separated and a decimal takes a point (1.57)",
    ]
    code, _, err = run(capsys, *MAP, "--yaw", "0,1.57", "--png", str(png))
    assert code == OK and "note: --" not in err
    code, _, err = run(capsys, *MAP, "--yaw", "1e300", "--png", str(png))  # refused: no note
    assert code == INVALID and err.splitlines()[-1] == (
        "error: grid.yaw (--yaw): Input should be less than or equal to 1000"
    )
    assert "note: --" not in err


def test_optimise_searches_a_height_range_and_a_spin_range_as_the_route(
    client: TestClient, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = run(
        capsys, "optimise", str(PROGRAM), "--robot", "ur5e", "--x=-0.1:0.1", "--y", "0.25:0.35",
        "--yaw=-0.5:0.5", "--z", "0:0.1", "--spin=-0.5:0.5", "--spin-mode", "fixed", "--json",
    )  # fmt: skip
    bounds = {"x": [-0.1, 0.1], "y": [0.25, 0.35], "yaw": [-0.5, 0.5]}
    bounds |= {"z": [0.0, 0.1], "spin": [-0.5, 0.5]}
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM.read_text()}, "bounds": bounds}
    theirs = api(client, "/v1/optimize", {**body, "method": "scipy", "spin_mode": "fixed"})
    mine = json.loads(out)
    for answer in (mine, theirs):
        answer["solver"].pop("seconds")
    assert code == OK and mine == theirs
    at = theirs["placement"]
    assert 0.0 <= at["z"] <= 0.1 and -0.5 <= at["spin"] <= 0.5


def test_a_branch_is_followed_as_the_routes_ik_branch_and_printed(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    file = _bent_ur5(tmp_path)  # numeric IK
    urdf = {"urdf": file.read_text(), "base_frame": "base", "tool_frame": "tool0"}
    named = {"shoulder": "left", "elbow": "up", "wrist": "flip"}
    for robot, body_robot, option, branch, printed in (
        ("ur5e", ROBOT, ["left/up/flip"], named, "branch: left/up/flip"),
        (
            str(file),
            urdf,
            ["0"],
            {"solution": 0},
            "branch: solution 0 (numeric IK, in seed order)",
        ),
    ):
        at = ["evaluate", str(PROGRAM), "--robot", robot, "--at=0,0.3,0,0", "--branch", *option]
        code, out, _ = run(capsys, *at, "--json")
        body = {"robot": body_robot, "path": {"cl_data": PROGRAM.read_text()}, "placement": AT}
        expected = api(
            client, "/v1/evaluate", {**body, "detail": "summary", "ik": {"branch": branch}}
        )
        assert code == OK and json.loads(out) == expected
        assert expected["branch"] == branch  # the branch asked for is the one followed
        code, out, _ = run(capsys, *at)
        assert printed in out.splitlines()


def test_a_branch_that_is_no_branch_exits_usage_or_invalid(
    capsys: pytest.CaptureFixture[str],
) -> None:
    at = ["evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0", "--branch"]
    with pytest.raises(SystemExit) as caught:
        main([*at, "up"])
    assert caught.value.code == USAGE
    assert "SHOULDER/ELBOW/WRIST" in capsys.readouterr().err
    code, out, err = run(capsys, *at, "front/up/flip")  # an OPW arm's names on a UR
    assert (code, out) == (INVALID, "")
    assert err.startswith(
        "error: ik.branch (--branch): {shoulder=front, elbow=up, wrist=flip} is not a"
    )


def test_a_command_is_bounded_by_the_job_limits_not_the_routes(
    client: TestClient,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Six placements of the program (89 waypoints) are 534 pairs: over a route limit of 100, which
    # POST /v1/map refuses; the command runs as a job does, under the job limit.
    monkeypatch.setenv("DTF_MAX_MAP_POSES", "100")
    get_settings.cache_clear()
    try:
        body = {
            "robot": ROBOT,
            "path": {"cl_data": PROGRAM.read_text()},
            "grid": {**GRID, "z": 0.0, "yaw": 0.0},
        }
        refused = client.post("/v1/map", json=body)
        assert refused.status_code == 422 and "DTF_MAX_MAP_POSES" in refused.text
        code, _, _ = run(capsys, *MAP, "--png", str(tmp_path / "map.png"))
        assert code == OK
        monkeypatch.setenv("DTF_MAX_JOB_POSES", "100")
        get_settings.cache_clear()
        code, out, err = run(capsys, *MAP, "--png", str(tmp_path / "map.png"))
        assert (code, out) == (INVALID, "")
        assert "DTF_MAX_JOB_POSES" in err
    finally:
        get_settings.cache_clear()


def test_a_command_loads_the_optimisers_and_matplotlib_only_when_it_needs_them() -> None:
    # Every call of dtf-place pays its imports: scipy's optimisers, casadi and matplotlib were
    # 0.7 s of the 2.3 s an evaluation of the slot plate took (2026-12-04); they are loaded by
    # the commands that optimise or draw.
    code = (
        "import sys\nfrom service.cli import main\n"
        f"main(['evaluate', {str(PROGRAM)!r}, '--robot', 'ur5e', '--at=0.2,0.3,0,1.57'])\n"
        "print(sorted(m for m in ('scipy.optimize', 'matplotlib', 'casadi') if m in sys.modules))"
    )
    run_ = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    )
    assert run_.stdout.splitlines()[-1] == "[]"


OPW_FILE = """# as ROS-Industrial's support packages write them for moveit_opw_kinematics_plugin
opw_kinematics_geometric_parameters:
    a1:  0.15
    a2:  -0.25
    b:   0.0
    c1:  0.525
    c2:  0.79
    c3:  0.835
    c4:  0.1
opw_kinematics_joint_offsets: [0.0, 0.0, deg(-90.0), 0.0, 0.0, rad(3.141592653589793)]
opw_kinematics_joint_sign_corrections: [1, 1, -1, -1, -1, -1]
"""
"""The FANUC M-20iA's geometry (the catalogue's fanuc_m20ia), angles in rosparam's forms."""


def test_an_opw_parameter_file_is_refused_with_the_robot_object_it_gives(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # It has no joint limits: the command prints the opw object read from it, for a robot JSON
    # file beside the maker's limits, and names the catalogue arm of that geometry.
    program, at = str(ROOT / "examples" / "cam" / "sweep_mm.cl"), "--at=0.9,0.2,0.3,0"
    code, _, err = run(
        capsys, "evaluate", program, "--robot", _text_file(tmp_path, "m20ia.yaml", OPW_FILE), at
    )
    assert code == INVALID
    assert "m20ia.yaml is a ROS-Industrial OPW parameter file" in err
    assert err.rstrip().endswith("its geometry is the catalogue's fanuc_m20ia: --robot fanuc_m20ia")
    opw = json.loads(err.split('{"opw": ', 1)[1].split(', "joint_position_limits"', 1)[0])
    offsets = [0.0, 0.0, math.radians(-90.0), 0.0, 0.0, math.pi]
    assert opw == {
        "a1": 0.15, "a2": -0.25, "b": 0.0, "c1": 0.525, "c2": 0.79, "c3": 0.835, "c4": 0.1,
        "offsets": offsets, "sign_corrections": [1, 1, -1, -1, -1, -1],
    }  # fmt: skip
    # that object with the arm's limits (the catalogue's) is the arm
    arm = next(arm for arm in ARMS if arm.name == "fanuc_m20ia")
    limits = {
        "joint_position_limits": [list(pair) for pair in arm.position_limits],
        "joint_velocity_limits": list(arm.velocity_limits),
    }
    robot = _file(tmp_path, "m20ia.json", {"opw": opw, **limits})
    code, out, _ = run(capsys, "evaluate", program, "--robot", robot, at, "--json")
    assert code == OK
    code, catalogue, _ = run(capsys, "evaluate", program, "--robot", "fanuc_m20ia", at, "--json")
    assert code == OK
    assert json.loads(out)["mu_path"] == json.loads(catalogue)["mu_path"] > 0.0


def test_an_opw_files_lists_it_lacks_are_said_with_what_is_written_for_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lacking = "\n".join(line for line in OPW_FILE.splitlines() if "joint_" not in line)
    robot = _text_file(tmp_path, "m20ia.yaml", lacking)
    code, _, err = run(capsys, "evaluate", str(PROGRAM), "--robot", robot, "--at=0,0.3,0,0")
    assert code == INVALID
    opw = json.loads(err.split('{"opw": ', 1)[1].split(', "joint_position_limits"', 1)[0])
    assert (opw["offsets"], opw["sign_corrections"]) == ([0.0] * 6, [1] * 6)
    assert err.rstrip().endswith(
        "(the file has no opw_kinematics_joint_offsets and no "
        "opw_kinematics_joint_sign_corrections: offsets 0, sign corrections 1 written)"
    )
    code, _, err = run(
        capsys, "evaluate", str(PROGRAM), "--robot", _text_file(tmp_path, "full.yaml", OPW_FILE),
        "--at=0,0.3,0,0",
    )  # fmt: skip
    assert code == INVALID and "written)" not in err  # the file gives both


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("arm.yaml", "robot: {a1: 0.1}\n", "arm.yaml is not an OPW parameter file"),
        ("arm.yaml", "a: [1, 2\n", "arm.yaml is not YAML"),
        (
            "arm.yaml",
            OPW_FILE.replace("deg(-90.0)", "degrees(-90)"),
            "opw_kinematics_joint_offsets[2] is 'degrees(-90)', not a number, deg(x) or rad(x)",
        ),
        ("arm.xml", "<robot/>", "arm.xml is neither a URDF (.urdf) nor a JSON file"),
        (
            "arm.yaml",
            OPW_FILE.replace("sign_corrections: [1,", "sign_corrections: [.nan,"),
            "opw_kinematics_joint_sign_corrections[0] is nan, not 1 or -1",
        ),
        (
            "arm.yaml",
            OPW_FILE.replace("sign_corrections: [1,", "sign_corrections: [-1.5,"),
            "opw_kinematics_joint_sign_corrections[0] is -1.5, not 1 or -1",
        ),
        (
            "arm.yaml",
            OPW_FILE.replace("a1: ", "a1: " + "1" * 400 + "  # "),
            "opw_kinematics_geometric_parameters.a1 is 1111111111",
        ),
        (
            "arm.yaml",
            OPW_FILE.replace("joint_offsets:", "joint_offset:"),
            "arm.yaml: key 'opw_kinematics_joint_offset' not read: an OPW parameter file holds "
            "opw_kinematics_geometric_parameters, opw_kinematics_joint_offsets and "
            "opw_kinematics_joint_sign_corrections, and a misspelt key would leave its values out",
        ),
        (
            "arm.yaml",
            OPW_FILE.replace("    c4:  0.1\n", "    c4:  0.1\n    c5:  0.2\n    C4:  0.1\n"),
            "arm.yaml: keys 'c5', 'C4' of opw_kinematics_geometric_parameters not read: it holds "
            "a1, a2, b, c1, c2, c3 and c4",
        ),
        (
            "arm.yaml",
            "a: " + "[" * 20_000 + "]" * 20_000,
            "arm.yaml: lists or maps nested 20000 deep (at most 10)",
        ),
        (
            "arm.yaml",
            "".join(
                f"l{k}: &l{k} [{', '.join([f'*l{k - 1}'] * 9)}]\n" for k in range(1, 9)
            ).replace("*l0", "1")
            + "opw_kinematics_geometric_parameters: {a1: *l8}\n",
            "YAML aliases (*name) are not read in a parameter file",
        ),
    ],
    ids=[
        "not-opw",
        "not-yaml",
        "bad-angle",
        "other-file",
        "nan-sign (a traceback)",
        "fractional sign (cut to -1)",
        "400-digit length (a traceback)",
        "misspelt key (its offsets left out, zeros printed)",
        "unknown lengths (left out)",
        "nested 20,000 deep (a traceback after 37 s)",
        "alias bomb (8 GB, a minute)",
    ],
)
def test_a_robot_file_of_another_kind_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, content: str, message: str
) -> None:
    robot = _text_file(tmp_path, name, content)
    code, _, err = run(capsys, "evaluate", str(PROGRAM), "--robot", robot, "--at=0,0.3,0,0")
    assert code == INVALID
    assert message in err


UR5_URDF = example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"


def test_windows_encoded_files_read_as_their_utf8_selves(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A cell JSON saved by PowerShell (UTF-16 with its mark), a URDF and a program with
    UTF-8's mark (Windows editors): each was a traceback or a refusal of line 1.

    The answer equals the one of the same files in plain UTF-8.
    """
    plain, windows = tmp_path / "plain", tmp_path / "windows"
    for folder in (plain, windows):
        folder.mkdir()
    no_tool = {name: value for name, value in CELL.items() if name != "tool"}  # tool0 is the TCP
    cell, urdf, program = json.dumps(no_tool), UR5_URDF.read_text(), PROGRAM.read_text()
    (plain / "cell.json").write_text(cell)
    (windows / "cell.json").write_bytes(cell.encode("utf-16"))  # with its byte order mark
    for folder, mark in ((plain, ""), (windows, "\ufeff")):
        (folder / "ur5.urdf").write_text(mark + urdf, encoding="utf-8")
        (folder / "slot.cls").write_text(mark + program, encoding="utf-8")
    answers = []
    for folder in (plain, windows):
        code, out, err = run(
            capsys, "evaluate", str(folder / "slot.cls"), "--robot", str(folder / "ur5.urdf"),
            "--cell", str(folder / "cell.json"), "--at=0.3,0.3,0,0", "--json",
        )  # fmt: skip
        assert code in (OK, INFEASIBLE), err
        answers.append(json.loads(out))
    assert answers[0] == answers[1]
    assert (windows / "cell.json").read_bytes()[:2] in (b"\xff\xfe", b"\xfe\xff")


@pytest.mark.parametrize(
    ("content", "said"),
    [
        (b"[" * 100_000, "the file is not JSON (maximum recursion depth"),
        (b'{"clearance": ' + b"1" * 5000 + b"}", "the file is not JSON (Exceeds the limit"),
        (b'{"clearance": 0.01, "name": "caf\xe9"}', "the file is not UTF-8 text (invalid"),
    ],
    ids=["nested 100,000 deep", "an integer of 5,000 digits", "Latin-1"],
)
def test_a_cell_file_that_cannot_be_read_is_an_invalid_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: bytes, said: str
) -> None:
    """Each was a Python traceback and exit 1 (RecursionError, ValueError, UnicodeDecodeError)."""
    cell = tmp_path / "cell.json"
    cell.write_bytes(content)
    code, _, err = run(
        capsys, "evaluate", str(PROGRAM), "--robot", "ur5e", "--cell", str(cell), "--at=0,0.3,0,0"
    )
    assert code == INVALID
    assert err.startswith(f"error: cell (--cell): {said}")


@pytest.mark.parametrize(
    ("redirect", "expected"),
    [("2>&-", OK), (">&-", NOT_WRITTEN), ("> /dev/full", NOT_WRITTEN)],
    ids=["stderr closed", "stdout closed", "stdout full"],
)
def test_an_answer_that_cannot_be_written_is_not_a_success(
    tmp_path: Path, redirect: str, expected: int
) -> None:
    """`dtf-place import f >&-` exited 0 with the answer nowhere, `> /dev/full` 3 (invalid
    input, which it was not; the work-bounds audit of stop 55); stderr closed still answers.

    (Before stop 52: AttributeError on None's flush, exit 1.)
    """
    if redirect.endswith("/dev/full") and not Path("/dev/full").exists():
        pytest.skip("no /dev/full here")
    marker = tmp_path / "rc"
    command = (
        f"{shlex.quote(sys.executable)} -m service.cli import {shlex.quote(str(PROGRAM))} "
        f"{redirect}; echo $? > {shlex.quote(str(marker))}"
    )
    done = subprocess.run(["bash", "-c", command], cwd=ROOT, timeout=300, capture_output=True)
    assert marker.read_text().strip() == str(expected)
    if expected == NOT_WRITTEN:
        assert b"error: " in done.stderr and b"written" in done.stderr


@contextlib.contextmanager
def _interruptible() -> Iterator[None]:
    """SIGINT caught (not ignored) here while a child starts, so the child starts with it default.

    As an interactive shell starts a command: a suite started in the background by a script
    (``cmd &``, nohup) has SIGINT ignored, which a child inherits through exec and Python then
    keeps (it installs KeyboardInterrupt only over the default), so the map below ran to its
    end and exited 0 (stop 76, a worktree run started with ``&``). A caught signal is reset to
    its default at exec; the test's own handler is put back at once.
    """
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


@pytest.mark.parametrize(
    ("stop", "said", "exit_code"),
    [(signal.SIGINT, "interrupted", 130), (signal.SIGTERM, "terminated", 143)],
)
def test_ctrl_c_stops_a_map_with_one_line_and_the_shells_code(
    tmp_path: Path, stop: signal.Signals, said: str, exit_code: int
) -> None:
    """SIGINT during a map printed a 30-line KeyboardInterrupt traceback (exit 1); SIGTERM
    (what timeout(1) and job runners send) ended it with nothing said (stop 61's CLI audit)."""
    grid = ["--x=-0.8:0.8:0.002", "--y=-0.8:0.8:0.002", "--png", str(tmp_path / "map.png")]
    command = [sys.executable, "-m", "service.cli", *MAP[:4], *grid, "--progress"]
    big = {"DTF_MAX_MAP_CELLS": "1000000", "DTF_MAX_MAP_POSES": "100000000"}  # minutes of work
    env = {**os.environ, **big}
    with _interruptible():
        process = subprocess.Popen(command, stderr=subprocess.PIPE, cwd=ROOT, env=env)
    with process:
        assert process.stderr is not None
        seen = b""
        while b"%" not in seen:  # the progress bar: the map is under way (not an import)
            byte = process.stderr.read(1)
            assert byte, seen.decode()  # it ended before its bar
            seen += byte
        process.send_signal(stop)
        told = process.stderr.read().decode()
        code = process.wait(timeout=120)
    assert code == exit_code and exit_code in (INTERRUPTED, TERMINATED)
    assert told.rstrip().endswith(said) and "Traceback" not in told
    assert not (tmp_path / "map.png").exists()


def test_an_operation_name_the_outputs_encoding_lacks_is_escaped_not_a_traceback(
    tmp_path: Path,
) -> None:
    """A Japanese operation name on a cp1252 output (a Windows console or pipe) raised
    UnicodeEncodeError (exit 1)."""
    program = tmp_path / "op.cl"
    program.write_text(
        "UNITS/MM\nTOOL PATH/荒加工_ÉBAUCHE,TOOL,T1\nGOTO/0,0,0,0,0,1\nGOTO/10,0,0,0,0,1\nFINI\n",
        encoding="utf-8",
    )
    env = {**os.environ, "PYTHONIOENCODING": "cp1252"}
    command = [sys.executable, "-m", "service.cli", "import", str(program)]
    done = subprocess.run(command, capture_output=True, cwd=ROOT, env=env, timeout=120)
    assert done.returncode == OK, done.stderr[-400:]
    assert "\\u8352\\u52a0\\u5de5_\xc9BAUCHE".encode("cp1252") in done.stdout
    # --json: JSON on any output (its escapes; the output's own, \U0001f527, are not JSON's)
    program.write_text(program.read_text(encoding="utf-8").replace(",TOOL", "\U0001f527,TOOL"))
    as_json = subprocess.run(
        [*command, "--json"], capture_output=True, cwd=ROOT, env=env, timeout=120
    )
    assert as_json.returncode == OK, as_json.stderr[-400:]
    assert as_json.stdout.isascii()
    assert json.loads(as_json.stdout)["pass_details"][0]["operation"] == "荒加工_ÉBAUCHE\U0001f527"


@pytest.mark.parametrize("where", ["the program", "a missing folder", "a folder"])
def test_a_png_that_cannot_be_written_is_refused_before_the_map(
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    where: str,
) -> None:
    """--png naming the program overwrote it with the picture; an unwritable one was found
    after the whole map, its error naming no option. Refused on --png before any work."""
    program = tmp_path / "program.cls"
    program.write_bytes(PROGRAM.read_bytes())
    png = {"the program": program, "a missing folder": tmp_path / "no" / "m.png"}.get(
        where, tmp_path
    )

    def no_work(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("the map was computed")

    monkeypatch.setattr("service.cli.computed_map", no_work)
    code, _, err = run(capsys, "map", str(program), *MAP[2:], "--png", str(png))
    assert code == INVALID and err.startswith("error: --png: "), err
    assert program.read_bytes() == PROGRAM.read_bytes()


def test_optimise_checks_the_programs_feed_at_the_optimum_as_evaluate_does(
    client: TestClient, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """A program at 5 m/s was optimised with no feed check (exit 0, feed_check null) where
    /v1/evaluate at the optimum says it does not run (cam.md section 7; api.md: optimize's
    evaluation is as /v1/evaluate's)."""
    source = (ROOT / "examples" / "cam" / "sweep_mm.cl").read_text()
    fast = re.sub(r"FEDRAT/MMPM, *[0-9.]+", "FEDRAT/MMPM, 300000.0", source)
    assert fast != source
    program = _text_file(tmp_path, "fast.cl", fast)
    fixed = ["--x=0.0:0.0", "--y", "0.45:0.45", "--yaw=0:0"]
    code, out, _ = run(capsys, "optimise", program, "--robot", "ur5e", *fixed, "--json")
    answer = json.loads(out)
    at = answer["placement"]
    placement = {k: at[k] for k in ("x", "y", "z", "yaw")}
    body = {"robot": ROBOT, "path": {"cl_data": fast}, "placement": placement}
    evaluated = api(client, "/v1/evaluate", body)
    assert evaluated["feed_check"]["feasible"] is False
    assert answer["evaluation"]["feed_check"] == evaluated["feed_check"]
    assert code == INFEASIBLE


def test_files_that_are_missing_huge_or_folders_are_named_on_their_option(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """A missing --robot x.json read as a catalogue name ('unknown robot'); a missing --cell or
    program was a bare '[Errno 2]'; /dev/zero was read until memory ran out (exit 1)."""
    huge = tmp_path / "huge.cl"
    with huge.open("wb") as stream:  # sparse: 9 MB of zeros, none written
        stream.truncate(9_000_000)
    cases = [
        (["import", str(tmp_path / "none.cl")], "program: no file"),
        (["import", str(tmp_path)], "program: "),
        (["import", str(huge)], "program: "),
        ([*MAP[:2], "--robot", str(tmp_path / "arm.json"), *MAP[4:], "--png", "m.png"], "--robot"),
        (
            [*MAP, "--png", str(tmp_path / "m.png"), "--cell", str(tmp_path / "c.json")],
            "cell (--cell): no",
        ),
    ]
    for argv, said in cases:
        code, _, err = run(capsys, *argv)
        assert code == INVALID and err.startswith(f"error: {said}"), (argv, err)
    assert "is longer than 8,000,000 bytes" in run(capsys, "import", str(huge))[2]


def test_options_that_would_be_ignored_are_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """--arc-tolerance on a CSV (no arcs: even -1 was taken) and an empty --base-frame (read as
    not given) did nothing, exit 0."""
    csv = _text_file(tmp_path, "p.csv", "0,0,0,0,0,1\n10,0,0,0,0,1\n")
    code, _, err = run(capsys, "import", csv, "--units", "mm", "--arc-tolerance", "1e-5")
    assert code == INVALID and err.startswith("error: --arc-tolerance: "), err
    urdf = str(example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf")
    at = ["--at=0.4,0.1,0,0"]
    code, _, err = run(capsys, "evaluate", str(PROGRAM), "--robot", urdf, "--base-frame", "", *at)
    assert code == INVALID and err.startswith("error: --base-frame: is empty"), err


def test_a_bad_setting_is_named_by_its_variable(tmp_path: Path) -> None:
    env = {**os.environ, "DTF_THREADS": "0"}
    command = [sys.executable, "-m", "service.cli", "import", str(PROGRAM)]
    done = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, env=env, timeout=120)
    assert done.returncode == SETTINGS  # the installation's, not the program's: not INVALID
    assert done.stderr.startswith("error: DTF_THREADS='0': Input should be greater than 0")


def test_the_joint_step_and_blend_length_reach_the_request(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The command line had no option for either (a post-processor could not ask for a finer
    step or another blend): each is the API's answer to the body with it, and changes it."""
    robot = {"model": "ur5e", "joint_acceleration_limits": [2.0] * 6}
    file = _file(tmp_path, "robot.json", robot)
    argv = ["evaluate", str(PROGRAM), "--robot", file, "--at=0,0.3,0,0", "--json"]
    body = {"robot": robot, "path": {"cl_data": PROGRAM.read_text()}, "placement": AT}
    body["detail"] = "summary"
    plain = api(client, "/v1/evaluate", body)
    code, out, _ = run(capsys, *argv, "--blend-length", "0.01")
    blended = api(client, "/v1/evaluate", {**body, "ik": {"blend_length": 0.01}})
    assert code == OK and json.loads(out) == blended
    assert blended["acceleration"]["mu_acc"] != plain["acceleration"]["mu_acc"]
    code, out, _ = run(capsys, *argv, "--max-joint-step", "0.001")
    stepped = api(client, "/v1/evaluate", {**body, "ik": {"max_joint_step": 0.001}})
    assert code == INFEASIBLE and json.loads(out) == stepped
    assert plain["feasible"] and stepped["reason"] == "discontinuous"


def test_a_normalised_quaternion_is_said(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A tcp quaternion 2e-4 off unit is normalised: the text said nothing of it."""
    robot = {"model": "ur5e", "tcp": {"position": [0, 0, 0.1], "orientation": [0, 0, 0, 0.9998]}}
    file = _file(tmp_path, "robot.json", robot)
    for argv in (
        ["evaluate", str(PROGRAM), "--robot", file, "--at=0,0.3,0,0"],
        [*MAP, "--robot", file, "--png", str(tmp_path / "map.png")],
    ):
        _, out, _ = run(capsys, *argv)
        assert (
            "normalised: the request's tool axes or quaternions, largest correction 2.0e-04" in out
        )
    _, out, _ = run(capsys, "evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0")
    assert "normalised" not in out


def test_optimise_starts_from_the_placement_given(
    client: TestClient, capsys: pytest.CaptureFixture[str]
) -> None:
    """The command line had no --start: the gain was over the box's centre, not over where the
    part is now. The answer is the API's for the body with that start (a negative value after a
    space, as --at takes it), its start is that placement, and one outside the box is refused
    naming start."""
    argv = [
        "optimise", str(PROGRAM), "--robot", "ur5e", "--x=-0.1:0.1", "--y", "0.25:0.35",
        "--yaw=-0.5:0.5", "--method", "casadi", "--json",
    ]  # fmt: skip
    code, out, _ = run(capsys, *argv, "--start", "-0.05,0.3,0,0.2")
    assert code == OK
    mine = json.loads(out)
    start = {"x": -0.05, "y": 0.3, "z": 0.0, "yaw": 0.2}
    bounds = {"x": [-0.1, 0.1], "y": [0.25, 0.35], "yaw": [-0.5, 0.5]}
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM.read_text()}, "bounds": bounds, "z": 0.0}
    theirs = api(client, "/v1/optimize", {**body, "start": start})
    for answer in (mine, theirs):
        answer["solver"].pop("seconds")
    assert mine == theirs
    assert {k: mine["start"]["placement"][k] for k in start} == start
    code, _, err = run(capsys, *argv, "--start=0.5,0.3,0,0")
    assert code == INVALID and "start" in err


def test_the_help_lists_every_exit_code(capsys: pytest.CaptureFixture[str]) -> None:
    """A post-processor's author reads the codes there: 6 (a DTF_ variable refused) was missing
    from it (the upgrade audit of stop 62)."""
    with pytest.raises(SystemExit) as ended:
        main(["--help"])
    assert ended.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    codes = (OK, INFEASIBLE, USAGE, INVALID, NOT_WRITTEN, SETTINGS, CUT, INTERRUPTED, CLOSED_PIPE)
    for code in (*codes, TERMINATED):
        assert re.search(rf"\b{code} [a-z]", text), code


@pytest.mark.parametrize(
    ("option", "field"),
    [("--max-joint-step", "ik.max_joint_step"), ("--blend-length", "ik.blend_length")],
)
def test_an_ik_option_refused_is_named_as_itself(
    capsys: pytest.CaptureFixture[str], option: str, field: str
) -> None:
    """Both were named --branch, the first option of the request's ``ik`` (audit 23)."""
    at = ["evaluate", str(PROGRAM), "--robot", "ur5e", "--at=0,0.3,0,0"]
    code, _, err = run(capsys, *at, option, "0")
    assert code == INVALID and err.startswith(f"error: {field} ({option}): "), err
