"""The web page in a real browser (Debian's chromium, headless, driven by Playwright): issue 14.

A live uvicorn serves the page and the API; every figure the page shows is compared with the
API's own answer to the same body, fetched here with httpx. Each test saves a screenshot under
``tests/artifacts/`` (a CI artefact, ignored by git).
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from playwright.sync_api import Browser, Page, sync_playwright

from tests.cases import ROOT
from tests.live import start_server

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
ARTIFACTS = ROOT / "tests" / "artifacts"
EXAMPLE_PATH = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())["path"]
SMALL = {
    "x-min": "-0.1",
    "x-max": "0.1",
    "x-step": "0.05",
    "y-min": "0.3",
    "y-max": "0.5",
    "y-step": "0.05",
    "z": "0.1",
    "yaws": "0, 1.5",
    "spins": "0",
}


@pytest.fixture(scope="module")
def url(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    env = {
        "DTF_DATA_DIR": str(tmp_path_factory.mktemp("web-jobs")),
        "DTF_WORKERS": "1",
        "DTF_MAX_JOB_CELLS": "2000000",
        "DTF_MAX_JOB_POSES": "500000000",
    }
    process, url = start_server(env, "--timeout-graceful-shutdown", "2")
    yield url
    process.terminate()
    process.wait()


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    if not Path(CHROMIUM).exists():
        pytest.fail(f"no chromium at {CHROMIUM}: .ci/run installs it with apt-get")
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, headless=True)
        yield browser
        browser.close()


@pytest.fixture
def page(browser: Browser, url: str, request: pytest.FixtureRequest) -> Iterator[Page]:
    page = browser.new_page(viewport={"width": 1400, "height": 1600})
    page.goto(url + "/")
    page.wait_for_selector("body[data-ready='1']", timeout=30_000)
    yield page
    ARTIFACTS.mkdir(exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / f"web-{request.node.name}.png"), full_page=True)
    page.close()


def fill(page: Page, values: dict[str, str]) -> None:
    for field, value in values.items():
        page.fill(f"#{field}", value)


def grid_of(values: dict[str, str]) -> dict[str, Any]:
    axis = lambda n: {k: float(values[f"{n}-{k}"]) for k in ("min", "max", "step")}  # noqa: E731
    return {
        "x": axis("x"),
        "y": axis("y"),
        "z": float(values["z"]),
        "yaw": [float(v) for v in values["yaws"].split(",")],
        "spin": [0.0],
    }


def run_small_map(page: Page, url: str) -> dict[str, Any]:
    """Run the small map from the page; the API's map of the same body."""
    assert page.input_value("#robot-model") == "ur5"
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    body = {"robot": {"model": "ur5"}, "path": EXAMPLE_PATH, "grid": grid_of(SMALL)}
    answer = httpx.post(f"{url}/v1/map", json=body, timeout=60)
    assert answer.status_code == 200, answer.text
    return answer.json()


def cell_point(
    page: Page, panel: int, cell: dict[str, Any], api: dict[str, Any]
) -> dict[str, float]:
    """Where a cell of a panel is on the screen."""
    xs = sorted({c["x"] for c in api["cells"]})
    ys = sorted({c["y"] for c in api["cells"]})
    canvas = page.locator(".panel canvas").nth(panel)
    size = int(canvas.get_attribute("data-cell") or 0)
    box = canvas.bounding_box()
    assert box is not None
    i, j = xs.index(cell["x"]), ys.index(cell["y"])
    return {"x": box["x"] + (i + 0.5) * size, "y": box["y"] + (len(ys) - 1 - j + 0.5) * size}


def test_a_small_map_shows_the_apis_cells_and_best(page: Page, url: str) -> None:
    api = run_small_map(page, url)
    assert page.get_attribute("#summary", "data-cells") == str(len(api["cells"]))
    assert page.locator(".panel canvas").count() == 2  # one panel per yaw
    assert page.text_content("#best-mu") == f"{api['best']['mu_path']:.6f} m/s"
    assert page.input_value("#limits input >> nth=0") == "3.15"  # the ur5's limits, shown


def test_hover_and_click_a_cell_plot_its_speeds(page: Page, url: str) -> None:
    api = run_small_map(page, url)
    per_panel = len(api["cells"]) // 2
    cell = next(c for c in api["cells"][:per_panel] if c["mu_path"] is not None)
    point = cell_point(page, 0, cell, api)
    page.mouse.move(point["x"], point["y"])
    tooltip = page.text_content("#tooltip") or ""
    assert f"mu_path {cell['mu_path']:.6f} m/s" in tooltip
    assert (
        f"joint {cell['bottleneck_joint'] + 1}, waypoint {cell['bottleneck_waypoint']}" in tooltip
    )
    page.mouse.click(point["x"], point["y"])
    page.wait_for_selector("#plot[data-drawn='1']", timeout=30_000)
    placement = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"], "spin": 0.0}
    evaluation = httpx.post(
        f"{url}/v1/evaluate",
        json={"robot": {"model": "ur5"}, "path": EXAMPLE_PATH, "placement": placement},
        timeout=60,
    ).json()
    bottleneck = evaluation["bottleneck"]
    assert page.get_attribute("#bottleneck", "data-waypoint") == str(bottleneck["waypoint"])
    assert page.get_attribute("#bottleneck", "data-joint") == str(bottleneck["joint"])
    assert bottleneck["joint_name"] in (page.text_content("#bottleneck") or "")


def test_a_large_map_is_cancelled_from_the_page(page: Page, url: str) -> None:
    fill(
        page,
        {
            **SMALL,
            "x-min": "-0.5",
            "x-max": "0.5",
            "x-step": "0.004",
            "y-min": "0.0",
            "y-max": "0.8",
            "y-step": "0.004",
        },
    )
    page.click("#run")
    page.wait_for_function("document.getElementById('bar').value > 0", timeout=60_000)
    assert "left" in (page.text_content("#eta") or "")
    page.click("#cancel")
    page.wait_for_function(
        "document.getElementById('job-status').textContent.startsWith('cancelled')",
        timeout=10_000,
    )
    jobs = httpx.get(f"{url}/v1/jobs", params={"limit": 1}).json()["jobs"]
    assert jobs[0]["status"] == "cancelled"


def test_optimise_marks_the_apis_optimum(page: Page, url: str) -> None:
    run_small_map(page, url)
    page.click("#optimize")
    page.wait_for_selector(".panel canvas[data-optimum='1']", timeout=120_000)
    grid = grid_of(SMALL)
    body = {
        "robot": {"model": "ur5"},
        "path": EXAMPLE_PATH,
        "method": "casadi",
        "z": 0.1,
        "bounds": {"x": [-0.1, 0.1], "y": [0.3, 0.5], "yaw": [0.0, 1.5]},
    }
    assert grid["yaw"] == [0.0, 1.5]
    api = httpx.post(f"{url}/v1/optimize", json=body, timeout=120).json()
    assert page.text_content("#opt-mu") == f"{api['mu_path']:.6f} m/s"
    assert "kuka" in (page.text_content("#frames") or "")


def test_a_zero_step_shows_the_apis_error_beside_the_field(page: Page, url: str) -> None:
    fill(page, {**SMALL, "x-step": "0"})
    page.click("#run")
    error = page.locator(".field[data-loc='grid.x.step'] .error")
    error.wait_for(timeout=10_000)
    page.wait_for_function(
        "document.querySelector(\".field[data-loc='grid.x.step'] .error\").textContent !== ''"
    )
    body = {
        "kind": "map",
        "request": {
            "robot": {"model": "ur5"},
            "path": EXAMPLE_PATH,
            "grid": {**grid_of(SMALL), "x": {"min": -0.1, "max": 0.1, "step": 0}},
        },
    }
    api = httpx.post(f"{url}/v1/jobs", json=body).json()
    assert error.text_content() == api["detail"][0]["msg"]


def test_the_pages_examples_are_the_repositorys() -> None:
    static = ROOT / "service" / "web" / "static" / "examples"
    assert json.loads((static / "readme_path.json").read_text()) == EXAMPLE_PATH
    cl = (ROOT / "examples" / "cam" / "sweep_mm.cl").read_text()
    assert (static / "sweep_mm.cl").read_text() == cl


def test_the_page_shows_what_the_import_read(page: Page, url: str) -> None:
    """Units and how they were known, each pass's operation, the skipped records (issue 25)."""
    page.select_option("#path-example", "nx_slot_plate.cls")
    page.wait_for_function(
        "document.getElementById('import').dataset.waypoints && "
        "document.getElementById('import-units').textContent.startsWith('inches')",
        timeout=30_000,
    )
    program = (ROOT / "examples" / "cam" / "nx_slot_plate.cls").read_text()
    api = httpx.post(f"{url}/v1/paths/import", json={"path": {"cl_data": program}}).json()
    assert page.get_attribute("#import", "data-waypoints") == str(len(api["waypoints"]))
    assert page.text_content("#import-units") == (
        f"{api['units']} ({api['units_source']}: {api['units_note']})"
    )
    operations = page.locator("#import-passes tbody tr td:nth-child(3)").all_text_contents()
    assert operations == [p["operation"] for p in api["pass_details"]]
    skipped = page.locator("#import-skipped li").all_text_contents()
    assert skipped == [
        f"{s['word']}: {s['count']} (first at line {s['first_line']})"
        for s in api["skipped_records"]
    ]
    assert (ROOT / "service" / "web" / "static" / "examples" / "nx_slot_plate.cls").read_text() == (
        program
    )


def test_a_program_without_units_asks_for_them_beside_the_field(page: Page, url: str) -> None:
    page.set_input_files(
        "#path-file",
        files=[
            {"name": "bare.cl", "mimeType": "text/plain", "buffer": b"GOTO/0,0,0\nGOTO/9,0,0\n"}
        ],
    )
    error = page.locator('.field[data-loc="path.units"] .error')
    error.wait_for(state="visible", timeout=30_000)
    page.wait_for_function(
        "document.querySelector('.field[data-loc=\"path.units\"] .error').textContent",
        timeout=30_000,
    )
    assert "states no units" in (error.text_content() or "")
    page.select_option("#path-units", "mm")
    page.wait_for_function("document.getElementById('import').dataset.waypoints", timeout=30_000)
    assert (
        page.text_content("#import-units")
        == "mm (request: the request's units (the file states none))"
    )
