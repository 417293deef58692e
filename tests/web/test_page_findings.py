"""The page's rough edges found in headless Chromium (issue 26), each checked in the browser.

A broken file shows its error and leaves no path; a CSV states no units, so the page asks for
them and a metres CSV reads as metres; the colour map has axes with ticks in metres; the
controller frames are rounded and carry their units; stale results go; the spin mode and the
optimiser's yaw range reach the README's free-spin figures; a URDF is taken as written; an
empty z is refused beside the field; no request of the page's ends in a 404.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import httpx
import pytest
from playwright.sync_api import Browser, Page

from tests.cases import ROOT
from tests.solver.families.recognised import bent_elbow
from tests.web.conftest import ARTIFACTS, snapshot
from tests.web.test_page import ACC, EXAMPLE_PATH, SMALL, cell_point, fill, grid_of, run_small_map

README = (ROOT / "README.md").read_text()


def error_beside(page: Page, loc: str) -> str:
    """The error text beside the field of ``loc``, once there is one."""
    selector = f".field[data-loc='{loc}'] .error"
    page.wait_for_function(
        f'document.querySelector("{selector}").textContent !== ""', timeout=30_000
    )
    return page.text_content(selector) or ""


def job_count(url: str) -> int:
    return len(httpx.get(f"{url}/v1/jobs", params={"limit": 100}).json()["jobs"])


def choose_file(page: Page, field: str, name: str, text: str) -> None:
    page.set_input_files(
        field, files=[{"name": name, "mimeType": "text/plain", "buffer": text.encode()}]
    )


# ---- a broken file, a CSV's units ---------------------------------------------------------------
def test_a_broken_json_file_shows_its_error_and_no_map_runs_the_old_path(
    page: Page, url: str
) -> None:
    page.wait_for_function("document.getElementById('import').dataset.waypoints")
    choose_file(page, "#path-file", "broken.json", '{"waypoints": [{"position": [0, 0')
    error = error_beside(page, "path")
    assert error.startswith("broken.json is not JSON: ")
    assert page.text_content("#path-info") == "broken.json: not read, no path"
    assert page.text_content("#import-summary") == ""  # the old path's reading is gone
    before = job_count(url)
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function(
        "document.querySelector(\".field[data-loc='path'] .error\").textContent"
        ".startsWith('No path to run')"
    )
    assert "broken.json is not JSON" in (page.text_content(".field[data-loc='path'] .error") or "")
    page.wait_for_timeout(500)
    assert job_count(url) == before  # no map of the previous path
    assert page.get_attribute("#summary", "data-cells") is None


def metres_csv() -> str:
    """A 0.1 m line along x, its tool axis tilting by 0.3 rad along it, written in metres."""
    rows = [
        f"{0.01 * k:.2f},0.0,0.0,{math.sin(0.03 * k):.9f},0,{math.cos(0.03 * k):.9f}"
        for k in range(11)
    ]
    return "x,y,z,i,j,k\n" + "\n".join(rows) + "\n"


def test_a_csv_states_no_units_so_the_page_asks_and_a_metres_csv_reads_as_metres(
    page: Page, url: str
) -> None:
    choose_file(page, "#path-file", "line_m.csv", metres_csv())
    assert error_beside(page, "path.units") == (
        "line_m.csv: a CSV file states no units; choose mm, inch or m here"
    )
    assert page.get_attribute("#import", "data-waypoints") is None  # not read as mm
    snapshot(page, "csv-asks-for-units")
    page.select_option("#path-units", "m")
    page.wait_for_function("document.getElementById('import').dataset.waypoints", timeout=30_000)
    assert page.text_content("#import-units") == "m (request: the request's units (m))"
    assert "100.0 mm of path" in (page.text_content("#import-summary") or "")
    fill(page, {**SMALL, "yaws": "0"})
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    path = {"csv": metres_csv(), "units": "m"}
    grid = {**grid_of(SMALL), "yaw": [0.0]}
    api = httpx.post(
        f"{url}/v1/map", json={"robot": {"model": "ur5"}, "path": path, "grid": grid}, timeout=60
    ).json()
    assert page.text_content("#best-mu") == f"{api['best']['mu_path']:.6f} m/s"
    millimetres = httpx.post(
        f"{url}/v1/map",
        json={"robot": {"model": "ur5"}, "path": {**path, "units": "mm"}, "grid": grid},
        timeout=60,
    ).json()
    # Read as mm, the same tilt over 0.1 mm: a thousandth of the speed, as the issue saw it.
    assert millimetres["best"]["mu_path"] < api["best"]["mu_path"] / 100


# ---- the colour map's axes -------------------------------------------------------------------
def test_the_colour_map_has_axes_with_ticks_in_metres_and_panel_titles(
    page: Page, url: str
) -> None:
    api = run_small_map(page, url)
    xs = sorted({c["x"] for c in api["cells"]})
    ys = sorted({c["y"] for c in api["cells"]})
    for panel, yaw in enumerate([0.0, 1.5]):
        figure = page.locator(".panel").nth(panel)
        canvas = figure.locator("canvas")
        box = canvas.bounding_box()
        assert box is not None
        size = int(canvas.get_attribute("data-cell") or 0)
        title = figure.locator(".panel-title").text_content() or ""
        assert title == f"yaw {yaw:.4f} rad ({math.degrees(yaw):.2f} deg), spin 0.0000 rad"
        assert figure.locator(".axis-title").all_text_contents() == ["x (m)", "y (m)"]
        for axis, values, centre in (("x", xs, "x"), ("y", ys, "y")):
            labels = figure.locator(f".tick-{axis}")
            assert labels.count() >= 3
            for k in range(labels.count()):
                value = float(labels.nth(k).text_content() or "nan")
                assert values[0] - 1e-9 <= value <= values[-1] + 1e-9
                # Where the label sits is where that value's cell centre is on the canvas.
                cell = (value - values[0]) / (values[1] - values[0])
                want = (
                    box["x"] + (cell + 0.5) * size
                    if axis == "x"
                    else box["y"] + (len(values) - 0.5 - cell) * size
                )
                label = labels.nth(k).bounding_box()
                assert label is not None
                got = label[centre] + label["width" if axis == "x" else "height"] / 2
                assert abs(got - want) <= 2.0, (axis, value, got, want)


# ---- stale results -----------------------------------------------------------------------------
def test_stale_results_go_when_a_new_job_starts_and_beside_a_new_error(
    page: Page, url: str
) -> None:
    api = run_small_map(page, url)
    cell = next(c for c in api["cells"] if c["mu_path"] is not None)
    page.mouse.click(**cell_point(page, 0, cell, api))
    page.wait_for_selector("#plot[data-drawn='1']", timeout=60_000)
    fill(page, {"x-min": "-0.5", "x-max": "0.5", "x-step": "0.004", "y-min": "0.0"})
    fill(page, {"y-max": "0.8", "y-step": "0.004"})
    page.click("#run")
    page.wait_for_function("document.getElementById('bar').value > 0", timeout=60_000)
    assert page.locator(".panel").count() == 0  # during the new job: no old map
    assert page.text_content("#summary") == ""
    assert page.text_content("#best-mu") == ""
    assert page.get_attribute("#plot", "data-drawn") is None
    assert page.text_content("#cell-summary", timeout=1000).startswith("Click")
    snapshot(page, "stale-cleared-during-a-new-job")
    page.click("#cancel")
    page.wait_for_function(
        "document.getElementById('job-status').textContent.startsWith('cancelled')",
        timeout=10_000,
    )
    fill(page, SMALL)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    fill(page, {"x-step": "0"})
    page.click("#run")
    assert error_beside(page, "grid.x.step")
    assert page.locator(".panel").count() == 0  # beside the new error: no old map
    assert page.text_content("#best-mu") == ""
    assert page.text_content("#job-status") == "no map: see the errors above"


# ---- spin mode, the optimiser's yaw range, the frames ------------------------------------------
def readme_line(prefix: str) -> str:
    block = README.split("## Five-axis: let the tool spin", 1)[1]
    return next(line for line in block.splitlines() if line.startswith(prefix))


def test_spin_free_and_any_yaw_reach_the_readmes_free_spin_figures(page: Page, url: str) -> None:
    """The README's +325 % at its placement, and its free-spin optimum, from the page alone."""
    assert [page.input_value(f"#{k}") for k in ("x-min", "x-max", "y-min", "y-max", "z")] == [
        "-0.25",
        "0.25",
        "0.25",
        "0.65",
        "0.1",
    ]  # the README's box and height are the page's defaults
    page.select_option("#spin-mode", "free")
    fill(page, {"yaws": "0"})
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    assert (page.locator(".panel-title").first.text_content() or "").endswith("+ free rate")
    api = httpx.post(
        f"{url}/v1/map",
        json={
            "robot": {"model": "ur5"},
            "path": EXAMPLE_PATH,
            "grid": {
                "x": {"min": -0.25, "max": 0.25, "step": 0.05},
                "y": {"min": 0.25, "max": 0.65, "step": 0.05},
                "z": 0.1,
                "yaw": [0.0],
            },
            "spin_mode": "free",
        },
        timeout=60,
    ).json()
    cell = next(c for c in api["cells"] if c["x"] == 0.0 and abs(c["y"] - 0.45) < 1e-9)
    page.mouse.click(**cell_point(page, 0, cell, api))
    page.wait_for_function(
        "document.getElementById('cell-summary').textContent.includes('over the spin fixed')",
        timeout=60_000,
    )
    summary = page.text_content("#cell-summary") or ""
    free = re.search(r"mu_path = (\S+) m/s.*\((\+\d+ %)\)", readme_line("free spin:"))
    fixed = re.search(r"mu_path = (\S+) m/s", readme_line("fixed spin:"))
    assert free and fixed
    assert summary.startswith(f"x 0.0000 m, y 0.4500 m, yaw 0.0000 rad: mu_path {free[1]} m/s")
    assert f"spin free: {free[2]} over the spin fixed ({fixed[1]} m/s)" in summary
    snapshot(page, "spin-free-cell-gain")

    page.check("#opt-any-yaw")
    assert page.is_disabled("#opt-yaw-min") and page.is_disabled("#opt-yaw-max")
    page.click("#optimize")
    page.wait_for_function(
        "document.getElementById('frames').tBodies[0].rows.length", timeout=300_000
    )
    optimum = re.search(
        r"mu_path = (\S+) m/s at x (\S+) m, y (\S+) m, yaw (\S+) rad",
        readme_line("free-spin optimum:"),
    )
    assert optimum
    assert page.text_content("#opt-mu") == f"{optimum[1]} m/s"
    where = page.text_content("#opt-where") or ""
    assert where.startswith(f"x {optimum[2]} m, y {optimum[3]} m, z 0.1000 m, yaw {optimum[4]} rad")
    assert where.endswith("spin free")
    check_frames(page, url)


def check_frames(page: Page, url: str) -> None:
    """The optimum's frames as the page shows them: the API's, rounded, with their units."""
    body = {
        "robot": {"model": "ur5"},
        "path": EXAMPLE_PATH,
        "bounds": {"x": [-0.25, 0.25], "y": [0.25, 0.65], "yaw": [-math.pi, math.pi]},
        "z": 0.1,
        "spin_mode": "free",
    }
    frames = httpx.post(f"{url}/v1/optimize", json=body, timeout=300).json()["placement"]["frames"]

    def r(value: float, digits: int) -> str:
        text = f"{value:.{digits}f}"
        return text.lstrip("-") if float(text) == 0 else text

    kuka, ur, abb = frames["kuka"], frames["ur"], frames["abb"]
    expected = {
        "kuka": (
            "{"
            + ", ".join(f"{k} {r(kuka[k], 3)}" for k in "XYZ")
            + ", "
            + ", ".join(f"{k} {r(kuka[k], 4)}" for k in "ABC")
            + "}",
            "mm, deg",
        ),
        "ur": ("p[" + ", ".join(r(v, 6) for v in ur) + "]", "m, rotation vector in rad"),
        "abb": (
            f"[[{', '.join(r(v, 3) for v in abb[0])}], [{', '.join(r(v, 6) for v in abb[1])}]]",
            "mm; quaternion w-first [q1 = w, q2 = x, q3 = y, q4 = z]",
        ),
    }
    for controller, (text, units) in expected.items():
        row = page.locator(f"#frames tr[data-controller='{controller}']")
        assert row.locator("code").text_content() == text
        assert (row.locator("td").nth(2).text_content() or "").startswith(units)
    shown = page.text_content("#frames") or ""
    assert not re.search(r"\d\.\d{7,}", shown)  # nothing printed to 13 decimals
    assert abb[1][0] == pytest.approx(math.cos(0.5 * kuka["A"] * math.pi / 180), abs=1e-9)


# ---- an own URDF, an empty z, the favicon ----------------------------------------------------
def ur5_urdf() -> str:
    import importlib.metadata

    dist = importlib.metadata.distribution("example-robot-data")
    root = "cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
    return Path(str(dist.locate_file(root))).read_text()


def test_a_urdf_file_is_taken_as_written_and_a_missing_frame_says_so_once(
    page: Page, url: str
) -> None:
    page.click("#own-urdf summary")
    choose_file(page, "#urdf-file", "ur5_robot.urdf", ur5_urdf())
    page.wait_for_function("document.getElementById('urdf').value.length > 0")
    assert page.input_value("#base-frame") == "base"  # REP 199's, the controller's frame
    assert "REP 199's controller frame" in (page.text_content("#base-frame-hint") or "")
    assert page.input_value("#tool-frame") == ""  # three tip links: the user chooses
    assert page.is_visible("#urdf-note") and page.is_disabled("#robot-model")
    small = {**SMALL, "x-step": "0.1", "y-step": "0.1", "yaws": "0"}
    fill(page, small)
    page.click("#run")
    assert error_beside(page, "robot.tool_frame") == "Field required"
    assert page.text_content(".field[data-loc='robot'] .error") == ""
    assert page.text_content("#form-error") == ""
    snapshot(page, "urdf-missing-tool-frame")
    page.fill("#tool-frame", "tool0")
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=120_000)
    robot = {"urdf": ur5_urdf(), "base_frame": "base", "tool_frame": "tool0"}
    grid = {**grid_of(small), "yaw": [0.0]}
    api = httpx.post(
        f"{url}/v1/map", json={"robot": robot, "path": EXAMPLE_PATH, "grid": grid}, timeout=120
    ).json()
    assert page.text_content("#best-mu") == f"{api['best']['mu_path']:.6f} m/s"
    assert page.text_content("#ik-line") == f"IK in closed form: {api['recognised']}"


def test_how_a_urdfs_ik_is_solved_is_said_under_the_map(page: Page, url: str) -> None:
    # ee_link (a tool frame turned on the DH flange) and a frame tilted about x (joint 1 not
    # upright in it) are recognised: the API's sentence; with its elbow's axis turned by a mrad
    # the chain is no UR arm's: numeric IK, said so.
    joint = (
        '<link name="tilted"/><joint name="tilted_joint" type="fixed"><parent link="base_link"/>'
        '<child link="tilted"/><origin xyz="0 0 0" rpy="0.3 0 0"/></joint>'
    )
    text = ur5_urdf().replace("</robot>", joint + "</robot>")
    bent = bent_elbow(text)
    page.click("#own-urdf summary")
    small = {**SMALL, "x-step": "0.1", "y-step": "0.1", "yaws": "0"}
    grid = {**grid_of(small), "yaw": [0.0]}
    for urdf, base, tool in (
        (text, "base_link", "ee_link"),
        (text, "tilted", "tool0"),
        (bent, "base_link", "tool0"),
    ):
        choose_file(page, "#urdf-file", "ur5_variant.urdf", urdf)
        page.wait_for_function("document.getElementById('urdf').value.length > 0")
        fill(page, small)
        page.fill("#base-frame", base)
        page.fill("#tool-frame", tool)
        page.click("#run")
        page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=120_000)
        robot = {"urdf": urdf, "base_frame": base, "tool_frame": tool}
        body = {"robot": robot, "path": EXAMPLE_PATH, "grid": grid}
        api = httpx.post(f"{url}/v1/map", json=body, timeout=120).json()
        shown = page.text_content("#ik-line") or ""
        if tool == "ee_link":
            assert "whose tool frame is the DH flange turned by 120 deg" in api["recognised"]
            assert shown == f"IK in closed form: {api['recognised']}"
        elif urdf is text:
            assert "tilted by 17.1887 deg about (-1, 0, 0)" in api["recognised"]
            assert shown == f"IK in closed form: {api['recognised']}"
        else:
            assert api["recognised"] is None
            assert shown.startswith("IK numeric") and "no OPW or UR arm's" in shown


def test_a_urdf_without_the_controllers_frame_gets_its_root_link(page: Page) -> None:
    text = ur5_urdf()  # without its link base (REP 199's controller frame) and that link's joint
    joint = text.index('"base_link-base_fixed_joint"')
    text = text.replace(
        text[text.index('<link name="base">') : text.index("</joint>", joint) + 8], ""
    )
    page.click("#own-urdf summary")
    choose_file(page, "#urdf-file", "ur5_no_base.urdf", text)
    page.wait_for_function("document.getElementById('urdf').value.length > 0")
    assert page.input_value("#base-frame") == "world"  # the chain's one root link
    hint = page.text_content("#base-frame-hint") or ""
    assert hint.startswith("world: the URDF's root link") and "no REP 199" in hint
    page.fill("#base-frame", "base_link")  # a frame of the user's: no hint of ours
    assert page.text_content("#base-frame-hint") == ""


def test_a_link_no_joint_names_is_no_frame_and_the_map_says_what_the_api_changed(
    page: Page, url: str
) -> None:
    # As the ROS 2 generated UR5e: <link name="world"/> joined to nothing; here without the
    # controller frame "base" too. The page fills the base frame with the chain's one root,
    # base_link (the stray link is no root: with it, there would be two and none filled), and
    # under the map says what the API left out, as its answer's robot_read says.
    text = ur5_urdf()
    for name in ("world_joint", "base_link-base_fixed_joint"):
        start = text.index(f'<joint name="{name}"')
        text = text[:start] + text[text.index("</joint>", start) + len("</joint>") :]
    start = text.index('<link name="base">')
    text = text[:start] + text[text.index("</link>", start) + len("</link>") :]
    start = text.index('<joint name="wrist_3_joint"')  # and, as Kinova's, a continuous joint
    end = text.index("</joint>", start)
    joint = re.sub(r' (lower|upper)="[^"]*"', "", text[start:end])
    text = text[:start] + joint.replace('"revolute"', '"continuous"') + text[end:]
    page.click("#own-urdf summary")
    choose_file(page, "#urdf-file", "ur5e_ros2_like.urdf", text)
    page.wait_for_function("document.getElementById('urdf').value.length > 0")
    assert page.input_value("#base-frame") == "base_link"
    page.fill("#tool-frame", "tool0")
    small = {**SMALL, "x-step": "0.1", "y-step": "0.1", "yaws": "0"}
    fill(page, small)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=120_000)
    robot = {"urdf": text, "base_frame": "base_link", "tool_frame": "tool0"}
    grid = {**grid_of(small), "yaw": [0.0]}
    api = httpx.post(
        f"{url}/v1/map", json={"robot": robot, "path": EXAMPLE_PATH, "grid": grid}, timeout=120
    ).json()
    assert api["robot_read"] == {
        "left_out_links": ["world"],
        "left_out_count": 1,
        "continuous_joints": ["wrist_3_joint"],
        "unlimited_joints": ["wrist_3_joint"],
        "locked_joints": [],
    }
    shown = page.text_content("#ik-line") or ""
    assert shown == (
        f"IK in closed form: {api['recognised']}; left out of the URDF, no joint names them: "
        "'world'; continuous joints read as revolute: 'wrist_3_joint' (no position limit: "
        "'wrist_3_joint')"
    )
    snapshot(page, "urdf-left-out-link")


# ---- a decimal comma in a list of yaws or spins ----------------------------------------------
def test_a_lists_reading_is_said_beside_it_and_a_decimal_comma_is_named(page: Page) -> None:
    """A list "1,57" is two yaws (1 and 57 rad, which the API takes): the page says so as typed.

    The angles a value beyond a turn is the same as, by hand: 57 - 9 (2 pi) = 0.45133,
    14 - 2 (2 pi) = 1.43363, -7 + 2 pi = -0.71681.
    """
    assert page.text_content("#yaws-read") == ""  # one yaw, 0: nothing to say
    page.fill("#yaws", "0, 1,57")
    assert page.text_content("#yaws-read") == (
        "read as 3 yaws: 0, 1, 57 rad; 57 rad is more than a turn (the same as 0.4513 rad): "
        "a decimal takes a point (1.57, not 1,57)"
    )
    assert "too-large" in (page.get_attribute("#yaws-read", "class") or "")
    page.fill("#yaws", "0, 1.57")
    assert page.text_content("#yaws-read") == "read as 2 yaws: 0, 1.57 rad"
    assert "too-large" not in (page.get_attribute("#yaws-read", "class") or "")
    page.fill("#spins", "3,14")
    assert page.text_content("#spins-read") == (
        "read as 2 spins: 3, 14 rad; 14 rad is more than a turn (the same as 1.4336 rad): "
        "a decimal takes a point (3.14, not 3,14)"
    )
    page.fill("#yaws", "-7")
    assert page.text_content("#yaws-read") == "-7 rad is more than a turn (the same as -0.7168 rad)"
    snapshot(page, "list-reading")


UNREAD = "not a number as typed (the browser reads it as empty); a decimal takes a point"


@pytest.mark.parametrize("button", ["#run", "#optimize"])
def test_a_number_the_browser_cannot_read_is_refused_beside_its_field_not_left_out(
    page: Page, url: str, button: str
) -> None:
    """A "1e400" in a number field: its value is "", which read as empty dropped a table.

    The browser's own reading, checked first: the field's value is "" and its badInput is set.
    """
    before = job_count(url)
    fill(page, SMALL)
    page.eval_on_selector_all("details", "els => els.forEach(e => e.open = true)")
    page.fill("#table-height", "1e400")
    page.fill("#tcp-yaw", "1e400")
    assert page.evaluate(
        "['table-height', 'tcp-yaw'].map((id) => [document.getElementById(id).value,"
        " document.getElementById(id).validity.badInput])"
    ) == [["", True], ["", True]]
    page.eval_on_selector_all("details", "els => els.forEach(e => e.open = false)")
    page.click(button)
    assert error_beside(page, "cell.table") == UNREAD
    assert error_beside(page, "robot.tcp") == f"tcp yaw (deg): {UNREAD}"
    assert page.evaluate("document.getElementById('cell-details').open")  # the error is seen
    page.wait_for_timeout(500)
    assert job_count(url) == before
    status = "#job-status" if button == "#run" else "#opt-mu"
    assert page.text_content(status) == (
        "no map: see the errors above" if button == "#run" else "no optimum: see the errors above"
    )


def test_an_unreadable_size_of_a_box_just_added_is_refused_beside_the_box(page: Page) -> None:
    page.eval_on_selector_all("details", "els => els.forEach(e => e.open = true)")
    page.click("#add-box")
    page.fill("#cell-boxes input[aria-label='box 1 ly (m)']", "1e400")
    page.click("#run")
    assert error_beside(page, "cell.fixed.0.box.size") == f"box 1 ly (m): {UNREAD}"
    assert page.text_content("#form-error") == ""


def test_a_feed_the_browser_cannot_read_is_refused_beside_it(page: Page, url: str) -> None:
    api = run_small_map(page, url)
    page.fill("#feed", "1e400")
    point = cell_point(page, 0, api["cells"][0], api)
    page.mouse.click(point["x"], point["y"])
    assert error_beside(page, "feed") == UNREAD
    assert page.text_content("#cell-summary") == "no evaluation: see the errors above"


@pytest.mark.parametrize("button", ["#run", "#optimize"])
def test_an_empty_z_is_refused_beside_the_field_not_read_as_zero(
    page: Page, url: str, button: str
) -> None:
    before = job_count(url)
    fill(page, {**SMALL, "z": ""})
    page.click(button)
    assert error_beside(page, "grid.z").startswith("Field required")
    page.wait_for_timeout(500)
    assert job_count(url) == before
    assert page.text_content("#opt-mu") in ("", "no optimum: see the errors above")


def test_cell_summaries_are_rounded(page: Page, url: str) -> None:
    # A step of 11 decimals: cells at x = -0.18333333333 and the like (a grid's values are the
    # decimals its bounds and step are written in, so 0.05 steps no longer make long floats).
    values = {**SMALL, "x-min": "-0.25", "x-max": "0.0", "x-step": "0.06666666667", "yaws": "0"}
    fill(page, values)
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    grid = {**grid_of(values), "yaw": [0.0]}
    api = httpx.post(
        f"{url}/v1/map", json={"robot": {"model": "ur5"}, "path": EXAMPLE_PATH, "grid": grid}
    ).json()
    cell = next(c for c in api["cells"] if c["mu_path"] is not None and len(repr(c["x"])) > 8)
    page.mouse.click(**cell_point(page, 0, cell, api))
    page.wait_for_function(
        "document.getElementById('cell-summary').textContent.includes('mu_path')",
        timeout=60_000,
    )
    summary = page.text_content("#cell-summary") or ""
    assert summary.startswith(f"x {cell['x']:.4f} m, y {cell['y']:.4f} m, yaw 0.0000 rad: ")
    assert repr(cell["x"]) not in summary


def test_a_programs_feed_is_shown_rounded_in_the_cell_summary(page: Page) -> None:
    """NX's 20 in/min is 0.008466666666666667 m/s: said as every speed on the page, to 1e-6."""
    page.select_option("#path-example", "nx_slot_plate.cls")
    page.wait_for_function(
        "document.getElementById('path-info').textContent.startsWith('nx_slot_plate') && "
        "document.getElementById('import').dataset.waypoints",
        timeout=30_000,
    )
    grid = {"x-min": "0.25", "x-max": "0.3", "x-step": "0.05", "y-min": "0.4", "y-max": "0.45"}
    fill(page, {**SMALL, **grid, "y-step": "0.05", "yaws": "0", "feed": "", "acc-limits": ACC})
    page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    page.locator(".panel canvas").first.focus()
    page.keyboard.press("Enter")  # the cell at x 0.25 m, y 0.4 m: feasible
    page.wait_for_selector("#plot[data-drawn='1']", timeout=60_000)
    summary = page.text_content("#cell-summary") or ""
    assert "; at 0.008467 m/s the largest joint use is " in summary, summary
    acceleration = page.text_content("#acceleration") or ""
    assert "; at 0.008467 m/s the largest acceleration use is " in acceleration, acceleration


@pytest.mark.parametrize("width", [1280, 800])
def test_no_request_of_the_page_fails_and_the_icon_is_served(
    browser: Browser, url: str, width: int
) -> None:
    page = browser.new_page(viewport={"width": width, "height": 900})
    failed: list[str] = []
    page.on("response", lambda r: failed.append(f"{r.status} {r.url}") if r.status >= 400 else 0)
    page.goto(url + "/")
    page.wait_for_selector("body[data-ready='1']", timeout=30_000)
    page.wait_for_load_state("networkidle")
    ARTIFACTS.mkdir(exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / f"web-start-{width}.png"), full_page=True)
    page.close()
    assert failed == []
    icon = httpx.get(f"{url}/favicon.ico")
    assert icon.status_code == 200 and icon.headers["content-type"] == "image/svg+xml"


def test_an_empty_feed_is_left_unset_and_a_zero_feed_is_the_apis_error_beside_it(
    page: Page, url: str
) -> None:
    api = run_small_map(page, url)
    cell = next(c for c in api["cells"] if c["mu_path"] is not None)
    page.fill("#feed", "")
    page.mouse.click(**cell_point(page, 0, cell, api))
    page.wait_for_selector("#plot[data-drawn='1']", timeout=60_000)
    assert (page.text_content("#cell-summary") or "").endswith(
        f"mu_path {cell['mu_path']:.6f} m/s; no feed to check"
    )
    page.fill("#feed", "0")
    page.mouse.click(**cell_point(page, 0, cell, api))
    placement = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"], "spin": 0.0}
    body = {"robot": {"model": "ur5"}, "path": EXAMPLE_PATH, "placement": placement, "feed": 0}
    detail = httpx.post(f"{url}/v1/evaluate", json=body).json()["detail"]
    assert [d["loc"] for d in detail] == [["body", "feed"]]
    assert error_beside(page, "feed") == detail[0]["msg"]
    assert page.get_attribute("#plot", "data-drawn") is None  # the previous cell's plot is gone


def test_an_optimisation_that_finds_nothing_says_why(page: Page, url: str) -> None:
    """Bounds 5 m from a UR5: the page says no placement, and why, in the API's words."""
    far = {**SMALL, "x-min": "5", "x-max": "5.1", "y-min": "5", "y-max": "5.1", "z": "0"}
    fill(page, {**far, "yaws": "0, 0.5"})
    page.click("#optimize")
    page.wait_for_selector("#opt-why:not([hidden])", timeout=120_000)
    body = {
        "robot": {"model": "ur5"},
        "path": EXAMPLE_PATH,
        "method": "casadi",
        "z": 0.0,
        "bounds": {"x": [5.0, 5.1], "y": [5.0, 5.1], "yaw": [0.0, 0.5]},
    }
    api = httpx.post(f"{url}/v1/optimize", json=body, timeout=120).json()
    assert not api["found"] and api["failure"]["tried"]["reasons"][0]["reason"] == "unreachable"
    assert page.text_content("#opt-mu") == "no feasible placement"
    assert page.text_content("#opt-why") == f"Why: {api['failure']['message']}."
    snapshot(page, "optimum-not-found-says-why")
