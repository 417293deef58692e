"""What the page says is its map's and the API's (the page audit of stop 56, in Chromium).

A clicked cell is evaluated with the map's own request, as its hover text is, whatever the
form says since; the cell under the pointer is the one painted there, to its last pixel; an
error names the waypoint, joint or item its loc names; a failure without a JSON answer, and a
pasted robot object that is not JSON, are said, never a blank; the tooltip stays inside the
window and shows for the keyboard too.
"""

from __future__ import annotations

import copy
import json
import math
import re
from pathlib import Path
from typing import Any

import httpx
import numpy as np
from playwright.sync_api import Page, Route
from scipy.spatial.transform import Rotation

from tests.cases import EXAMPLES
from tests.web.test_page import EXAMPLE_PATH, SMALL, cell_point, fill, grid_of, run_small_map
from tests.web.test_page_cell import open_editor
from tests.web.test_page_findings import choose_file, error_beside


def run_job(page: Page, button: str = "#run") -> str:
    """Click Run (or ``button``): the id of the job the page submits."""
    with page.expect_response(
        lambda r: r.request.method == "POST" and r.url.endswith("/v1/jobs")
    ) as sent:
        page.click(button)
    job_id: str = sent.value.json()["id"]
    return job_id


def reload_page(page: Page) -> None:
    """Reload the page and wait until it is ready."""
    page.reload()
    page.wait_for_function("document.body.dataset.ready === '1'")


def _first_feasible(api: dict[str, Any]) -> dict[str, Any]:
    return next(c for c in api["cells"] if c["mu_path"] is not None)


def test_a_clicked_cell_is_the_maps_even_after_the_form_changed(page: Page, url: str) -> None:
    """Joint 1's speed limit lowered to 0.5 rad/s after the map: the click still answers the
    map's mu_path (the API's evaluation of the map's request), and says so (before, it answered
    0.187889 m/s beside a cell coloured 0.291404)."""
    api = run_small_map(page, url)
    cell = _first_feasible(api)
    page.fill("#limits input >> nth=0", "0.5")
    page.dispatch_event("#limits input >> nth=0", "input")
    point = cell_point(page, 0, cell, api)
    page.mouse.click(point["x"], point["y"])
    page.wait_for_function(
        "document.getElementById('cell-summary').textContent.includes('mu_path')", timeout=30_000
    )
    placement = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"], "spin": 0.0}
    body = {"robot": {"model": "ur5"}, "path": EXAMPLE_PATH, "placement": placement}
    evaluation = httpx.post(f"{url}/v1/evaluate", json=body, timeout=60).json()
    summary = page.text_content("#cell-summary") or ""
    assert f"mu_path {evaluation['mu_path']:.6f} m/s" in summary
    assert f"{cell['mu_path']:.6f}" in summary
    assert "with the map's inputs" in summary


def test_the_cell_under_the_pointer_is_the_one_painted_there(page: Page, url: str) -> None:
    """At the last pixel of a cell's drawing (Playwright's position is from the canvas's
    padding box, inside any border) the tooltip names that cell, not its neighbour."""
    api = run_small_map(page, url)
    xs = sorted({c["x"] for c in api["cells"]})
    ys = sorted({c["y"] for c in api["cells"]})
    canvas = page.locator(".panel canvas").nth(0)
    size = int(canvas.get_attribute("data-cell") or 0)
    for i in range(len(xs)):
        for at in (0.5, size - 0.5):  # the first and the last pixel of cell column i
            canvas.hover(position={"x": i * size + at, "y": size * (len(ys) - 0.5)})
            tooltip = page.text_content("#tooltip") or ""
            assert tooltip.startswith(f"x {xs[i]:.4f} m, y {ys[0]:.4f} m"), (i, at, tooltip)


def _bad_path(waypoint: int) -> str:
    path = copy.deepcopy(EXAMPLE_PATH)
    path["waypoints"][waypoint]["orientation"] = [0.9, 0.0, 0.0, 0.0]
    return json.dumps(path)


def test_an_error_names_its_waypoint_and_its_joint(page: Page, url: str) -> None:
    """A path with a bad quaternion at waypoint 7: beside the path as it is read, and again
    when Run finds no path; a joint's speed limit beside the limits, by its index."""
    choose_file(page, "#path-file", "bad.json", _bad_path(7))
    body = {"robot": {"model": "ur5"}, "path": json.loads(_bad_path(7)), "grid": grid_of(SMALL)}
    detail = httpx.post(f"{url}/v1/map", json=body, timeout=60).json()["detail"]
    assert detail[0]["loc"] == ["body", "path", "waypoints", 7, "orientation"]
    assert error_beside(page, "path") == f"waypoints[7].orientation: {detail[0]['msg']}"
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function(
        "document.querySelector(\".field[data-loc='path'] .error\").textContent"
        ".startsWith('No path to run')"
    )
    error = page.text_content(".field[data-loc='path'] .error") or ""
    assert f"path.waypoints[7].orientation: {detail[0]['msg']}" in error
    page.reload()
    page.wait_for_selector("body[data-ready='1']", timeout=30_000)
    page.fill("#limits input >> nth=2", "-1")
    page.dispatch_event("#limits input >> nth=2", "input")
    fill(page, SMALL)
    page.click("#run")
    assert error_beside(page, "robot.joint_velocity_limits").startswith("[2]: ")


def test_an_answer_that_is_not_json_or_none_is_said(page: Page) -> None:
    def text_500(route: Route) -> None:
        route.fulfill(status=500, content_type="text/plain", body="Internal Server Error")

    page.route("**/v1/jobs", text_500)
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("document.getElementById('form-error').textContent !== ''")
    assert (page.text_content("#form-error") or "").startswith("HTTP 500")
    page.unroute("**/v1/jobs")
    page.route("**/v1/optimize", lambda route: route.abort())
    page.click("#optimize")
    page.wait_for_function(
        "document.getElementById('form-error').textContent.includes('no answer from the service')"
    )


def test_a_robot_object_that_is_not_json_is_said_beside_the_robot(page: Page) -> None:
    errors: list[str] = []
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.click("#own-json summary")
    page.fill("#robot-json", "{oops")
    fill(page, SMALL)
    page.click("#optimize")
    assert error_beside(page, "robot").startswith("the robot object is not JSON: ")
    assert errors == []


def test_the_tooltip_stays_in_the_window_and_shows_for_the_keyboard(page: Page, url: str) -> None:
    api = run_small_map(page, url)
    page.set_viewport_size({"width": 700, "height": 900})
    canvas = page.locator(".panel canvas").last
    canvas.scroll_into_view_if_needed()
    size = int(canvas.get_attribute("data-cell") or 0)
    xs = sorted({c["x"] for c in api["cells"]})
    canvas.hover(position={"x": len(xs) * size - 1, "y": size / 2})
    tip = page.locator("#tooltip").bounding_box()
    assert tip is not None
    assert 0 <= tip["x"] and tip["x"] + tip["width"] <= 700
    page.mouse.move(0, 0)
    page.locator(".panel canvas").first.focus()
    page.keyboard.press("ArrowRight")
    assert page.is_visible("#tooltip")
    assert (page.text_content("#tooltip") or "").startswith(f"x {xs[1]:.4f} m")


def _refused_as_work(route: Route) -> None:
    """The route's answer to a search over its size limit (service/config.py's hint)."""
    detail = [
        {
            "loc": ["body", "bounds"],
            "msg": "the casadi search evaluates placements of 133 waypoints: ..., as work "
            "6.339e+06 closed-form poses (ur IK, with a cell); the limit is 5000000 "
            "(DTF_MAX_MAP_POSES); narrow the bounds; POST /v1/jobs runs bigger searches",
            "type": "invalid_input",
        }
    ]
    route.fulfill(status=422, content_type="application/json", body=json.dumps({"detail": detail}))


def test_a_search_too_large_for_a_request_runs_as_a_job(page: Page, url: str) -> None:
    """The route refusing the search for its size (as it refuses a cell at the default bounds:
    6.3 million poses), the page submits the same body as an optimisation job and shows its
    answer, which is the route's."""
    page.route("**/v1/optimize", _refused_as_work)
    fill(page, SMALL)
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#optimize")
    submitted = json.loads(sent.value.post_data or "{}")
    assert submitted["kind"] == "optimize"
    page.wait_for_function(
        "document.getElementById('opt-mu').textContent.endsWith(' m/s')", timeout=120_000
    )
    api = httpx.post(f"{url}/v1/optimize", json=submitted["request"], timeout=120).json()
    assert page.text_content("#opt-mu") == f"{api['mu_path']:.6f} m/s"
    assert page.is_disabled("#opt-cancel")


def test_an_optimisation_job_is_stopped_from_the_page(page: Page, url: str) -> None:
    page.route("**/v1/optimize", _refused_as_work)
    fill(page, {**SMALL, "x-min": "-0.3", "x-max": "0.3", "y-min": "0.2", "y-max": "0.7"})
    page.click("#opt-any-yaw")
    page.click("#optimize")
    page.wait_for_function(
        "document.getElementById('opt-mu').textContent.startsWith('optimising as job')",
        timeout=60_000,
    )
    job_id = (page.text_content("#opt-mu") or "").split()[3].rstrip(":")
    page.click("#opt-cancel")
    assert (page.text_content("#opt-mu") or "").startswith("cancelled: stopped from the page")
    for _ in range(50):
        status = httpx.get(f"{url}/v1/jobs/{job_id}").json()["status"]
        if status != "running":
            break
        page.wait_for_timeout(100)
    assert status == "cancelled"


def _submit_optimisation_job(page: Page) -> str:
    """Optimise a search the route refuses as work (as a job): its id, once it runs."""
    page.route("**/v1/optimize", _refused_as_work)
    fill(page, {**SMALL, "x-min": "-0.3", "x-max": "0.3", "y-min": "0.2", "y-max": "0.7"})
    page.click("#opt-any-yaw")
    return run_job(page, "#optimize")


def test_a_reloaded_page_shows_its_last_optimisation_job_again(page: Page, url: str) -> None:
    """An optimisation that ran as a job was lost at a reload (only the last map job was
    offered): now offered, watched to its end, and shown with the job's own inputs whatever the
    form holds; a path change leaves it running, and Stop optimising cancels it."""
    job_id = _submit_optimisation_job(page)
    reload_page(page)
    page.wait_for_selector("#opt-resume:not([hidden])", timeout=30_000)
    offer = page.text_content("#opt-resume-text") or ""
    said = r"((queued|running), \d+ %|done)"
    assert re.fullmatch(rf"Your last optimisation, job {job_id} \(submitted .+\): {said}\.", offer)
    fill(page, {"x-min": "-0.05", "x-max": "0.05"})  # the form's inputs are not the job's
    page.click("#opt-resume-show")
    page.wait_for_selector("#opt-resume", state="hidden")
    page.wait_for_function(
        "document.getElementById('opt-mu').textContent.endsWith(' m/s')", timeout=120_000
    )
    job = httpx.get(f"{url}/v1/jobs/{job_id}").json()
    assert job["status"] == "done"
    assert page.text_content("#opt-mu") == f"{job['result']['mu_path']:.6f} m/s"
    assert (page.text_content("#opt-own") or "").startswith(
        f"Job {job_id}'s optimum, with the job's own inputs"
    )
    assert page.is_visible("#frames")
    assert page.locator(".panel canvas[data-optimum='1']").count() == 0


def test_a_resumed_optimisation_job_runs_on_when_the_inputs_change(page: Page, url: str) -> None:
    job_id = _submit_optimisation_job(page)
    reload_page(page)
    page.wait_for_selector("#opt-resume:not([hidden])", timeout=30_000)
    if (page.text_content("#opt-resume-text") or "").endswith(": done."):
        return  # ended before the reload: nothing runs to leave or stop (the test above)
    page.click("#opt-resume-show")
    page.wait_for_function(
        f"document.getElementById('opt-mu').textContent.startsWith('optimising as job {job_id}')"
    )
    page.fill("#x-step", "0.04")  # not a path or robot change: watched on
    page.select_option("#robot-model", "ur10")
    assert (page.text_content("#opt-mu") or "").startswith(
        f"no longer watched (job {job_id} runs on)"
    )
    assert httpx.get(f"{url}/v1/jobs/{job_id}").json()["status"] in ("queued", "running", "done")
    page.wait_for_selector("#opt-resume:not([hidden])", timeout=30_000)
    page.click("#opt-resume-show")
    page.wait_for_function(
        f"document.getElementById('opt-mu').textContent.startsWith('optimising as job {job_id}')"
        " || document.getElementById('opt-mu').textContent.endsWith(' m/s')"
    )
    if (page.text_content("#opt-mu") or "").endswith(" m/s"):
        return  # it ended meanwhile
    page.click("#opt-cancel")
    assert (page.text_content("#opt-mu") or "").startswith("cancelled: stopped from the page")
    for _ in range(50):
        status = httpx.get(f"{url}/v1/jobs/{job_id}").json()["status"]
        if status not in ("queued", "running"):
            break
        page.wait_for_timeout(100)
    assert status in ("cancelled", "done")


def test_the_best_line_says_the_spin_of_a_spun_map(page: Page, url: str) -> None:
    fill(page, {**SMALL, "spins": "0, 1.2"})
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    grid = {**grid_of(SMALL), "spin": [0.0, 1.2]}
    body = {"robot": {"model": "ur5"}, "path": EXAMPLE_PATH, "grid": grid}
    best = httpx.post(f"{url}/v1/map", json=body, timeout=60).json()["best"]["placement"]
    assert (page.text_content("#best-where") or "").endswith(f"spin {best['spin']:.4f} rad")


def test_an_optimum_marked_on_another_yaws_panel_says_so(page: Page, url: str) -> None:
    """Any yaw: the optimum's yaw is none of the map's two; its marker goes on the nearest
    panel's, and the page says which and what the optimum's is."""
    api = run_small_map(page, url)
    page.click("#opt-any-yaw")
    page.click("#optimize")
    page.wait_for_selector(".panel canvas[data-optimum='1']", timeout=120_000)
    request = {
        "robot": {"model": "ur5"},
        "path": EXAMPLE_PATH,
        "method": "casadi",
        "z": 0.1,
        "bounds": {"x": [-0.1, 0.1], "y": [0.3, 0.5], "yaw": [-math.pi, math.pi]},
    }
    optimum = httpx.post(f"{url}/v1/optimize", json=request, timeout=120).json()["placement"]
    yaws = sorted({c["yaw"] for c in api["cells"]})
    nearest = min(yaws, key=lambda y: abs(y - optimum["yaw"]))
    note = page.text_content("#opt-marked") or ""
    if abs(nearest - optimum["yaw"]) > 1e-9:
        assert page.is_visible("#opt-marked")
        assert f"at yaw {nearest:.4f} rad" in note and f"{optimum['yaw']:.4f} rad" in note
    else:
        assert not page.is_visible("#opt-marked")


def test_the_tool_point_fields_give_the_robots_tcp(page: Page, url: str) -> None:
    """A catalogue robot's tool point from the page (its tool in the cell needs one): the six
    fields are sent as robot.tcp, the angles as scipy turns them (R = Rz Ry Rx, degrees), and
    the map is the API's of that body."""
    page.click("#tool-point summary")
    fill(page, {**SMALL, "tcp-z": "0.12", "tcp-roll": "20", "tcp-yaw": "-35"})
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    request = json.loads(sent.value.post_data or "{}")["request"]
    tcp = request["robot"]["tcp"]
    assert tcp["position"] == [0, 0, 0.12]
    expected = Rotation.from_euler("ZYX", [-35.0, 0.0, 20.0], degrees=True).as_quat()
    np.testing.assert_allclose(tcp["orientation"], expected, atol=1e-15)
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    api = httpx.post(f"{url}/v1/map", json=request, timeout=60).json()
    assert page.text_content("#best-mu") == f"{api['best']['mu_path']:.6f} m/s"


SELF_GRID = {  # the page audit's grid: 25 of its cells self-colliding on the UR5
    "x-min": "-0.4",
    "x-max": "0.6",
    "x-step": "0.05",
    "y-min": "0.1",
    "y-max": "0.8",
    "y-step": "0.05",
    "z": "0.1",
    "yaws": "0, 1.5708",
    "spins": "0",
}


def test_the_robot_is_checked_against_itself_with_no_object(page: Page, url: str) -> None:
    """Asked (or a clearance given), the page sends a cell with no object: the arm against
    itself (cell.md); before, link radii or a clearance without an object were dropped and
    nothing was checked."""
    open_editor(page)
    page.check("#self-check")
    assert "the robot against itself (no object)" in (page.text_content("#cell-status") or "")
    fill(page, SELF_GRID)
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    request = json.loads(sent.value.post_data or "{}")["request"]
    assert request["cell"] == {"fixed": [], "workpiece": []}
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=120_000)
    api = httpx.post(f"{url}/v1/map", json=request, timeout=120).json()
    collisions = sum(c["reason"] == "collision" for c in api["cells"])
    assert collisions > 0
    assert page.get_attribute("#summary", "data-collisions") == str(collisions)
    page.uncheck("#self-check")
    page.fill("#clearance", "0.01")
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    cell = json.loads(sent.value.post_data or "{}")["request"]["cell"]
    assert cell == {"fixed": [], "workpiece": [], "clearance": 0.01}


def test_the_ik_branch_and_joint_step_chosen_on_the_page_reach_the_api(
    page: Page, url: str
) -> None:
    """The page had no field for either: every map, cell and optimum followed the auto branch
    with the 0.35 rad step. A branch made of the robot's levels (GET /v1/robots) and a step are
    sent, the page's best is the API's answer to that body, and every feasible cell is on the
    branch chosen; a step the API refuses is said beside its field."""
    branch = {"shoulder": "right", "elbow": "down", "wrist": "flip"}
    options = page.locator("#ik-branch option")
    assert options.count() == 1 + 8  # auto and the UR5's 2 x 2 x 2
    page.select_option("#ik-branch", json.dumps(branch, separators=(",", ":")))
    fill(page, {**SMALL, "max-joint-step": "0.3"})
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    submitted = json.loads(sent.value.post_data or "{}")["request"]
    assert submitted["ik"] == {"blend_length": 0.002, "max_joint_step": 0.3, "branch": branch}
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    api = httpx.post(f"{url}/v1/map", json=submitted, timeout=60).json()
    feasible = [c for c in api["cells"] if c["mu_path"] is not None]
    assert feasible and all(c["branch"] == branch for c in feasible)
    assert page.text_content("#best-mu") == f"{api['best']['mu_path']:.6f} m/s"
    fill(page, {"max-joint-step": "-1"})
    page.click("#run")
    detail = httpx.post(
        f"{url}/v1/map", json={**submitted, "ik": {**submitted["ik"], "max_joint_step": -1.0}}
    ).json()["detail"]
    assert [d["loc"][1:] for d in detail] == [["ik", "max_joint_step"]]
    assert error_beside(page, "ik.max_joint_step") == detail[0]["msg"]


def test_the_optimiser_searches_the_height_and_spin_ranges_given_on_the_page(
    page: Page, url: str
) -> None:
    """The page searched only at the grid's z and without spin (bounds.z and bounds.spin had no
    field). Both ranges reach the request (without z, as the API asks), the page's optimum is
    the API's answer to it, inside them; a range the wrong way round is said beside its field."""
    fill(
        page,
        {**SMALL, "opt-z-min": "0.05", "opt-z-max": "0.15", "opt-spin-min": "-0.5",
         "opt-spin-max": "0.5"},
    )  # fmt: skip
    with page.expect_request(lambda r: r.method == "POST" and "/v1/optimize" in r.url) as sent:
        page.click("#optimize")
    submitted = json.loads(sent.value.post_data or "{}")
    assert "z" not in submitted
    assert submitted["bounds"]["z"] == [0.05, 0.15]
    assert submitted["bounds"]["spin"] == [-0.5, 0.5]
    page.wait_for_function(
        "document.getElementById('opt-mu').textContent.endsWith(' m/s')", timeout=120_000
    )
    api = httpx.post(f"{url}/v1/optimize", json=submitted, timeout=120).json()
    assert page.text_content("#opt-mu") == f"{api['mu_path']:.6f} m/s"
    placement = api["placement"]
    assert 0.05 <= placement["z"] <= 0.15 and -0.5 <= placement["spin"] <= 0.5
    fill(page, {"opt-z-min": "0.15", "opt-z-max": "0.05"})
    page.click("#optimize")
    wrong = {**submitted, "bounds": {**submitted["bounds"], "z": [0.15, 0.05]}}
    detail = httpx.post(f"{url}/v1/optimize", json=wrong).json()["detail"]
    assert [d["loc"][1:3] for d in detail] == [["bounds", "z"]]
    assert error_beside(page, "bounds.z") == detail[0]["msg"]


def test_the_map_and_a_clicked_cell_say_what_was_normalised(page: Page, url: str) -> None:
    """A pasted robot's tcp quaternion 2e-4 off unit is normalised by the API: the map and the
    cell said nothing of it (the map's answer did not carry it either)."""
    robot = {"model": "ur5", "tcp": {"position": [0, 0, 0.05], "orientation": [0, 0, 0, 0.9998]}}
    page.click("#own-json summary")
    page.fill("#robot-json", json.dumps(robot))
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=120_000)
    body = {"robot": robot, "path": EXAMPLE_PATH, "grid": grid_of(SMALL)}
    api = httpx.post(f"{url}/v1/map", json=body, timeout=120).json()
    said = "normalised, largest correction 2.0e-4"
    assert f"{api['axis_correction']:.1e}".replace("e-04", "e-4") == "2.0e-4"
    assert said in (page.text_content("#summary") or "")
    cell = _first_feasible(api)
    point = cell_point(page, 0, cell, api)
    page.mouse.click(point["x"], point["y"])
    page.wait_for_function(
        "document.getElementById('cell-summary').textContent.includes('mu_path')", timeout=30_000
    )
    assert said in (page.text_content("#cell-summary") or "")


def test_a_reloaded_page_shows_its_last_map_with_the_maps_own_request(page: Page, url: str) -> None:
    """A reload lost the map (a long job ran on with nothing to show it): the page remembers
    its last map job, offers it, draws the job's cells and evaluates a clicked cell with the
    job's request (GET /v1/jobs/{id}/request), not the form's."""
    fill(page, SMALL)
    job_id = run_job(page)
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    reload_page(page)
    assert page.is_visible("#resume")
    assert f"job {job_id}" in (page.text_content("#resume-text") or "")
    assert "done" in (page.text_content("#resume-text") or "")
    page.click("#resume-show")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    # the form is not the shown map's: said beside its status
    assert f"(job {job_id}'s own inputs; the form keeps yours)" in (
        page.text_content("#job-status") or ""
    )
    request = httpx.get(f"{url}/v1/jobs/{job_id}/request").json()["request"]
    api = httpx.post(f"{url}/v1/map", json=request, timeout=60).json()
    assert page.get_attribute("#summary", "data-cells") == str(len(api["cells"]))
    assert page.text_content("#best-mu") == f"{api['best']['mu_path']:.6f} m/s"
    cell = _first_feasible(api)
    point = cell_point(page, 0, cell, api)
    page.mouse.click(point["x"], point["y"])
    page.wait_for_function(
        "document.getElementById('cell-summary').textContent.includes('mu_path')", timeout=30_000
    )
    body = {key: value for key, value in request.items() if key != "grid"}
    body["placement"] = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"], "spin": 0.0}
    evaluation = httpx.post(f"{url}/v1/evaluate", json=body, timeout=60).json()
    assert f"mu_path {evaluation['mu_path']:.6f} m/s" in (page.text_content("#cell-summary") or "")


def test_the_map_is_saved_as_the_apis_png_and_a_refusal_is_said(page: Page, url: str) -> None:
    """The page drew its map on canvases with nothing to save for a report: 'Save the map as a
    PNG' downloads the API's picture of the map: its job's (drawn from the stored cells, any
    size), which is the map route's picture of the job's request byte for byte; where the job
    is gone, the map route's. A picture refused is said beside the button, no file."""
    run_small_map(page, url)
    with page.expect_request(lambda r: "/v1/jobs/" in r.url and r.url.endswith("/png")) as sent:
        with page.expect_download() as download:
            page.click("#png")
    saved = Path(download.value.path()).read_bytes()
    job_id = sent.value.url.split("/")[-2]
    asked = httpx.get(f"{url}/v1/jobs/{job_id}/request", timeout=60).json()
    assert asked["request"]["grid"] == grid_of(SMALL)
    api = httpx.post(f"{url}/v1/map/png", json=asked["request"], timeout=60)
    assert api.status_code == 200 and saved[:8] == b"\x89PNG\r\n\x1a\n"
    assert saved == api.content
    assert page.text_content("#png-status") == "saved as dtf-map.png"

    assert httpx.delete(f"{url}/v1/jobs/{job_id}", timeout=60).status_code == 204
    with page.expect_request(lambda r: r.url.endswith("/v1/map/png")) as again:
        with page.expect_download() as download:
            page.click("#png")
    assert again.value.post_data_json == asked["request"]
    assert Path(download.value.path()).read_bytes() == api.content

    def refuse(route: Route) -> None:
        said = "40 panels; the limit is 16 (DTF_MAX_PNG_PANELS)"
        detail = [{"loc": ["body", "grid"], "msg": said, "type": "invalid_input"}]
        route.fulfill(
            status=422, content_type="application/json", body=json.dumps({"detail": detail})
        )

    page.route("**/v1/map/png", refuse)
    page.click("#png")
    page.wait_for_function("document.getElementById('png-status').textContent.startsWith('no')")
    assert page.text_content("#png-status") == (
        "no picture: grid: 40 panels; the limit is 16 (DTF_MAX_PNG_PANELS)"
    )


def test_the_optimiser_starts_where_the_part_is_now(page: Page, url: str) -> None:
    """The page had no start: the gain it showed was over the box's centre. A start typed in is
    sent (z the grid's), and the gain shown is the API's over it; an empty field beside filled
    ones is the API's error beside the start."""
    fill(page, {**SMALL, "opt-start-x": "-0.05", "opt-start-y": "0.35", "opt-start-yaw": "0.5"})
    with page.expect_request(lambda r: r.method == "POST" and "/v1/optimize" in r.url) as sent:
        page.click("#optimize")
    submitted = json.loads(sent.value.post_data or "{}")
    assert submitted["start"] == {"x": -0.05, "y": 0.35, "z": 0.1, "yaw": 0.5}
    page.wait_for_function(
        "document.getElementById('opt-mu').textContent.endsWith(' m/s')", timeout=120_000
    )
    api = httpx.post(f"{url}/v1/optimize", json=submitted, timeout=120).json()
    start = f"{api['start']['mu_path']:.6f} m/s"
    gain = f"+{api['improvement_percent']:.2f} %"
    assert page.text_content("#opt-improvement") == f"({gain} over the start, {start})"
    fill(page, {"opt-start-y": ""})
    page.click("#optimize")
    refused = {**submitted, "start": {**submitted["start"], "y": None}}
    detail = httpx.post(f"{url}/v1/optimize", json=refused).json()["detail"]
    assert [d["loc"][1:] for d in detail] == [["start", "y"]]
    assert error_beside(page, "start") == f"y: {detail[0]['msg']}"


def test_a_numeric_arms_branch_and_an_optimisation_after_a_fixed_branch_map_are_taken(
    page: Page, url: str
) -> None:
    """Found by a page audit: a Panda branch was sent as {"solution": "3"} (GET /v1/robots lists
    the indices as words) and refused; and with any branch chosen Optimise sent ik.branch,
    which /v1/optimize refuses (it takes the fastest). The index is sent as a number; the
    optimiser's request leaves the branch out."""
    page.select_option("#robot-model", "panda")
    page.select_option("#ik-branch", json.dumps({"solution": 3}, separators=(",", ":")))
    fill(page, {**SMALL, "yaws": "0"})
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    request = json.loads(sent.value.post_data or "{}")["request"]
    assert request["ik"]["branch"] == {"solution": 3}
    assert httpx.post(f"{url}/v1/map", json=request, timeout=120).status_code == 200
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=120_000)
    page.select_option("#robot-model", "ur5")
    page.select_option("#ik-branch", json.dumps(UR_BRANCH, separators=(",", ":")))
    fill(page, {**SMALL, "opt-spin-min": "0.5", "opt-spin-max": "1", "opt-start-x": "0",
                "opt-start-y": "0.4", "opt-start-yaw": "0"})  # fmt: skip
    with page.expect_request(lambda r: r.method == "POST" and "/v1/optimize" in r.url) as sent:
        page.click("#optimize")
    submitted = json.loads(sent.value.post_data or "{}")
    assert "branch" not in submitted["ik"]
    assert submitted["start"]["spin"] == 0.75  # the spin range's middle: 0 is outside it
    page.wait_for_function(
        "document.getElementById('opt-mu').textContent.endsWith(' m/s')", timeout=120_000
    )
    api = httpx.post(f"{url}/v1/optimize", json=submitted, timeout=120).json()
    assert page.text_content("#opt-mu") == f"{api['mu_path']:.6f} m/s"


UR_BRANCH = {"shoulder": "left", "elbow": "up", "wrist": "noflip"}


def test_a_cancelled_last_job_is_not_offered(page: Page, url: str) -> None:
    """It was offered, and showing it drew nothing: only queued, running and done jobs are."""
    fill(page, {**SMALL, "x-min": "-0.5", "x-max": "0.5", "x-step": "0.004",
                "y-min": "0.0", "y-max": "0.8", "y-step": "0.004"})  # fmt: skip
    page.click("#run")
    page.wait_for_function("document.getElementById('bar').value > 0", timeout=60_000)
    page.click("#cancel")
    page.wait_for_function(
        "document.getElementById('job-status').textContent.startsWith('cancelled')",
        timeout=10_000,
    )
    reload_page(page)
    assert page.is_hidden("#resume")


def test_a_map_cleared_or_a_resumed_job_left_is_offered_again(page: Page, url: str) -> None:
    """A map cleared by another robot, or a reopened job left by one, was offered again only
    after a reload: it is offered at once, and shown again as it was."""
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    cells = page.get_attribute("#summary", "data-cells")
    page.select_option("#robot-model", "ur10")
    page.wait_for_function("!document.getElementById('resume').hidden", timeout=10_000)
    assert "done" in (page.text_content("#resume-text") or "")
    page.click("#resume-show")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    assert page.get_attribute("#summary", "data-cells") == cells

    fill(page, {**SMALL, "x-min": "-0.5", "x-max": "0.5", "x-step": "0.004",
                "y-min": "0.0", "y-max": "0.8", "y-step": "0.004"})  # fmt: skip
    job_id = run_job(page)
    page.wait_for_function("document.getElementById('bar').value > 0", timeout=60_000)
    reload_page(page)
    page.click("#resume-show")
    page.wait_for_function(
        "document.getElementById('job-status').textContent.startsWith('running')"
    )
    page.select_option("#robot-model", "ur10")
    page.wait_for_function("!document.getElementById('resume').hidden", timeout=10_000)
    assert (page.text_content("#job-status") or "").startswith(f"no longer watched (job {job_id}")
    assert f"job {job_id}" in (page.text_content("#resume-text") or "")
    httpx.post(f"{url}/v1/jobs/{job_id}/cancel", timeout=30)


def test_earlier_maps_are_listed_and_shown_again(page: Page, url: str) -> None:
    """Only the last map job was offered after a reload: the service's earlier map jobs are
    listed, newest first, and any of them is drawn again with its own request."""
    ids = []
    for values in (SMALL, {**SMALL, "y-step": "0.1"}):  # 50 cells, then 30
        fill(page, values)
        ids.append(run_job(page))
        page.wait_for_function(
            "document.getElementById('job-status').textContent.startsWith('done')",
            timeout=60_000,
        )
    reload_page(page)
    assert page.is_visible("#earlier")
    page.click("#earlier summary")
    listed = page.eval_on_selector_all("#earlier-list li", "items => items.map(i => i.dataset.job)")
    assert ids[0] in listed and ids[1] in listed
    assert listed.index(ids[1]) < listed.index(ids[0])  # newest first
    page.click(f"#earlier-list li[data-job='{ids[0]}'] button")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    request = httpx.get(f"{url}/v1/jobs/{ids[0]}/request").json()["request"]
    api = httpx.post(f"{url}/v1/map", json=request, timeout=60).json()
    assert page.get_attribute("#summary", "data-cells") == str(len(api["cells"]))
    assert page.text_content("#best-mu") == f"{api['best']['mu_path']:.6f} m/s"


def test_a_late_offer_of_the_last_map_does_not_follow_a_newer_map(page: Page, url: str) -> None:
    """The audit's race: map A drawn, the robot changed (A offered again, its GET slow) and a
    map B run at once: B drawn, then 'Your last map, job A' appeared, whose 'Show it' replaced B."""
    fill(page, SMALL)
    first = run_job(page)
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    asked = []

    def slow(route: Route) -> None:
        asked.append(route.request.url)
        page.wait_for_timeout(1500)
        route.continue_()

    page.route(f"**/v1/jobs/{first}", slow)
    page.select_option("#robot-model", "ur10")
    fill(page, {**SMALL, "y-step": "0.1"})
    second = run_job(page)
    assert second != first
    page.wait_for_function(
        "document.getElementById('job-status').textContent.startsWith('done')", timeout=60_000
    )
    page.wait_for_timeout(2500)  # the slow answer about the first job has come meanwhile
    assert asked and page.is_hidden("#resume")
    assert page.get_attribute("#summary", "data-cells") == "30"  # the second map's


def test_another_clients_job_shown_from_earlier_maps_is_only_stopped_watching(
    page: Page, url: str
) -> None:
    """Audit 26's F1: a page showing another client's running map from Earlier maps cancelled
    it with its Cancel (its owner's page said only 'cancelled'), though a new robot or path
    leaves such a job running. Its Cancel now says and does 'Stop watching'."""
    body = json.loads((EXAMPLES / "evaluate_request.json").read_text())
    grid = {
        "x": {"min": -0.5, "max": 0.5, "step": 0.004},
        "y": {"min": 0.0, "max": 0.8, "step": 0.004},
    }
    request = {"robot": body["robot"], "path": body["path"], "grid": {**grid, "z": 0.1, "yaw": 0.0}}
    submitted = httpx.post(f"{url}/v1/jobs", json={"kind": "map", "request": request}, timeout=30)
    assert submitted.status_code == 202, submitted.text
    job_id = submitted.json()["id"]
    try:
        reload_page(page)
        page.click("#earlier summary")
        page.click(f"#earlier-list li[data-job='{job_id}'] button")
        page.wait_for_function(
            "document.getElementById('job-status').textContent.startsWith('running')",
            timeout=60_000,
        )
        assert page.text_content("#cancel") == "Stop watching"
        page.click("#cancel")
        page.wait_for_function(
            "document.getElementById('job-status').textContent.startsWith('no longer watched')"
        )
        assert f"job {job_id} runs on" in (page.text_content("#job-status") or "")
        assert page.text_content("#cancel") == "Cancel" and page.is_disabled("#cancel")
        status = httpx.get(f"{url}/v1/jobs/{job_id}", timeout=30).json()["status"]
        assert status in ("running", "done")
    finally:
        httpx.post(f"{url}/v1/jobs/{job_id}/cancel", timeout=30)
