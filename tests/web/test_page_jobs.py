"""The page's map job from submit to drawing, when the user or the network does not wait.

A double click submits one job; a poll that fails is asked again, saying whether the service
answered, and a job gone says so; a new path or robot while a job or an optimisation runs drops
its answer, and clears the map, the optimum and the cell shown; a map and an optimisation at
once show both; a map over DTF_JOB_PAGE_CELLS cells is read in pages of GET
/v1/jobs/{id}/result and drawn.
"""

from __future__ import annotations

import contextlib
from typing import Any

import httpx
import pytest
from playwright.sync_api import Error as PlaywrightError
from playwright.sync_api import Page, Route

from tests.web.conftest import PAGE_CELLS
from tests.web.test_page import (
    EXAMPLE_PATH,
    SMALL,
    cell_point,
    fill,
    grid_of,
    page_colour,
    run_small_map,
)
from tests.web.test_page_findings import choose_file


def map_posts(page: Page) -> list[str]:
    """The URLs of the page's map submissions (POST /v1/jobs), as they are sent."""
    posts: list[str] = []
    page.on(
        "request",
        lambda r: posts.append(r.url) if r.method == "POST" and r.url.endswith("/v1/jobs") else 0,
    )
    return posts


def test_a_double_click_on_run_submits_one_job(page: Page) -> None:
    posts = map_posts(page)
    fill(page, SMALL)
    page.dblclick("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    page.wait_for_timeout(300)
    assert len(posts) == 1
    assert page.is_enabled("#run") and page.is_disabled("#cancel")


def test_a_failed_poll_is_asked_again_and_the_map_drawn(page: Page) -> None:
    """One GET /v1/jobs/{id} that gets no answer (a network blip) ends nothing."""
    failed: list[str] = []

    def blip(route: Route) -> None:
        if not failed and route.request.method == "GET":
            failed.append(route.request.url)
            route.abort()
        else:
            route.continue_()

    page.route("**/v1/jobs/*", blip)
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=20_000)
    assert len(failed) == 1
    assert page.is_enabled("#run") and page.is_disabled("#cancel")
    assert (page.text_content("#job-status") or "").startswith("done: ")


def test_a_service_down_for_longer_than_a_few_seconds_is_waited_for(page: Page) -> None:
    """Audit 26's O2: the page gave up on its job after 7.5 s of polls with no answer, though a
    first start after an upgrade takes minutes and the job survives it. Its polls go unanswered
    for 9 s here (five in a row, where the old schedule gave up): it keeps asking, draws the map."""
    failed: list[str] = []
    down: list[float] = []

    def restarting(route: Route) -> None:
        if route.request.method == "GET":
            now = page.evaluate("performance.now()")
            down.append(down[0] if down else now)
            if now - down[0] < 9_000:
                failed.append(route.request.url)
                route.abort()
                return
        route.continue_()

    page.route("**/v1/jobs/*", restarting)
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    assert len(failed) >= 5  # as many as the old schedule gave up after, and more
    assert (page.text_content("#job-status") or "").startswith("done: ")


def test_a_poll_answered_with_a_5xx_says_the_status_and_is_asked_again(page: Page) -> None:
    """The service answered (a 503, the job store unusable): the note says so, not "no answer"."""
    answered: list[str] = []
    held: list[Route] = []  # the poll after the 503, until the note is read

    def unavailable(route: Route) -> None:
        if route.request.method != "GET":
            route.continue_()
        elif not answered:
            answered.append(route.request.url)
            detail = [
                {"loc": [], "msg": "the job store is locked", "type": "job_store_unavailable"}
            ]
            route.fulfill(status=503, json={"detail": detail}, headers={"Retry-After": "30"})
        elif not held:
            held.append(route)
        else:
            route.continue_()

    page.route("**/v1/jobs/*", unavailable)
    fill(page, SMALL)
    page.click("#run")
    while not held:
        page.wait_for_timeout(50)
    eta = page.text_content("#eta") or ""
    assert eta.startswith("the service answered 503 (") and eta.endswith(
        "the job store is locked): asking again"
    ), eta
    held[0].continue_()
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=20_000)
    assert (page.text_content("#job-status") or "").startswith("done: ")


def test_a_job_deleted_by_another_client_says_so_and_run_is_back(page: Page, url: str) -> None:
    deleted: list[int] = []

    def delete_first(route: Route) -> None:  # another client deletes the job before a poll
        if not deleted and route.request.method == "GET":
            deleted.append(httpx.delete(route.request.url).status_code)
        route.continue_()

    page.route("**/v1/jobs/*", delete_first)
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("!document.getElementById('run').disabled", timeout=20_000)
    assert deleted == [204]
    job = page.text_content("#job-status") or ""
    assert job.startswith("no map: job ") and "is gone (404" in job, job
    assert page.is_disabled("#cancel") and page.locator(".panel").count() == 0


OTHER_PROGRAM = "UNITS/MM\nGOTO/0,0,0,0,0,1\nGOTO/50,0,0,0,0,1\nGOTO/50,50,0,0,0,1\n"


@pytest.mark.parametrize("change", ["path", "robot"])
def test_a_new_path_or_robot_drops_the_running_jobs_map(page: Page, change: str) -> None:
    """The old job's polls are held until the new input is in: then its answer draws nothing."""
    held: list[Route] = []
    page.route(
        "**/v1/jobs/*", lambda r: held.append(r) if r.request.method == "GET" else r.continue_()
    )
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("!document.getElementById('cancel').disabled", timeout=20_000)
    while not held:
        page.wait_for_timeout(50)
    job = held[0].request.url
    cancels: list[str] = []
    page.on("request", lambda r: cancels.append(r.url) if r.url.endswith("/cancel") else 0)
    if change == "path":
        choose_file(page, "#path-file", "other.cl", OTHER_PROGRAM)
        page.wait_for_function("document.getElementById('import').dataset.waypoints === '3'")
    else:
        page.select_option("#robot-model", "ur10")
    for route in held:  # the old job's answer comes now
        route.continue_()
    page.unroute("**/v1/jobs/*")
    while httpx.get(job).json()["status"] in ("queued", "running"):
        page.wait_for_timeout(100)
    page.wait_for_timeout(500)  # the page's polls, were it still watching, have seen it end
    assert page.locator(".panel").count() == 0
    assert page.text_content("#summary") == ""
    assert (page.text_content("#job-status") or "").startswith("cancelled: ")
    assert page.is_enabled("#run") and page.is_disabled("#cancel")
    assert cancels == [f"{job}/cancel"]  # and the job stopped on the service


@pytest.mark.parametrize("change", ["path", "robot"])
def test_a_new_path_or_robot_drops_the_running_optimisation(page: Page, change: str) -> None:
    """The optimisation's request is held until the new input is in: its answer shows nothing."""
    held: list[Route] = []
    page.route("**/v1/optimize", lambda r: held.append(r))
    failed: list[str] = []
    page.on("requestfailed", lambda r: failed.append(r.url) if r.url.endswith("/optimize") else 0)
    fill(page, SMALL)
    page.click("#optimize")
    while not held:
        page.wait_for_timeout(50)
    if change == "path":
        choose_file(page, "#path-file", "other.cl", OTHER_PROGRAM)
        page.wait_for_function("document.getElementById('import').dataset.waypoints === '3'")
    else:
        page.select_option("#robot-model", "ur10")
    with contextlib.suppress(PlaywrightError):  # the page aborted it: nothing to answer
        held[0].fulfill(response=held[0].fetch(timeout=60_000))  # the old optimum comes now
    page.wait_for_timeout(300)  # the page, were it still waiting, has shown it
    assert (page.text_content("#opt-mu") or "").startswith("cancelled: ")
    assert page.text_content("#opt-where") == "" and page.is_hidden("#frames")
    assert failed == [held[0].request.url]  # aborted: the service stops the search
    assert page.text_content("#form-error") == ""


@pytest.mark.parametrize("change", ["path", "robot"])
def test_a_new_path_or_robot_clears_the_map_the_optimum_and_the_cell(
    page: Page, url: str, change: str
) -> None:
    """A cell clicked on the old map is being evaluated: its answer shows nothing either."""
    api = run_small_map(page, url)
    page.click("#optimize")
    page.wait_for_selector(".panel canvas[data-optimum='1']", timeout=20_000)
    held: list[Route] = []
    page.route("**/v1/evaluate", lambda r: held.append(r))
    cell = next(c for c in api["cells"] if c["mu_path"] is not None)
    page.mouse.click(**cell_point(page, 0, cell, api))
    while not held:
        page.wait_for_timeout(50)
    if change == "path":
        choose_file(page, "#path-file", "other.cl", OTHER_PROGRAM)
        page.wait_for_function("document.getElementById('import').dataset.waypoints === '3'")
    else:
        page.select_option("#robot-model", "ur10")
    held[0].continue_()  # the old cell's evaluation comes now
    page.wait_for_timeout(500)  # the page, were it still waiting, has shown it
    assert (page.text_content("#cell-summary") or "").startswith("Click")
    assert page.get_attribute("#plot", "data-drawn") is None
    assert page.locator(".panel").count() == 0 and page.text_content("#summary") == ""
    assert page.text_content("#opt-mu") == "" and page.is_hidden("#frames")
    assert (page.text_content("#job-status") or "").startswith("map cleared: ")


class Held:
    """The page's API requests of one method to URLs holding ``part``, held while ``holding``;
    every other request goes on."""

    def __init__(self, page: Page, method: str, part: str) -> None:
        self.routes: list[Route] = []
        self.holding = True

        def hold(route: Route) -> None:
            request = route.request
            if self.holding and request.method == method and part in request.url:
                self.routes.append(route)
            else:
                route.continue_()

        page.route("**/v1/**", hold)

    def first(self, page: Page) -> None:
        """Wait until one request is held."""
        while not self.routes:
            page.wait_for_timeout(50)


def test_a_map_run_during_an_optimisation_cancels_it(page: Page) -> None:
    """Run asks a map of the inputs as they are now: an optimisation under way (of the inputs
    when Optimise was clicked) is cancelled and its answer never shown; its mu_path line says
    so. (An optimum kept across a Run was marked on a map of other inputs: the README's
    cell example then showed the no-cell optimum's marker on the collision cell.)"""
    held = Held(page, "POST", "/v1/optimize")
    fill(page, SMALL)
    page.click("#optimize")
    held.first(page)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=20_000)
    for route in held.routes:
        route.abort()
    assert (page.text_content("#opt-mu") or "").startswith("cancelled: a map was run")
    assert page.query_selector(".panel canvas[data-optimum='1']") is None
    assert page.get_attribute("#summary", "data-cells") == "50"


def test_an_optimum_found_while_a_map_job_runs_is_marked_on_its_map(page: Page) -> None:
    """The optimum comes first, the map after: it is marked on the map once drawn."""
    held = Held(page, "GET", "/v1/jobs/")
    fill(page, SMALL)
    page.click("#run")
    held.first(page)
    page.click("#optimize")
    page.wait_for_function("document.getElementById('opt-where').textContent", timeout=20_000)
    held.holding = False
    for route in held.routes:
        route.continue_()
    page.wait_for_selector(".panel canvas[data-optimum='1']", timeout=20_000)
    assert page.is_visible("#opt-mu-line") and page.is_visible("#frames")
    assert (page.text_content("#opt-mu") or "").endswith(" m/s")
    assert (page.text_content("#job-status") or "").startswith("done: ")


REASON_COLOURS = {  # app.js's
    "unreachable": (224, 224, 224),
    "joint_limits": (244, 166, 192),
    "singular": (85, 85, 85),
    "discontinuous": (255, 183, 77),
}


def test_a_map_over_the_page_size_is_read_in_pages_and_drawn(page: Page, url: str) -> None:
    """11 x 6 cells at 2 yaws: 132 cells, the job's answer without them, 3 pages of 60."""
    values = {**SMALL, "x-step": "0.02", "y-step": "0.04"}
    pages = []
    page.on("request", lambda r: pages.append(r.url) if "/result?" in r.url else 0)
    first: list[Route] = []  # held until the page has said what it reads
    page.route("**/result?*", lambda r: r.continue_() if first else first.append(r))
    fill(page, values)
    page.click("#run")
    while not first:
        page.wait_for_timeout(50)
    assert page.text_content("#job-status") == "done: reading the map's cells, 0 of 132"
    first[0].continue_()
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=30_000)
    body = {"robot": {"model": "ur5"}, "path": EXAMPLE_PATH, "grid": grid_of(values)}
    api = httpx.post(f"{url}/v1/map", json=body, timeout=60).json()
    cells: list[dict[str, Any]] = api["cells"]
    assert len(cells) == 132 and len(pages) == -(-132 // PAGE_CELLS)
    assert page.get_attribute("#summary", "data-cells") == "132"
    assert page.locator(".panel canvas").count() == 2
    assert page.text_content("#best-mu") == f"{api['best']['mu_path']:.6f} m/s"
    # Every cell painted in its colour, the last page's (the second panel's end) too.
    mus = [c["mu_path"] for c in cells if c["mu_path"] is not None]
    low, high = min(mus), max(mus)
    painted = page.evaluate(
        """() => [...document.querySelectorAll('.panel canvas')].flatMap((canvas) => {
            const size = Number(canvas.dataset.cell), nx = Number(canvas.dataset.nx);
            const ny = Number(canvas.dataset.ny), g = canvas.getContext('2d'), out = [];
            for (let k = 0; k < nx * ny; k++) {
                const i = k % nx, j = Math.floor(k / nx);
                const at = [i * size + size / 2, (ny - 1 - j) * size + size / 2];
                out.push([...g.getImageData(at[0], at[1], 1, 1).data.slice(0, 3)]);
            }
            return out;
        })"""
    )
    want = [
        list(REASON_COLOURS[c["reason"]])
        if c["mu_path"] is None
        else list(page_colour((c["mu_path"] - low) / (high - low)))
        for c in cells
    ]
    assert painted == want
    assert page.is_enabled("#run") and page.is_disabled("#cancel")


def test_a_map_of_131044_cells_is_drawn(page: Page) -> None:
    """The page's own drawMap on a 362 x 362 answer: Math.min(...cells) would throw."""
    drawn = page.evaluate(
        """() => {
            const n = 362, cells = [];
            for (let k = 0; k < n * n; k++) {
                cells.push({ x: (k % n) / 1000, y: Math.floor(k / n) / 1000, yaw: 0, spin: 0,
                    mu_path: 0.1 + k / 1e7, reason: null, bottleneck_joint: 0,
                    bottleneck_waypoint: 0, branch: {} });
            }
            const top = cells[n * n - 1];
            const best = { placement: { ...top, z: 0.1 }, mu_path: top.mu_path };
            drawMap({ cells, feasible_cells: n * n, best, worst: best });
            return [document.getElementById('summary').dataset.cells,
                document.getElementById('cb-min').textContent,
                document.getElementById('cb-max').textContent];
        }"""
    )
    assert drawn == ["131044", "0.100 m/s", "0.113 m/s"]
