"""``found: false`` says why; a failed waypoint of a CAM program names its pass and operation.

Two searches no placement inside the bounds can win: bounds 5 m from a UR5e's base (0.85 m of
reach: its first waypoint is out of reach from every placement), and a CL program whose second
operation turns the horizontal tool axis three times about the vertical (a rotary table's
work: no arm follows it). The pass each waypoint belongs to is known from how the program is
written here, and the first operation alone runs at the same placement.
"""

from __future__ import annotations

import json
import math
import re
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.cli import INFEASIBLE, main
from tests.cases import ROOT

ROBOT = {"model": "ur5e"}
FLAT = 21  # waypoints of the first operation
AT = {"x": 0.0, "y": 0.4, "z": 0.1, "yaw": 0.0}
BOUNDS = {"bounds": {"x": [-0.3, 0.3], "y": [0.2, 0.6], "yaw": [-3.14, 3.14]}, "z": 0.1}
FAR = {"bounds": {"x": [5.0, 5.1], "y": [5.0, 5.1], "yaw": [-0.5, 0.5]}, "z": 0.0}
POSES = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())["path"]


def program(*, rotary: bool = True) -> str:
    """FLAT_PASS: a straight 100 mm cut, tool vertical; ROTARY_SPIN: the axis horizontal,
    pointing out of a 30 mm circle it goes round three times, 10 degrees a step."""
    lines = ["UNITS/MM", "MULTAX/ON", "TOOL PATH/FLAT_PASS,TOOL,MILL_6", "FEDRAT/MMPM,1000"]
    lines += [f"GOTO/{-50 + 5 * k:.4f},0.0,0.0,0.0,0.0,1.0" for k in range(FLAT)]
    lines.append("END-OF-PATH")
    if rotary:
        lines += ["TOOL PATH/ROTARY_SPIN,TOOL,MILL_6", "FEDRAT/MMPM,1000"]
        for k in range(3 * 36 + 1):
            c, s = math.cos(math.radians(10 * k)), math.sin(math.radians(10 * k))
            lines.append(f"GOTO/{30 * c:.4f},{30 * s:.4f},-20.0,{c:.7f},{s:.7f},0.0")
        lines.append("END-OF-PATH")
    return "\n".join(lines) + "\n"


def post(client: TestClient, route: str, body: dict[str, Any]) -> dict[str, Any]:
    answer = client.post(route, json={"robot": ROBOT, **body})
    assert answer.status_code == 200, answer.text
    result: dict[str, Any] = answer.json()
    return result


def test_bounds_out_of_reach_say_unreachable_at_the_first_waypoint(client: TestClient) -> None:
    answer = post(client, "/v1/optimize", {"path": POSES, **FAR})
    assert not answer["found"]
    failure = answer["failure"]
    assert (failure["reason"], failure["failed_waypoint"]) == ("unreachable", 0)
    assert failure["count"] == failure["judged"] >= 1
    assert (failure["failed_pass"], failure["failed_operation"]) == (None, None)  # poses
    assert failure["judged"] == 1  # the coarse map has no placement to propose: the start alone
    # Every placement its coarse map tried is 5 m from a 0.85 m arm: out of reach at once.
    tried = failure["tried"]
    n = tried["placements"]
    assert n > 1 and tried["feasible"] == 0
    assert tried["reasons"] == [
        {
            "reason": "unreachable",
            "count": n,
            "failed_waypoint": 0,
            "failed_pass": None,
            "failed_operation": None,
        }
    ]
    assert failure["message"] == (
        "the search proposed no placement but the start, and the start does not run it: "
        f"unreachable, first at waypoint 0; none of the {n} placements it tried on the whole "
        f"path runs it: {n} unreachable, most often first at waypoint 0"
    )
    start = answer["start"]
    assert (start["mu_path"], start["reason"], start["failed_waypoint"]) == (
        None,
        "unreachable",
        0,
    )


@pytest.mark.parametrize("method", ["casadi", "scipy"])
def test_a_rotary_table_operation_is_named_as_why_nothing_is_found(
    client: TestClient, method: str
) -> None:
    body = {"path": {"cl_data": program()}, **BOUNDS, "method": method}
    answer = post(client, "/v1/optimize", body)
    assert not answer["found"] and answer["solver"]["status"].startswith("no feasible")
    failure = answer["failure"]
    assert failure["failed_waypoint"] >= FLAT  # in the second operation
    assert (failure["failed_pass"], failure["failed_operation"]) == (1, "ROTARY_SPIN")
    assert "(pass 1, ROTARY_SPIN)" in failure["message"]
    # What the search tried (its coarse map, its evolution) fails in the rotary operation too,
    # each reason most often there; the sentence says it, most common first.
    tried = failure["tried"]
    assert tried["feasible"] == 0
    counts = [r["count"] for r in tried["reasons"]]
    assert sum(counts) == tried["placements"] > 1 and counts == sorted(counts, reverse=True)
    for r in tried["reasons"]:
        assert r["failed_waypoint"] >= FLAT
        assert (r["failed_pass"], r["failed_operation"]) == (1, "ROTARY_SPIN")
        assert (
            f"{r['count']} {r['reason']}, most often first at waypoint {r['failed_waypoint']} "
            "(pass 1, ROTARY_SPIN)" in failure["message"]
        )
    assert answer["start"]["reason"] is not None and answer["start"]["failed_waypoint"] >= FLAT
    alone = post(
        client, "/v1/evaluate", {"path": {"cl_data": program(rotary=False)}, "placement": AT}
    )
    assert alone["feasible"]  # the first operation runs: the rotary one is why


def test_evaluate_names_the_pass_and_operation_of_the_failed_waypoint(
    client: TestClient,
) -> None:
    answer = post(client, "/v1/evaluate", {"path": {"cl_data": program()}, "placement": AT})
    assert not answer["feasible"] and answer["failed_waypoint"] >= FLAT
    assert (answer["failed_pass"], answer["failed_operation"]) == (1, "ROTARY_SPIN")
    far = post(client, "/v1/evaluate", {"path": POSES, "placement": {**AT, "x": 5.0}})
    assert (far["reason"], far["failed_pass"], far["failed_operation"]) == (
        "unreachable",
        None,
        None,
    )


def test_a_found_optimum_has_no_failure(client: TestClient) -> None:
    body = {"path": {"cl_data": program(rotary=False)}, **BOUNDS}
    answer = post(client, "/v1/optimize", body)
    assert answer["found"] and answer["failure"] is None
    assert answer["start"]["reason"] is None and answer["start"]["failed_waypoint"] is None


def test_the_cli_says_why(tmp_path: Any, capsys: pytest.CaptureFixture[str]) -> None:
    file = tmp_path / "rotary.cl"
    file.write_text(program())
    code = main(["evaluate", str(file), "--robot", "ur5e", "--at=0,0.4,0.1,0"])
    out = capsys.readouterr().out
    said = re.search(r"\(line (\d+), pass 1, ROTARY_SPIN\)$", out.splitlines()[-1])
    assert code == INFEASIBLE and said is not None  # the line of a GOTO of that pass
    assert program().splitlines()[int(said.group(1)) - 1].startswith("GOTO")
    code = main(
        ["optimise", str(file), "--robot", "ur5e", "--x=-0.3:0.3", "--y=0.2:0.6", "--z=0.1"]
    )
    out = capsys.readouterr().out
    assert code == INFEASIBLE
    last = out.splitlines()[-1]
    assert last.startswith("no feasible placement inside the bounds: the search proposed no")
    assert "ROTARY_SPIN" in last
