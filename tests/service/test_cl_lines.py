"""Each waypoint of a CL program leads back to its line (audit 25: a failed or limiting waypoint
could not be found in the program; arcs and dropped points make its index no GOTO's count).

The expected lines come from a regex reading of the program written here: its cutting GOTOs
in order (a rapid's target and a GOTO to where the tool is are no waypoint), each at the
coordinates it states, and the CIRCLE's line for the arc's inner points.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.cli import OK
from tests.service.test_cli import run

PROGRAM = """$$ each waypoint's line
PARTNO LINES
UNITS/MM
MULTAX/ON
RAPID
GOTO/0, 400, 100, 0, 0, 1
FEDRAT/MMPM, 600
GOTO/0, 400, 50, 0, 0, 1
GOTO/20, 400, 50, 0, 0, 1
GOTO/20, 400, 50, 0, 0, 1
CIRCLE/20, 420, 50, 0, 0, 1, 20
GOTO/40, 420, 50, $
     0, 0, 1
GOTO/40, 460, 50, 0, 0, 1
RAPID
GOTO/40, 460, 100, 0, 0, 1
GOTO/60, 460, 50, 0, 0, 1
GOTO/80, 460, 50, 0, 0, 1
FINI
"""
ROBOT = {"model": "ur5"}
PLACEMENT = {"x": 0.0, "y": 0.0, "z": 0.0, "yaw": 0.0}


def cutting_gotos(text: str) -> list[tuple[int, np.ndarray]]:
    """The program's cutting GOTOs, by a regex: (line, position in m), in order."""
    found: list[tuple[int, np.ndarray]] = []
    rapid = False
    lines = text.splitlines()
    for number, line in enumerate(lines, start=1):
        if line.startswith("RAPID"):
            rapid = True
        match = re.match(r"GOTO/([^$]*)(\$?)", line)
        if match is None:
            continue
        values = match.group(1) + (lines[number] if match.group(2) else "")
        position = np.array([float(v) for v in values.split(",")[:3]]) / 1000.0
        if rapid:
            rapid = False
        elif not found or not np.array_equal(found[-1][1], position):
            found.append((number, position))
    return found


def test_the_import_gives_each_waypoints_line(client: TestClient) -> None:
    answer = client.post("/v1/paths/import", json={"path": {"cl_data": PROGRAM}})
    assert answer.status_code == 200, answer.text
    read = answer.json()
    lines = read["lines"]
    assert len(lines) == len(read["waypoints"])
    gotos = cutting_gotos(PROGRAM)
    circle = next(n for n, text in enumerate(PROGRAM.splitlines(), 1) if text.startswith("CIRCLE"))
    inner = [k for k, line in enumerate(lines) if line == circle]
    assert inner and read["arcs"] == 1  # the arc's inner points, between its start and end
    assert [line for line in lines if line != circle] == [line for line, _ in gotos]
    positions = np.array([w["position"] for w in read["waypoints"]])
    for line, position in gotos:
        np.testing.assert_allclose(positions[lines.index(line)], position, atol=1e-12)
    assert inner == list(range(inner[0], inner[-1] + 1))
    assert lines[inner[0] - 1] < circle < lines[inner[-1] + 1]
    # poses have no lines
    poses = [
        {"position": w["position"], "orientation": w["orientation"]} for w in read["waypoints"]
    ]
    assert (
        client.post("/v1/paths/import", json={"path": {"waypoints": poses}}).json()["lines"] is None
    )


def test_a_failed_and_a_limiting_waypoint_name_their_lines(
    client: TestClient, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    body = {"robot": ROBOT, "path": {"cl_data": PROGRAM}, "placement": PLACEMENT}
    answer = client.post("/v1/evaluate", json=body).json()
    assert answer["feasible"], answer["reason"]
    lines = client.post("/v1/paths/import", json={"path": body["path"]}).json()["lines"]
    bottleneck = answer["bottleneck"]
    assert bottleneck["line"] == lines[bottleneck["waypoint"]]
    far = PROGRAM.replace("GOTO/80, 460, 50", "GOTO/2000, 460, 50")
    failed = client.post("/v1/evaluate", json={**body, "path": {"cl_data": far}}).json()
    (last, _) = cutting_gotos(far)[-1]
    assert failed["reason"] == "unreachable"
    assert failed["failed_line"] == last and PROGRAM.splitlines()[last - 1].startswith("GOTO/80")
    assert failed["failed_pass"] == 1
    program = tmp_path / "far.cl"
    program.write_text(far)
    code, out, _ = run(capsys, "evaluate", str(program), "--robot", "ur5", "--at=0,0,0,0")
    assert code != OK
    assert f"at waypoint {failed['failed_waypoint']} (line {last}, pass 1, LINES)" in out
