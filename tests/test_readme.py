"""The README's commands are what CI runs, and its worked example prints what the app answers."""

from __future__ import annotations

import importlib
import json
import re
import sys
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from service.cli import OK, main
from service.main import app
from tests.cases import EXAMPLES, ROOT

README = (ROOT / "README.md").read_text()


def _quick_start_commands() -> list[str]:
    block = README.split("## Quick start", 1)[1].split("```sh", 1)[1].split("```", 1)[0]
    return [line for line in block.splitlines() if line and not line.startswith("#")]


def test_quick_start_is_two_commands_and_ci_runs_the_test_one() -> None:
    commands = _quick_start_commands()
    assert len(commands) == 2
    assert "uvicorn service.main:app --host 127.0.0.1 --port 8000" in commands[0]
    ci_lines = (ROOT / ".ci" / "run").read_text().splitlines()
    assert commands[1] in ci_lines


def test_worked_example_output() -> None:
    example = README.split("## Worked example", 1)[1]
    printed = re.search(r"prints\n\n```\n(.*)\n```", example).group(1)
    request = json.loads((EXAMPLES / "evaluate_request.json").read_text())
    r = TestClient(app).post("/v1/evaluate", json=request).json()
    expected = (
        f"mu_path = {r['mu_path']:.6f} m/s, limited by {r['bottleneck']['joint_name']} "
        f"at waypoint {r['bottleneck']['waypoint']}"
    )
    assert printed == expected
    assert "@examples/evaluate_request.json" in example


def _example_lines(heading: str, module: str) -> tuple[list[str], list[str]]:
    """What the README says an example prints under ``heading``, and what it prints."""
    section = README.split(heading, 1)[1]
    printed = re.search(r"prints\n\n```\n(.*?)\n```", section, re.S).group(1)
    assert f"python3 examples/{module}.py" in section
    sys.path.insert(0, str(EXAMPLES))
    try:
        example = importlib.import_module(module)
    finally:
        sys.path.remove(str(EXAMPLES))
    client = TestClient(app)

    def post(route: str, body: dict) -> dict:
        response = client.post(route, json=body)
        assert response.status_code == 200, response.text
        return response.json()

    return printed.splitlines(), example.lines(post)


def test_five_axis_example_output() -> None:
    printed, lines = _example_lines("## Five-axis: let the tool spin", "five_axis")
    assert printed == lines


def test_cam_example_output() -> None:
    printed, lines = _example_lines(
        "## CAM programs: from a CL file to the controller", "cam_program"
    )
    assert printed == lines


def test_cam_command_line_output(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """The NX listing through ``dtf-place``: the README shows what the commands print.

    A picture the README writes (``--png /tmp/...``) is written to the test's own folder
    instead, its name put back in what is compared: the README's file is one fixed path, which
    a run by another account could not write (owned by the account that ran the tests first:
    exit 3, "cannot be written (permissions)", stop 76) and which two runs at once shared.
    """
    section = README.split("### CL files as CAM systems write them", 1)[1]
    block = section.split("```sh\n", 1)[1].split("```", 1)[0]
    commands = [line.split() for line in block.splitlines() if line]
    printed = re.search(r"print\n\n```\n(.*?)\n```", section, re.S).group(1)
    assert all(command[0] == "dtf-place" for command in commands)
    pictures: dict[str, str] = {}  # the test's file: the README's
    for command in commands:
        if "--png" in command:
            at = command.index("--png") + 1
            ours = str(tmp_path / Path(command[at]).name)
            pictures[ours], command[at] = command[at], ours
        assert main(command[1:]) == OK
    out = capsys.readouterr().out
    for ours, theirs in pictures.items():
        assert Path(ours).read_bytes().startswith(b"\x89PNG")
        out = out.replace(ours, theirs)
    assert pictures and out.rstrip("\n") == printed


def test_acceleration_example_output() -> None:
    printed, lines = _example_lines(
        "## Joint accelerations: the feed the arm can really run", "accelerations"
    )
    assert printed == lines


def test_cell_example_output() -> None:
    printed, lines = _example_lines("## The cell: placements that hit nothing", "cell")
    assert printed == lines


def test_the_work_weights_the_readme_names_are_the_codes() -> None:
    """The README said free-spin maps with an angled tool weigh 30 closed-form poses a pose after
    the code had made it 12 (found by a reading of the README against the code, stop 57)."""
    from solver.path.problem import EXACT_SPIN_COST

    (weight,) = re.findall(r"such maps weigh (\d+) closed-form poses a pose", README)
    assert float(weight) == EXACT_SPIN_COST


def test_every_route_is_named_in_the_readme() -> None:
    """Each operation of the app, as `METHOD /path` (`{id}` for a job's id; `/v1/jobs[/{id}]`
    names the listing and one job): a route added without a word in the README fails here."""
    named = set()
    for method, path in re.findall(r"`(GET|POST|PUT|PATCH|DELETE) (/[^`\s]*)`", README):
        named |= {(method, re.sub(r"\[.*?\]", "", path)), (method, re.sub(r"[\[\]]", "", path))}
    operations = {
        (method.upper(), path.replace("{job_id}", "{id}"))
        for path, methods in app.openapi()["paths"].items()
        for method in methods
    }
    assert operations - named == set()


def test_the_settings_table_lists_every_setting_with_its_default() -> None:
    """Read from README's table (a regex) against the settings' own fields: operators found
    five limits (DTF_MAX_MAP_CELLS, DTF_MAX_SOLVER_SECONDS...) named nowhere but the code
    (operator audit of 2026-12-07, L1)."""
    from service.config import Settings

    table = README.split("### Settings", 1)[1].split("### Upgrading", 1)[0]
    shown = dict(re.findall(r"^\| `DTF_(\w+)` \| ([^|]+?) \|", table, flags=re.MULTILINE))
    fields = Settings.model_fields
    assert sorted(shown) == sorted(name.upper() for name in fields)
    for name, field in fields.items():
        said = shown[name.upper()]
        if field.default_factory is not None:
            assert said == "the core count", name
        elif field.default is None or field.default == ():  # nothing set: an empty list too
            assert said == "none", name
        elif isinstance(field.default, int | float):
            assert float(said.replace(",", "")) == field.default, name
        else:
            assert said == str(field.default), name
