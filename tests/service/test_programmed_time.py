"""How long a program runs as programmed: each pass's way and time at its FEDRATs (audit 25:
a post-processor's first question, "how long does the program as written take", had no answer).

The expected figures come from a regex reading of a program written here: each cutting move's
length from the GOTOs' coordinates, at the FEDRAT in force when its GOTO is read (APT's modal
feed), a pass starting at a rapid's target.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.cli import OK
from tests.service.test_cli import run

PROGRAM = """UNITS/MM
MULTAX/ON
RAPID
GOTO/0, 400, 100, 0, 0, 1
FEDRAT/MMPM, 600
GOTO/0, 400, 50, 0, 0, 1
GOTO/30, 400, 50, 0, 0, 1
GOTO/30, 440, 50, 0, 0, 1
FEDRAT/MMPM, 1200
GOTO/60, 440, 50, 0, 0, 1
GOTO/60, 440, 50, 0.1, 0, 0.995
RAPID
GOTO/60, 440, 100, 0, 0, 1
GOTO/80, 440, 50, 0, 0, 1
FEDRAT/MMPM, 300
GOTO/80, 480, 47, 0, 0, 1
FINI
"""


def passes_by_regex(text: str) -> list[tuple[float, float]]:
    """Each pass's (length in m, time in s): its moves at the feed in force at their GOTO.

    A pass starts at the first GOTO after a rapid's target: the move into it is no pass's.
    """
    passes: list[tuple[float, float]] = []
    feed: float | None = None
    rapid = False
    last: np.ndarray | None = None
    for line in text.splitlines():
        if match := re.match(r"FEDRAT/MMPM,\s*([\d.]+)", line):
            feed = float(match.group(1)) / 60.0 / 1000.0  # m/s
        elif line.startswith("RAPID"):
            rapid = True
        elif match := re.match(r"GOTO/(.*)", line):
            point = np.array([float(v) for v in match.group(1).split(",")[:3]]) / 1000.0
            if rapid:  # a rapid's target: the GOTO after it starts a pass
                rapid, last = False, None
                continue
            if last is None:
                passes.append((0.0, 0.0))
                last = point
                continue
            assert last is not None and feed is not None
            move = float(np.linalg.norm(point - last))
            length, time = passes[-1]
            passes[-1] = (length + move, time + move / feed)
            last = point
    return passes


def test_each_pass_says_its_way_and_its_time_as_programmed(client: TestClient) -> None:
    answer = client.post("/v1/paths/import", json={"path": {"cl_data": PROGRAM}})
    assert answer.status_code == 200, answer.text
    details = answer.json()["pass_details"]
    expected = passes_by_regex(PROGRAM)
    assert len(details) == len(expected) == 2
    for part, (length, time) in zip(details, expected, strict=True):
        assert part["length"] == pytest.approx(length, rel=1e-12)
        assert part["time"] == pytest.approx(time, rel=1e-12)
    assert expected[0] == pytest.approx((0.1, 3.0 + 4.0 + 1.5))  # the turn in place: 0
    body = {"robot": {"model": "ur5"}, "path": {"cl_data": PROGRAM}}
    evaluated = client.post(
        "/v1/evaluate", json={**body, "placement": {"x": 0, "y": 0, "z": 0, "yaw": 0}}
    )
    assert evaluated.json()["path_read"]["pass_details"] == details
    poses = [
        {"position": w["position"], "orientation": w["orientation"]}
        for w in answer.json()["waypoints"]
    ]
    (plain,) = client.post("/v1/paths/import", json={"path": {"waypoints": poses}}).json()[
        "pass_details"
    ]
    assert plain["time"] is None and plain["length"] > sum(length for length, _ in expected)


def test_the_import_prints_the_cutting_time(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    program = tmp_path / "timed.cl"
    program.write_text(PROGRAM)
    code, out, _ = run(capsys, "import", str(program))
    total = sum(time for _, time in passes_by_regex(PROGRAM))
    assert code == OK
    assert f"cutting time: {total:.1f} s at the programmed feeds (" in out
