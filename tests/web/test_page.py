"""The web page in a real browser (Debian's chromium, headless, driven by Playwright): issue 14.

A live uvicorn serves the page and the API; every figure the page shows is compared with the
API's own answer to the same body, fetched here with httpx. Each test saves a screenshot under
``tests/artifacts/`` (a CI artefact, ignored by git).
"""

from __future__ import annotations

import json
import math
from typing import Any

import httpx
import pytest
from playwright.sync_api import Browser, Page

from tests.cases import MAP_EVALUATE_RTOL, ROOT
from tests.web.conftest import ARTIFACTS

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


def beside(field: str, detail: dict[str, Any]) -> str:
    """The text the page shows beside the field whose loc is ``field`` for an API error: the
    message, led by the part of the error's loc the field does not name ("[2]: ...")."""
    loc = [str(p) for p in detail["loc"] if p not in ("body", "request")]
    rest = loc[len(field.split(".")) :]
    text = "".join(f"[{p}]" if p.isdigit() else ("." if k else "") + p for k, p in enumerate(rest))
    return f"{text}: {detail['msg']}" if text else str(detail["msg"])


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
    canvas.scroll_into_view_if_needed()  # the mouse reaches only what the window shows
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
    # the ETA once a second progress report gives the job's rate (none at the first)
    page.wait_for_function(
        "document.getElementById('eta').textContent.includes('left')", timeout=30_000
    )
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
    assert page.locator("#frames tr[data-controller='kuka'] code").count() == 1


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
    # numbered as the API's failed_pass and messages number them (from 0), its waypoints too
    numbers = page.locator("#import-passes tbody tr td:nth-child(1)").all_text_contents()
    assert numbers == [str(k) for k in range(len(api["passes"]))]
    spans = page.locator("#import-passes tbody tr td:nth-child(2)").all_text_contents()
    assert spans == [f"{start}-{stop - 1}" for start, stop in api["passes"]]
    skipped = page.locator("#import-skipped li").all_text_contents()
    assert skipped == [
        f"{s['word']}: {s['count']} (first at line {s['first_line']})"
        for s in api["skipped_records"]
    ]
    assert api["ended"] is True
    assert page.text_content("#import-end") == api["end_note"]
    assert "cut-short" not in (page.get_attribute("#import-end", "class") or "")
    assert (ROOT / "service" / "web" / "static" / "examples" / "nx_slot_plate.cls").read_text() == (
        program
    )


def test_a_path_that_skips_no_record_says_none(page: Page, url: str) -> None:
    """The README example (a JSON path) has no record to skip: the list says so, not nothing."""
    page.wait_for_function(
        "document.getElementById('import').dataset.waypoints === '133'", timeout=30_000
    )
    api = httpx.post(f"{url}/v1/paths/import", json={"path": EXAMPLE_PATH}).json()
    assert api["skipped_records"] == []
    assert page.locator("#import-skipped li").all_text_contents() == ["none"]


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
    # No FINI after its last move: the page says it may be cut short, in red
    assert (page.text_content("#import-end") or "").startswith(
        "no FINI or END-OF-PATH after the last move (GOTO at line 2): the program may be cut short"
    )
    assert page.get_attribute("#import-end", "class") == "cut-short"


# ---- joint accelerations (issue 24): mu_acc, what binds, the cycle time ------------------------
ACC = "10, 10, 10, 10, 10, 10"
UR5_ACC = {"model": "ur5", "joint_acceleration_limits": [10.0] * 6}
STOPS = [(68, 1, 84), (59, 82, 139), (33, 145, 140), (94, 201, 98), (253, 231, 37)]


def page_colour(fraction: float) -> tuple[int, int, int]:
    """The page's colour scale (app.js ``colour``), written again: dark blue, green, yellow."""
    t = min(max(fraction, 0.0), 1.0) * (len(STOPS) - 1)
    k = min(int(t), len(STOPS) - 2)
    mix = [
        math.floor(a + (b - a) * (t - k) + 0.5) for a, b in zip(STOPS[k], STOPS[k + 1], strict=True)
    ]
    return mix[0], mix[1], mix[2]


def pixel(page: Page, panel: int, cell: dict[str, Any], api: dict[str, Any]) -> tuple[int, ...]:
    """The colour the page painted at the centre of a cell of a panel."""
    xs = sorted({c["x"] for c in api["cells"]})
    ys = sorted({c["y"] for c in api["cells"]})
    i, j = xs.index(cell["x"]), ys.index(cell["y"])
    rgba = page.evaluate(
        """([panel, i, j, ny]) => {
            const canvas = document.querySelectorAll('.panel canvas')[panel];
            const size = Number(canvas.dataset.cell);
            const at = [i * size + size / 2, (ny - 1 - j) * size + size / 2];
            return [...canvas.getContext('2d').getImageData(at[0], at[1], 1, 1).data];
        }""",
        [panel, i, j, len(ys)],
    )
    return tuple(rgba[:3])


def run_acceleration_map(page: Page, url: str, blend: str = "0.002") -> dict[str, Any]:
    """The small map from the page with every joint at 10 rad/s^2; the API's map of that body."""
    fill(page, {**SMALL, "acc-limits": ACC, "blend-length": blend})
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=120_000)
    body = {
        "robot": UR5_ACC,
        "path": EXAMPLE_PATH,
        "grid": grid_of(SMALL),
        "ik": {"blend_length": float(blend)},
    }
    answer = httpx.post(f"{url}/v1/map", json=body, timeout=120)
    assert answer.status_code == 200, answer.text
    return answer.json()


def evaluate_api(url: str, cell: dict[str, Any], **extra: Any) -> dict[str, Any]:
    placement = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"], "spin": 0.0}
    body = {"robot": UR5_ACC, "path": EXAMPLE_PATH, "placement": placement, **extra}
    answer = httpx.post(f"{url}/v1/evaluate", json=body, timeout=60)
    assert answer.status_code == 200, answer.text
    return dict(answer.json())


def test_acceleration_limits_colour_the_map_by_mu_acc_and_the_hover_says_what_binds(
    page: Page, url: str
) -> None:
    api = run_acceleration_map(page, url)
    feasible = [c for c in api["cells"] if c["mu_path"] is not None]
    assert feasible and all(c["mu_acc"] is not None for c in feasible)
    assert page.get_attribute("#summary", "data-key") == "mu_acc"
    assert page.text_content("#cb-label") == "mu_acc (m/s)"
    low, high = min(c["mu_acc"] for c in feasible), max(c["mu_acc"] for c in feasible)
    assert page.text_content("#cb-min") == f"{low:.3f} m/s"
    assert page.text_content("#cb-max") == f"{high:.3f} m/s"
    best = api["best"]
    assert page.text_content("#best-mu") == (
        f"mu_acc {best['mu_acc']:.6f} m/s (mu_path {best['mu_path']:.6f} m/s)"
    )
    by_acceleration = sum(c["limited_by"] == "acceleration" for c in feasible)
    assert f"limited by acceleration in {by_acceleration} cells" in (
        page.text_content("#summary") or ""
    )
    per_panel = len(api["cells"]) // 2
    panel_cells = [c for c in api["cells"][:per_panel] if c["mu_path"] is not None]
    speed_low = min(c["mu_path"] for c in feasible)
    speed_high = max(c["mu_path"] for c in feasible)
    # A cell whose mu_acc colour differs from its mu_path colour: the page paints the former.
    cell = next(
        c
        for c in panel_cells
        if c["limited_by"] == "acceleration"
        and page_colour((c["mu_acc"] - low) / (high - low))
        != page_colour((c["mu_path"] - speed_low) / (speed_high - speed_low))
    )
    assert pixel(page, 0, cell, api) == page_colour((cell["mu_acc"] - low) / (high - low))
    point = cell_point(page, 0, cell, api)
    page.mouse.move(point["x"], point["y"])
    page.wait_for_selector("#tooltip[data-where='1']", timeout=30_000)
    tooltip = page.text_content("#tooltip") or ""
    assert f"mu_path {cell['mu_path']:.6f} m/s" in tooltip
    assert f"mu_acc {cell['mu_acc']:.6f} m/s, limited by acceleration" in tooltip
    acc = evaluate_api(url, cell, detail="summary")["acceleration"]
    assert acc["mu_acc"] == pytest.approx(cell["mu_acc"], rel=MAP_EVALUATE_RTOL)
    assert acc["limited_by"] == "acceleration"
    assert (
        f"where: joint {acc['joint'] + 1} ({acc['joint_name']}), waypoint {acc['waypoint']}"
        in tooltip
    )


def test_a_clicked_cell_shows_mu_acc_the_acceleration_use_and_the_cycle_times(
    page: Page, url: str
) -> None:
    api = run_acceleration_map(page, url, blend="0.004")
    per_panel = len(api["cells"]) // 2
    cell = next(c for c in api["cells"][:per_panel] if c["limited_by"] == "acceleration")
    point = cell_point(page, 0, cell, api)
    page.mouse.click(point["x"], point["y"])
    page.wait_for_selector("#plot[data-drawn='1']", timeout=60_000)
    answer = evaluate_api(url, cell, feed=0.1, ik={"blend_length": 0.004})
    acc, times = answer["acceleration"], answer["cycle_time"]
    # The blend length reached the API: at the default 2 mm mu_acc is another figure.
    default = evaluate_api(url, cell, detail="summary")["acceleration"]
    assert default["mu_acc"] != acc["mu_acc"]
    assert acc["mu_acc"] == pytest.approx(cell["mu_acc"], rel=MAP_EVALUATE_RTOL)
    assert acc["blend_length"] == 0.004
    text = page.text_content("#acceleration") or ""
    assert text.startswith(f"mu_acc {acc['mu_acc']:.6f} m/s (blend 4.000 mm): ")
    assert (
        f"joint {acc['joint'] + 1} ({acc['joint_name']}) binds at waypoint {acc['waypoint']}"
        in text
    )
    assert page.text_content("#cycle-time") == (
        f"cycle time: {times['constant_feed_time']:.3f} s at the constant feed mu_acc, "
        f"{times['ramp']:.3f} s with the ramps at the pass ends, "
        f"{times['time_optimal']:.3f} s time-optimal (feed free along the path)"
    )
    # The plot's third panel: |D_i| F^2 / a_j from the API's qdd_at_mu_acc = D_i mu_acc^2.
    scale = (0.1 / acc["mu_acc"]) ** 2 / 10.0
    rows = [w["qdd_at_mu_acc"] for w in answer["waypoints"] if w["qdd_at_mu_acc"] is not None]
    assert rows and len(rows) < len(answer["waypoints"])  # none within the blend of the ends
    peak = max(abs(v) * scale for row in rows for v in row)
    assert page.get_attribute("#plot", "data-panels") == "3"
    assert page.get_attribute("#plot", "data-acceleration-use") == f"{peak:.6f}"
    assert f"the largest acceleration use is {100 * peak:.1f} %" in text


def test_without_acceleration_limits_the_page_shows_mu_path_only(page: Page, url: str) -> None:
    api = run_small_map(page, url)
    assert page.get_attribute("#summary", "data-key") == "mu_path"
    assert page.text_content("#cb-label") == "mu_path (m/s)"
    cell = next(c for c in api["cells"] if c["mu_path"] is not None)
    assert cell["mu_acc"] is None
    page.mouse.click(**cell_point(page, 0, cell, api))
    page.wait_for_selector("#plot[data-drawn='1']", timeout=60_000)
    assert page.text_content("#acceleration") == ""
    assert page.text_content("#cycle-time") == ""
    assert page.get_attribute("#plot", "data-panels") == "2"


def test_the_optimum_shows_its_mu_acc(page: Page, url: str) -> None:
    run_acceleration_map(page, url)
    page.click("#optimize")
    page.wait_for_selector(".panel canvas[data-optimum='1']", timeout=300_000)
    body = {
        "robot": UR5_ACC,
        "path": EXAMPLE_PATH,
        "method": "casadi",
        "z": 0.1,
        "bounds": {"x": [-0.1, 0.1], "y": [0.3, 0.5], "yaw": [0.0, 1.5]},
        "ik": {"blend_length": 0.002},
    }
    api = httpx.post(f"{url}/v1/optimize", json=body, timeout=300).json()
    assert api["mu_acc"] is not None
    assert page.text_content("#opt-acc") == f"{api['mu_acc']:.6f} m/s"
    assert page.text_content("#opt-mu") == f"{api['mu_path']:.6f} m/s"
    assert page.is_visible("#opt-acc-line")
    acc = api["evaluation"]["acceleration"]
    assert page.text_content("#opt-acc-binds") == (
        f"(+{api['improvement_percent']:.2f} % over the start's mu_acc) the acceleration of "
        f"joint {acc['joint'] + 1} ({acc['joint_name']}) binds at waypoint {acc['waypoint']}"
    )
    assert page.text_content("#opt-improvement") == (
        f"(the start's mu_path: {api['start']['mu_path']:.6f} m/s)"
    )


@pytest.mark.parametrize("typed", ["10, 10, 10", "10, 10, ten, 10, 10, 10"])
def test_acceleration_limits_the_api_refuses_show_its_error_beside_the_field(
    page: Page, url: str, typed: str
) -> None:
    fill(page, {**SMALL, "acc-limits": typed})
    page.click("#run")
    selector = ".field[data-loc='robot.joint_acceleration_limits'] .error"
    page.wait_for_function(f'document.querySelector("{selector}").textContent !== ""')
    limits = [float(v) if v.strip() != "ten" else None for v in typed.split(",")]
    body = {
        "kind": "map",
        "request": {
            "robot": {"model": "ur5", "joint_acceleration_limits": limits},
            "path": EXAMPLE_PATH,
            "grid": grid_of(SMALL),
            "ik": {"blend_length": 0.002},
        },
    }
    answer = httpx.post(f"{url}/v1/jobs", json=body)
    assert answer.status_code == 422
    detail = answer.json()["detail"]
    assert [d["loc"][2:4] for d in detail] == [["robot", "joint_acceleration_limits"]]
    assert page.text_content(selector) == beside("robot.joint_acceleration_limits", detail[0])
    assert page.text_content("#form-error") == ""
    assert page.get_attribute("#summary", "data-cells") is None  # no map ran


def test_a_pasted_robot_brings_its_own_acceleration_limits(page: Page, url: str) -> None:
    robot = {"model": "ur5", "joint_acceleration_limits": [5.0] * 6}
    page.click("#own-json summary")
    page.fill("#robot-json", json.dumps(robot))
    assert page.is_disabled("#acc-limits") and page.is_disabled("#limits input >> nth=0")
    assert page.is_visible("#own-robot-note")
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=120_000)
    body = {"robot": robot, "path": EXAMPLE_PATH, "grid": grid_of(SMALL)}
    api = httpx.post(f"{url}/v1/map", json=body, timeout=120).json()
    best = api["best"]
    assert page.text_content("#best-mu") == (
        f"mu_acc {best['mu_acc']:.6f} m/s (mu_path {best['mu_path']:.6f} m/s)"
    )


@pytest.mark.parametrize("width", [1280, 800])
def test_the_acceleration_page_reads_at_1280_and_800_px(
    browser: Browser, url: str, width: int
) -> None:
    page = browser.new_page(viewport={"width": width, "height": 900})
    page.goto(url + "/")
    page.wait_for_selector("body[data-ready='1']", timeout=30_000)
    api = run_acceleration_map(page, url)
    cell = next(c for c in api["cells"] if c["limited_by"] == "acceleration")
    page.locator(".panel canvas").nth(0).scroll_into_view_if_needed()
    page.mouse.click(**cell_point(page, 0, cell, api))
    page.wait_for_selector("#plot[data-drawn='1']", timeout=60_000)
    overflow = page.evaluate("document.documentElement.scrollWidth - window.innerWidth")
    ARTIFACTS.mkdir(exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / f"web-accelerations-{width}.png"), full_page=True)
    page.close()
    assert overflow <= 0  # nothing wider than the window


def test_a_zero_blend_length_shows_the_apis_error_beside_the_field(page: Page, url: str) -> None:
    fill(page, {**SMALL, "acc-limits": ACC, "blend-length": "0"})
    page.click("#run")
    selector = ".field[data-loc='ik.blend_length'] .error"
    page.wait_for_function(f'document.querySelector("{selector}").textContent !== ""')
    body = {
        "kind": "map",
        "request": {
            "robot": UR5_ACC,
            "path": EXAMPLE_PATH,
            "grid": grid_of(SMALL),
            "ik": {"blend_length": 0.0},
        },
    }
    detail = httpx.post(f"{url}/v1/jobs", json=body).json()["detail"]
    assert [d["loc"][2:] for d in detail] == [["ik", "blend_length"]]
    assert page.text_content(selector) == detail[0]["msg"]


def test_an_empty_blend_length_is_left_out_not_sent_as_zero(page: Page, url: str) -> None:
    """As every other empty field: the API's default (0.002 m) applies, no error beside it."""
    fill(page, {**SMALL, "acc-limits": ACC, "blend-length": ""})
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    body = sent.value.post_data_json
    assert isinstance(body, dict) and body["request"]["ik"] == {}
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    assert page.text_content(".field[data-loc='ik.blend_length'] .error") == ""
    assert page.get_attribute("#summary", "data-key") == "mu_acc"
